// The end condition and its straight path (end_condition.h): LoadPath's prescribed values against
// what EquilibriumProblem applies, and a path traced through a held coordinate's reaction meeting
// the displacement-controlled one where λ equals the reaction.
#include <catch2/catch.hpp>

#include <Eigen/Core>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "fixed_lambda_newton.h"

namespace mech = buckle::mechanics;

namespace {

mech::Chain chain4() { return mech::Chain::uniform(4, mech::SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)); }

}  // namespace

TEST_CASE("load path: the problem's end loads at λ are the start loads moved along the direction", "[end_condition]") {
  const mech::Chain chain = chain4();
  mech::LoadPath path;
  path.start = mech::EndCondition::freeEnd(Eigen::Vector3d(-0.2, 0.1, 0.05));
  path.direction = Eigen::Vector3d(1.0, 0.5, -0.25);
  path.startValue = -0.3;
  mech::EquilibriumProblem problem(chain, path.problemEnd(), path.direction);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(problem.dimension(), 0.01);
  for (double lambda : {-0.3, 0.0, 0.7, -1.9}) {
    const mech::Wrench F = problem.wrench(u, lambda);
    const Eigen::Vector3d expected = path.start.value + (lambda - path.startValue) * path.direction;
    CHECK((F - expected).cwiseAbs().maxCoeff() <= 1e-15);
    CHECK((path.at(lambda).value - expected).cwiseAbs().maxCoeff() <= 1e-15);
  }
  CHECK((problem.wrench(u, path.startValue) - path.start.value).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("load path through the reaction: at λ = the held coordinate's reaction it is the same equilibrium",
          "[end_condition]") {
  const mech::Chain chain = chain4();
  // the end held at (x0, y0): an equilibrium of the displacement-controlled path at its start
  mech::LoadPath held;
  held.start = mech::EndCondition::heldPosition(7.9, 0.3);
  held.direction = Eigen::Vector3d::UnitX();
  held.startValue = 7.9;
  mech::EquilibriumProblem displacement(chain, held.problemEnd(), held.direction);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(displacement.dimension());
  u.head(4) << 0.06, 0.02, -0.02, -0.06;
  u = buckle::test::polishAtFixedLambda(displacement, u, held.startValue, 30);
  Eigen::VectorXd F(displacement.dimension());
  REQUIRE(buckle::continuation::BoundProblem(displacement).residual(u, held.startValue, F));
  REQUIRE(F.norm() <= 1e-12);
  const mech::Pose pose = mech::endPose(chain, u.head(4));
  REQUIRE(std::abs(pose[0] - 7.9) <= 1e-12);
  const double Rx = displacement.wrench(u, held.startValue)[0];
  REQUIRE(std::abs(Rx) > 1e-3);  // a real reaction, not a trivial check

  // x released and loaded along itself from zero: λ = F_x; y still held at y0
  const mech::LoadPath released = held.throughReaction(0);
  CHECK(released.start.control[0] == mech::Control::Load);
  CHECK(released.start.control[1] == mech::Control::Held);
  CHECK(released.start.value[1] == 0.3);
  CHECK(released.startValue == 0.0);
  mech::EquilibriumProblem reaction(chain, released.problemEnd(), released.direction);
  REQUIRE(reaction.dimension() == 5);
  Eigen::VectorXd v(5);
  v << u.head(4), u[5];  // the joint angles and y's reaction
  Eigen::VectorXd G(5);
  REQUIRE(buckle::continuation::BoundProblem(reaction).residual(v, Rx, G));
  CHECK(G.norm() <= 1e-12);
  CHECK((reaction.wrench(v, Rx) - displacement.wrench(u, held.startValue)).cwiseAbs().maxCoeff() <= 1e-14);
  // a load-controlled coordinate cannot be traced through its reaction
  CHECK_THROWS_AS(released.throughReaction(0), std::invalid_argument);
  CHECK_THROWS_AS(held.throughReaction(2), std::invalid_argument);
}
