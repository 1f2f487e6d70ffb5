// The continuation core on the chain (issue 3, "Mechanics on the core"): branch points against
// the closed forms (eq 17) and the linear-buckling eigenvalues, the post-buckling branches
// (eq 18, Table I), folds against an independent extended-system solve, and the hard cases.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"
#include "critical_loads.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "buckle/mechanics/wall_contact.h"
#include "curled_chain.h"
#include "wall_statics.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

EquilibriumBranchOptions pinnedOptions(double lambdaMin, int depth) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = lambdaMin;
  o.tracer.lambdaMax = 1.0;
  o.tracer.step.maxStep = 0.05;
  o.tracer.step.initialStep = 0.01;
  o.tracer.maxPoints = 2000;
  o.tree.branchSwitching = depth;
  return o;
}

std::vector<const cont::SpecialPoint*> branchPoints(const cont::Branch& b) {
  return b.specialPointsOfType(cont::SpecialPointType::BranchPoint);
}

// The classification of a special point of branch `bi`.
const Classification& nameOf(const EquilibriumBranches& r, size_t bi, const cont::SpecialPoint* sp) {
  const cont::Branch& b = r.tree.branches[bi];
  return r.classifications[bi][size_t(sp - b.specialPoints.data())];
}

using buckle::mechanics::testing::compressiveCriticalLoads;

}  // namespace

TEST_CASE("n = 3 clamped-pinned: branch points equal the closed forms (17) on a grid", "[equilibrium_branches]") {
  for (double ab : {0.2, 0.5, 0.8}) {
    for (double L0b : {1.9, 2.25, 3.0}) {
      const double a = ab, b = 1.0, k = 1.0, L0 = L0b;
      const AnalyticBuckling3 ref = analyticClampedPinned3(a, b, k, L0);
      if (ref.kappa <= 0.05) continue;  // straight state unstable or degenerate: other tests
      EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0)),
                                 EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
      EquilibriumBranchOptions o = pinnedOptions(1.2 * ref.FxZ, 0);
      const EquilibriumBranches r =
          traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
      const auto bps = branchPoints(r.tree.branches.at(0));
      INFO("a/b=" << ab << " L0/b=" << L0b);
      REQUIRE(bps.size() == 2);
      CHECK(std::abs(bps[0]->lambda - ref.FxU) <= 1e-10);
      CHECK(std::abs(bps[1]->lambda - ref.FxZ) <= 1e-10);
      CHECK(bps[0]->lambdaAccuracy <= 1e-10);
      CHECK(bps[0]->inertiaBefore == 0);
      CHECK(bps[0]->inertiaAfter == 1);
      CHECK(bps[1]->inertiaAfter == 2);
      CHECK(nameOf(r, 0, bps[0]).phenomenon == Phenomenon::Buckling);
      CHECK(nameOf(r, 0, bps[0]).shape == "U");
      CHECK(nameOf(r, 0, bps[1]).shape == "Z");
      CHECK(nameOf(r, 0, bps[1]).stableBefore == false);
    }
  }
}

TEST_CASE("n = 4..50 clamped-pinned: branch points equal the linear-buckling eigenvalues", "[equilibrium_branches]") {
  const SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  for (int n = 4; n <= 50; n += (n < 12 ? 1 : 7)) {
    const Chain chain = Chain::uniform(n, p);
    const std::vector<double> compressive = compressiveCriticalLoads(chain);
    REQUIRE(compressive.size() >= 2);
    // Trace through the first two critical loads (and stop before the third).
    const double stop = compressive.size() > 2 ? 0.5 * (compressive[1] + compressive[2]) : 1.2 * compressive[1];
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
    EquilibriumBranchOptions o = pinnedOptions(stop, 0);
    o.tracer.step.maxStep = std::abs(compressive[0]) / 8;
    o.tracer.step.initialStep = o.tracer.step.maxStep / 2;
    const EquilibriumBranches r =
        traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
    const auto bps = branchPoints(r.tree.branches.at(0));
    INFO("n=" << n);
    REQUIRE(bps.size() == 2);
    for (int i = 0; i < 2; ++i)
      CHECK(std::abs(bps[size_t(i)]->lambda - compressive[size_t(i)]) <= 1e-10 * std::max(1.0, std::abs(compressive[size_t(i)])));
  }
}

TEST_CASE("switching at the branch points: U stable with dx = mu_U b q2^2, Z unstable", "[equilibrium_branches]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  const AnalyticBuckling3 ref = analyticClampedPinned3(a, b, k, L0);
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(-2.5, 1);
  o.tracer.step.maxStep = 0.02;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(r.tree.branches.size() == 5);  // trivial + 2 directions at each of the 2 BPs
  const double length = problem.chain().length();
  int uBranches = 0, zBranches = 0;
  for (size_t bi = 1; bi < r.tree.branches.size(); ++bi) {
    const cont::Branch& br = r.tree.branches[bi];
    REQUIRE(br.parentId == 0);
    REQUIRE(br.points.size() > 5);
    const double bpLambda = r.tree.branches[0].specialPoints.at(size_t(br.parentSpecialPoint)).lambda;
    const bool isU = std::abs(bpLambda - ref.FxU) < 1e-8;
    REQUIRE((isU || std::abs(bpLambda - ref.FxZ) < 1e-8));
    (isU ? uBranches : zBranches)++;
    const double mu = isU ? ref.muU : ref.muZ;
    bool checkedSmall = false;
    // Far out the U branch folds near the joint limits (|Fx| ≈ 1.755 here) and loses stability:
    // the claims below are for the part before the first fold.
    const auto folds = br.specialPointsOfType(cont::SpecialPointType::Fold);
    const size_t end = folds.empty() ? br.points.size() : size_t(folds.front()->index) + 1;
    REQUIRE(end > 5);
    for (size_t pi = 1; pi < end; ++pi) {
      const cont::ContinuationPoint& pt = br.points[pi];
      const Eigen::VectorXd q = pt.u.head(3);
      const double q2 = q[1];
      if (std::abs(q2) < 0.05 && std::abs(q2) > 1e-3) {
        // δx = μ b q2² + O(q2⁴): relative error O(q2²)
        const double dx = length - endPose(problem.chain(), q)[0];
        CHECK(dx == Approx(mu * b * q2 * q2).epsilon(0.02));
        CHECK(shapeName(q, 1e-12) == (isU ? "U" : "Z"));
        checkedSmall = true;
      }
      if (std::abs(q2) > 1e-3) CHECK(pt.stability.negative == (isU ? 0 : 1));
    }
    CHECK(checkedSmall);
  }
  CHECK(uBranches == 2);
  CHECK(zBranches == 2);
}

