// The path and steps of data/scenes/default.json, shared by the tests that trace its chain.
#pragma once

#include "buckle/mechanics/equilibrium_branches.h"

namespace buckle::mechanics::testing {

/// Fx from 0 to −2.5 (λ = Fx), initial step 0.02, at most 0.05; the rest the library's defaults.
inline EquilibriumBranchOptions defaultScenePath() {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = -2.5;
  o.tracer.lambdaMax = 0.0;
  o.tracer.step.initialStep = 0.02;
  o.tracer.step.maxStep = 0.05;
  return o;
}

}  // namespace buckle::mechanics::testing
