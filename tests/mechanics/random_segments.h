// Random asymmetric segment parameters for the derivative and cross-formulation tests.
#pragma once

#include <random>

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

}  // namespace buckle::mechanics::testing