namespace {
// The AUTO case I_up (free end, κ < 0, Fy = 0.01, Fx moved): the box and range of its fold tests.
EquilibriumBranchOptions iUpOptions() {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = -1.0;
  o.tracer.lambdaMax = 1.0;
  o.tracer.step.maxStep = 0.05;
  o.tracer.maxPoints = 400;
  o.tree.branchSwitching = 0;
  o.tracer.boxLower = Eigen::VectorXd::Constant(4, -3.0);
  o.tracer.boxUpper = Eigen::VectorXd::Constant(4, 3.0);
  return o;
}
}  // namespace

TEST_CASE("fold: free end, kappa < 0, lateral load (AUTO case I_up) against the extended system", "[equilibrium_branches]") {
  // L0 = 0.5 makes κ < 0: the straight state is unstable; Fy = 0.01 selects a bent path that folds.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(0.0, 0.01, 0.0)),
                             Eigen::Vector3d(1, 0, 0), EquilibriumOptions{false});
  EquilibriumBranchOptions o = iUpOptions();
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
  CHECK(r.startUnstable);
  const auto folds = r.tree.branches[0].specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(!folds.empty());
  const cont::SpecialPoint& lp = *folds.front();
  CHECK(lp.lambda == Approx(0.17770974215).margin(5e-11));  // AUTO-07p, 11 digits
  CHECK(lp.refined);
  CHECK(lp.lambdaAccuracy <= 1e-11);
  // λ-component of the tangent and the smallest eigenvalue of K_q − K_g vanish at the fold.
  CHECK(std::abs(lp.tangent[3]) <= 1e-6);
  Eigen::MatrixXd H(3, 3);
  totalPotentialHessian(chain, lp.u, problem.wrench(lp.u, lp.lambda), H);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  Eigen::Index zeroIndex = 0;
  CHECK(es.eigenvalues().cwiseAbs().minCoeff(&zeroIndex) <= 1e-8);
  // Independent solve of the extended system (F = 0, F_u v = 0, v0ᵀv = 1) by Newton with a
  // finite-difference Jacobian, from a perturbed start.
  Eigen::VectorXd z(7);
  z << lp.u + Eigen::VectorXd::Constant(3, 1e-3), lp.lambda + 1e-3, es.eigenvectors().col(zeroIndex);
  const Eigen::Vector3d v0 = es.eigenvectors().col(zeroIndex);
  auto G = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd g(7), F(3), Fl(3);
    Eigen::MatrixXd Fu(3, 3);
    buckle::continuation::BoundProblem(problem).residual(x.head(3), x[3], F);
    buckle::continuation::BoundProblem(problem).jacobian(x.head(3), x[3], Fu, Fl);
    g << F, Fu * x.segment(4, 3), v0.dot(x.segment(4, 3)) - 1.0;
    return g;
  };
  for (int it = 0; it < 30; ++it) {
    const Eigen::VectorXd g = G(z);
    Eigen::MatrixXd Jz(7, 7);
    for (int j = 0; j < 7; ++j) {
      Eigen::VectorXd zp = z, zm = z;
      zp[j] += 1e-7;
      zm[j] -= 1e-7;
      Jz.col(j) = (G(zp) - G(zm)) / 2e-7;
    }
    z -= Jz.partialPivLu().solve(g);
  }
  CHECK(G(z).norm() <= 1e-12);
  CHECK(std::abs(z[3] - lp.lambda) <= 1e-11);
  // Unstable on both sides (index 3 → 2): a fold with no physical event.
  CHECK(lp.inertiaBefore == 3);
  CHECK(lp.inertiaAfter == 2);
  CHECK(nameOf(r, 0, &lp).phenomenon == Phenomenon::None);
}

TEST_CASE("hard case: kappa = 0 double zero at Fx = 0 is detected", "[equilibrium_branches]") {
  // L0 = 2b(1 − (a/b)²) = 1.5: the straight state's Hessian is Fx·G, zero at Fx = 0 (AUTO misses it).
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(-2.5, 0);
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.5, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 1);
  CHECK(bps[0]->multiplicity == 2);
  CHECK(std::abs(bps[0]->lambda) <= 1e-9);
  CHECK(bps[0]->inertiaBefore == 0);
  CHECK(bps[0]->inertiaAfter == 2);
}

TEST_CASE("hard case: a = b (kappa = k b L0) still gives the closed-form branch points", "[equilibrium_branches]") {
  const double a = 1.0, b = 1.0, k = 2.0, L0 = 1.0;
  const AnalyticBuckling3 ref = analyticClampedPinned3(a, b, k, L0);
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const EquilibriumBranches r = traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0,
                                                cont::InitialDirection::decreasingLambda(), pinnedOptions(1.1 * ref.FxZ, 0));
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 2);
  CHECK(std::abs(bps[0]->lambda - ref.FxU) <= 1e-10);
  CHECK(std::abs(bps[1]->lambda - ref.FxZ) <= 1e-10);
}

TEST_CASE("hard case: a path that runs into a joint limit stops exactly on it", "[equilibrium_branches]") {
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.qMinUser = -0.6;
  p.qMaxUser = 0.6;
  const Chain chain = Chain::uniform(3, p);
  // Free end under a growing lateral force: the joints bend until one reaches 0.6.
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 10.0;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  o.contact = false;  // the old behaviour: the branch ends at the limit (contact: test_contact.cpp)
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& br = r.tree.branches[0];
  CHECK(br.stopReason == cont::StopReason::Boundary);
  const auto bds = br.specialPointsOfType(cont::SpecialPointType::Boundary);
  REQUIRE(bds.size() == 1);
  CHECK(bds[0]->u.head(3).cwiseAbs().maxCoeff() == Approx(0.6).margin(1e-12));
  CHECK_THAT(bds[0]->boundaryName, Catch::Contains("limit"));
  CHECK(nameOf(r, 0, bds[0]).phenomenon == Phenomenon::QuasiBuckling);
}

