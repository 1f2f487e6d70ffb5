// The base wall as a barrier of the dynamics (dynamics.h, IntegrationOptions::admissible) and the
// landing on it (wall_landing.h), against the test's own geometry and statics.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/wall_landing.h"

#include "curled_chain.h"
#include "test_geometry.h"
#include "wall_statics.h"

using namespace buckle::mechanics;

namespace {

using buckle::test::across;
using buckle::test::along;
using buckle::test::geometry;
using buckle::test::moment;
using buckle::test::Geometry;
using buckle::test::smallestVertexX;
using buckle::test::Statics;
using buckle::test::vertexAt;
using buckle::test::wallStatics;

double chainLength(const Chain& chain) { return chain.linkLengths().sum(); }

// The curled chain of contact_release (no joint stop) under an end force Fy applied at once: its
// gradient flow swings segment 5's distal triangle round towards the clamp's wall.
constexpr double kFy = 0.13;

IntegrationOptions recorded() {
  IntegrationOptions o;
  o.recordTrajectory = true;
  return o;
}

}  // namespace

TEST_CASE("barrier: the sudden-load flow of the curled chain passes the wall without it and stops on it with it",
          "[wall][dynamics]") {
  const Chain chain = testing::curledChain(false);
  const EndCondition end = EndCondition::freeEnd(Wrench(0.0, kFy, 0.0));
  const Eigen::VectorXd q0 = testing::curledShape();
  REQUIRE(smallestVertexX(chain, q0) > 0.0);
  const double L = chainLength(chain);

  // Without the barrier some vertex goes behind the wall (the free flow ignores it).
  std::unique_ptr<DynamicsModel> free = makeDynamicsModel(chain, end, DynamicsScene(), q0);
  const DynamicsResult through = simulate(*free, q0, Vector(), recorded());
  double deepest = std::numeric_limits<double>::infinity();
  for (const TrajectorySample& s : through.trajectory) deepest = std::min(deepest, smallestVertexX(chain, s.q));
  INFO("without the barrier: " << through.message << ", deepest vertex x " << deepest);
  REQUIRE(deepest < -1e-3 * L);

  // With it the flow stops where the first vertex reaches x = 0, within the step tolerance.
  std::unique_ptr<DynamicsModel> model = makeDynamicsModel(chain, end, DynamicsScene(), q0);
  IntegrationOptions o = recorded();
  o.admissible = wallBarrier(chain);
  const DynamicsResult stopped = simulate(*model, q0, Vector(), o);
  INFO(stopped.message);
  REQUIRE(stopped.reason == IntegrationStop::Barrier);
  CHECK(std::abs(smallestVertexX(chain, stopped.q)) <= 1e-9 * L);
  CHECK(smallestVertexX(chain, stopped.q) >= 0.0);
  // the first time the free flow reaches the wall is where the barrier stopped it
  double tFirst = std::numeric_limits<double>::infinity();
  for (const TrajectorySample& s : through.trajectory)
    if (smallestVertexX(chain, s.q) < 0.0) {
      tFirst = s.t;
      break;
    }
  CHECK(stopped.time <= tFirst);
  // before the stop: a gradient flow, Π never increases, no vertex behind the wall
  REQUIRE(stopped.trajectory.size() > 10);
  for (size_t k = 1; k < stopped.trajectory.size(); ++k) {
    const TrajectorySample &a = stopped.trajectory[k - 1], &b = stopped.trajectory[k];
    INFO("sample " << k << " t = " << b.t);
    CHECK(b.potential <= a.potential + 1e-12 * std::max(1.0, std::abs(a.potential)));
    CHECK(smallestVertexX(chain, b.q) >= 0.0);
  }
  // a start behind the wall stops at once
  Eigen::VectorXd behind = stopped.q;
  behind[4] += 0.05 * (through.q[4] - stopped.q[4]) / std::max(1e-300, std::abs(through.q[4] - stopped.q[4]));
  if (smallestVertexX(chain, behind) < 0.0) {
    const DynamicsResult none = simulate(*model, behind, Vector(), o);
    CHECK(none.reason == IntegrationStop::Barrier);
    CHECK(none.steps == 0);
  }
}

