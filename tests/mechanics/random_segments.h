// Random asymmetric segment parameters for the derivative and cross-formulation tests.
#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/segment.h"

namespace buckle::mechanics::testing {

struct SegmentRanges {
  double aLo = 0.1, aHi = 0.9;
  double bLo = 0.6, bHi = 1.5;
  double kLo = 0.5, kHi = 3.0;
  double LLo = 1.5, LHi = 2.8;
};

/// Every triangle, spring and preload drawn independently from `r`.
inline SegmentParameters randomSegment(std::mt19937& rng, const SegmentRanges& r = {}) {
  std::uniform_real_distribution<double> A(r.aLo, r.aHi), B(r.bLo, r.bHi), K(r.kLo, r.kHi), L(r.LLo, r.LHi);
  SegmentParameters p;
  p.a1 = A(rng);
  p.a2 = A(rng);
  p.b1 = B(rng);
  p.b2 = B(rng);
  p.k1 = K(rng);
  p.k2 = K(rng);
  p.L1_0 = L(rng);
  p.L2_0 = L(rng);
  return p;
}

/// u = (q, r) of size N for `chain`: joint angles within 70 % of the limits, multipliers in [−1.5, 1.5].
/// n random segments (randomSegment).
inline std::vector<SegmentParameters> randomSegments(std::mt19937& rng, int n, const SegmentRanges& r = {}) {
  std::vector<SegmentParameters> segments;
  for (int i = 0; i < n; ++i) segments.push_back(randomSegment(rng, r));
  return segments;
}

inline Eigen::VectorXd randomState(std::mt19937& rng, const Chain& chain, int N) {
  std::uniform_real_distribution<double> W(-1.5, 1.5);
  const int n = chain.size();
  Eigen::VectorXd u(N);
  for (int i = 0; i < n; ++i) {
    std::uniform_real_distribution<double> Q(0.7 * chain.lowerLimits()[i], 0.7 * chain.upperLimits()[i]);
    u[i] = Q(rng);
  }
  for (int i = n; i < N; ++i) u[i] = W(rng);
  return u;
}

}  // namespace buckle::mechanics::testing
