// Shared set-up of the benchmarks of paths under a payload (actuation_path, task_path; issue 29):
// the paper's chain of n segments in a unit system, its payload −0.9/n k b on x and y, the start
// (the straight chain loaded to the payload, not timed) and the command line.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::bench {

/// The unit systems timed: nondimensional (b = 1, k = 1) and SI (b = 0.02 m, k = 2000 N/m).
struct PayloadUnits {
  const char* name;
  double b, k;
};
constexpr PayloadUnits kPayloadUnits[] = {{"nondimensional", 1.0, 1.0}, {"SI (b=0.02 m)", 0.02, 2000.0}};

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

/// `--reps R` and `--quick` (n ≤ 50, one repetition).
inline void payloadArguments(int argc, char** argv, int& reps, bool& quick) {
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
  }
}

}  // namespace buckle::bench
