// Unit-scaling invariance of the chain's continuation (issue 6, hard case "extreme units";
// issue 12): lengths ×L and spring stiffnesses ×k scale every load by F₀ = k·L (eq 17: Fx = λ k
// [b L0 − 2(b² − a²)] / b) and leave the angles unchanged, so located points must scale exactly —
// with the same solver options for every scaling, because the core works in the chain's own
// units (EquilibriumProblem::scales(), continuation/scaled_problem.h): step sizes are
// dimensionless and every tolerance relative. All scalings L ∈ {1e-3, 1, 1e3},
// k ∈ {1e-6, 1e-3, 1, 1e3, 1e6} for the branch points and for the fold (before the scaled core,
// 10 of them failed: benchmarks/RESULTS.md, "Extreme units").
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/linear_buckling.h"
#include "relative_error.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

const std::vector<double> kScales = {1e-3, 1.0, 1e3};
const std::vector<double> kStiffnessScales = {1e-6, 1e-3, 1.0, 1e3, 1e6};

using buckle::test::relativeError;

// The AUTO-07p harness's options (DS = 0.01, DSMAX = 0.05, DSMIN = 1e-4), λ range
// [lambdaMin, lambdaMax]: the same (dimensionless) steps for every unit system.
cont::TracerOptions options(double lambdaMin, double lambdaMax) {
  cont::TracerOptions o;
  o.step.initialStep = 0.01;
  o.step.maxStep = 0.05;
  o.step.minStep = 1e-4;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = lambdaMax;
  o.maxPoints = 20000;
  return o;
}

// Trivial branch of the clamped–pinned chain (a, b, L0) = (0.5, 2.25)·L, stiffness k.
std::vector<cont::SpecialPoint> trivialBranchPoints(double L, double k) {
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const double F0 = k * L;
  const cont::Branch br = cont::trace(problem, Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda(),
                                      options(-2.5 * F0, 0.0));
  std::vector<cont::SpecialPoint> out;
  for (const cont::SpecialPoint* sp : br.specialPointsOfType(cont::SpecialPointType::BranchPoint)) out.push_back(*sp);
  return out;
}

// Free end, L0 = 0.5 L (κ < 0), lateral end force 0.01 F₀, Fx increasing: AUTO's I_up.
std::vector<cont::SpecialPoint> folds(double L, double k) {
  const double F0 = k * L;
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, k, 0.5 * L)),
                             EndCondition::freeEnd(Eigen::Vector3d(0, 0.01 * F0, 0)), Eigen::Vector3d(1, 0, 0));
  const cont::Branch br = cont::trace(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(),
                                      options(-3.0 * F0, 3.0 * F0));
  std::vector<cont::SpecialPoint> out;
  for (const cont::SpecialPoint* sp : br.specialPointsOfType(cont::SpecialPointType::Fold)) out.push_back(*sp);
  return out;
}

// The U branch of the clamped–pinned chain, switched to at the first branch point (the
// library's bifurcatingDirection and switchBranch, given the point in the user's units), to its
// end on the user joint limit |q| = 1.5 (AUTO's A_U): (Fx there, max |q|).
std::pair<double, double> limitEnd(double L, double k) {
  SegmentParameters p = SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L);
  p.qMinUser = -1.5;
  p.qMaxUser = 1.5;
  EquilibriumProblem problem(Chain::uniform(3, p), EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  cont::Tracer tracer(problem, options(-3.0 * k * L, 0.0));
  const cont::Branch trivial = tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda());
  const auto bps = trivial.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  Eigen::VectorXd direction;
  REQUIRE(cont::bifurcatingDirection(problem, *bps[0], direction));
  const cont::Branch u = cont::switchBranch(tracer, *bps[0], direction, 1);
  const auto bds = u.specialPointsOfType(cont::SpecialPointType::Boundary);
  REQUIRE(bds.size() == 1);
  return {bds[0]->lambda, bds[0]->u.head(3).cwiseAbs().maxCoeff()};
}

}  // namespace

TEST_CASE("unit scaling: branch switching reaches the same joint limit in every unit system", "[unit_scaling]") {
  const std::pair<double, double> reference = limitEnd(1.0, 1.0);
  CHECK(std::abs(reference.second - 1.5) <= 1e-12);
  for (double L : kScales)
    for (double k : {1e-6, 1.0, 1e6}) {
      INFO("lengths x" << L << ", stiffness x" << k);
      const std::pair<double, double> end = limitEnd(L, k);
      CHECK(relativeError(end.first, k * L * reference.first) <= 1e-10);
      CHECK(std::abs(end.second - 1.5) <= 1e-12);
    }
}

TEST_CASE("unit scaling: branch points scale as k L and match eq 17 for lengths x1e-3..x1e3, stiffness x1e-6..x1e6",
          "[unit_scaling]") {
  const std::vector<cont::SpecialPoint> reference = trivialBranchPoints(1.0, 1.0);
  REQUIRE(reference.size() == 2);
  for (double L : kScales)
    for (double k : kStiffnessScales) {
      INFO("lengths x" << L << ", stiffness x" << k);
      const AnalyticBuckling3 exact = analyticClampedPinned3(0.5 * L, L, k, 2.25 * L);
      const std::vector<cont::SpecialPoint> bps = trivialBranchPoints(L, k);
      REQUIRE(bps.size() == 2);
      CHECK(relativeError(bps[0].lambda, exact.FxU) <= 1e-9);
      CHECK(relativeError(bps[1].lambda, exact.FxZ) <= 1e-9);
      CHECK(relativeError(bps[0].lambda, k * L * reference[0].lambda) <= 1e-12);
      CHECK(relativeError(bps[1].lambda, k * L * reference[1].lambda) <= 1e-12);
      CHECK(bps[0].u.head(3).cwiseAbs().maxCoeff() <= 1e-12);  // on the straight branch
      CHECK(bps[0].multiplicity == 1);
      CHECK(bps[1].multiplicity == 1);
      CHECK(bps[0].inertiaBefore == 0);
      CHECK(bps[0].inertiaAfter == 1);
      CHECK(bps[1].inertiaAfter == 2);
    }
}

TEST_CASE("unit scaling: the fold scales as k L, its joint angles are unit-free, lengths x1e-3..x1e3, stiffness x1e-6..x1e6", "[unit_scaling]") {
  const std::vector<cont::SpecialPoint> reference = folds(1.0, 1.0);
  REQUIRE(reference.size() == 1);
  CHECK(reference[0].lambda == Approx(0.1777097421507).margin(1e-12));  // ref.py (shared/peers/auto07p)
  for (double L : kScales)
    for (double k : kStiffnessScales) {
      INFO("lengths x" << L << ", stiffness x" << k);
      const std::vector<cont::SpecialPoint> lps = folds(L, k);
      REQUIRE(lps.size() == 1);
      CHECK(relativeError(lps[0].lambda, k * L * reference[0].lambda) <= 1e-10);
      CHECK((lps[0].u - reference[0].u).cwiseAbs().maxCoeff() <= 1e-10);
      CHECK(lps[0].inertiaBefore == 3);
      CHECK(lps[0].inertiaAfter == 2);
    }
}