TEST_CASE("hard case: n = 200, closely spaced critical loads all found once", "[equilibrium_branches]") {
  const int n = 200;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  REQUIRE(crit.size() > 6);
  // Range through the first 5 critical loads; with a step larger than their spacing several
  // of them fall inside one step.
  const double stop = 0.5 * (crit[4] + crit[5]);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(stop, 0);
  o.tracer.step.maxStep = std::abs(stop) / 3;
  o.tracer.step.initialStep = o.tracer.step.maxStep;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 5);
  for (size_t i = 0; i < 5; ++i) {
    INFO("critical load " << i);
    CHECK(bps[i]->multiplicity == 1);
    CHECK(std::abs(bps[i]->lambda - crit[i]) <= 1e-9 * std::max(1.0, std::abs(crit[i])));
  }
}

TEST_CASE("hard case: an impossible target is reported and the points before it are kept", "[equilibrium_branches]") {
  // An end torque of 10 cannot be carried: the joints bend until a closing spring reaches zero
  // length, where the model refuses points (joint-limit events switched off here). The corrector
  // must fail there, the step shrink below its minimum, and every point be kept.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1), EquilibriumOptions{false});
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 10.0;
  o.tracer.maxPoints = 5000;
  o.tracer.step.maxStep = 0.05;
  o.tracer.step.minStep = 1e-6;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& br = r.tree.branches[0];
  CHECK(br.stopReason == cont::StopReason::StepSizeTooSmall);
  CHECK_THAT(br.stopMessage, Catch::Contains("KIN_"));
  REQUIRE(br.points.size() > 10);
  for (const cont::ContinuationPoint& pt : br.points) {
    Eigen::VectorXd F(problem.dimension());
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(pt.u, pt.lambda, F));
    CHECK(F.norm() <= 1e-8);
  }
  // The last point is close to a geometric limit: that is what stopped it.
  double closest = 1e9;
  for (int i = 0; i < 3; ++i)
    closest = std::min(closest, chain.segment(i).geometricUpperLimit() - std::abs(br.points.back().u[i]));
  CHECK(closest < 1e-2);
  CHECK(br.points.back().lambda < 10.0);
}

TEST_CASE("hard case: kappa = 0 at n = 4, 5, 10: the (n-1)-fold zero at Fx = 0 is one point", "[equilibrium_branches]") {
  // K_q = 0 on the straight chain: the reduced Hessian is −Fx·G with G definite on ker J_h
  // (dimension n − 1), so all n − 1 eigenvalues cross zero at Fx = 0; for odd n − 1 the
  // determinant changes sign too, and the point must still be reported once.
  for (int n : {4, 5, 10}) {
    INFO("n=" << n);
    EquilibriumProblem problem(Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5)),
                               EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
    const EquilibriumBranches r = traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.5,
                                                  cont::InitialDirection::decreasingLambda(), pinnedOptions(-2.5, 0));
    const auto bps = branchPoints(r.tree.branches.at(0));
    REQUIRE(bps.size() == 1);
    CHECK(bps[0]->multiplicity == n - 1);
    CHECK(std::abs(bps[0]->lambda) <= 1e-9);
    CHECK(bps[0]->inertiaBefore == 0);
    CHECK(bps[0]->inertiaAfter == n - 1);
  }
}

TEST_CASE("hard case: top of the spectrum, n = 60: six critical loads 2e-3 apart, each once, relative 1e-9",
          "[equilibrium_branches]") {
  // Near the most compressive critical load the spacing is ~1/n² (2.1e-3 at |Fx| = 1.5 here).
  // Start between the 7th- and 6th-last loads (index m − 7) and take steps of a third of the range.
  const int n = 60;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  REQUIRE(crit.size() > 8);
  const size_t first = crit.size() - 6;
  const double start = 0.5 * (crit[first - 1] + crit[first]);
  const double stop = crit.back() - 0.5 * (crit[crit.size() - 2] - crit.back());
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(stop, 0);
  o.tracer.lambdaMax = start;
  o.tracer.step.maxStep = o.tracer.step.initialStep = (start - stop) / 3;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), start, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 6);
  for (size_t i = 0; i < 6; ++i) {
    INFO("critical load " << first + i);
    CHECK(bps[i]->multiplicity == 1);
    CHECK(bps[i]->inertiaBefore == int(first + i));
    CHECK(bps[i]->inertiaAfter == int(first + i) + 1);
    CHECK(std::abs(bps[i]->lambda - crit[first + i]) <= 1e-9 * std::abs(crit[first + i]));
  }
}

// ---- above the dense crossover (maxDenseLocationDimension): the O(n) refinements -----------

TEST_CASE("n = 500 clamped-pinned, default options: the clustered low end to 1e-12 relative, with null vectors",
          "[equilibrium_branches]") {
  // N = 501 > maxDenseLocationDimension = 16: located and refined by the structured path. The
  // first critical loads are ~κ/n² with gaps of the same order; a step of a third of the range
  // puts two of them in one step.
  const int n = 500;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  REQUIRE(crit.size() > 4);
  const double stop = 0.5 * (crit[3] + crit[4]);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(stop, 0);
  REQUIRE(problem.dimension() > o.tracer.location.maxDenseDimension);
  o.tracer.step.maxStep = o.tracer.step.initialStep = std::abs(stop) / 3;
  o.tracer.step.minStep = 1e-6 * o.tracer.step.maxStep;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 4);
  const int N = problem.dimension();
  for (size_t i = 0; i < 4; ++i) {
    const cont::SpecialPoint& bp = *bps[i];
    INFO("critical load " << i << ": " << bp.note);
    CHECK(bp.refined);
    CHECK(bp.multiplicity == 1);
    CHECK(std::abs(bp.lambda - crit[i]) <= 1e-12 * std::abs(crit[i]));
    CHECK(bp.u.head(n).cwiseAbs().maxCoeff() <= 1e-14);  // on the straight chain
    // Kernel of F_x: the trivial tangent e_λ and the buckling mode; left null vector = the mode
    // (F_u symmetric, F_λ = 0 on the straight chain).
    REQUIRE(bp.nullVectors.cols() == 2);
    REQUIRE(bp.leftNullVector.size() == N);
    CHECK(std::abs(std::abs(bp.nullVectors(N, 0)) - 1.0) <= 1e-10);
    Vector y(N);
    Vector phi = bp.nullVectors.col(1);
    REQUIRE(buckle::continuation::BoundProblem(problem).jacobianApply(bp.u, bp.lambda, phi, y));
    CHECK(y.norm() <= 1e-10);
    CHECK(std::abs(phi.head(N).dot(bp.leftNullVector)) >= 1.0 - 1e-10);
  }
}

