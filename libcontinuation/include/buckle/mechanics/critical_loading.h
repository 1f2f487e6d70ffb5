// Which linear-buckling problem a path asks (linear_buckling.h): the loading whose critical values
// are wanted, and whether the paper's closed forms (eq 15–18) apply to it.
#pragma once

#include <Eigen/Core>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

/// The end condition and load direction of a path's critical loads.
struct CriticalLoading {
  EndCondition end;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

/// Along a held end coordinate c (displacement control) the critical values are those of c's
/// reaction: c released and loaded along e_c. Along loads they are the path's: `direction`
/// (dFx, dFy, dMe per unit of the path parameter) without the components of held coordinates,
/// which carry reactions, not loads. `coordinate`: the path's end coordinate (0 x, 1 y, 2 φ).
CriticalLoading criticalLoading(const EndCondition& end, int coordinate, const Eigen::Vector3d& direction);

/// True when the closed forms of three identical symmetric segments, clamped–pinned, apply
/// (analyticClampedPinned3, eq 15–18): three segments with equal triangles, springs and free
/// lengths on both sides and all alike, the straight unloaded shape q0 = 0, y held, x loaded
/// along the path, φ free, and neither a transverse load nor an end moment in the direction.
bool clampedPinned3Applies(const Chain& chain, ConstVectorRef q0, const CriticalLoading& loading);

/// How many critical load factors of the linearised problem at the unloaded shape q0 lie between
/// 0 and `lambda` (either sign): neg H(λ) − neg H(0), H(λ) = K_q(q0) − K_g(q0, λ·direction) on ker
/// of the held rows of J (Sylvester: each eigenvalue of the pencil (K_q, K_g) passed makes one more
/// negative eigenvalue), two O(n) Sturm counts (chain_structure.h). For a branch that stays at q0
/// as the load grows (the straight chain under an axial load) these are the branch points it
/// meets; otherwise an estimate. Body loads are not included. Throws std::invalid_argument for a
/// q0 of the wrong size.
int criticalLoadCount(const Chain& chain, ConstVectorRef q0, const CriticalLoading& loading, double lambda);

}  // namespace buckle::mechanics
