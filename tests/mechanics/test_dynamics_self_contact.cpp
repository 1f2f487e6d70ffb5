// The chain's contact with itself as a one-sided contact of the dynamics (dynamics.h,
// IntegrationOptions::self; dynamics_contacts.h): the hook hit by an end moment at once curls
// until its end meets its own straight part, is held there (the impact, then sliding) and comes
// to rest on the continuation's constrained equilibrium, against contact_geometry.h's clearance
// scan (no two links in each other), the tests' own statics and a dense solve of the stiff
// stepper's stage system, in three systems of units.
#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/jump.h"
#include "hook_chain.h"

namespace mech = buckle::mechanics;
using buckle::test::Hook;
using buckle::test::hookStatics;
using Eigen::VectorXd;

namespace {

// The end moment applied at once: past the moment (0.19 k b²) at which the statics' end meets link 3.
constexpr double kMoment = 0.25;

// The first self contact event (nullptr when none).
const mech::ContactEvent* firstSelfContact(const mech::DynamicsResult& r) {
  for (const mech::ContactEvent& e : r.contactEvents)
    if (e.self.vertex.segment >= 0 && e.contact) return &e;
  return nullptr;
}

// The smallest self clearance over the recorded trajectory.
double deepest(const mech::Chain& chain, const mech::DynamicsResult& r) {
  double d = std::numeric_limits<double>::infinity();
  for (const mech::TrajectorySample& s : r.trajectory) d = std::min(d, mech::selfClearance(chain, s.q).distance);
  return d;
}

}  // namespace

TEST_CASE("self contact in the dynamics: the gradient flow curls onto itself, slides and rests held, in any units",
          "[self_contact][dynamics]") {
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}, std::pair{1e-4, 1e8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    Hook hook(sL, sK);
    const double Me = kMoment * sK * sL * sL;
    const mech::Wrench W(0.0, 0.0, Me);
    std::unique_ptr<mech::DynamicsModel> model =
        mech::makeDynamicsModel(hook.chain, mech::EndCondition::freeEnd(W), mech::DynamicsScene(), hook.q0);
    mech::IntegrationOptions o;
    o.recordTrajectory = true;
    // without the contact the end passes through link 3: the test below can fail
    const mech::DynamicsResult through = mech::simulate(*model, hook.q0, VectorXd(), o);
    CHECK(deepest(hook.chain, through) < -1e-3 * sL);

    o.self = true;
    const mech::DynamicsResult r = mech::simulate(*model, hook.q0, VectorXd(), o);
    INFO(r.message);
    REQUIRE(r.reason == mech::IntegrationStop::Rest);
    const mech::ContactEvent* touch = firstSelfContact(r);
    REQUIRE(touch != nullptr);
    CHECK(touch->self.label() == "8d- on 3p[j,+]");
    REQUIRE(r.selfContacts.size() == 1);
    CHECK(r.selfContacts[0] == touch->self);
    // never in each other (beyond the event's slack), Π never increasing
    REQUIRE(r.trajectory.size() > 10);
    CHECK(deepest(hook.chain, r) >= -2e-9 * sL);
    for (size_t k = 1; k < r.trajectory.size(); ++k)
      CHECK(r.trajectory[k].potential <= r.trajectory[k - 1].potential + 1e-10 * std::abs(r.trajectory[k - 1].potential));
    // at rest: the continuation's constrained equilibrium, its force that of the test's own statics
    mech::ContactSet held;
    held.hold(r.selfContacts[0]);
    const mech::ConstrainedEquilibrium ce =
        mech::solveConstrainedEquilibrium(hook.problem, held, hook.problem.initialGuess(r.q, Me), Me);
    REQUIRE(ce.converged);
    CHECK((ce.u.head(8) - r.q).cwiseAbs().maxCoeff() <= 1e-7);
    const auto [imbalance, mu] = hookStatics(hook.chain, ce.u.head(8), Me, held.self()[0]);
    CHECK(imbalance < 1e-9 * sK * sL * sL);
    CHECK(mu > 0.0);
    REQUIRE(r.selfForces.size() == 1);
    CHECK(r.selfForces[0] == Approx(mu).epsilon(1e-6));
    CHECK(ce.selfForces[0] == Approx(mu).epsilon(1e-8));
    CHECK(model->selfCount() == 0);  // the model's own contact set is restored
  }
}