TEST_CASE("structured and dense refinement agree on the same chain (crossover forced)", "[equilibrium_branches]") {
  SECTION("branch points of a clamped-pinned chain of 40 segments") {
    const int n = 40;
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    const std::vector<double> crit = compressiveCriticalLoads(chain);
    REQUIRE(crit.size() > 3);
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
    EquilibriumBranchOptions o = pinnedOptions(0.5 * (crit[2] + crit[3]), 0);
    o.tracer.step.maxStep = o.tracer.step.initialStep = std::abs(crit[0]) / 2.7;
    o.tracer.location.maxDenseDimension = 400;  // N = 41: dense
    const EquilibriumBranches dense =
        traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
    o.tracer.location.maxDenseDimension = 10;
    const EquilibriumBranches fast =
        traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
    const auto d = branchPoints(dense.tree.branches.at(0)), s = branchPoints(fast.tree.branches.at(0));
    REQUIRE(d.size() == 3);
    REQUIRE(s.size() == 3);
    for (size_t i = 0; i < 3; ++i) {
      INFO("branch point " << i);
      CHECK(s[i]->refined);
      CHECK(std::abs(s[i]->lambda - d[i]->lambda) <= 1e-12 * std::abs(d[i]->lambda));
      CHECK(std::abs(s[i]->lambda - crit[i]) <= 1e-12 * std::abs(crit[i]));
      CHECK(std::abs(s[i]->leftNullVector.dot(d[i]->leftNullVector)) >= 1.0 - 1e-9);
      CHECK(std::abs(s[i]->nullVectors.col(1).dot(d[i]->nullVectors.col(1))) >= 1.0 - 1e-9);
      CHECK(std::abs(s[i]->tangent.dot(d[i]->tangent)) >= 1.0 - 1e-9);
    }
  }
  SECTION("the fold of the free end under a lateral load (AUTO case I_up)") {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5));
    EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(0.0, 0.01, 0.0)),
                               Eigen::Vector3d(1, 0, 0));
    EquilibriumBranchOptions o = iUpOptions();
    const EquilibriumBranches dense =
        traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
    o.tracer.location.maxDenseDimension = 1;
    const EquilibriumBranches fast =
        traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
    const auto d = dense.tree.branches[0].specialPointsOfType(cont::SpecialPointType::Fold);
    const auto s = fast.tree.branches[0].specialPointsOfType(cont::SpecialPointType::Fold);
    REQUIRE(!d.empty());
    REQUIRE(s.size() == d.size());
    for (size_t i = 0; i < d.size(); ++i) {
      INFO("fold " << i << ": " << s[i]->note);
      CHECK(s[i]->refined);
      CHECK(std::abs(s[i]->lambda - d[i]->lambda) <= 1e-12 * std::max(1.0, std::abs(d[i]->lambda)));
      CHECK((s[i]->u - d[i]->u).norm() <= 1e-6);
      CHECK(std::abs(s[i]->nullVectors.col(0).dot(d[i]->nullVectors.col(0))) >= 1.0 - 1e-9);
    }
    CHECK(s.front()->lambda == Approx(0.17770974215).margin(5e-11));  // AUTO-07p, 11 digits
  }
}

TEST_CASE("n = 500: the first branch point is switched on both sides above the dense crossover",
          "[equilibrium_branches]") {
  const int n = 500;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  REQUIRE(crit.size() > 2);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(0.5 * (crit[0] + crit[1]), 1);
  o.tracer.step.maxStep = o.tracer.step.initialStep = std::abs(crit[0]) / 2.7;  // no step ends on the point
  o.tracer.step.minStep = 1e-6 * o.tracer.step.maxStep;
  cont::TracerOptions children = o.tracer;
  children.maxPoints = 8;
  children.lambdaMin = 2.0 * crit[1];
  o.tree.childTracer = children;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 1);
  INFO(bps[0]->note);
  CHECK(std::abs(bps[0]->lambda - crit[0]) <= 1e-12 * std::abs(crit[0]));
  REQUIRE(r.tree.branches.size() == 3);
  double sideSign[2] = {0.0, 0.0};
  for (size_t bi = 1; bi < 3; ++bi) {
    const cont::Branch& child = r.tree.branches[bi];
    INFO("child " << bi << ": " << child.stopMessage);
    REQUIRE(child.points.size() >= 3);
    const cont::ContinuationPoint& p = child.points.back();
    // Off the straight chain (a pitchfork leaves along the mode: ‖q‖ ≈ the arclength from the
    // branch point) and an equilibrium; the two sides are mirror images.
    CHECK(p.u.head(n).norm() >= 0.5 * (p.arclength - child.points.front().arclength));
    Vector F(problem.dimension());
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(p.u, p.lambda, F));
    CHECK(F.norm() <= 1e-8);
    sideSign[bi - 1] = p.u[n / 2];
  }
  CHECK(sideSign[0] * sideSign[1] < 0.0);  // the two sides of the pitchfork
}

