// The n = 3 sweep of all_equilibria.cpp (private to the library): the stationary points of E(q1)
// along both inverse-kinematics branches of the end held at (x, y) (energy_landscape.h, eq 6–8),
// with the cells the landscape's sign test cannot see refined, and the topology of the
// configuration set for the Morse-type count.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/chain.h"

namespace buckle::mechanics::detail {

struct SweepPoint {
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  bool stable = false;   ///< d²E/dq1² > 0 along the branch
  bool refined = false;  ///< found by refining a cell, not by the landscape's sign test
};

struct SweepResult {
  std::vector<SweepPoint> equilibria;
  MorseCheck morse;  ///< applies, expected, loops, arcs, basis (sum is left to the caller)
};

/// Throws std::invalid_argument unless the chain has 3 segments and samples >= 2. `body`: the
/// weight and point loads (the curve's function is then E + V, eq B1).
SweepResult sweepEquilibria(const Chain& chain, double x, double y, int samples, const BodyLoads& body = BodyLoads());

}  // namespace buckle::mechanics::detail
