// A third-party use of the continuation core: the two-bar von Mises truss. Two linear springs
// (axial stiffness k, unloaded length L0 = sqrt(a² + h²)) meet at an apex of height w above
// their supports at ±a; a load P pushes the apex down. The potential Π(w) = k (L − L0)² − P (h − w),
// L = sqrt(a² + w²), gives the one-unknown problem
//   F(w, P) = dΠ/dw = 2k w (1 − L0/L) + P = 0,   F_w = 2k (1 − L0 a²/L³) = d²Π/dw²,   F_P = 1,
// whose limit points (snap-through) are at L*³ = L0 a², i.e. w* = ±sqrt(L*² − a²) and
// P* = ±2k w* (L0/L* − 1). The program traces the branch from the unloaded truss and exits
// non-zero unless each located fold agrees with the closed form within its reported accuracy.
#include <buckle/continuation/tracer.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace bc = buckle::continuation;

class VonMisesTruss : public bc::Problem {
 public:
  VonMisesTruss(double a, double h, double k) : a_(a), h_(h), k_(k), L0_(std::hypot(a, h)) {}
  int dimension() const override { return 1; }
  bool residual(bc::ProblemWorkspace &, bc::ConstVectorRef u, double P, bc::VectorRef F) const override {
    F[0] = 2.0 * k_ * u[0] * (1.0 - L0_ / std::hypot(a_, u[0])) + P;
    return std::isfinite(F[0]);
  }
  bool jacobian(bc::ProblemWorkspace &, bc::ConstVectorRef u, double, bc::MatrixRef Fu,
                bc::VectorRef FP) const override {
    const double L = std::hypot(a_, u[0]);
    Fu(0, 0) = 2.0 * k_ * (1.0 - L0_ * a_ * a_ / (L * L * L));
    FP[0] = 1.0;
    return std::isfinite(Fu(0, 0));
  }
  // F is the gradient of Π: its Jacobian is the stiffness, stable where positive.
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(bc::ProblemWorkspace &ws, bc::ConstVectorRef u, double P, bc::Matrix &H,
                         bc::Matrix &C) const override {
    H.resize(1, 1);
    bc::Vector FP(1);
    C.resize(0, 1);
    return jacobian(ws, u, P, H, FP);
  }
  // Units: the rise h for w, the shallow-truss limit load k h³/a² for P and F.
  bc::ProblemScales scales() const override {
    bc::ProblemScales s = bc::ProblemScales::ones(1);
    s.unknowns[0] = h_;
    s.parameter = s.residuals[0] = k_ * h_ * h_ * h_ / (a_ * a_);
    s.stability = k_;
    return s;
  }
  double limitLoad(double sign) const {
    const double L = std::cbrt(L0_ * a_ * a_);
    return sign * 2.0 * k_ * std::sqrt(L * L - a_ * a_) * (L0_ / L - 1.0);
  }
  // F's largest term, 2k|w|L0/L: F (and so P) is computed to about one rounding of it.
  double roundingOfF(double w) const {
    return std::numeric_limits<double>::epsilon() * 2.0 * k_ * std::abs(w) * L0_ / std::hypot(a_, w);
  }

 private:
  double a_, h_, k_, L0_;
};

int main() {
  VonMisesTruss truss(/*a [m]*/ 2.0, /*h [m]*/ 0.3, /*k [N/m]*/ 5.0e6);
  bc::TracerOptions options;
  options.lambdaMax = 2.0 * truss.limitLoad(1.0);  // past the snap back to the inverted truss
  const bc::Branch branch =
      bc::trace(truss, bc::Vector::Constant(1, 0.3), 0.0, bc::InitialDirection::increasingLambda(), options);
  std::printf("branch: %zu points, stopped: %s\n", branch.points.size(), bc::toString(branch.stopReason));
  int folds = 0, failures = 0;
  for (const bc::SpecialPoint &sp : branch.specialPoints) {
    std::printf("%-2s w = %-10.6g P = %-14.10g stability %d -> %d", bc::label(sp.type), sp.u[0],
                sp.lambda, sp.inertiaBefore, sp.inertiaAfter);
    if (sp.type == bc::SpecialPointType::Fold) {
      const double exact = truss.limitLoad(sp.u[0] > 0.0 ? 1.0 : -1.0);
      const double error = std::abs(sp.lambda - exact);
      const bool ok = error <= sp.lambdaAccuracy + truss.roundingOfF(sp.u[0]);
      std::printf("  closed form %.10g, |error| %.2g, reported accuracy %.2g %s", exact, error, sp.lambdaAccuracy,
                  ok ? "ok" : "DISAGREES");
      ++folds;
      failures += ok ? 0 : 1;
    }
    std::printf("\n");
  }
  if (folds != 2) std::printf("expected 2 limit points (snap-through and snap-back), found %d\n", folds);
  return folds == 2 && failures == 0 ? 0 : 1;
}