namespace {

// The smallest eigenvalue of the Hessian of Π − μ x_v (the test's own: the library's Π Hessian,
// ∂²x_v by central differences of vertexAt) on the kernel of ∇x_v (central differences).
double constrainedLowest(const Chain& chain, const Eigen::VectorXd& q, const Wrench& W, const WallVertex& v, double mu) {
  const int n = chain.size();
  Eigen::MatrixXd H(n, n);
  totalPotentialHessian(chain, q, W, H);
  const double h = 1e-4;
  Eigen::MatrixXd grad(1, n);  // (a dynamic matrix: the QR's Q below is then n×n)
  auto x = [&](const Eigen::VectorXd& qq) { return vertexAt(chain, qq, v).x(); };
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd a = q, b = q;
    a[j] += 1e-6;
    b[j] -= 1e-6;
    grad(0, j) = (x(a) - x(b)) / 2e-6;
    for (int l = 0; l < n; ++l) {
      Eigen::VectorXd pp = q, pm = q, mp = q, mm = q;
      pp[j] += h, pp[l] += h, pm[j] += h, pm[l] -= h, mp[j] -= h, mp[l] += h, mm[j] -= h, mm[l] -= h;
      H(j, l) -= mu * (x(pp) - x(pm) - x(mp) + x(mm)) / (4 * h * h);
    }
  }
  H = 0.5 * (H + H.transpose()).eval();
  const Eigen::MatrixXd Gt = grad.transpose();
  const Eigen::MatrixXd Z = Gt.fullPivHouseholderQr().matrixQ().rightCols(n - 1);
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Z.transpose() * H * Z).eigenvalues()[0];
}

SuddenLoadOptions suddenWithWall() {
  SuddenLoadOptions o;
  o.wall = true;
  o.integration.recordTrajectory = true;
  return o;
}

}  // namespace

TEST_CASE("wall landing: the curled chain under a sudden Fy lands on the wall with the wall force of its statics",
          "[wall][dynamics]") {
  const Chain chain = testing::curledChain(false);
  const double L = chainLength(chain);
  const Eigen::Vector2d F(0.0, kFy);
  const SuddenLoadResult r =
      simulateSuddenLoad(chain, EndCondition::freeEnd(Wrench(0.0, kFy, 0.0)), testing::curledShape(), Vector(), suddenWithWall());
  INFO(r.message);
  REQUIRE(r.reachedWall);
  REQUIRE(r.success);
  REQUIRE(r.wallContacts.size() == 1);
  REQUIRE(r.wallForces.size() == 1);
  const WallVertex v = r.wallContacts[0];
  CHECK(v == r.wallVertex);  // the vertex that stopped the flow holds
  CHECK(std::abs(vertexAt(chain, r.rest, v).x()) <= 1e-12 * L);
  CHECK(smallestVertexX(chain, r.rest) >= -1e-12 * L);
  // the independent statics: every joint's moment balance closes with one wall force, equal to μ
  const Statics s = wallStatics(chain, r.rest, F, v);
  CHECK(s.imbalance <= 1e-11);
  CHECK(s.clampImbalance <= 1e-11);
  CHECK(s.mu > 0.0);
  CHECK(r.wallForces[0] == Approx(s.mu).epsilon(1e-9));
  // stable on the constrained tangent: the dense operator's lowest eigenvalue, as the library's
  const double lowest = constrainedLowest(chain, r.rest, Wrench(0.0, kFy, 0.0), v, s.mu);
  CHECK(lowest > 0.0);
  CHECK(r.stability.valid());
  CHECK(r.stability.negative == 0);
  CHECK(r.stability.zero == 0);
  REQUIRE(r.stability.lowest.size() >= 1);
  CHECK(r.stability.lowest[0] == Approx(lowest).epsilon(1e-6));
  // the continuation's wall equilibrium at the same load (contact.h) is the same state
  ContactSet set;
  set.touch(v);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  const ConstrainedEquilibrium ce = solveConstrainedEquilibrium(problem, set, problem.initialGuess(r.rest, kFy), kFy);
  REQUIRE(ce.converged);
  CHECK((ce.u.head(5) - r.rest).cwiseAbs().maxCoeff() <= 1e-10);
  // and the library's constrained operator (ContactProblem::stabilityOperator) on ker ∇x_v has
  // the test's lowest eigenvalue
  ContactProblem cp(problem, set);
  Eigen::VectorXd u(cp.dimension());
  u << ce.u, ce.wallForces;
  Eigen::MatrixXd Hl, Cl;
  REQUIRE(buckle::continuation::BoundProblem(cp).stabilityOperator(u, kFy, Hl, Cl));
  const Eigen::MatrixXd Ct = Cl.transpose();
  const Eigen::MatrixXd Zl = Ct.fullPivHouseholderQr().matrixQ().rightCols(5 - Cl.rows());
  const Eigen::MatrixXd Hz = Zl.transpose() * Hl * Zl;
  const double lowestLibrary = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (Hz + Hz.transpose())).eigenvalues()[0];
  INFO("Sturm route's lowest " << r.stability.lowest.transpose());
  CHECK(lowestLibrary == Approx(lowest).epsilon(1e-6));
}

