#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/koiter.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/post_buckling.h"

#include "random_segments.h"
#include "unequal_springs.h"
#include "test_chains.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::kAxial;

/// u on the parent branch at λ: Newton at fixed λ from the parent's tangent line, each step the
/// bordered solve [[F_u, F_λ], [e_λᵀ]] of the chain's structured solver (O(n); dense below its
/// fallback size when the joint block is singular).
Eigen::VectorXd parentAt(EquilibriumProblem& p, const cont::SpecialPoint& bp, const KoiterCoefficients& k,
                         double lambda) {
  const int N = p.dimension();
  Eigen::VectorXd u = bp.u + k.parentSlope * (lambda - bp.lambda), F(N), rhs = Eigen::VectorXd::Zero(N + 1),
                  step(N + 1), c = Eigen::VectorXd::Zero(N + 1);
  c[N] = 1.0;
  const buckle::continuation::BoundProblem solverBound(p);  // outlives the solver
  const auto solver = solverBound.makeStructuredSolver();
  for (int it = 0; it < 30; ++it) {
    REQUIRE(buckle::continuation::BoundProblem(p).residual(u, lambda, F));
    REQUIRE(solver->factor(u, lambda, c) == cont::Factorization::Regular);
    rhs.head(N) = -F;
    REQUIRE(solver->solve(rhs, step));
    u += step.head(N);
    if (step.head(N).norm() <= 1e-15 * (1.0 + u.norm())) break;
  }
  return u;
}

struct Fit {
  double a = 0.0, b = 0.0, c4 = 0.0;
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
  f.c4 = c[3] / std::pow(xiMax, 4);
  return f;
}

/// The tree from the straight chain under decreasing λ: the start branch in coarse steps, the
/// switched ones in fine steps (the fit needs points near the branch point), `childPoints` each.
EquilibriumBranches traceChain(EquilibriumProblem& p, int n, double lambdaMin, int depth, int childPoints = 60,
                               const std::function<bool(const cont::Branch&, const cont::SpecialPoint&)>& at = nullptr) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = lambdaMin;
  o.tracer.lambdaMax = 0.5 * std::abs(lambdaMin);
  o.tracer.step.maxStep = 0.02 * std::abs(lambdaMin);
  o.tracer.maxPoints = 400;
  o.tracer.corrector.tolerance = 1e-12;
  cont::TracerOptions child = o.tracer;
  child.step.maxStep = 0.01;
  child.maxPoints = childPoints;
  o.tree.childTracer = child;
  o.tree.branchSwitching = depth;
  o.tree.switchAt = at;
  o.contact = false;
  return traceEquilibria(p, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
}

