// A third-party problem given by its residual alone (buckle::continuation::NumericDiffProblem:
// every derivative by finite differences): a steep two-bar truss braced by a lateral spring.
// Two linear bars (stiffness k, unloaded length L0 = sqrt(a² + h²)) join the supports (∓a, 0) to
// the apex (u, w); a lateral spring c holds the apex at u = 0 and a load P pushes it down. The
// potential Π = k/2 [(L1 − L0)² + (L2 − L0)²] + c/2 u² + P w, L1,2 = |(u ± a, w)|, gives
//   F = ∇Π = (k(1 − L0/L1)(u + a) + k(1 − L0/L2)(u − a) + c u,  k(1 − L0/L1) w + k(1 − L0/L2) w + P),
// whose Jacobian the user does not write. On the symmetric branch u = 0 (L1 = L2 = L):
//   P = −2k w (1 − L0/L); a limit point (snap-through) where ∂²Π/∂w² = 0, L³ = L0 a²; a branch
//   point (the apex swaying sideways) where ∂²Π/∂u² = 2k(1 − L0/L + L0 a²/L³) + c = 0, i.e. at the
//   roots of (1 + c/2k) L³ − L0 L² + L0 a² = 0 in a < L < L0 (two of them for a truss this steep).
// The program traces the symmetric branch from the unloaded truss and exits non-zero unless it
// finds the two branch points and the limit point, each where the closed form puts it to the
// accuracy of the finite differences.
#include <buckle/continuation/numeric_diff.h>
#include <buckle/continuation/tracer.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace bc = buckle::continuation;

class BracedTruss : public bc::NumericDiffProblem {
 public:
  BracedTruss(double a, double h, double k, double c) : a_(a), h_(h), k_(k), c_(c), L0_(std::hypot(a, h)) {}
  int dimension() const override { return 2; }
  bool residual(bc::ProblemWorkspace &, bc::ConstVectorRef x, double P, bc::VectorRef F) const override {
    const double u = x[0], w = x[1];
    const double s1 = k_ * (1.0 - L0_ / std::hypot(u + a_, w)), s2 = k_ * (1.0 - L0_ / std::hypot(u - a_, w));
    F[0] = s1 * (u + a_) + s2 * (u - a_) + c_ * u;
    F[1] = (s1 + s2) * w + P;
    return F.allFinite();
  }
  // F is the gradient of Π: the stability operator is its Jacobian (here the differenced one).
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(bc::ProblemWorkspace &ws, bc::ConstVectorRef x, double P, bc::Matrix &H,
                         bc::Matrix &C) const override {
    H.resize(2, 2);
    C.resize(0, 2);
    bc::Vector FP(2);
    return jacobian(ws, x, P, H, FP);
  }
  // Units: the span a for u, the rise h for w, k h for P and F (the steps of the differences are
  // relative to these).
  bc::ProblemScales scales() const override {
    bc::ProblemScales s = bc::ProblemScales::ones(2);
    s.unknowns << a_, h_;
    s.parameter = k_ * h_;
    s.residuals.setConstant(k_ * h_);
    s.stability = k_;
    return s;
  }
  /// P on the symmetric branch where the bars have length L.
  double loadAt(double L) const { return -2.0 * k_ * std::sqrt(L * L - a_ * a_) * (1.0 - L0_ / L); }
  double limitLoad() const { return loadAt(std::cbrt(L0_ * a_ * a_)); }
  /// The loads of the branch points: the roots of the cubic on each side of its minimum.
  std::vector<double> branchLoads() const {
    const double beta = 1.0 + c_ / (2.0 * k_);
    auto cubic = [&](double L) { return beta * L * L * L - L0_ * L * L + L0_ * a_ * a_; };
    const double bottom = 2.0 * L0_ / (3.0 * beta);
    std::vector<double> loads;
    for (const auto &[lo0, hi0] : {std::pair{a_, bottom}, std::pair{bottom, L0_}}) {
      double lo = lo0, hi = hi0;
      if (!(lo < hi) || cubic(lo) * cubic(hi) > 0.0) continue;
      while (true) {  // bisection down to adjacent doubles
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (cubic(lo) * cubic(mid) <= 0.0 ? hi : lo) = mid;
      }
      loads.push_back(loadAt(0.5 * (lo + hi)));
    }
    return loads;
  }

 private:
  double a_, h_, k_, c_, L0_;
};

int main() {
  BracedTruss truss(/*a [m]*/ 1.0, /*h [m]*/ 4.0, /*k [N/m]*/ 1.0e5, /*c [N/m]*/ 1.0e3);
  bc::TracerOptions options;
  options.lambdaMin = -0.5 * truss.limitLoad();  // past the snap-through, into the inverted truss
  options.lambdaMax = 2.0 * truss.limitLoad();
  const bc::Branch branch = bc::trace(truss, (bc::Vector(2) << 0.0, 4.0).finished(), 0.0,
                                      bc::InitialDirection::increasingLambda(), options);
  std::printf("symmetric branch: %zu points, stopped: %s\n", branch.points.size(), bc::toString(branch.stopReason));

  // The located points sit where the *differenced* Jacobian is singular: off the exact point by
  // the differences' error, ~ε^{2/3} ≈ 4e-11 of the terms of F; 1e-9 of the load scale k h is
  // that with a margin.
  const double tolerance = 1e-9 * truss.scales().parameter;
  const std::vector<double> bps = truss.branchLoads();
  int folds = 0, branchPoints = 0, failures = 0;
  for (const bc::SpecialPoint &sp : branch.specialPoints) {
    std::printf("%-2s u = %-10.3g w = %-10.6g P = %-14.10g stability %d -> %d", bc::label(sp.type), sp.u[0], sp.u[1],
                sp.lambda, sp.inertiaBefore, sp.inertiaAfter);
    double exact = NAN;
    if (sp.type == bc::SpecialPointType::Fold) {
      exact = truss.limitLoad();
      ++folds;
    } else if (sp.type == bc::SpecialPointType::BranchPoint) {
      for (const double P : bps)
        if (std::isnan(exact) || std::abs(P - sp.lambda) < std::abs(exact - sp.lambda)) exact = P;
      ++branchPoints;
    }
    if (!std::isnan(exact)) {
      const bool ok = std::abs(sp.lambda - exact) <= tolerance;
      std::printf("  closed form %.10g, |error| %.2g %s", exact, std::abs(sp.lambda - exact), ok ? "ok" : "DISAGREES");
      failures += ok ? 0 : 1;
    }
    std::printf("\n");
  }
  const bool complete = folds == 1 && branchPoints == 2 && bps.size() == 2;
  if (!complete) std::printf("expected 1 limit point and 2 branch points, found %d and %d\n", folds, branchPoints);
  return complete && failures == 0 ? 0 : 1;
}
