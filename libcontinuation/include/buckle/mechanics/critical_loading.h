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

}  // namespace buckle::mechanics