namespace {

// The κ = 0 straight chain near Fx = 0, independently of the core's reduced equation: with E even
// and its quadratic term zero, E(q_i) = E₀ + e₄q_i⁴ + …, x = x₀ − ½qᵀGq + …, y = J_y q + …, the
// branches leave along the critical lines of f(z) = Σz_i⁴ / (zᵀGz)² on ker J_y (the Lagrange
// condition 4e₄z³ = μGz + ν J_yᵀ of the leading orders). G and J_y from the stability operator at
// q = 0: with K_q = 0 it is H = −Fx·G on ker C, C = J_y.
struct QuarticRatio {
  Eigen::MatrixXd G, Z;  // G (n×n), Z: orthonormal basis of ker J_y (n × (n−1))
  explicit QuarticRatio(EquilibriumProblem& problem) {
    const int n = problem.segments();
    Eigen::MatrixXd H, C;
    Eigen::VectorXd u = Eigen::VectorXd::Zero(problem.dimension());
    REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, 1.0, H, C));
    G = -H;  // Fx = 1
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(C, Eigen::ComputeFullV);
    Z = svd.matrixV().rightCols(n - 1);
  }
  double operator()(const Eigen::VectorXd& z) const {
    const double g = z.dot(G * z);
    return z.array().pow(4).sum() / (g * g);
  }
  // tangential gradient of f on ker J_y at z (f is homogeneous of degree 0: the gradient is tangent)
  Eigen::VectorXd gradient(const Eigen::VectorXd& z) const {
    const double g = z.dot(G * z);
    const Eigen::VectorXd full = 4.0 * z.array().pow(3).matrix() / (g * g) -
                                 4.0 * z.array().pow(4).sum() / (g * g * g) * (G * z);
    return Z * (Z.transpose() * full);
  }
};

EquilibriumBranches kappaZeroTree(EquilibriumProblem& problem, int n) {
  EquilibriumBranchOptions o = pinnedOptions(-0.5, 1);
  o.tracer.lambdaMax = 0.5;
  o.tree.childTracer = o.tracer;
  o.tree.childTracer->maxPoints = 12;
  o.tree.childTracer->step.maxStep = 0.02;
  return traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.3, cont::InitialDirection::decreasingLambda(), o);
}

}  // namespace

TEST_CASE("kappa = 0, n = 3: the double point is switched along every predicted direction", "[equilibrium_branches]") {
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const EquilibriumBranches r = kappaZeroTree(problem, 3);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 1);
  const cont::SpecialPoint& bp = *bps[0];
  CHECK(bp.multiplicity == 2);
  CHECK(std::abs(bp.lambda) <= 1e-12);  // linear buckling: every critical load is 0 (degenerate)
  CHECK(bp.refined);
  // independent count: critical lines of the quartic ratio on the circle of ker J_y (sign changes
  // of df/dθ over a half turn)
  const QuarticRatio f(problem);
  int lines = 0;
  const int samples = 20000;
  const double pi = std::acos(-1.0);
  auto slope = [&](double th) {
    const Eigen::VectorXd z = std::cos(th) * f.Z.col(0) + std::sin(th) * f.Z.col(1);
    const Eigen::VectorXd dz = -std::sin(th) * f.Z.col(0) + std::cos(th) * f.Z.col(1);
    return f.gradient(z).dot(dz);
  };
  for (int k = 0; k < samples; ++k)
    if ((slope(pi * k / samples) > 0.0) != (slope(pi * (k + 1) / samples) > 0.0)) ++lines;
  INFO(bp.note);
  CHECK(bp.branchesPredicted == 2 * lines);
  CHECK(bp.branchesFound == bp.branchesPredicted);
  CHECK(int(r.tree.branches.size()) == 1 + bp.branchesPredicted);
}

TEST_CASE("kappa = 0, n = 4: the triple point, every direction a critical line of the quartic ratio",
          "[equilibrium_branches]") {
  EquilibriumProblem problem(Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const EquilibriumBranches r = kappaZeroTree(problem, 4);
  const auto bps = branchPoints(r.tree.branches.at(0));
  REQUIRE(bps.size() == 1);
  const cont::SpecialPoint& bp = *bps[0];
  CHECK(bp.multiplicity == 3);
  CHECK(std::abs(bp.lambda) <= 1e-12);
  INFO(bp.note);
  CHECK(bp.branchesPredicted >= 6);  // at least the three lines of a Morse function on RP²
  CHECK(bp.branchesFound == bp.branchesPredicted);
  REQUIRE(int(r.tree.branches.size()) == 1 + bp.branchesPredicted);
  // each child's first point is along a critical line of f: the tangential gradient vanishes to
  // O(amplitude²) relative
  const QuarticRatio f(problem);
  for (size_t b = 1; b < r.tree.branches.size(); ++b) {
    const cont::Branch& child = r.tree.branches[b];
    REQUIRE(child.points.size() >= 2);
    const Eigen::VectorXd z = child.points[1].u.head(4).normalized();
    const double amplitude = child.points[1].u.head(4).norm();
    INFO("branch " << b << " amplitude " << amplitude);
    const double g = z.dot(f.G * z);
    const double scale = (4.0 * z.array().pow(3).matrix() / (g * g)).norm();  // one of the gradient's two terms
    CHECK(f.gradient(z).norm() / scale <= 50.0 * amplitude * amplitude + 1e-6);
  }
}

// ---- many special points per step, tiny steps (issue 13: certified counting on long chains) ---

namespace {
// The first `count` compressive critical loads of the straight clamped–pinned chain, closest to 0
// first, by the O(n) route of linear_buckling.h (Sturm counts + Rayleigh quotient).
std::vector<double> firstCriticalLoads(const Chain& chain, int count) {
  LinearBucklingOptions lbo;
  lbo.count = count;
  const LinearBucklingResult lb =
      linearBuckling(chain, Eigen::VectorXd::Zero(chain.size()), EndCondition::clampedPinned(0.0), lbo);
  std::vector<double> crit;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0) crit.push_back(m.lambda);
  std::sort(crit.begin(), crit.end(), [](double x, double y) { return x > y; });
  return crit;
}

// The straight clamped–pinned chain from Fx = 0 down to `stop` in steps `step`, above the dense
// crossover (the O(n) refinements); with childPoints > 0 every branch point switched, its children
// traced in the same steps.
EquilibriumBranches tracePinnedAboveCrossover(const Chain& chain, double stop, double step, int childPoints = 0,
                                              double childLambdaMin = 0.0) {
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(stop, childPoints > 0 ? 1 : 0);
  REQUIRE(problem.dimension() > o.tracer.location.maxDenseDimension);
  o.tracer.step.maxStep = o.tracer.step.initialStep = step;
  o.tracer.step.minStep = 1e-6 * step;
  if (childPoints > 0) {
    cont::TracerOptions children = o.tracer;
    children.maxPoints = childPoints;
    children.lambdaMin = childLambdaMin;
    o.tree.childTracer = children;
  }
  return traceEquilibria(problem, Eigen::VectorXd::Zero(chain.size()), 0.0, cont::InitialDirection::decreasingLambda(), o);
}
}  // namespace

