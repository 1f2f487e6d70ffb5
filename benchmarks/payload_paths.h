// Shared set-up of the benchmarks of paths under a payload (actuation_path, task_path; issue 29):
// the paper's chain of n segments in a unit system, its payload −0.9/n k b on x and y, the start
// (the straight chain loaded to the payload, not timed); units and command line: common.h.
#pragma once

#include <Eigen/Core>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "common.h"

namespace buckle::bench {

/// n paper segments (a = 0.5 b, L0 = 2.25 b) in units (b, k).
inline mechanics::Chain payloadChain(int n, double b, double k) {
  return mechanics::Chain::uniform(n, mechanics::SegmentParameters::symmetric(0.5 * b, b, k, 2.25 * b));
}
/// Fx = Fy = −0.9/n k b (−0.3 at n = 3, the actuation_dL0 scene).
inline Eigen::Vector3d payloadOf(int n, double b, double k) {
  return Eigen::Vector3d(-0.9 / n * k * b, -0.9 / n * k * b, 0.0);
}

/// The straight chain loaded to `payload` along λ·payload, λ: 0 → 1: the joint angles into q;
/// false when the loading does not reach λ = 1.
inline bool loadedStart(const mechanics::Chain& chain, const Eigen::Vector3d& payload, Eigen::VectorXd& q) {
  mechanics::EquilibriumProblem ramp(chain, mechanics::EndCondition::freeEnd(), payload);
  continuation::TracerOptions ro;
  ro.lambdaMin = -1.0;
  ro.lambdaMax = 1.0;
  ro.maxPoints = 100000;
  const continuation::Branch loading = continuation::trace(ramp, Eigen::VectorXd::Zero(chain.size()), 0.0,
                                                           continuation::InitialDirection::increasingLambda(), ro);
  if (loading.stopReason != continuation::StopReason::LambdaRange) return false;
  q = loading.points.back().u;
  return true;
}

}  // namespace buckle::bench
