// Hard cases of the chain's continuation (issue 33, docs/continuation.md "Hard cases"): branch
// points crowded at loads 1e-10 of the path's range, switched like any other and at the loads of
// eq 17 scaled by κ; a pitchfork reached along its bifurcated branch, reported once as a branch
// point with its stability on each side.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"
#include "critical_loads.h"
#include "test_chains.h"
#include "buckle/mechanics/load_history.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::kAxial;

using buckle::mechanics::testing::compressiveCriticalLoads;

}  // namespace

TEST_CASE("hard case: three branch points at ~1e-10 of the range are located at kappa times eq 17 and switched",
          "[equilibrium_branches][hard]") {
  // κ = k(b L0 − 2(b² − a²)) = L0 − 1.5 here: the critical loads are κ times those at κ = 1
  // (K_q = κ·I at the straight shape, K_g independent of κ), so at κ = 1e-10 they crowd at
  // ~1e-10 while the path runs to −0.01. The κ the chain sees is L0 − 1.5 in double (exact).
  for (const double scale : {1.0, 1e-4}) {  // lengths ×1e-4, stiffness ×1e8 (loads ×1e4)
    const double L0 = 1.5 + 1e-10, kappa = L0 - 1.5;
    const double ks = scale == 1.0 ? 1.0 : 1e8;
    const Chain reference = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.5));
    std::vector<double> expected = compressiveCriticalLoads(reference);
    REQUIRE(expected.size() == 3);
    const double forceUnit = ks * scale;  // Fx = λκ/b: k·length
    for (double& x : expected) x *= kappa * forceUnit;
    const Chain chain =
        Chain::uniform(4, SegmentParameters::symmetric(0.5 * scale, 1.0 * scale, 1.0 * ks, L0 * scale));
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), kAxial);
    EquilibriumBranchOptions o;
    o.tracer.lambdaMin = -0.01 * forceUnit;
    o.tracer.lambdaMax = 0.0;
    o.tracer.step.maxStep = 0.05;
    o.tracer.step.initialStep = 0.02;
    o.tree.branchSwitching = 1;
    cont::TracerOptions child = o.tracer;
    child.maxPoints = 20;
    o.tree.childTracer = child;
    const EquilibriumBranches r =
        traceEquilibria(problem, Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda(), o);
    INFO("scale " << scale);
    const auto bps = r.tree.branches.at(0).specialPointsOfType(cont::SpecialPointType::BranchPoint);
    REQUIRE(bps.size() == 3);
    for (size_t i = 0; i < 3; ++i) {
      INFO("BP " << i << " at " << bps[i]->lambda << ", expected " << expected[i] << ": " << bps[i]->note);
      // κ is known to the rounding of L0 (its ulp against κ: ~2e-6 relative), not better
      const double known = 16.0 * std::numeric_limits<double>::epsilon() * L0 / kappa;
      CHECK(std::abs(bps[i]->lambda - expected[i]) <= known * std::abs(expected[i]));
      CHECK(bps[i]->note.find("switched") != std::string::npos);
    }
    // every one switched on both sides: 1 + 3·2 branches, each child leaving its own point
    REQUIRE(r.tree.branches.size() == 7);
    for (size_t b = 1; b < 7; ++b) {
      const cont::Branch& c = r.tree.branches[b];
      CHECK(c.parentId == 0);
      CHECK(c.points.size() >= 2);
      CHECK(c.stopReason != cont::StopReason::SwitchFailed);
    }
  }
}

