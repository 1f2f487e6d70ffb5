// Names of chain shapes: Table I of the paper for three segments, sign changes in general.
#pragma once

#include <Eigen/Core>
#include <string>

namespace buckle::mechanics {

/// Number of sign changes along v, skipping entries with |v_i| <= tolerance.
int signChanges(const Eigen::Ref<const Eigen::VectorXd>& v, double tolerance = 0.0);

/// Name of a configuration (or of a mode) given by joint angles q.
///  - "straight" when every |q_i| <= straightTolerance;
///  - n = 3 (Table I): "U" for the sign patterns (−,+,+) and (+,−,−), "Z" for (−,+,−) and
///    (+,−,+), "other" for anything else (including a component with |q_i| <= straightTolerance);
///  - other n: "mode k", k = number of sign changes of the link angles θ_m = q_1 + … + q_m
///    (entries with |θ_m| <= straightTolerance skipped). The first clamped–pinned buckling mode
///    is "mode 1" (the U shape has one), the first cantilever mode "mode 0".
std::string shapeName(const Eigen::Ref<const Eigen::VectorXd>& q, double straightTolerance = 1e-9);

/// The straightness tolerance (rad, the angles' own unit) the reports and landings name the
/// shapes of equilibria with: a chain bent by less than 1e-6 rad at every joint is straight.
inline constexpr double kStraightTolerance = 1e-6;

/// Shape name of a mode vector, scale-free: the tolerance is relative to max |z_i|.
std::string modeShapeName(const Eigen::Ref<const Eigen::VectorXd>& z, double relativeTolerance = 1e-9);

}  // namespace buckle::mechanics
