// The straight clamped–pinned chain's compressive critical loads by linear buckling: the
// reference the continuation tests compare located branch points with.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "buckle/mechanics/linear_buckling.h"

namespace buckle::mechanics::testing {

/// Compressive critical loads (λ < 0) of the straight clamped–pinned chain, closest to 0 first.
inline std::vector<double> compressiveCriticalLoads(const Chain& chain) {
  const LinearBucklingResult lb =
      linearBuckling(chain, Eigen::VectorXd::Zero(chain.size()), EndCondition::clampedPinned(0.0));
  std::vector<double> crit;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0) crit.push_back(m.lambda);
  std::sort(crit.begin(), crit.end(), [](double x, double y) { return x > y; });
  return crit;
}

}  // namespace buckle::mechanics::testing