/// Every branch point of branch `parent` with children: its reported coefficients against the fit.
int checkAgainstTraced(EquilibriumProblem& p, const EquilibriumBranches& r, int parent, double xiMax,
                       double tolA = 1e-5, double tolB = 1e-4) {
  int checked = 0;
  const cont::Branch& b = r.tree.branches[size_t(parent)];
  for (size_t s = 0; s < b.specialPoints.size(); ++s) {
    if (b.specialPoints[s].type != cont::SpecialPointType::BranchPoint) continue;
    const SpecialPointReport* rep = nullptr;
    for (const SpecialPointReport& x : r.reports[size_t(parent)].specialPoints)
      if (x.source == int(s)) rep = &x;
    REQUIRE(rep);
    const KoiterCoefficients& k = rep->koiter;
    INFO("branch " << parent << ", BP at " << b.specialPoints[s].lambda << ": " << k.message);
    REQUIRE(k.valid);
    const Fit f = fitTracedChildren(p, r.tree, parent, int(s), k, xiMax);
    if (f.points < 8) continue;
    INFO("a = " << k.a << " (fit " << f.a << "), b = " << k.b << " (fit " << f.b << "), " << f.points << " points");
    const double scale = std::max(std::abs(k.b), std::abs(k.a));
    CHECK(std::abs(f.a - k.a) <= tolA * scale);
    CHECK(std::abs(f.b - k.b) <= tolB * scale);
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
      // the O(n) algebra on the bent parent: the same coefficients
      const cont::SpecialPoint& sp = r.tree.branches[b].specialPoints[size_t(s.source)];
      const KoiterCoefficients fast = koiterCoefficients(p, sp, cont::CoefficientAlgebra::Structured);
      INFO(fast.message);
      REQUIRE(fast.valid);
      const double scale = std::max(std::abs(s.koiter.a), std::abs(s.koiter.b));
      CHECK(std::abs(fast.a - s.koiter.a) <= 1e-10 * scale);
      CHECK(std::abs(fast.b - s.koiter.b) <= 1e-9 * scale);
      CHECK(std::abs(fast.transversality / s.koiter.transversality - 1.0) <= 1e-10);
      CHECK((fast.parentSlope - s.koiter.parentSlope).norm() <= 1e-10 * s.koiter.parentSlope.norm());
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
    o.tree.branchSwitching = 0;
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

namespace {
/// The first branch point of the straight chain (end `end`, compressed along x), traced alone.
cont::SpecialPoint firstStraightBranchPoint(EquilibriumProblem& p, double lambdaStop) {
  cont::TracerOptions o;
  o.lambdaMin = lambdaStop;
  o.lambdaMax = 0.5 * std::abs(lambdaStop);
  o.step.maxStep = o.step.initialStep = std::abs(lambdaStop) / 2.7;
  o.step.minStep = 1e-6 * o.step.maxStep;
  o.corrector.tolerance = 1e-12;
  const cont::Branch b = cont::trace(p, Eigen::VectorXd::Zero(p.dimension()), 0.0,
                                     cont::InitialDirection::decreasingLambda(), o);
  const auto bps = b.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  return *bps.front();
}

/// The two compressive critical loads of the straight chain closest to zero (linear_buckling).
std::pair<double, double> firstTwoCriticalLoads(const Chain& chain, const EndCondition& end) {
  LinearBucklingOptions lo;
  lo.count = 8;  // O(n) above kStructuredBucklingFrom segments
  const LinearBucklingResult lb = linearBuckling(chain, Eigen::VectorXd::Zero(chain.size()), end, lo);
  std::vector<double> crit;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0) crit.push_back(m.lambda);
  std::sort(crit.begin(), crit.end(), [](double x, double y) { return x > y; });
  REQUIRE(crit.size() >= 2);
  return {crit[0], crit[1]};
}

}  // namespace

TEST_CASE("Koiter coefficients: the O(n) algebra equals the dense one at n = 40 and 300", "[koiter]") {
  for (int n : {40, 300}) {
    struct Case {
      const char* name;
      SegmentParameters segment;
      EndCondition end;
    };
    EndCondition held = EndCondition::clampedPinned(0.0);
    held.control[2] = Control::Held;
    const Case cases[] = {{"clamped-pinned", SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25), EndCondition::clampedPinned(0.0)},
                          {"y and phi held", SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25), held},
                          {"unequal springs (transcritical)", testing::unequalSprings(), EndCondition::clampedPinned(0.0)}};
    for (const Case& c : cases) {
      INFO("n = " << n << ", " << c.name);
      const Chain chain = Chain::uniform(n, c.segment);
      EquilibriumProblem p(chain, c.end, kAxial);
      const auto crit = firstTwoCriticalLoads(chain, c.end);
      const cont::SpecialPoint bp = firstStraightBranchPoint(p, 0.5 * (crit.first + crit.second));
      const KoiterCoefficients dense = koiterCoefficients(p, bp, cont::CoefficientAlgebra::Dense);
      const KoiterCoefficients fast = koiterCoefficients(p, bp, cont::CoefficientAlgebra::Structured);
      INFO(dense.message << " / " << fast.message);
      REQUIRE(dense.valid);
      REQUIRE(fast.valid);
      INFO("a = " << dense.a << " / " << fast.a << ", b = " << dense.b << " / " << fast.b);
      const double scale = std::max(std::abs(dense.a), std::abs(dense.b));
      CHECK(std::abs(fast.a - dense.a) <= 1e-10 * scale);
      CHECK(std::abs(fast.b - dense.b) <= 1e-10 * scale);
      CHECK(std::abs(fast.transversality / dense.transversality - 1.0) <= 1e-10);
      CHECK((fast.mode - dense.mode).norm() <= 1e-10);
      CHECK(fast.kind == dense.kind);
      // the automatic choice is one of the two (structured above the crossover)
      const KoiterCoefficients automatic = koiterCoefficients(p, bp);
      CHECK(automatic.b == (p.dimension() > cont::kDenseCoefficientDimension ? fast.b : dense.b));
      if (std::string(c.name).rfind("unequal", 0) == 0) CHECK(dense.kind == KoiterKind::Asymmetric);
    }
  }
}

