// The base wall as a one-sided contact of the dynamics (dynamics.h, IntegrationOptions::wall;
// dynamics_contacts.h): the chain reaches the wall, slides along it and rests on the constrained
// equilibrium, against the test's own geometry (finite differences of its vertices) and statics,
// in three systems of units.
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
#include "buckle/mechanics/unloaded_shape.h"

#include "curled_chain.h"
#include "wall_statics.h"

using namespace buckle::mechanics;

namespace {

using buckle::test::smallestVertexX;
using buckle::test::vertexAt;
using buckle::test::wallStatics;

// The curled chain of contact_release under an end force Fy applied at once: segment 5's distal
// triangle swings round onto the clamp's wall (test_wall_landing.cpp).
constexpr double kFy = 0.13;

struct Units {
  double length, stiffness;
  double force() const { return stiffness * length; }  // k b: a force
};

// ∇x_v by central differences of the test's own vertex.
Eigen::VectorXd vertexGradient(const Chain& chain, const Eigen::VectorXd& q, const WallVertex& v) {
  Eigen::VectorXd g(q.size());
  for (int j = 0; j < q.size(); ++j) {
    Eigen::VectorXd a = q, b = q;
    a[j] += 1e-6;
    b[j] -= 1e-6;
    g[j] = (vertexAt(chain, a, v).x() - vertexAt(chain, b, v).x()) / 2e-6;
  }
  return g;
}

// The first contact event with the wall (nullptr when none).
const ContactEvent* firstWallContact(const DynamicsResult& r) {
  for (const ContactEvent& e : r.contactEvents)
    if (e.joint < 0 && e.contact) return &e;
  return nullptr;
}

// The constrained equilibrium with `set` at Fy (contact.h), from q.
ConstrainedEquilibrium constrainedAt(const Chain& chain, const ContactSet& set, const Eigen::VectorXd& q, double fy) {
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  return solveConstrainedEquilibrium(problem, set, problem.initialGuess(q, fy), fy);
}

}  // namespace

TEST_CASE("wall contact: the gradient flow reaches the wall, slides along it and rests on the constrained equilibrium",
          "[wall][dynamics]") {
  const Units u = GENERATE(Units{1.0, 1.0}, Units{1e4, 1e-8}, Units{1e-4, 1e8});
  INFO("lengths x" << u.length << ", stiffness x" << u.stiffness);
  const Chain chain = testing::curledChain(false, u.length, u.stiffness);
  const double L = chain.linkLengths().sum();
  const double fy = kFy * u.force();
  const Wrench W(0.0, fy, 0.0);
  const Eigen::VectorXd q0 = testing::curledShape();
  std::unique_ptr<DynamicsModel> model = makeDynamicsModel(chain, EndCondition::freeEnd(W), DynamicsScene(), q0);
  IntegrationOptions o;
  o.wall = true;
  o.recordTrajectory = true;
  const DynamicsResult r = simulate(*model, q0, Vector(), o);
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  const ContactEvent* touch = firstWallContact(r);
  REQUIRE(touch != nullptr);
  REQUIRE(r.wallContacts.size() == 1);
  const WallVertex v = r.wallContacts[0];
  CHECK(touch->vertex == v);
  CHECK(touch->t > 0.0);

  // Never behind the wall (beyond the event's slack); Π never increases (a gradient flow, held
  // on the wall by a force that does no work).
  REQUIRE(r.trajectory.size() > 10);
  int onWall = 0;
  for (size_t k = 1; k < r.trajectory.size(); ++k) {
    const TrajectorySample &a = r.trajectory[k - 1], &b = r.trajectory[k];
    INFO("sample " << k << " t = " << b.t);
    CHECK(smallestVertexX(chain, b.q) >= -2e-9 * L);
    CHECK(b.potential <= a.potential + 1e-10 * std::abs(a.potential));
    if (b.t <= touch->t) continue;
    // Sliding (c = 1): the velocity keeps the vertex on the wall, ∇x_v·q̇ = 0, and c q̇ + ∇Π is
    // the wall's generalised force μ ∇x_v with μ ≥ 0.
    ++onWall;
    const Eigen::VectorXd gx = vertexGradient(chain, b.q, v);
    Eigen::VectorXd gradPi(5);
    totalPotentialGradient(chain, b.q, W, gradPi);
    const Eigen::VectorXd force = b.qdot + gradPi;
    const double mu = force.dot(gx) / gx.squaredNorm();
    CHECK(std::abs(gx.dot(b.qdot)) <= 1e-6 * gx.norm() * (b.qdot.norm() + gradPi.norm()));
    CHECK((force - mu * gx).norm() <= 1e-6 * gradPi.norm());
    CHECK(mu >= -1e-9 * u.force());
  }
  CHECK(onWall > 5);

  // The rest point is the continuation's constrained equilibrium (contact.h) and its force that
  // of the test's own statics.
  ContactSet set;
  set.touch(v);
  const ConstrainedEquilibrium ce = constrainedAt(chain, set, r.q, fy);
  REQUIRE(ce.converged);
  CHECK((ce.u.head(5) - r.q).cwiseAbs().maxCoeff() <= 1e-7);
  const buckle::test::Statics s = wallStatics(chain, ce.u.head(5), Eigen::Vector2d(0.0, fy), v);
  CHECK(s.mu > 0.0);
  REQUIRE(r.wallForces.size() == 1);
  CHECK(r.wallForces[0] == Approx(s.mu).epsilon(1e-6));
  CHECK(ce.wallForces[0] == Approx(s.mu).epsilon(1e-9));
  // the model's own contact set is restored
  CHECK(model->wallCount() == 0);
}