TEST_CASE("hard case: unloading along the U branch to its tip gives one BP, stable on both sides, no fold",
          "[equilibrium_branches][hard]") {
  // the default chain: the U pitchfork at Fx_U = −0.7063 (eq 17), supercritical; the history
  // 0 → −1.7 → 0 follows the U branch out and back to its tip, the same branch point reached
  // along the bifurcated branch, where the U branch turns in Fx
  for (const double scale : {1.0, 1e-4}) {
    const double ks = scale == 1.0 ? 1.0 : 1e8, forceUnit = ks * scale;
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5 * scale, scale, ks, 2.25 * scale));
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), kAxial);
    const AnalyticBuckling3 exact = analyticClampedPinned3(0.5, 1.0, 1.0, 2.25);
    LoadHistoryOptions o;
    o.tracer.step.maxStep = 0.05;
    o.tracer.step.initialStep = 0.02;
    const LoadHistoryResult h =
        followLoadHistory(problem, Eigen::VectorXd::Zero(3), {0.0, -1.7 * forceUnit, 0.0}, o);
    INFO("scale " << scale << ": " << h.message);
    CHECK(h.success);
    CHECK(h.jumps.empty());
    int bps = 0, folds = 0;
    for (size_t s = 0; s < h.segments.size(); ++s)
      for (const cont::SpecialPoint& sp : h.segments[s].specialPoints) {
        INFO("segment " << s << " leg " << h.segmentLeg[s] << ": " << cont::label(sp.type) << " at " << sp.lambda
                        << " " << sp.note);
        const bool atU = std::abs(sp.lambda - exact.FxU * forceUnit) <= 1e-6 * std::abs(exact.FxU * forceUnit);
        if (!atU) continue;
        if (sp.type == cont::SpecialPointType::Fold) ++folds;
        // the unloading leg (towards waypoint 2): the tip reached along the U branch
        if (sp.type == cont::SpecialPointType::BranchPoint && h.segmentLeg[s] == 2) {
          ++bps;
          CHECK(std::abs(sp.lambda - exact.FxU * forceUnit) <= 1e-10 * std::abs(exact.FxU * forceUnit));
          CHECK(sp.inertiaBefore == 0);  // the U branch is stable on both sides of its tip
          CHECK(sp.inertiaAfter == 0);
        }
      }
    CHECK(folds == 0);
    CHECK(bps == 1);
  }
}