TEST_CASE("Koiter coefficients at n = 1000 (scaled units) against the traced bifurcated branches", "[koiter]") {
  // lengths x1e-3, stiffness x1e6: λ in units of k·b = 1e3; N = 1001 unknowns, the O(n) algebra
  const int n = 1000;
  const double ls = 1e-3, ks = 1e6;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * ls, ls, ks, 2.25 * ls));
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  REQUIRE(p.dimension() > cont::kDenseCoefficientDimension);
  const auto crit = firstTwoCriticalLoads(chain, EndCondition::clampedPinned(0.0));
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = 0.5 * (crit.first + crit.second);
  o.tracer.lambdaMax = -o.tracer.lambdaMin;
  o.tracer.step.maxStep = o.tracer.step.initialStep = std::abs(crit.first) / 2.7;
  o.tracer.step.minStep = 1e-6 * o.tracer.step.maxStep;
  o.tracer.corrector.tolerance = 1e-12;
  cont::TracerOptions child = o.tracer;
  child.lambdaMin = 2.0 * crit.second;
  child.step.maxStep = child.step.initialStep = 0.002;  // scaled arclength: ~ξ (rad) per step
  child.maxPoints = 40;
  o.tree.childTracer = child;
  o.tree.branchSwitching = 1;
  o.contact = false;
  const EquilibriumBranches r =
      traceEquilibria(p, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(r.tree.branches.size() >= 3);
  // the mode's amplitude ξ ≈ θ_max·π/√n: |ξ| ≤ 0.025 keeps the link angles below ~0.25 rad; b to
  // 1e-3 relative (the degree-5 fit's own truncation was 6e-4 over |ξ| ≤ 0.05)
  CHECK(checkAgainstTraced(p, r, 0, 0.025, 1e-5, 1e-3) == 1);
  const SpecialPointReport* rep = nullptr;
  for (const SpecialPointReport& x : r.reports[0].specialPoints)
    if (x.type == EventType::BranchPoint) rep = &x;
  REQUIRE(rep);
  CHECK(rep->koiter.kind == KoiterKind::Supercritical);  // the paper's segments
  CHECK(std::abs(rep->koiter.a) <= 1e-8 * std::abs(rep->koiter.b));
  CHECK(rep->imperfections.size() == 5);  // Fx, y, Me, dL0 of all segments and of the worst one
}

TEST_CASE("Koiter coefficients of the transcritical points of a chain with unequal springs, against the traced branches",
          "[koiter]") {
  const Chain chain = Chain::uniform(3, testing::unequalSprings());
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  const EquilibriumBranches r = traceChain(p, 3, -1.6, 1);
  CHECK(checkAgainstTraced(p, r, 0, 0.15) >= 1);
  int asymmetric = 0;
  for (const SpecialPointReport& s : r.reports[0].specialPoints)
    if (s.type == EventType::BranchPoint && s.koiter.valid && s.koiter.kind == KoiterKind::Asymmetric) {
      CHECK(std::abs(s.koiter.a) > 1e-3 * std::abs(s.koiter.b));
      ++asymmetric;
    }
  CHECK(asymmetric >= 1);
}