TEST_CASE("wall contact: the inertial chain hits the wall inelastically, slides and comes to rest on it",
          "[wall][dynamics]") {
  const Chain chain = testing::curledChain(false);
  const double L = chain.linkLengths().sum();
  const Wrench W(0.0, kFy, 0.0);
  const Eigen::VectorXd q0 = testing::curledShape();
  DynamicsScene scene;
  scene.inertia = InertiaData::uniformRods(chain, 1.0);
  scene.jointDamping.assign(5, 2.0);
  std::unique_ptr<DynamicsModel> model = makeDynamicsModel(chain, EndCondition::freeEnd(W), scene, q0);
  IntegrationOptions o;
  o.wall = true;
  o.recordTrajectory = true;
  o.absoluteTolerance = o.relativeTolerance = 1e-11;
  const DynamicsResult r = simulate(*model, q0, Vector(), o);
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  const ContactEvent* touch = firstWallContact(r);
  REQUIRE(touch != nullptr);
  // the impact takes the velocity into the wall out of the motion: kinetic energy is lost, and
  // K + Π + W_d (the loss counted as dissipated) is conserved to the integrator's tolerance
  CHECK(touch->kineticLost > 0.0);
  CHECK(r.maxEnergyBalanceError <= 1e-8 * std::abs(r.initialEnergy));
  for (size_t k = 1; k < r.trajectory.size(); ++k) {
    const TrajectorySample& b = r.trajectory[k];
    INFO("sample " << k << " t = " << b.t);
    CHECK(smallestVertexX(chain, b.q) >= -2e-9 * L);
  }
  // while the first vertex is held, its velocity along x is zero (sliding or at rest)
  int held = 0;
  for (const TrajectorySample& b : r.trajectory) {
    if (b.t <= touch->t) continue;
    const bool released = std::any_of(r.contactEvents.begin(), r.contactEvents.end(), [&](const ContactEvent& e) {
      return e.joint < 0 && !e.contact && e.vertex == touch->vertex && e.t < b.t;
    });
    if (released) break;
    ++held;
    const Eigen::VectorXd gx = vertexGradient(chain, b.q, touch->vertex);
    CHECK(std::abs(gx.dot(b.qdot)) <= 1e-6 * gx.norm() * std::max(b.qdot.norm(), 1e-12));
  }
  CHECK(held > 5);
  // at rest: the constrained equilibrium of its final contact set, pushing
  REQUIRE_FALSE(r.wallContacts.empty());
  ContactSet set;
  for (const WallVertex& v : r.wallContacts) set.touch(v);
  const ConstrainedEquilibrium ce = constrainedAt(chain, set, r.q, kFy);
  REQUIRE(ce.converged);
  CHECK((ce.u.head(5) - r.q).cwiseAbs().maxCoeff() <= 1e-7);
  for (int k = 0; k < r.wallForces.size(); ++k) {
    CHECK(r.wallForces[k] > 0.0);
    CHECK(r.wallForces[k] == Approx(ce.wallForces[k]).epsilon(1e-6));
  }
}