TEST_CASE("n = 1000, soft joints: one step over four critical loads 1e-7 apart finds each once, to 1e-12",
          "[equilibrium_branches]") {
  // κ = k(bL0 − 2(b² − a²)) = 7.5e−3: the critical loads ~κ/n² lie ~1e−7 apart in the chain's force
  // unit k̄b̄, as those of the n = 10 000 chain with κ = 0.75 (RESULTS.md, "Trees of long chains":
  // five in one coarse step, one reported twice and one missed). That is the size of the bracketing
  // secant's tolerance coarseTolerance·max(1, |λ|) = 1e−7: Newton then started next to a neighbour.
  const int n = 1000;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5075));
  const std::vector<double> crit = firstCriticalLoads(chain, 6);
  REQUIRE(crit.size() == 6);
  REQUIRE(crit[1] - crit[0] > -3e-7);  // the spacing this test is about
  const double stop = 0.5 * (crit[4] + crit[5]);
  // the first step, 0.9 of the range, holds the first four critical loads
  REQUIRE(0.9 * std::abs(stop) > std::abs(crit[3]));
  const EquilibriumBranches r = tracePinnedAboveCrossover(chain, stop, 0.9 * std::abs(stop));
  const cont::Branch& trivial = r.tree.branches.at(0);
  const auto bps = branchPoints(trivial);
  REQUIRE(bps.size() == 5);
  int inFirstStep = 0;
  for (size_t i = 0; i < 5; ++i) {
    const cont::SpecialPoint& bp = *bps[i];
    INFO("critical load " << i << ": " << bp.note);
    CHECK(bp.refined);
    CHECK(bp.multiplicity == 1);
    CHECK(std::abs(bp.lambda - crit[i]) <= 1e-12 * std::abs(crit[i]));
    CHECK(bp.inertiaAfter - bp.inertiaBefore == 1);
    if (bp.index == 0) ++inFirstStep;
  }
  CHECK(inFirstStep >= 3);
}

TEST_CASE("n = 10000: the children of a branch point traced in steps of 4e-9 show no folds", "[equilibrium_branches]") {
  // The children in the trivial branch's own steps (benchmarks/RESULTS.md, "Location on long
  // chains"): λ − λ_c ~ λ_c s² with λ_c ~ 1e−7 stays below the rounding of the equations' λ terms,
  // t_λ and the crossing eigenvalue of F_u flip together with rounding from step to step, and the
  // parity check of foldBetween confirmed them: 22 LPs on each child before. The turning is not
  // resolved there (classifyInterval), and the eigenvalue crossing that came with it is the same
  // rounding (no spurious BP either).
  const int n = 10000;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const std::vector<double> crit = firstCriticalLoads(chain, 2);
  REQUIRE(crit.size() == 2);
  const double stop = 0.5 * (crit[0] + crit[1]);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(stop, 1);
  o.tracer.step.maxStep = o.tracer.step.initialStep = std::abs(stop) / 39.0;
  o.tracer.step.minStep = 1e-6 * o.tracer.step.maxStep;
  o.tracer.lambdaMax = 0.0;
  o.tracer.maxPoints = 43;
  o.tracer.detection.lowestEigenvalues = 1;
  cont::TracerOptions child = o.tracer;
  child.step.initialStep = child.step.maxStep = 4e-9;
  child.step.minStep = 1e-6 * child.step.maxStep;
  child.maxPoints = 40;
  child.lambdaMin = 2.0 * crit[1];
  o.tree.childTracer = child;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto& branches = r.tree.branches;
  REQUIRE(branches.size() == 3);
  REQUIRE(branchPoints(branches[0]).size() == 1);
  CHECK(std::abs(branchPoints(branches[0])[0]->lambda - crit[0]) <= 1e-12 * std::abs(crit[0]));
  for (size_t k = 1; k < branches.size(); ++k) {
    INFO("child " << k);
    CHECK(branches[k].points.size() == 40);
    CHECK(branches[k].specialPointsOfType(cont::SpecialPointType::Fold).empty());
    CHECK(branchPoints(branches[k]).empty());
  }
}

TEST_CASE("reports handed over as branches become final equal the kept ones, the traced points are released",
          "[equilibrium_branches]") {
  // The paper's chain to Fx = −2.5: the U branches reach joint 2's limit and go on locked
  // (contact stretches), the − sides are mirror images. Streaming (onReport) must not change
  // one number of any report, and must hand each branch over exactly once.
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(-2.5, 1);
  o.report.stiffness = true;
  const EquilibriumBranches kept =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
  std::vector<std::pair<int, BranchReport>> handed;
  o.onReport = [&](const cont::Branch& b, BranchReport&& report) {
    CHECK(!b.points.empty());  // released only after the hand-over
    handed.emplace_back(b.id, std::move(report));
  };
  const EquilibriumBranches streamed =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(kept.tree.branches.size() == 5);
  REQUIRE(streamed.tree.branches.size() == kept.tree.branches.size());
  REQUIRE(handed.size() == kept.tree.branches.size());
  CHECK(handed.back().first == 0);  // the parent after its children
  bool locked = false;
  for (const auto& [id, report] : handed) {
    const BranchReport& ref = kept.reports.at(size_t(id));
    CHECK(streamed.tree.branches[size_t(id)].points.empty());
    CHECK(streamed.reports[size_t(id)].points.empty());
    CHECK(streamed.tree.branches[size_t(id)].specialPoints.size() == kept.tree.branches[size_t(id)].specialPoints.size());
    REQUIRE(report.points.size() == ref.points.size());
    for (size_t i = 0; i < ref.points.size(); ++i) {
      CHECK(report.points[i].parameter == ref.points[i].parameter);
      CHECK(report.points[i].q == ref.points[i].q);
      CHECK(report.points[i].negative == ref.points[i].negative);
      CHECK((report.points[i].K.array() == ref.points[i].K.array() ||
             (report.points[i].K.array().isNaN() && ref.points[i].K.array().isNaN())).all());
      locked = locked || !ref.points[i].locked.empty();
    }
    REQUIRE(report.specialPoints.size() == ref.specialPoints.size());
    for (size_t s = 0; s < ref.specialPoints.size(); ++s) {
      CHECK(report.specialPoints[s].type == ref.specialPoints[s].type);
      CHECK(report.specialPoints[s].parameter == ref.specialPoints[s].parameter);
      CHECK(report.specialPoints[s].note == ref.specialPoints[s].note);
    }
  }
  CHECK(locked);  // the comparison covered contact stretches
  CHECK(streamed.startUnstable == kept.startUnstable);
}

