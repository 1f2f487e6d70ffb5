// The curled chain of data/scenes/contact_release.json for the contact tests: five paper segments
// (a = 0.5, b = 1, k = 1, L0 = 2.25) curled by their unloaded shape q0 = (0.2, 1.3, 1.3, 1.3, 1.3),
// the end behind the root, so that a growing Fy swings segment 5's distal triangle onto the wall.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::mechanics::testing {

inline Eigen::VectorXd curledShape() {
  Eigen::VectorXd q0(5);
  q0 << 0.2, 1.3, 1.3, 1.3, 1.3;
  return q0;
}

/// Joint 1 stopped at q_min = 0.1 when `stop` (the scene's), lengths scaled by sL, spring
/// stiffnesses by sK.
inline Chain curledChain(bool stop, double sL = 1.0, double sK = 1.0) {
  std::vector<SegmentParameters> segs(5, SegmentParameters::symmetric(0.5 * sL, 1.0 * sL, 1.0 * sK, 2.25 * sL));
  if (stop) segs[0].qMinUser = 0.1;
  return Chain(preloadsForShape(segs, curledShape()));
}

/// The base wall as a constraint (contact.h).
inline EquilibriumOptions withWall() {
  EquilibriumOptions o;
  o.wallAsBoundary = true;
  return o;
}

/// One branch from λ = 0 to `to`, the scene's steps (in the problem's own units: unit-free).
inline EquilibriumBranchOptions curledTrace(double to) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = to;
  o.tracer.step.initialStep = 0.01;
  o.tracer.step.maxStep = 0.02;
  o.tree.branchSwitching = 0;
  return o;
}

}  // namespace buckle::mechanics::testing