TEST_CASE("A degenerate pitchfork (the design map's DP): b zero to its accuracy, the quartic term decides",
          "[koiter]") {
  // a/b = 2: the DP where b changes sign, located by the two-parameter analysis to 4e-13 in L0
  const double dp = 0.6200239760986634;
  auto pointAt = [](double L0, std::vector<double>* c4Fit) {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(2.0, 1.0, 1.0, L0));
    EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
    const EquilibriumBranches r = traceChain(p, 3, -12.0, c4Fit ? 1 : 0);
    for (const SpecialPointReport& s : r.reports[0].specialPoints)
      if (s.type == EventType::BranchPoint && s.koiter.valid) {
        if (c4Fit) c4Fit->push_back(fitTracedChildren(p, r.tree, 0, s.source, s.koiter, 0.15).c4);
        return s.koiter;
      }
    FAIL("no branch point with Koiter coefficients");
    return KoiterCoefficients();
  };
  std::vector<double> fit;
  const KoiterCoefficients k = pointAt(dp, &fit);
  INFO("b = " << k.b << " +- " << k.bAccuracy << ", c4 = " << k.c4 << " +- " << k.c4Accuracy);
  CHECK(std::abs(k.b) <= k.bAccuracy);
  CHECK(k.degenerate);
  REQUIRE(k.decided);
  CHECK(std::abs(k.c4) > 100.0 * k.c4Accuracy);
  // the same quartic term from the traced bifurcated branch (a least-squares fit of its λ(ξ),
  // degree 5 on |ξ| ≤ 0.15: its own truncation is ~c₆ξ² of c₄, a percent)
  REQUIRE(fit.size() == 1);
  INFO("fit c4 = " << fit[0]);
  CHECK(std::abs(fit[0] - k.c4) <= 2e-2 * std::abs(k.c4));
  CHECK(postBucklingName(k) == std::string("degenerate ") + toString(k.kind));
  CHECK(k.kind == (k.c4 * k.transversality < 0.0 ? KoiterKind::Supercritical : KoiterKind::Subcritical));
  // either side of the DP b is well resolved, of opposite signs, and the kinds differ: b changes
  // sign there (the two-parameter location, independent of this reduction)
  const KoiterCoefficients below = pointAt(dp - 1e-4, nullptr), above = pointAt(dp + 1e-4, nullptr);
  CHECK_FALSE(below.degenerate);
  CHECK_FALSE(above.degenerate);
  CHECK(below.b * above.b < 0.0);
  CHECK(below.kind != above.kind);
  // the accuracy is not a blanket: b(L0) ≈ slope·(L0 − DP) is resolved 1e-8 away from the DP
  const double slope = (above.b - below.b) / 2e-4;
  CHECK(k.bAccuracy <= std::abs(slope) * 1e-8);
}

TEST_CASE("The degenerate pitchfork in scaled units: b zero to its accuracy in every unit system", "[koiter]") {
  // lengths ×L, stiffness ×K: λ and b scale with the force K·L; the reduction runs in the
  // problem's own units, so b/(K L) and its accuracy are those of the unscaled chain
  const double dp = 0.6200239760986634;
  for (auto [L, K] : std::vector<std::pair<double, double>>{{1, 1}, {1e-4, 1e8}, {1, 1e8}, {1e-4, 1e4}, {2.0, 1.0}}) {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(2.0 * L, 1.0 * L, 1.0 * K, dp * L));
    EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
    const EquilibriumBranches r = traceChain(p, 3, -12.0 * K * L, 0);
    int found = 0;
    for (const SpecialPointReport& s : r.reports[0].specialPoints)
      if (s.type == EventType::BranchPoint && s.koiter.valid) {
        ++found;
        INFO("L " << L << " K " << K << ": b/(KL) = " << s.koiter.b / (K * L) << " +- " << s.koiter.bAccuracy / (K * L));
        CHECK(std::abs(s.koiter.b) <= s.koiter.bAccuracy);
        CHECK(s.koiter.degenerate);
        // b's slope in L0 is about 0.04 K (L0 in b): the accuracy resolves L0 to 1e-8 of b
        CHECK(s.koiter.bAccuracy <= 0.04 * K * L * 1e-8);
      }
    CHECK(found == 1);
  }
}
