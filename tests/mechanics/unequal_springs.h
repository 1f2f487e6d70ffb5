// A segment whose straight chain has transcritical (asymmetric) branch points, for the Koiter and
// imperfection tests.
#pragma once

#include "buckle/mechanics/segment.h"

namespace buckle::mechanics::testing {

/// The paper's segment (a = b/2, L0 = 2.25b, k) with unequal springs k1 = 1.5k, k2 = 0.5k whose
/// free lengths keep the spring tensions equal, k1(L(0) − L1_0) = k2(L(0) − L2_0) (= the paper
/// segment's −k b/4; L(0) = 2b): the torque vanishes at q = 0, so the straight chain is an
/// equilibrium under any axial load, but E is not even in q, E‴(0) = 3(k1 − k2)L′(0)L″(0) ≠ 0,
/// so its branch points are transcritical (docs/mechanics.md, Post-buckling at every branch point).
/// Lengths in units of `length`, stiffness in units of `stiffness`.
inline SegmentParameters unequalSprings(double length = 1.0, double stiffness = 1.0) {
  SegmentParameters p = SegmentParameters::symmetric(0.5 * length, length, stiffness, 2.25 * length);
  const double L = 2.0 * length, tension = -0.25 * stiffness * length;
  p.k1 = 1.5 * stiffness;
  p.k2 = 0.5 * stiffness;
  p.L1_0 = L - tension / p.k1;
  p.L2_0 = L - tension / p.k2;
  return p;
}

}  // namespace buckle::mechanics::testing
