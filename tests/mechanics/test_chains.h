// Chains, loads and masses the mechanics tests share.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "random_segments.h"

namespace buckle::mechanics::testing {

/// The end load's direction of the clamped–pinned column: axial, along x.
inline const Eigen::Vector3d kAxial(1.0, 0.0, 0.0);

/// The paper's main case (κ = 0.75 > 0) in lengths ×L and stiffnesses ×k.
inline Chain stiffChain(int n = 3, double L = 1.0, double k = 1.0) {
  return Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L));
}

/// n segments drawn independently (randomSegment).
inline Chain randomChain(std::mt19937& rng, int n) {
  std::vector<SegmentParameters> segments;
  for (int i = 0; i < n; ++i) segments.push_back(randomSegment(rng));
  return Chain(segments);
}

/// Joint angles drawn uniformly within `fraction` of each joint's limits.
inline Eigen::VectorXd randomAngles(std::mt19937& rng, const Chain& chain, double fraction = 0.8) {
  Eigen::VectorXd q(chain.size());
  for (int i = 0; i < chain.size(); ++i) {
    std::uniform_real_distribution<double> Q(fraction * chain.lowerLimits()[i], fraction * chain.upperLimits()[i]);
    q[i] = Q(rng);
  }
  return q;
}

/// Links of different masses and inertias, every other one with its centre of mass off the link's
/// middle (the others on it: NaN).
inline InertiaData unevenInertia(const Chain& chain) {
  InertiaData data;
  for (int i = 0; i < chain.size(); ++i)
    data.links.push_back({0.7 + 0.3 * i, 0.05 + 0.02 * i,
                          i % 2 == 0 ? 0.3 * chain.linkLengths()[i + 1] : std::numeric_limits<double>::quiet_NaN()});
  return data;
}

/// What `f` is refused with (std::invalid_argument's message), or "accepted".
inline std::string rejection(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace buckle::mechanics::testing
