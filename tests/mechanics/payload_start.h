// The chain under an end payload reached from its unloaded shape by loading it quasi-statically
// (λ: 0 → 1 along λ·payload), written in the tests apart from the scene runner's start.
#pragma once

#include <catch2/catch.hpp>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::test {

inline Eigen::VectorXd underPayload(const mechanics::Chain& chain, const Eigen::Vector3d& payload) {
  const mechanics::UnloadedShape shape = mechanics::unloadedShape(chain);
  REQUIRE(shape.allFound);
  mechanics::EquilibriumProblem ramp(chain, mechanics::EndCondition::freeEnd(), payload);
  continuation::TracerOptions o;
  o.lambdaMin = -1.0;
  o.lambdaMax = 1.0;
  o.maxPoints = 5000;
  o.corrector.tolerance = 1e-12;
  const continuation::Branch b =
      continuation::trace(ramp, shape.q, 0.0, continuation::InitialDirection::increasingLambda(), o);
  REQUIRE(b.stopReason == continuation::StopReason::LambdaRange);
  REQUIRE(b.specialPointsOfType(continuation::SpecialPointType::Fold).empty());  // no snap on the way
  return b.points.back().u;
}

}  // namespace buckle::test
