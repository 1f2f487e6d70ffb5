// The contact problem's stability on the reduced chain structure (mechanics/contact_stability.cpp):
// the eigenvalue rates of a locked stretch by Hellmann–Feynman (ContactProblem::stabilitySlopes)
// against central differences of its own eigenvalues along the tangent, and the bound on every
// eigenvalue's rate (stabilityRateBound) against the dense spectra's, at random points of a
// chain past the dense routes, with none, one and two held end coordinates, in two unit systems.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "random_segments.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

TEST_CASE("contact stability: the eigenvalue rates of a locked stretch equal differences of its eigenvalues",
          "[contact_stability]") {
  const int n = 120;
  for (const double unit : {1.0, 1e-4}) {  // lengths ×1e−4 with stiffness ×1e8: the same rates, scaled
    INFO("length unit " << unit);
    std::mt19937 rng(120);
    testing::SegmentRanges ranges;
    ranges.aLo *= unit, ranges.aHi *= unit, ranges.bLo *= unit, ranges.bHi *= unit;
    ranges.LLo *= unit, ranges.LHi *= unit;
    const double stiffness = unit == 1.0 ? 1.0 : 1e8;
    ranges.kLo *= stiffness, ranges.kHi *= stiffness;
    const Chain chain(testing::randomSegments(rng, n, ranges));
    const double force = stiffness * unit;  // k b: the forces' unit
    std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.3, 0.3);
    const std::vector<EndCondition> ends = {EndCondition::freeEnd(), EndCondition::clampedPinned(0.0),
                                            EndCondition::heldPosition(0.0, 0.0)};
    for (const EndCondition& end : ends) {
      INFO("held end coordinates " << end.heldIndices().size());
      EquilibriumProblem problem(chain, end, Eigen::Vector3d(1.0, 0.3, 0.2 * unit));
      ContactSet locked;
      locked.lock(7, LimitSide::Upper);
      locked.lock(61, LimitSide::Lower);
      locked.lock(100, LimitSide::Upper);
      const ContactProblem contact(problem, locked);
      const int N = contact.dimension();
      Eigen::VectorXd u(N), du(N);
      for (int i = 0; i < N; ++i) {
        u[i] = i < n ? Q(rng) : force * W(rng);
        du[i] = i < n ? W(rng) : force * W(rng);
      }
      for (const LockedJoint& l : locked.joints()) du[l.joint] = 0.0;  // a locked joint stays at its limit
      du /= du.head(n).norm();
      const double lambda = -0.5 * force, dlambda = 0.3 * force;
      auto ws = contact.createWorkspace();
      cont::StabilityInfo info;
      REQUIRE(contact.stability(*ws, u, lambda, 0, info));
      const int first = std::max(0, info.negative - 1);
      Eigen::VectorXd mu(2), slopes(2);
      REQUIRE(contact.stabilityEigenvalues(*ws, u, lambda, first, mu));
      REQUIRE(contact.stabilitySlopes(*ws, u, lambda, du, dlambda, first, mu, slopes));
      // central differences: O(h²) from the third derivative, the eigenvalues' own accuracy / h
      const double h = 1e-5;
      Eigen::VectorXd plus(2), minus(2);
      REQUIRE(contact.stabilityEigenvalues(*ws, u + h * du, lambda + h * dlambda, first, plus));
      REQUIRE(contact.stabilityEigenvalues(*ws, u - h * du, lambda - h * dlambda, first, minus));
      const Eigen::VectorXd differenced = (plus - minus) / (2.0 * h);
      const double scale = stiffness * unit * unit;  // k b²: the operator's unit
      for (int j = 0; j < 2; ++j) {
        INFO("eigenvalue " << first + j << " = " << mu[j] << ", rate " << slopes[j] << ", differenced "
                           << differenced[j]);
        CHECK(std::abs(slopes[j] - differenced[j]) <= 1e-7 * scale);
        CHECK(std::abs(slopes[j]) > 1e-3 * scale);  // a rate that is there, not a vanishing one
      }
      // the bound on every eigenvalue's rate holds for all of them (dense spectra, differenced)
      double bound = 0.0;
      REQUIRE(contact.stabilityRateBound(*ws, u, lambda, du, dlambda, bound));
      const int count = n - int(locked.joints().size()) - int(end.heldIndices().size());
      Eigen::VectorXd all(count), allPlus(count), allMinus(count);
      REQUIRE(contact.cont::Problem::stabilityEigenvalues(*ws, u + h * du, lambda + h * dlambda, 0, allPlus));
      REQUIRE(contact.cont::Problem::stabilityEigenvalues(*ws, u - h * du, lambda - h * dlambda, 0, allMinus));
      const double fastest = ((allPlus - allMinus) / (2.0 * h)).cwiseAbs().maxCoeff();
      INFO("bound " << bound << ", fastest eigenvalue " << fastest);
      CHECK(fastest <= bound);
      CHECK(bound < 1e3 * fastest);  // a bound, not infinity
    }
  }
}

TEST_CASE("contact stability: with a vertex on the wall the rates and their bound are not offered (its row moves)",
          "[contact_stability]") {
  std::mt19937 rng(7);
  const int n = 60;
  const Chain chain(testing::randomSegments(rng, n));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  ContactSet locked;
  locked.lock(10, LimitSide::Upper);
  locked.touch(WallVertex{2, 3});
  const ContactProblem contact(problem, locked);
  auto ws = contact.createWorkspace();
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(contact.dimension(), 0.1);
  Eigen::VectorXd du = Eigen::VectorXd::Zero(contact.dimension()), mu(1), slopes(1);
  du[0] = 1.0;
  mu[0] = 0.0;
  CHECK_FALSE(contact.stabilitySlopes(*ws, u, -0.5, du, 0.1, 0, mu, slopes));
  double bound = 0.0;
  CHECK_FALSE(contact.stabilityRateBound(*ws, u, -0.5, du, 0.1, bound));
}

TEST_CASE("contact stability: a locked stretch carries the certified counting's eigenvalues next to zero",
          "[contact_stability]") {
  // As test_contact's n = 50 chain: the root joint locks and the branch goes on locked. Every
  // point of the locked stretch has the two eigenvalues next to zero (the hidden-crossing monitor
  // runs there too), equal to the dense eigen-solve of the locked problem at the point, and the
  // bound on their rates that lets a step skip measuring them.
  const int n = 50;
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  std::vector<SegmentParameters> segs(size_t(n), p);
  segs[0].qMaxUser = 0.02;
  const Chain chain(segs);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 0.01;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& branch = r.tree.branches.at(0);
  const BranchReport& rep = r.reports.at(0);
  REQUIRE(rep.points.size() == branch.points.size());
  int checked = 0;
  for (const PointReport& pr : rep.points) {
    if (pr.locked.empty()) continue;
    const cont::ContinuationPoint& point = branch.points[size_t(pr.index)];
    INFO("point " << pr.index);
    REQUIRE(point.spectrum.valid());
    CHECK(std::isfinite(point.spectrum.rateBound));
    const ContactProblem locked(problem, pr.locked);
    auto ws = locked.createWorkspace();
    Eigen::VectorXd dense(point.spectrum.count);
    REQUIRE(locked.cont::Problem::stabilityEigenvalues(*ws, point.u, point.lambda, point.spectrum.first, dense));
    for (int j = 0; j < point.spectrum.count; ++j) CHECK(point.spectrum.values[j] == Approx(dense[j]).margin(1e-10));
    ++checked;
  }
  CHECK(checked >= 3);
}