TEST_CASE("wall contact: long curled chains pushed into the wall come to rest on it (n = 50, 1000)",
          "[wall][dynamics][long]") {
  // Every joint bent by 170°/n: the chain curls back towards the clamp, its end in front of the
  // wall; an end force Fx < 0 (a load on the soft long chain of the size of its buckling loads)
  // pushes the last triangle onto the wall.
  const int n = GENERATE(50, 1000);
  INFO("n = " << n);
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(n, 170.0 * M_PI / 180.0 / n);
  const std::vector<SegmentParameters> segs(size_t(n), SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Chain chain(preloadsForShape(segs, q0));
  const double L = chain.linkLengths().sum();
  REQUIRE(smallestVertexX(chain, q0) > 0.0);
  const double fx = -20.0 / (double(n) * n);
  std::unique_ptr<DynamicsModel> model =
      makeDynamicsModel(chain, EndCondition::freeEnd(Wrench(fx, 0.0, 0.0)), DynamicsScene(), q0);
  IntegrationOptions o = jumpIntegrationDefaults(n);  // the stiff steppers of long chains
  o.wall = true;
  o.recordTrajectory = true;
  o.recordInterval = 0.5;
  const DynamicsResult r = simulate(*model, q0, Vector(), o);
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  const ContactEvent* touch = firstWallContact(r);
  REQUIRE(touch != nullptr);
  REQUIRE_FALSE(r.wallContacts.empty());
  // The held vertex drifts off the wall by the integration error, which its lever arms sum
  // (‖∇x_v‖₁ times a step's error tolerance per joint; the κ_h terms pull it back): within ten
  // times that, and nothing deeper.
  const Eigen::VectorXd gx = vertexGradient(chain, r.q, touch->vertex);
  const double drift = 10.0 * gx.lpNorm<1>() * (o.absoluteTolerance + o.relativeTolerance * r.q.cwiseAbs().maxCoeff());
  INFO("drift bound " << drift << " (b = 1)");
  CHECK(drift < 1e-4 * L);
  for (const TrajectorySample& b : r.trajectory) CHECK(smallestVertexX(chain, b.q) >= -drift);
  ContactSet set;
  for (const WallVertex& v : r.wallContacts) set.touch(v);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0), testing::withWall());
  const ConstrainedEquilibrium ce = solveConstrainedEquilibrium(problem, set, problem.initialGuess(r.q, fx), fx);
  REQUIRE(ce.converged);
  CHECK((ce.u.head(n) - r.q).cwiseAbs().maxCoeff() <= 1e-7);
  for (int k = 0; k < r.wallForces.size(); ++k) {
    CHECK(ce.wallForces[k] > 0.0);
    CHECK(r.wallForces[k] == Approx(ce.wallForces[k]).epsilon(1e-6));
  }
}

TEST_CASE("wall contact: a vertex held on the wall whose force pulls is released and the chain flows off the wall",
          "[wall][dynamics]") {
  // At Fy = 0.2 (past contact_release's WR at 0.1499) the vertex 5d- held on the wall would pull.
  const Chain chain = testing::curledChain(false);
  const double fy = 0.2;
  const WallVertex v{4, 4};
  ContactSet set;
  set.touch(v);
  const ConstrainedEquilibrium held = constrainedAt(chain, set, testing::curledShape(), fy);
  REQUIRE(held.converged);
  REQUIRE(held.wallForces[0] < 0.0);
  const Wrench W(0.0, fy, 0.0);
  const Eigen::VectorXd q0 = held.u.head(5);
  std::unique_ptr<DynamicsModel> model = makeDynamicsModel(chain, EndCondition::freeEnd(W), DynamicsScene(), q0);
  model->setWallContacts({v});
  IntegrationOptions o;
  o.wall = true;
  const DynamicsResult r = simulate(*model, q0, Vector(), o);
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  REQUIRE_FALSE(r.contactEvents.empty());
  const ContactEvent& release = r.contactEvents.front();
  CHECK(release.joint == -1);
  CHECK(release.vertex == v);
  CHECK_FALSE(release.contact);
  CHECK(release.t == 0.0);
  CHECK(release.torque == Approx(held.wallForces[0]).epsilon(1e-6));
  CHECK(r.wallContacts.empty());
  // a free equilibrium in front of the wall: ∇Π = 0 by the library's total potential
  Eigen::VectorXd g(5);
  totalPotentialGradient(chain, r.q, W, g);
  CHECK(g.cwiseAbs().maxCoeff() <= 1e-8);
  CHECK(smallestVertexX(chain, r.q) > 0.0);
  // the model's own contact set is restored
  REQUIRE(model->wallCount() == 1);
  CHECK(model->wallContacts()[0] == v);
}

TEST_CASE("wall contact: the model refuses a vertex that does not move or is given twice", "[wall][dynamics]") {
  const Chain chain = testing::curledChain(false);
  std::unique_ptr<DynamicsModel> model =
      makeDynamicsModel(chain, EndCondition::freeEnd(), DynamicsScene(), testing::curledShape());
  CHECK_THROWS_AS(model->setWallContacts({WallVertex{0, 1}}), std::invalid_argument);  // the clamp's corner
  CHECK_THROWS_AS(model->setWallContacts({WallVertex{2, 3}, WallVertex{2, 3}}), std::invalid_argument);
  CHECK(model->wallCount() == 0);
}