TEST_CASE("the tree on two and three threads reports what one thread does: stretches, mirror images, contacts",
          "[equilibrium_branches]") {
  // Six segments to Fx = −2.5: five branch points, their U-like children reach joint limits and go
  // on locked, the − sides are mirror images. The children are traced, extended and reported on
  // workers (TreeOptions::threads, childWork); the tree must be the same: ids, parents, the named
  // special points, every reported point (the eigenvalue searches start from the worker's own
  // previous values: the same to rounding).
  EquilibriumProblem problem(Chain::uniform(6, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = pinnedOptions(-2.5, 1);
  auto run = [&](int threads) {
    o.tree.threads = threads;
    std::vector<std::pair<int, BranchReport>> handed;
    o.onReport = [&](const cont::Branch& b, BranchReport&& report) { handed.emplace_back(b.id, std::move(report)); };
    EquilibriumBranches r =
        traceEquilibria(problem, Eigen::VectorXd::Zero(6), 0.0, cont::InitialDirection::decreasingLambda(), o);
    std::sort(handed.begin(), handed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return std::make_pair(std::move(r), std::move(handed));
  };
  const auto [one, oneReports] = run(1);
  REQUIRE(one.tree.branches.size() == 11);
  bool locked = false, mirrored = false;
  for (int threads : {2, 3}) {
    INFO("threads " << threads);
    const auto [many, manyReports] = run(threads);
    REQUIRE(many.tree.branches.size() == one.tree.branches.size());
    REQUIRE(manyReports.size() == oneReports.size());
    for (size_t b = 0; b < one.tree.branches.size(); ++b) {
      INFO("branch " << b);
      const cont::Branch &x = one.tree.branches[b], &y = many.tree.branches[b];
      CHECK(y.parentId == x.parentId);
      CHECK(y.parentSpecialPoint == x.parentSpecialPoint);
      CHECK(y.mirrorOf == x.mirrorOf);
      mirrored = mirrored || x.mirrorOf >= 0;
      REQUIRE(many.classifications[b].size() == one.classifications[b].size());
      for (size_t s = 0; s < one.classifications[b].size(); ++s)
        CHECK(many.classifications[b][s].explanation == one.classifications[b][s].explanation);
      const BranchReport &ref = oneReports[b].second, &got = manyReports[b].second;
      REQUIRE(manyReports[b].first == int(b));
      REQUIRE(got.points.size() == ref.points.size());
      for (size_t i = 0; i < ref.points.size(); ++i) {
        CHECK(std::abs(got.points[i].parameter - ref.points[i].parameter) <= 1e-12 * std::max(1.0, std::abs(ref.points[i].parameter)));
        CHECK((got.points[i].q - ref.points[i].q).norm() <= 1e-12 * std::max(1.0, ref.points[i].q.norm()));
        CHECK(got.points[i].negative == ref.points[i].negative);
        CHECK(got.points[i].locked == ref.points[i].locked);
        CHECK(got.points[i].branch == int(b));
        CHECK(std::abs(got.points[i].minEigenvalue - ref.points[i].minEigenvalue) <=
              1e-9 * std::max(1.0, std::abs(ref.points[i].minEigenvalue)));
        locked = locked || !ref.points[i].locked.empty();
      }
      REQUIRE(got.specialPoints.size() == ref.specialPoints.size());
      for (size_t s = 0; s < ref.specialPoints.size(); ++s) {
        CHECK(got.specialPoints[s].type == ref.specialPoints[s].type);
        CHECK(got.specialPoints[s].branch == int(b));
        CHECK(got.specialPoints[s].stabilityAfter == ref.specialPoints[s].stabilityAfter);
        CHECK(std::abs(got.specialPoints[s].parameter - ref.specialPoints[s].parameter) <=
              1e-12 * std::max(1.0, std::abs(ref.specialPoints[s].parameter)));
      }
    }
  }
  CHECK(locked);    // the comparison covered contact stretches
  CHECK(mirrored);  // and mirror images
}

using testing::curledChain;
using testing::curledShape;
using testing::curledTrace;
using testing::withWall;

TEST_CASE("contact: a branch that runs out of points on a later stretch names the branch's max_points, not the "
          "stretch's share",
          "[equilibrium][contact]") {
  const Chain chain = curledChain(true);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), withWall());
  EquilibriumBranchOptions o = curledTrace(1.0);
  o.tracer.maxPoints = 30;  // past the wall contact near Fy = 0.11 (point ~10), before the release
  const EquilibriumBranches r = traceEquilibria(problem, curledShape(), 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& b = r.tree.branches[0];
  REQUIRE(r.contact[0].size() >= 2);  // it did run into a second stretch
  CHECK(b.stopReason == cont::StopReason::MaxPoints);
  CHECK(int(b.points.size()) == o.tracer.maxPoints);
  INFO(b.stopMessage);
  CHECK(b.stopMessage.rfind("reached maxPoints = 30 ", 0) == 0);
}

TEST_CASE("wall: contact_release no longer passes through the wall, holding segment 5 on it between WC and WR",
          "[equilibrium][wall]") {
  const Chain chain = curledChain(true);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), withWall());
  const EquilibriumBranchOptions o = curledTrace(1.0);
  const EquilibriumBranches r = traceEquilibria(problem, curledShape(), 0.0, cont::InitialDirection::increasingLambda(), o);
  const BranchReport& rep = r.reports[0];
  std::vector<std::string> events;
  for (const SpecialPointReport& sp : rep.specialPoints)
    if (sp.type != EventType::StiffnessMinimum) events.push_back(label(sp.type));
  // SC: the curled start's last link overlaps the clamped triangle (d_self = −0.0058, the links'
  // outlines, contact_geometry.h) and the first pull separates them
  CHECK(events == std::vector<std::string>{"WC", "WR", "CT", "RL", "SC"});
  for (const SpecialPointReport& sp : rep.specialPoints)
    if (sp.type == EventType::SelfContact) CHECK(sp.lambda < 0.01);
  CHECK(selfClearance(chain, curledShape()).distance < 0.0);
  CHECK(r.tree.branches[0].stopReason == cont::StopReason::LambdaRange);
  // every traced point, and every point of the free chain's own trace (wall off) in between,
  // against the test's own vertices (wall_statics.h): the moving triangles' corners and joints
  double deepest = 0.0;
  for (const cont::ContinuationPoint& p : r.tree.branches[0].points)
    deepest = std::min(deepest, buckle::test::smallestVertexX(chain, p.u.head(5)));
  CHECK(deepest >= -1e-12);
  // the wall stretch: vertex 5d- held, pushed (μ ≥ 0); the wall forces 0 at both ends
  const SpecialPointReport* wc = nullptr;
  const SpecialPointReport* wr = nullptr;
  for (const SpecialPointReport& sp : rep.specialPoints) {
    if (sp.type == EventType::WallContact) wc = &sp;
    if (sp.type == EventType::WallRelease) wr = &sp;
  }
  REQUIRE(wc);
  REQUIRE(wr);
  CHECK(wc->vertex == WallVertex{4, 4});
  CHECK(wr->vertex == WallVertex{4, 4});
  CHECK(std::abs(wc->contactForce) <= 1e-12);
  CHECK(std::abs(wr->contactForce) <= 1e-12);
  int held = 0;
  for (const PointReport& pt : rep.points) {
    if (pt.locked.wallCount() == 0) continue;
    ++held;
    CHECK(pt.parameter >= wc->parameter - 1e-12);
    CHECK(pt.parameter <= wr->parameter + 1e-12);
    CHECK(pt.wallForces[0] >= -1e-12);
  }
  CHECK(held >= 3);
  // without the wall the same chain passes through it there
  EquilibriumProblem ghost(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  const EquilibriumBranches g = traceEquilibria(ghost, curledShape(), 0.0, cont::InitialDirection::increasingLambda(), o);
  double ghostDeepest = 0.0;
  for (const cont::ContinuationPoint& p : g.tree.branches[0].points)
    ghostDeepest = std::min(ghostDeepest, buckle::test::smallestVertexX(chain, p.u.head(5)));
  CHECK(ghostDeepest < -1e-2);
}

TEST_CASE("wall: a vertex pressed on the wall releases where the reversed load brings its force back to zero",
          "[equilibrium][wall]") {
  // Leg 1: Fy grows to 0.13, segment 5's distal corner is pressed on the wall (WC near 0.1104).
  const Chain chain = curledChain(false);
  EquilibriumProblem up(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), withWall());
  const EquilibriumBranchOptions o = curledTrace(0.13);
  const EquilibriumBranches r = traceEquilibria(up, curledShape(), 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& leg1 = r.tree.branches[0];
  const ContactSet set = r.contact[0].back().locked;
  REQUIRE(set.wallCount() == 1);
  double contactFy = 0.0;
  for (const SpecialPointReport& sp : r.reports[0].specialPoints)
    if (sp.type == EventType::WallContact) contactFy = sp.parameter;
  REQUIRE(contactFy > 0.1);
  // Leg 2: from the pressed state at Fy = 0.13 the load decreases (Fy = 0.13 − λ).
  EquilibriumProblem down(chain, EndCondition::freeEnd(Eigen::Vector3d(0, 0.13, 0)), Eigen::Vector3d(0, -1, 0), withWall());
  ContactProblem pressed(down, set);
  const Eigen::VectorXd start = pressed.withWallForces(*pressed.createWorkspace(), leg1.points.back().u, 0.0);
  REQUIRE(start[start.size() - 1] > 1e-3);  // pushed
  cont::TracerOptions to = o.tracer;
  to.lambdaMax = 0.13;
  cont::Branch leg2 = cont::trace(pressed, start, 0.0, cont::InitialDirection::increasingLambda(), to);
  REQUIRE(leg2.stopReason == cont::StopReason::Boundary);
  CHECK(leg2.specialPoints.back().boundaryName == wallReleaseName(set.wall()[0]));
  const std::vector<ContactStretch> stretches = continueUnderContact(down, leg2, to, 10.0, set);
  REQUIRE(stretches.size() == 2);
  CHECK(stretches[1].locked.empty());
  CHECK(leg2.stopReason == cont::StopReason::LambdaRange);
  // the release: the wall force's zero, located; the same load as the contact of leg 1 (both are
  // where the free and the pressed equilibria meet with μ = 0)
  const auto found = std::find_if(leg2.specialPoints.begin(), leg2.specialPoints.end(), [&set](const cont::SpecialPoint& sp) {
    return sp.boundaryName == wallReleaseName(set.wall()[0]);
  });
  REQUIRE(found != leg2.specialPoints.end());
  const cont::SpecialPoint& release = *found;
  ContactProblem at(down, set);
  CHECK(std::abs(at.wallForces(*at.createWorkspace(), release.u, release.lambda)[0]) <= 1e-10);
  CHECK(0.13 - release.lambda == Approx(contactFy).epsilon(1e-9));
  // the free branch resumes: clear of the wall, equilibria of the free chain, down to Fy = 0
  Eigen::VectorXd F(down.dimension());
  for (size_t i = size_t(stretches[1].firstPoint); i < leg2.points.size(); ++i) {
    CHECK(nearestWallVertex(chain, leg2.points[i].u.head(5)).distance > 0.0);
    REQUIRE(buckle::continuation::BoundProblem(down).residual(leg2.points[i].u, leg2.points[i].lambda, F));
    CHECK(F.cwiseAbs().maxCoeff() <= 1e-9);
  }
  CHECK(leg2.points.back().lambda == Approx(0.13));
}
