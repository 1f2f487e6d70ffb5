// Shared set-up of the benchmark programs: the chains and states they time.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "../apps/problems/auto_cases.h"

namespace buckle::bench {

using mechanics::Chain;
using mechanics::EndCondition;
using mechanics::EquilibriumOptions;
using mechanics::EquilibriumProblem;
using mechanics::SegmentParameters;

/// The paper's main segment (apps/problems/auto_cases.h).
using problems::mainSegment;

/// Clamped–pinned chain of n segments, λ = Fx.
inline EquilibriumProblem clampedPinned(int n, bool structuredStability = true, double L0 = 2.25) {
  EquilibriumOptions o;
  o.structuredStability = structuredStability;
  return EquilibriumProblem(Chain::uniform(n, mainSegment(L0)), EndCondition::clampedPinned(0.0),
                            Eigen::Vector3d(1, 0, 0), o);
}

/// A generic bent state: q_i = 0.3 sin(2π i / n) + 0.05, reaction 0.1.
inline Eigen::VectorXd bentState(int n, int held) {
  Eigen::VectorXd u(n + held);
  for (int i = 0; i < n; ++i) u[i] = 0.3 * std::sin(6.283185307179586 * (i + 0.5) / n) + 0.05;
  for (int k = 0; k < held; ++k) u[n + k] = 0.1;
  return u;
}

/// The unit systems a benchmark repeats its rows in: nondimensional (b = k = 1) and SI
/// (b = 0.02 m, k = 2000 N/m: the same problem in metres and newtons).
struct BenchUnits {
  const char* name;
  double b, k;
};
inline constexpr BenchUnits kBenchUnits[] = {{"nondimensional", 1.0, 1.0}, {"SI (b=0.02 m)", 0.02, 2000.0}};

/// The options `--reps R` (≥ 1) and `--quick` (n ≤ 50, one repetition) of the path benchmarks.
inline void parseRepsQuick(int argc, char** argv, int& reps, bool& quick) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--reps" && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (std::string(argv[i]) == "--quick") quick = true;
  }
  if (quick) reps = 1;
}

/// A path benchmark's command line: `--reps R`, `--quick` (parseRepsQuick) and the chain sizes of
/// `--n N` options (each ≥ 3; `defaults` when none is given).
struct PathArgs {
  int reps = 3;
  bool quick = false;
  std::vector<int> sizes;
};
inline PathArgs pathArgs(int argc, char** argv, std::vector<int> defaults) {
  PathArgs a;
  parseRepsQuick(argc, argv, a.reps, a.quick);
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--n") a.sizes.push_back(std::max(3, std::atoi(argv[++i])));
  if (a.sizes.empty()) a.sizes = std::move(defaults);
  return a;
}

/// Seconds since t0 on the steady clock.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace buckle::bench
