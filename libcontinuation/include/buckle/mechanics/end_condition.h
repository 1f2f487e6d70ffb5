// What is prescribed at the end effector: each of x, y, φ is either load-controlled (a given
// force / torque) or displacement-controlled (a given coordinate, whose reaction becomes an
// unknown Lagrange multiplier). A LoadPath moves all prescribed values along a straight line
// in load / displacement space with the path parameter λ.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "buckle/mechanics/conventions.h"

namespace buckle::mechanics {

enum class Control { Load, Held };

struct EndCondition {
  std::array<Control, 3> control{Control::Load, Control::Load, Control::Load};
  /// Load: (Fx, Fy, Me) component; Held: the coordinate's prescribed value.
  Eigen::Vector3d value = Eigen::Vector3d::Zero();

  /// Every coordinate load-controlled (cantilever under an end wrench).
  static EndCondition freeEnd(const Eigen::Vector3d& wrench = Eigen::Vector3d::Zero());
  /// Clamped–pinned column (eq 14–17): y held at `y`, rotation free (Me = 0), x under Fx.
  static EndCondition clampedPinned(double Fx, double y = 0.0);
  /// End held at (x, y), rotation free (system 13).
  static EndCondition heldPosition(double x, double y);

  bool isHeld(EndCoordinate c) const { return control[static_cast<size_t>(c)] == Control::Held; }
  /// Indices (0 = x, 1 = y, 2 = φ) of the held coordinates, in that order.
  std::vector<int> heldIndices() const;
  std::vector<int> loadedIndices() const;
  int heldCount() const { return static_cast<int>(heldIndices().size()); }
};

/// A straight path of the prescribed values: at path parameter λ they are
///   prescribed(λ) = start.value + (λ − startValue)·direction.
struct LoadPath {
  EndCondition start;                                   ///< the end condition at λ = startValue
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< d prescribed / dλ
  double startValue = 0.0;

  /// The end condition EquilibriumProblem takes with `direction` (its prescribed(λ) = value +
  /// λ·direction): the start's values moved back to λ = 0.
  EndCondition problemEnd() const;
  /// The end condition with the prescribed values at path parameter λ.
  EndCondition at(double lambda) const;
  /// The same path traced through the reaction of its held coordinate c (reaction_path.h): c
  /// released and loaded along itself from zero (λ = F_c, startValue 0), the other prescribed
  /// values fixed at their start values.
  LoadPath throughReaction(int c) const;
};

}  // namespace buckle::mechanics
