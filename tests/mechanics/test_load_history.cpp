// Hysteresis: a bistable segment (κ < 0) under an end torque cycled up and down snaps at the
// folds of its torque–angle curve, from the closed form, and each snap releases energy; and a
// history held at the base wall, against the tests' own statics (wall_statics.h).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/shape_name.h"

#include "curled_chain.h"
#include "wall_statics.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;
using buckle::test::smallestVertexX;
using buckle::test::Statics;
using buckle::test::vertexAt;
using buckle::test::wallStatics;

namespace {

// Symmetric segment: M(q) = 2k[(b² − a²) sin q − b L0 sin(q/2)] (eq 10). Its folds under an end
// torque are where dM/dq = 0: with c = cos(q/2), 2(b² − a²)c² − (b L0/2)c − (b² − a²) = 0.
double foldTorque(double a, double b, double k, double L0) {
  const double A = 2 * (b * b - a * a), B = -0.5 * b * L0, C = -(b * b - a * a);
  const double c = (-B + std::sqrt(B * B - 4 * A * C)) / (2 * A);
  const double q = 2 * std::acos(c);
  return 2 * k * ((b * b - a * a) * std::sin(q) - b * L0 * std::sin(q / 2));  // M at the fold (q > 0)
}

}  // namespace

TEST_CASE("bistable segment under a cycled end torque: unstable start, two snaps per cycle at the folds",
          "[load_history]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 1.4;  // κ = k(bL0 − 2(b² − a²)) = −0.1 < 0
  EquilibriumProblem problem(Chain::uniform(1, SegmentParameters::symmetric(a, b, k, L0)), EndCondition::freeEnd(),
                             Eigen::Vector3d(0, 0, 1));
  const double Mfold = foldTorque(a, b, k, L0);  // equilibrium M + Me = 0: folds at Me = ±|Mfold|
  REQUIRE(Mfold > 0.0);
  LoadHistoryOptions o;
  o.tracer.step.maxStep = 0.005;
  o.tracer.step.initialStep = 0.001;
  const std::vector<double> waypoints = {0.0, 0.05, -0.05, 0.05};
  const LoadHistoryResult r = followLoadHistory(problem, Eigen::VectorXd::Zero(1), waypoints, o);
  INFO(r.message);
  REQUIRE(r.success);
  REQUIRE(r.jumps.size() >= 3);
  CHECK(r.jumps[0].trigger == JumpTrigger::UnstableStart);
  int folds = 0;
  for (const JumpRecord& j : r.jumps) {
    CHECK(j.success);
    CHECK(j.energyReleased > 0.0);
    if (j.trigger != JumpTrigger::Fold) continue;
    ++folds;
    CHECK(std::abs(j.criticalLambda) == Approx(Mfold).epsilon(1e-9));
    // It snaps to the other side: the joint angle changes sign.
    CHECK(j.from[0] * j.to[0] < 0.0);
  }
  // 0 → 0.05 → −0.05 → 0.05 crosses ±Mfold at least twice after the start jump.
  CHECK(folds >= 2);
  // Every followed piece is stable and an equilibrium.
  for (const cont::Branch& s : r.segments)
    for (const cont::ContinuationPoint& p : s.points) {
      CHECK(p.stability.negative == 0);
      Eigen::VectorXd F(1);
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(p.u, p.lambda, F));
      CHECK(std::abs(F[0]) <= 1e-9);
    }
  // Hysteresis: on the way down the snap happens at −Mfold, on the way up at +Mfold.
  bool up = false, down = false;
  for (const JumpRecord& j : r.jumps) {
    if (j.trigger != JumpTrigger::Fold) continue;
    if (j.criticalLambda > 0) up = true;
    if (j.criticalLambda < 0) down = true;
  }
  CHECK(up);
  CHECK(down);
}

TEST_CASE("load history rejects bad input", "[load_history]") {
  EquilibriumProblem problem(Chain::uniform(1, SegmentParameters::symmetric(0.5, 1, 1, 2.25)), EndCondition::freeEnd(),
                             Eigen::Vector3d(0, 0, 1));
  LoadHistoryOptions o;
  CHECK_THROWS_WITH(followLoadHistory(problem, Eigen::VectorXd::Zero(1), {0.0}, o), Catch::Contains("two waypoints"));
  CHECK_THROWS_WITH(followLoadHistory(problem, Eigen::VectorXd::Zero(1), {0.0, std::nan("")}, o),
                    Catch::Contains("finite"));
  o.overshoot = -1;
  CHECK_THROWS_WITH(followLoadHistory(problem, Eigen::VectorXd::Zero(1), {0.0, 1.0}, o), Catch::Contains("overshoot"));
}

