// The units a scene's numbers are in, for labels only. The equations are homogeneous in length
// and force (eq 1-29), so buckle computes in whatever consistent units the scene is written in
// and every result comes out in those units; what it cannot know is their names. A scene says
// them (`"units": {"length": "m", "force": "N"}`), or that it is nondimensional (lengths in b,
// forces in k b: then b = k = 1), or nothing: then every label says "in the scene's units".
#pragma once

#include <string>

#include "scene/json_reader.h"

namespace buckle::scene {

/// Physical dimension of a reported quantity, as a product of the scene's length L and force F.
enum class Dimension {
  None,                 ///< a count or a ratio
  Angle,                ///< rad
  Length,               ///< L
  Force,                ///< F
  Moment,               ///< F·L (torques, energies, eigenvalues of the stability operator)
  Stiffness,            ///< F/L (Cartesian stiffness K_F)
  Compliance,           ///< L/F (C_F = K_F⁻¹)
  RotationalStiffness,  ///< F·L/rad (joint stiffness K_q, the end's rotational stiffness)
  Time,                 ///< the model time of the dynamics
  Frequency,            ///< 1/time
  /// rad per time unit of the scene's length, force and mass units, τ = √(mass·length/force)
  /// (natural frequencies: rad/s for m, N, kg)
  AngularFrequency,
  /// The gravitational acceleration: force per mass (m/s² = N/kg with m, N, kg)
  Acceleration
};

struct UnitSystem {
  enum class Kind {
    Consistent,      ///< no `units`: numbers in the scene's own consistent units, unnamed
    Nondimensional,  ///< `"units": "nondimensional"`: lengths in b, forces in k b (b = k = 1)
    Named            ///< `"units": {"length": …, "force": …}`
  };
  Kind kind = Kind::Consistent;
  std::string length, force;  ///< Named only: e.g. "m", "N"
  /// Named only, optional: the mass unit ("kg"), which masses (mass per length in mass/length)
  /// are in; the natural frequencies need it to have a named unit (vibration.h).
  std::string mass;

  /// The unit of a quantity: "N/m", "k b^2", or (Consistent) "force/length"; "" for None.
  std::string unit(Dimension d) const;
  /// The unit in parentheses after a quantity's name: " (N)", " (units of k b)",
  /// " (force, in the scene's units)", " (rad)"; "" for None.
  std::string suffix(Dimension d) const;
  /// The units as written to summary.json: kind and, per dimension, the unit.
  nlohmann::json toJson() const;
};

/// True for a unit name that goes into every output target unquoted (see parseUnits).
bool validUnitName(const std::string& name);

/// Parses the scene's `units` (absent: Consistent). Unit names are short printable words made of
/// letters, digits, spaces and . / ^ * - µ μ · (at most 16 bytes), so that they go into every
/// target (gnuplot, CSV, JSON, HTML, SVG) without quoting.
UnitSystem parseUnits(const JsonReader& r, const nlohmann::json& v, const JsonReader::Pointer& p);

}  // namespace buckle::scene
