#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/koiter.h"
#include "buckle/mechanics/post_buckling.h"

#include "random_segments.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {
const Eigen::Vector3d kAxial(1.0, 0.0, 0.0);

/// u on the parent branch at λ: Newton at fixed λ from the parent's tangent line (dense).
Eigen::VectorXd parentAt(EquilibriumProblem& p, const cont::SpecialPoint& bp, const KoiterCoefficients& k,
                         double lambda) {
  const int N = p.dimension();
  Eigen::VectorXd u = bp.u + k.parentSlope * (lambda - bp.lambda), F(N), Fl(N);
  Eigen::MatrixXd Fu(N, N);
  for (int it = 0; it < 30; ++it) {
    REQUIRE(p.residual(u, lambda, F));
    REQUIRE(p.jacobian(u, lambda, Fu, Fl));
    const Eigen::VectorXd du = Fu.fullPivLu().solve(-F);
    u += du;
    if (du.norm() <= 1e-15 * (1.0 + u.norm())) break;
  }
  return u;
}

struct Fit {
  double a = 0.0, b = 0.0;
  int points = 0;
};

/// λ − λc = Σ_{j=1..5} c_j ξ^j by least squares over the traced points of the branches switched
/// at branch point `sp` of branch `parent` with |ξ| ≤ xiMax, ξ = m·(q − q_p(λ)) the amplitude of
/// the unit joint-angle mode against the parent at the same λ: finite differences of the traced
/// bifurcated branch, independent of the reduction.
Fit fitTracedChildren(EquilibriumProblem& p, const cont::BranchTree& tree, int parent, int sp,
                      const KoiterCoefficients& k, double xiMax) {
  const cont::SpecialPoint& bp = tree.branches[size_t(parent)].specialPoints[size_t(sp)];
  const int n = p.segments();
  std::vector<double> xs, ls;
  for (const cont::Branch& b : tree.branches) {
    if (b.parentId != parent || b.parentSpecialPoint != sp) continue;
    for (size_t i = 1; i < b.points.size(); ++i) {
      const cont::ContinuationPoint& pt = b.points[i];
      const double xi = k.mode.dot(pt.u.head(n) - parentAt(p, bp, k, pt.lambda).head(n));
      if (std::abs(xi) > xiMax) break;
      xs.push_back(xi);
      ls.push_back(pt.lambda - bp.lambda);
    }
  }
  Fit f;
  f.points = int(xs.size());
  if (f.points < 8) return f;
  const int degree = 5;
  Eigen::MatrixXd V(f.points, degree);
  Eigen::VectorXd y(f.points);
  for (int i = 0; i < f.points; ++i) {
    const double s = xs[size_t(i)] / xiMax;  // scaled abscissa: a well-conditioned Vandermonde
    for (int j = 0; j < degree; ++j) V(i, j) = std::pow(s, j + 1);
    y[i] = ls[size_t(i)];
  }
  const Eigen::VectorXd c = V.colPivHouseholderQr().solve(y);
  f.a = c[0] / xiMax;
  f.b = c[1] / (xiMax * xiMax);
  return f;
}

/// The tree from the straight chain under decreasing λ: the start branch in coarse steps, the
/// switched ones in fine steps (the fit needs points near the branch point), `childPoints` each.
EquilibriumBranches traceChain(EquilibriumProblem& p, int n, double lambdaMin, int depth, int childPoints = 60,
                               const std::function<bool(const cont::Branch&, const cont::SpecialPoint&)>& at = nullptr) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = lambdaMin;
  o.tracer.lambdaMax = 0.5 * std::abs(lambdaMin);
  o.tracer.maxStep = 0.02 * std::abs(lambdaMin);
  o.tracer.maxPoints = 400;
  o.tracer.newtonTolerance = 1e-12;
  cont::TracerOptions child = o.tracer;
  child.maxStep = 0.01;
  child.maxPoints = childPoints;
  o.childTracer = child;
  o.switchingDepth = depth;
  o.switchAt = at;
  o.contact = false;
  return traceEquilibria(p, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
}

/// Every branch point of branch `parent` with children: its reported coefficients against the fit.
int checkAgainstTraced(EquilibriumProblem& p, const EquilibriumBranches& r, int parent, double xiMax) {
  int checked = 0;
  const cont::Branch& b = r.tree.branches[size_t(parent)];
  for (size_t s = 0; s < b.specialPoints.size(); ++s) {
    if (b.specialPoints[s].type != cont::SpecialPointType::BranchPoint) continue;
    const SpecialPointReport* rep = nullptr;
    for (const SpecialPointReport& x : r.reports[size_t(parent)].specialPoints)
      if (x.source == int(s)) rep = &x;
    REQUIRE(rep);
    const KoiterCoefficients& k = rep->koiter;
    INFO("branch " << parent << ", BP at " << b.specialPoints[s].lambda << ": " << k.error);
    REQUIRE(k.valid);
    const Fit f = fitTracedChildren(p, r.tree, parent, int(s), k, xiMax);
    if (f.points < 8) continue;
    INFO("a = " << k.a << " (fit " << f.a << "), b = " << k.b << " (fit " << f.b << "), " << f.points << " points");
    const double scale = std::max(std::abs(k.b), std::abs(k.a));
    CHECK(std::abs(f.a - k.a) <= 1e-5 * scale);
    CHECK(std::abs(f.b - k.b) <= 1e-4 * scale);
    ++checked;
  }
  return checked;
}
}  // namespace