TEST_CASE("the default chain compressed past its buckling load follows the U branch from the pitchfork",
          "[load_history]") {
  // The paper's chain (a = 0.5, b = 1, k = 1, L0 = 2.25), clamped-pinned, Fx from 0 to -1.7: the
  // straight branch loses stability at the supercritical pitchfork Fx_U (eq 17); the chain does
  // not jump there but bends into the stable U branch and follows it, back to Fx = 0 unloading.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  LoadHistoryOptions options;
  options.tracer.step.maxStep = 0.05;
  const AnalyticBuckling3 exact = analyticClampedPinned3(0.5, 1.0, 1.0, 2.25);
  const LoadHistoryResult h = followLoadHistory(problem, Eigen::VectorXd::Zero(3), {0.0, -1.7, 0.0}, options);
  INFO(h.message);
  REQUIRE(h.success);
  CHECK(h.jumps.empty());  // buckling without a jump, and unloading back along the same branches
  REQUIRE(h.segments.size() == 4);
  REQUIRE(h.segmentBifurcated.size() == h.segments.size());

  // 1. the straight branch, up to the branch point
  const cont::Branch& straight = h.segments[0];
  CHECK_FALSE(h.segmentBifurcated[0]);
  CHECK(straight.points.back().lambda == Approx(exact.FxU).epsilon(1e-12));
  for (const cont::ContinuationPoint& p : straight.points) CHECK(p.u.head(3).cwiseAbs().maxCoeff() < 1e-12);

  // 2. the U branch from there to the waypoint, stable all the way
  CHECK(h.segmentBifurcated[1]);
  const cont::Branch& u = h.segments[1];
  CHECK(u.points.front().lambda == Approx(exact.FxU).epsilon(1e-12));
  CHECK(u.points.back().lambda == Approx(-1.7).margin(1e-12));
  for (size_t i = 1; i < u.points.size(); ++i) {
    const Eigen::VectorXd q = u.points[i].u.head(3);
    CHECK(shapeName(q, 1e-9) == "U");       // Table I: the one-bow shape
    CHECK(u.points[i].lambda < exact.FxU);  // supercritical: the load keeps growing
    CHECK(u.points[i].stability.negative == 0);
    Eigen::VectorXd F(problem.dimension());
    buckle::continuation::BoundProblem(problem).residual(u.points[i].u, u.points[i].lambda, F);
    CHECK(F.norm() < 1e-9);                 // in equilibrium
  }
  // 3. unloading: back along U to the branch point (where U ends), then along the straight branch
  CHECK(h.segments[2].points.back().lambda == Approx(exact.FxU).epsilon(1e-9));
  CHECK(h.segmentBifurcated[3]);
  CHECK(h.segments[3].points.back().lambda == Approx(0.0).margin(1e-12));
  CHECK(h.segments[3].points.back().u.head(3).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("compressed to -2.5, the default chain leaves the U branch by a jump at its fold", "[load_history]") {
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  LoadHistoryOptions options;
  options.tracer.step.maxStep = 0.05;
  const LoadHistoryResult h = followLoadHistory(problem, Eigen::VectorXd::Zero(3), {0.0, -2.5}, options);
  INFO(h.message);
  REQUIRE(h.segments.size() >= 2);
  CHECK(h.segmentBifurcated[1]);
  // the U branch is followed to its fold (the one the tracer locates on it), where the chain jumps
  const auto folds = h.segments[1].specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(folds.size() == 1);
  CHECK(folds[0]->lambda == Approx(-1.7554).margin(1e-4));
  REQUIRE(!h.jumps.empty());
  CHECK(h.jumps[0].trigger == JumpTrigger::Fold);
  CHECK(h.jumps[0].fromSegment == 1);
  CHECK(h.jumps[0].criticalLambda == folds[0]->lambda);
  // The snap runs joint 2 into its geometric limit, which holds it (one-sided contact): the
  // chain lands on a stable constrained equilibrium and the history goes on, locked, to -2.5.
  REQUIRE(h.jumps[0].success);
  REQUIRE(h.jumps[0].contactSides.size() == 3);
  CHECK(h.jumps[0].contactSides[1] == 1);
  CHECK(h.jumps[0].to[1] == chain.upperLimits()[1]);
  CHECK(h.jumps[0].contactTorques[1] < 0.0);  // compressive at an upper limit
  // the contact torque closes joint 2's balance: τ_c = ∂E/∂q_2 − (JᵀF)_2 with the landing's wrench
  Eigen::VectorXd g(3);
  totalPotentialGradient(chain, h.jumps[0].to.head(3), h.jumps[0].load, g);
  CHECK(h.jumps[0].contactTorques[1] == Approx(g[1]).epsilon(1e-9));
  CHECK(std::abs(g[0]) < 1e-10);
  CHECK(std::abs(g[2]) < 1e-10);
  CHECK(h.success);
  INFO(h.message);
  REQUIRE(h.jumps[0].toSegment >= 0);
  const cont::Branch& after = h.segments[size_t(h.jumps[0].toSegment)];
  CHECK(after.points.back().lambda == Approx(-2.5));
  for (const cont::ContinuationPoint& p : after.points) CHECK(p.u[1] == chain.upperLimits()[1]);  // still locked
}

TEST_CASE("load history at the base wall: held on it to the waypoint, released where the reversed load brings its "
          "force back to zero",
          "[load_history][wall]") {
  // contact_release's curled chain (curled_chain.h), free end, Fy from 0 up to 0.13 and back:
  // on the way up segment 5's distal corner reaches the wall and is held on it; on the way down
  // it leaves the wall where its wall force returns to zero, at the load where it came.
  const Chain chain = testing::curledChain(false);
  const double L = chain.linkLengths().sum();
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  LoadHistoryOptions o;
  o.tracer.step.initialStep = 0.01;
  o.tracer.step.maxStep = 0.02;
  o.jump.wall = true;
  const LoadHistoryResult h = followLoadHistory(problem, testing::curledShape(), {0.0, 0.13, 0.0}, o);
  INFO(h.message);
  REQUIRE(h.success);
  CHECK(h.jumps.empty());
  REQUIRE(h.segments.size() == 2);
  REQUIRE(h.segmentContacts.size() == 2);
  const WallVertex v{4, 4};
  // every point clear of the wall or on it, the held vertex's force that of the test's statics
  int onWall = 0;
  for (size_t k = 0; k < 2; ++k)
    for (size_t i = 0; i < h.segments[k].points.size(); ++i) {
      const cont::ContinuationPoint& p = h.segments[k].points[i];
      const Eigen::VectorXd q = p.u.head(5);
      CHECK(smallestVertexX(chain, q) >= -1e-12 * L);
      const ContactSet& set = lockedAt(h.segmentContacts[k], int(i));
      if (set.wallCount() == 0) continue;
      ++onWall;
      REQUIRE(set.wallCount() == 1);
      CHECK(set.wall()[0] == v);
      CHECK(std::abs(vertexAt(chain, q, v).x()) <= 1e-12 * L);
      const Statics s = wallStatics(chain, q, Eigen::Vector2d(0.0, p.lambda), v);
      CHECK(s.imbalance <= 1e-10);
      CHECK(s.mu >= -1e-12);
      ContactProblem held(problem, set);
      CHECK(held.wallForces(*held.createWorkspace(), p.u, p.lambda)[0] == Approx(s.mu).margin(1e-10));
    }
  CHECK(onWall >= 4);
  // leg 1: free, then on the wall from the contact to the waypoint; leg 2: on the wall from the
  // waypoint to the release, then free again
  REQUIRE(h.segmentContacts[0].size() == 2);
  REQUIRE(h.segmentContacts[1].size() == 2);
  CHECK(h.segmentContacts[0][1].locked.wallCount() == 1);
  CHECK(h.segmentContacts[1][0].locked.wallCount() == 1);
  CHECK(h.segmentContacts[1][1].locked.wallCount() == 0);
  const cont::ContinuationPoint& contact = h.segments[0].points[size_t(h.segmentContacts[0][1].firstPoint - 1)];
  const cont::ContinuationPoint& release = h.segments[1].points[size_t(h.segmentContacts[1][1].firstPoint - 1)];
  // both events on the wall with zero force: the same state of the chain, reached from both sides
  for (const cont::ContinuationPoint* e : {&contact, &release}) {
    CHECK(std::abs(vertexAt(chain, e->u.head(5), v).x()) <= 1e-12 * L);
    CHECK(std::abs(wallStatics(chain, e->u.head(5), Eigen::Vector2d(0.0, e->lambda), v).mu) <= 1e-10);
  }
  CHECK(release.lambda == Approx(contact.lambda).epsilon(1e-10));
  CHECK((release.u.head(5) - contact.u.head(5)).cwiseAbs().maxCoeff() <= 1e-8);
  // the continuation's wall contact on the same chain (equilibrium_branches.h) at the same load
  const EquilibriumBranches traced = traceEquilibria(problem, testing::curledShape(), 0.0,
                                                     cont::InitialDirection::increasingLambda(), testing::curledTrace(0.13));
  const auto& sps = traced.tree.branches[0].specialPoints;
  const auto wc = std::find_if(sps.begin(), sps.end(),
                               [](const cont::SpecialPoint& sp) { return sp.boundaryName == EquilibriumProblem::wallBoundaryName(); });
  REQUIRE(wc != sps.end());
  CHECK(contact.lambda == Approx(wc->lambda).epsilon(1e-10));
  // without the wall the same history passes through it
  EquilibriumProblem ghost(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  const LoadHistoryResult through = followLoadHistory(ghost, testing::curledShape(), {0.0, 0.13}, o);
  REQUIRE(through.success);
  CHECK(smallestVertexX(chain, through.segments.back().points.back().u.head(5)) < -1e-3 * L);
}