TEST_CASE("wall landing: a jump with the wall comes to rest on it, without it lands behind it, flagged",
          "[wall][jump]") {
  const Chain chain = testing::curledChain(false);
  const double L = chainLength(chain);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  JumpOptions o;
  o.perturbation = 0.0;  // released from the unloaded shape at Fy = kFy (not an equilibrium there)
  o.wall = true;
  o.integration.recordTrajectory = true;
  const JumpResult j = simulateJump(problem, testing::curledShape(), kFy, o);
  INFO(j.message);
  REQUIRE(j.reachedWall);
  CHECK(j.stopReason == IntegrationStop::Rest);  // it slid along the wall to rest (IntegrationOptions::wall)
  CHECK(std::abs(j.wallGap) <= 1e-9 * L);
  CHECK(std::abs(vertexAt(chain, j.restPoint, j.wallVertex).x()) <= 1e-9 * L);
  REQUIRE(j.success);
  REQUIRE(j.wallContacts.size() == 1);
  CHECK(j.wallForces[0] > 0.0);
  const Eigen::VectorXd q = j.to.head(5);
  const Statics s = wallStatics(chain, q, Eigen::Vector2d(0.0, kFy), j.wallContacts[0]);
  CHECK(s.imbalance <= 1e-11);
  CHECK(j.wallForces[0] == Approx(s.mu).epsilon(1e-9));
  CHECK(smallestVertexX(chain, q) >= -1e-12 * L);
  CHECK(j.energyReleased > 0.0);

  JumpOptions ghost = o;
  ghost.wall = false;
  const JumpResult through = simulateJump(problem, testing::curledShape(), kFy, ghost);
  INFO(through.message);
  CHECK_FALSE(through.reachedWall);
  // the wall not traced: the chain passes through it (as the continuation's BC), said so
  CHECK(through.behindWall);
  CHECK(smallestVertexX(chain, through.to.head(5)) < -1e-3 * L);
  CHECK(through.message.find("behind the base wall") != std::string::npos);
}

TEST_CASE("wall landing: a vertex whose wall force would pull is released and the chain lands off the wall",
          "[wall]") {
  // Past the release WR (Fy = 0.1499 on contact_release's branch) the vertex held on the wall
  // would pull it: the active set lets it go and the landing is the free equilibrium.
  const Chain chain = testing::curledChain(false);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  const double fy = 0.2;
  const WallVertex v{4, 4};
  ContactSet start;
  start.touch(v);
  // the pulling state exists: the vertex held on the wall at fy has a negative force
  const ConstrainedEquilibrium held = solveConstrainedEquilibrium(problem, start, problem.initialGuess(testing::curledShape(), fy), fy);
  REQUIRE(held.converged);
  REQUIRE(held.wallForces[0] < 0.0);
  const WallLanding w = landOnWall(problem, start, testing::curledShape(), fy);
  INFO(w.message);
  REQUIRE(w.converged);
  CHECK(w.contacts.wallCount() == 0);
  CHECK(w.message.find("released") != std::string::npos);
  CHECK(w.stable);
  const Eigen::VectorXd q = w.u.head(5);
  CHECK(smallestVertexX(chain, q) > 0.0);
  // a free equilibrium: ∇Π = 0 by the library's total potential's gradient
  Eigen::VectorXd g(5);
  totalPotentialGradient(chain, q, Wrench(0.0, fy, 0.0), g);
  CHECK(g.cwiseAbs().maxCoeff() <= 1e-11);
}
