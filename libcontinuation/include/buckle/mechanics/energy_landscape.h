// Energy landscape of a three-segment chain with its end held at (x, y), rotation free
// (eq 6–8, Fig 4, 5, 7).
//
// For a given q1 the remaining two joints follow from the inverse kinematics of the two-link
// arm (ℓ2, ℓ3) from joint 2 to the end (docs/mechanics.md erratum 6, with the chain's link lengths ℓ0 … ℓ3):
//   d = (x − ℓ0 − ℓ1 cos q1, y − ℓ1 sin q1),  C3 = (|d|² − ℓ2² − ℓ3²) / (2 ℓ2 ℓ3),
//   S3 = ±√(1 − C3²) (branch: sign S3 = sign q3),
//   q3 = atan2(S3, C3),  q2 = atan2(d_y, d_x) − atan2(ℓ3 S3, ℓ2 + ℓ3 C3) − q1  (wrapped to (−π, π]).
// Along a branch the joint angles are a curve q(q1) with tangent t = (1, t2, t3), J_p t = 0, and
//   dE/dq1 = ∇E·t = (1 + t2 + t3)·Me,   Me = (J⁻ᵀ ∇E)_φ  (eq 12, third row: the end torque
// needed to hold the configuration; it vanishes at the equilibria with Me = 0),
//   d²E/dq1² = tᵀ ∇²E t + ∇E·q''  — at an equilibrium tᵀ (K_q − K_g(F)) t, the Hessian of the
// total potential projected on ker J_p: > 0 stable, < 0 unstable.
// With body loads (the links' weight, point loads at joints: body_loads.h) E is E + V (eq B1)
// throughout: ∇V = −τ (eq B2), ∇²V(i, j) = γ_max(i,j) (eq B3), and the end torque balances both.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "buckle/mechanics/body_loads.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/chain.h"

namespace buckle::mechanics {

enum class LandscapeStatus { Feasible, NoInverseKinematics, JointLimit };

struct LandscapeSample {
  double q1 = 0.0;
  LandscapeStatus status = LandscapeStatus::NoInverseKinematics;
  int violatedJoint = -1;            ///< 1-based joint index when status == JointLimit
  Eigen::Vector3d q = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double energy = std::numeric_limits<double>::quiet_NaN();  ///< E(q1) (also beyond a joint limit)
  double dEdq1 = std::numeric_limits<double>::quiet_NaN();
  double d2Edq1 = std::numeric_limits<double>::quiet_NaN();
  double endTorque = std::numeric_limits<double>::quiet_NaN();  ///< Me(q1) (NaN where J is singular)
};

struct LandscapeEquilibrium {
  int branch = +1;                     ///< +1: q3 >= 0 branch, −1: q3 <= 0 branch
  double q1 = 0.0;
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  double energy = 0.0;
  double d2Edq1 = 0.0;                 ///< second derivative along the branch
  bool stable = false;                 ///< d2Edq1 > 0
  Wrench F = Wrench::Zero();           ///< end reaction (Fx, Fy, Me) with ∇E = Jᵀ F (eq 12)
  double residual = 0.0;               ///< ‖∇E − J_pᵀ F_p‖∞ with Me = 0
  std::string shape;                   ///< shapeName(q): "U", "Z", "other", "straight"
};

struct EnergyLandscape {
  double x = 0.0, y = 0.0;
  std::vector<LandscapeSample> positive;  ///< branch q3 >= 0, ascending q1
  std::vector<LandscapeSample> negative;  ///< branch q3 <= 0, ascending q1
  std::vector<LandscapeEquilibrium> equilibria;  ///< feasible stationary points, both branches, ascending q1
};

struct LandscapeOptions {
  int samples = 721;  ///< q1 grid size
  /// q1 range; default (NaN) the first joint's limits.
  double q1Min = std::numeric_limits<double>::quiet_NaN();
  double q1Max = std::numeric_limits<double>::quiet_NaN();
  /// The weight and point loads (their rates ignored: BodyLoads::atParameter(0)); none by default.
  BodyLoads body;

  /// Empty when valid, else what is wrong, the field named by its path after `prefix` (the body
  /// loads are checked against the chain by energyLandscape).
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// Joint angles on one IK branch for a given q1; false when the end is out of reach.
bool landscapeInverseKinematics(const Chain& chain, double x, double y, double q1, int branch, Eigen::Vector3d& q);

/// Evaluate one point of the landscape; `body` (optional, its last update() is overwritten): the
/// body loads' terms, E + V.
LandscapeSample landscapeSample(const Chain& chain, double x, double y, double q1, int branch,
                                BodyLoadTerms* body = nullptr);

/// Throws std::invalid_argument if the chain does not have 3 segments or x, y are not finite.
EnergyLandscape energyLandscape(const Chain& chain, double x, double y, const LandscapeOptions& options = {});

}  // namespace buckle::mechanics