TEST_CASE("hard case: kappa = 0, the multiple point at the start of the path is switched like one met on the way",
          "[equilibrium_branches][hard]") {
  // L0 = 1.5: κ = 0, the unloaded straight chain's stiffness is singular and the linear analysis
  // puts all n − 1 compressive critical loads at Fx = 0 (n = 3: a double point, n = 4: a triple
  // one). Traced from Fx = 0 itself, both ways, the point is at the start of both roots; the same
  // tree traced from Fx = 0.3 meets it on the way (test_equilibrium_branches.cpp checks that one's
  // directions against the critical lines of the quartic ratio, the linear analysis at κ = 0): the
  // same directions, all found; in the chain's own units and in lengths ×1e−4, stiffness ×1e8.
  const int n = GENERATE(3, 4);
  const double L = GENERATE(1.0, 1e-4);
  const double K = L == 1.0 ? 1.0 : 1e8, F = K * L;
  INFO("n = " << n << ", lengths x" << L << ", stiffness x" << K);
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, 1.0 * L, 1.0 * K, 1.5 * L));
  for (const double crit : compressiveCriticalLoads(chain)) CHECK(std::abs(crit) <= 1e-12 * F);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), kAxial);
  auto tree = [&](double lambda0, std::vector<cont::InitialDirection> starts) {
    EquilibriumBranchOptions o;
    o.tracer.lambdaMin = -0.5 * F;
    o.tracer.lambdaMax = 0.5 * F;
    o.tracer.step.maxStep = 0.05;
    o.tracer.step.initialStep = 0.01;
    o.tree.branchSwitching = 1;
    cont::TracerOptions child = o.tracer;
    child.maxPoints = 12;
    child.step.maxStep = 0.02;
    o.tree.childTracer = child;
    return traceEquilibria(problem, Eigen::VectorXd::Zero(n), lambda0, starts, o);
  };
  const EquilibriumBranches atStart =
      tree(0.0, {cont::InitialDirection::decreasingLambda(), cont::InitialDirection::increasingLambda()});
  const EquilibriumBranches onTheWay = tree(0.3 * F, {cont::InitialDirection::decreasingLambda()});
  auto multiple = [n](const EquilibriumBranches& r, int& roots) {
    const cont::SpecialPoint* found = nullptr;
    roots = 0;
    for (const cont::Branch& b : r.tree.branches) {
      if (b.parentId >= 0) continue;
      ++roots;
      for (const cont::SpecialPoint& sp : b.specialPoints)
        if (sp.type == cont::SpecialPointType::BranchPoint && sp.multiplicity == n - 1 && sp.branchesPredicted > 0)
          found = &sp;
    }
    return found;
  };
  int roots = 0;
  const cont::SpecialPoint* start = multiple(atStart, roots);
  CHECK(roots == 2);
  REQUIRE(start);
  const cont::SpecialPoint* way = multiple(onTheWay, roots);
  for (const cont::Branch& br : onTheWay.tree.branches)
    for (const cont::SpecialPoint& sp : br.specialPoints)
      UNSCOPED_INFO("on the way: branch " << br.id << " " << label(sp.type) << " at " << sp.lambda << " m "
                                          << sp.multiplicity << " predicted " << sp.branchesPredicted << ": " << sp.note);
  REQUIRE(way);
  INFO(start->note);
  CHECK(std::abs(start->lambda) <= 1e-12 * F);
  CHECK(start->branchesPredicted == way->branchesPredicted);
  CHECK(start->branchesFound == start->branchesPredicted);
  // switched once, not again from the other root (the same point)
  CHECK(int(atStart.tree.branches.size()) == 2 + start->branchesPredicted);
  // the children leave along the same lines (as a set, up to sign)
  std::vector<Eigen::VectorXd> a, b;
  for (const cont::Branch& c : atStart.tree.branches)
    if (c.parentId >= 0 && c.points.size() >= 2) a.push_back(c.points[1].u.head(n).normalized());
  for (const cont::Branch& c : onTheWay.tree.branches)
    if (c.parentId >= 0 && c.points.size() >= 2) b.push_back(c.points[1].u.head(n).normalized());
  REQUIRE(a.size() == b.size());
  for (const Eigen::VectorXd& z : a) {
    double best = 0.0;
    for (const Eigen::VectorXd& w : b) best = std::max(best, std::abs(z.dot(w)));
    CHECK(best >= 0.999);
  }
}

TEST_CASE("hard case: a multiple point above the simple points' dense crossover keeps its dense kernel check",
          "[equilibrium_branches][hard]") {
  // Simple points go to O(N) algebra from N = maxDenseLocationDimension on; a point of multiplicity
  // m ≥ 2 keeps the SVD of F_x up to kMaxDenseMultiplePointDimension, which verifies that ker F_x
  // is (m+1)-dimensional (`refined`) and gives the null vectors its switching starts from. The
  // κ = 0 chain of 6 segments meets its quintuple point at Fx = 0 (N = 7 > 1 here).
  const int n = 6;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), kAxial);
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = -0.5;
  o.tracer.lambdaMax = 0.5;
  o.tracer.step.maxStep = 0.05;
  o.tracer.step.initialStep = 0.01;
  o.tracer.location.maxDenseDimension = 1;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.3, {cont::InitialDirection::decreasingLambda()}, o);
  const auto bps = r.tree.branches.at(0).specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  const cont::SpecialPoint& bp = *bps.front();
  INFO(bp.note);
  CHECK(bp.multiplicity == n - 1);
  CHECK(std::abs(bp.lambda) <= 1e-12);
  CHECK(bp.refined);
  CHECK(bp.augmentedResidualNorm <= 1e-8);
  CHECK(bp.nullVectors.cols() == n);  // the (m+1)-dimensional kernel
}