TEST_CASE("self contact in the dynamics: the inertial hook strikes itself inelastically and rests held",
          "[self_contact][dynamics]") {
  // (damped enough not to swing its end round to a joint of the straight part: a vertex at a
  // joint, which the model does not hold)
  Hook hook(1.0, 1.0);
  const mech::Wrench W(0.0, 0.0, kMoment);
  mech::DynamicsScene scene;
  scene.inertia = mech::InertiaData::uniformRods(hook.chain, 1.0);
  scene.jointDamping.assign(8, 10.0);
  std::unique_ptr<mech::DynamicsModel> model =
      mech::makeDynamicsModel(hook.chain, mech::EndCondition::freeEnd(W), scene, hook.q0);
  mech::IntegrationOptions o;
  o.self = true;
  o.recordTrajectory = true;
  o.absoluteTolerance = o.relativeTolerance = 1e-11;
  const mech::DynamicsResult r = mech::simulate(*model, hook.q0, VectorXd(), o);
  INFO(r.message);
  for (const mech::ContactEvent& e : r.contactEvents)
    UNSCOPED_INFO("t = " << e.t << ": " << (e.contact ? "contact " : "release ") << e.self.label() << ", force " << e.torque);
  REQUIRE(r.reason == mech::IntegrationStop::Rest);
  const mech::ContactEvent* touch = firstSelfContact(r);
  REQUIRE(touch != nullptr);
  // the impact takes the approach velocity out of the motion; K + Π + W_d is conserved
  CHECK(touch->kineticLost > 0.0);
  CHECK(r.maxEnergyBalanceError <= 1e-8 * std::abs(r.initialEnergy));
  CHECK(deepest(hook.chain, r) >= -2e-9);
  // at rest on the constrained equilibrium of its final contacts, every force pushing
  REQUIRE_FALSE(r.selfContacts.empty());
  mech::ContactSet held;
  for (const mech::SelfContact& c : r.selfContacts) held.hold(c);
  const mech::ConstrainedEquilibrium ce =
      mech::solveConstrainedEquilibrium(hook.problem, held, hook.problem.initialGuess(r.q, kMoment), kMoment);
  REQUIRE(ce.converged);
  CHECK((ce.u.head(8) - r.q).cwiseAbs().maxCoeff() <= 1e-7);
  for (int k = 0; k < r.selfForces.size(); ++k) {
    CHECK(r.selfForces[k] > 0.0);
    CHECK(r.selfForces[k] == Approx(ce.selfForces[k]).epsilon(1e-6));
  }
}

TEST_CASE("self contact in the dynamics: the stiff stepper's stage solve with a held contact against a dense solve",
          "[self_contact][dynamics]") {
  // (I − aJ̃) k = b of the gradient flow with a self contact held: the rank-2 part bordered
  // (dynamics_gradient_flow.cpp) against the dense LU of I − aJ with J by central differences
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    Hook hook(sL, sK);
    const double Me = kMoment * sK * sL * sL;
    const mech::EquilibriumBranches t = hook.trace(hook.upTo(0.25));
    REQUIRE(t.contact[0].size() == 2);
    const mech::SelfContact c = t.contact[0][1].locked.self()[0];
    // a state off the equilibrium (a flow in progress), near the contact
    VectorXd q = t.tree.branches[0].points.back().u.head(8);
    q += 0.01 * VectorXd::LinSpaced(8, -1.0, 1.0);
    for (const bool endHeld : {false, true}) {
      INFO("end y held: " << endHeld);
      mech::EndCondition end = mech::EndCondition::freeEnd(mech::Wrench(0.0, 0.0, Me));
      if (endHeld) {  // y held where it is: one more border column
        end.control[1] = mech::Control::Held;
        end.value[1] = mech::endPose(hook.chain, q)[1];
      }
      mech::GradientFlowModel model(hook.chain, end, mech::DynamicsScene(), hook.q0);
      model.setSelfContacts({c});
      VectorXd x(9);
      model.packState(q, VectorXd(), x);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(9, 9);
      model.jacobian(x.data(), J.data());
      for (const double a : {1e-3, 1.0}) {
        const double scaled = a / (sK * sL * sL);  // the flow's time unit is c / k b²
        const VectorXd b = VectorXd::LinSpaced(9, 1.0, 2.0);
        VectorXd k(9);
        REQUIRE(model.solveLinearized(x.data(), scaled, b.data(), k.data()));
        const VectorXd dense = (Eigen::MatrixXd::Identity(9, 9) - scaled * Eigen::MatrixXd(J)).partialPivLu().solve(b);
        CHECK((k - dense).norm() <= 1e-5 * dense.norm());
      }
    }
  }
}

TEST_CASE("self contact in the dynamics: a sudden moment lands the hook on its held equilibrium",
          "[self_contact][dynamics]") {
  Hook hook(1.0, 1.0);
  const mech::EquilibriumBranches t = hook.trace(hook.upTo(kMoment));
  REQUIRE(t.contact[0].size() == 2);
  const VectorXd qStatic = t.tree.branches[0].points.back().u.head(8);
  REQUIRE(t.tree.branches[0].points.back().lambda == Approx(kMoment).epsilon(1e-12));
  for (const bool self : {true, false}) {
    INFO("self contact traced: " << self);
    mech::SuddenLoadOptions o;
    o.self = self;
    const mech::SuddenLoadResult r = mech::simulateSuddenLoad(
        hook.chain, mech::EndCondition::freeEnd(mech::Wrench(0.0, 0.0, kMoment)), hook.q0, qStatic, o);
    INFO(r.message);
    if (!self) {  // the end passes through link 3 to a rest shape that is not the held one
      CHECK(mech::selfClearance(hook.chain, r.rest).distance < -1e-3);
      continue;
    }
    REQUIRE(r.success);
    REQUIRE(r.selfContacts.size() == 1);
    CHECK(r.selfContacts[0] == t.contact[0][1].locked.self()[0]);
    CHECK(r.selfForces[0] > 0.0);
    CHECK_FALSE(r.differs);
    CHECK(r.maxDifference < 1e-8);
  }
}