TEST_CASE("Koiter coefficients of the n = 3 paper chain's U and Z points against the traced branches", "[koiter]") {
  // the paper's chain (supercritical) and a tall-triangle one (subcritical U point)
  for (double a : {0.5, 2.5}) {
    const double L0 = a < 1 ? 2.25 : 0.5;
    INFO("a = " << a);
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(a, 1.0, 1.0, L0));
    EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
    const EquilibriumBranches r = traceChain(p, 3, a < 1 ? -1.6 : -12.0, 1);
    CHECK(checkAgainstTraced(p, r, 0, 0.15) >= (a < 1 ? 2 : 1));
    // the first point's kind against the atlas' classification (the traced branch's stability)
    const FirstBuckling fb = firstBuckling(chain, EndCondition::clampedPinned(0.0), kAxial, Eigen::VectorXd::Zero(3));
    for (const SpecialPointReport& s : r.reports[0].specialPoints)
      if (s.type == EventType::BranchPoint && std::abs(s.lambda - fb.critical) <= 1e-9 * std::abs(fb.critical)) {
        CHECK(s.koiter.a == 0.0);  // symmetric pitchfork of the straight chain (E even in q)
        CHECK(std::string(toString(s.koiter.kind)) == toString(fb.kind));
      }
  }
}

TEST_CASE("Koiter coefficients at a secondary branch point of a bent branch", "[koiter]") {
  // five segments, y and φ held, compressed by Fx: the third mode's bent branch (symmetric
  // under reversal) loses its symmetry at a secondary pitchfork, Fx ≈ −2.245
  const Chain chain = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EndCondition end = EndCondition::clampedPinned(0.0);
  end.control[2] = Control::Held;
  EquilibriumProblem p(chain, end, kAxial);
  const auto at = [](const cont::Branch& b, const cont::SpecialPoint& bp) {
    return b.id == 0 ? bp.lambda < -1.3 : bp.lambda > -2.4;
  };
  const EquilibriumBranches r = traceChain(p, 5, -2.4, 2, 400, at);
  int secondary = 0;
  for (size_t b = 1; b < r.tree.branches.size(); ++b) {
    for (const SpecialPointReport& s : r.reports[b].specialPoints) {
      if (s.type != EventType::BranchPoint || !s.koiter.valid) continue;
      CHECK(s.q.cwiseAbs().maxCoeff() > 0.3);  // bent
      CHECK(std::abs(s.koiter.a) <= 1e-8 * std::abs(s.koiter.b));  // symmetry-breaking pitchfork
      CHECK(s.koiter.parentSlope.head(5).norm() > 0.1);  // the parent is not a trivial branch
    }
    secondary += checkAgainstTraced(p, r, int(b), 0.15);
  }
  CHECK(secondary >= 1);
}

TEST_CASE("Koiter coefficients of a random non-uniform chain against the traced branches", "[koiter]") {
  std::mt19937 rng(11);
  std::vector<SegmentParameters> segments;
  std::uniform_real_distribution<double> A(0.3, 0.7), B(0.8, 1.3), K(0.5, 2.0), L(2.0, 2.6);
  for (int i = 0; i < 4; ++i) segments.push_back(SegmentParameters::symmetric(A(rng), B(rng), K(rng), L(rng)));
  const Chain chain(segments);
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  const EquilibriumBranches r = traceChain(p, 4, -1.5, 1);
  CHECK(checkAgainstTraced(p, r, 0, 0.15) >= 1);
}

TEST_CASE("Koiter coefficients scale with the units: lengths x1e-3, stiffness x1e6", "[koiter]") {
  const double ls = 1e-3, ks = 1e6;
  auto bps = [](double l, double k) {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5 * l, l, k, 2.25 * l));
    EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
    EquilibriumBranchOptions o;
    o.tracer.lambdaMin = -1.6 * k * l;
    o.tracer.lambdaMax = 1.0 * k * l;
    o.switchingDepth = 0;
    const EquilibriumBranches r =
        traceEquilibria(p, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
    std::vector<KoiterCoefficients> out;
    for (const SpecialPointReport& s : r.reports[0].specialPoints)
      if (s.type == EventType::BranchPoint) out.push_back(s.koiter);
    return out;
  };
  const std::vector<KoiterCoefficients> one = bps(1.0, 1.0), scaled = bps(ls, ks);
  REQUIRE(one.size() == 2);
  REQUIRE(scaled.size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    REQUIRE(one[i].valid);
    REQUIRE(scaled[i].valid);
    // ξ is an angle; λ a force, unit k·b
    CHECK(std::abs(scaled[i].b - one[i].b * ks * ls) <= 1e-8 * std::abs(one[i].b) * ks * ls);
    CHECK(std::abs(scaled[i].a) <= 1e-12 * std::abs(scaled[i].b));
    CHECK(scaled[i].kind == one[i].kind);
  }
}
