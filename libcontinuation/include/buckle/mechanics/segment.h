// One dual-triangle segment: two rigid triangles on a passive joint, two preloaded springs.
// Conventions: conventions.h.
#pragma once

#include <limits>

namespace buckle::mechanics {

struct SegmentParameters {
  double a1 = 0.5, b1 = 1.0;   ///< proximal triangle: half-height a, half-length b
  double a2 = 0.5, b2 = 1.0;   ///< distal triangle
  double k1 = 1.0, k2 = 1.0;   ///< spring stiffnesses (spring 1 closes for q > 0)
  double L1_0 = 2.25, L2_0 = 2.25;  ///< spring free lengths (the control inputs)
  /// Optional user joint limits, intersected with the geometric ones.
  double qMinUser = -std::numeric_limits<double>::infinity();
  double qMaxUser = std::numeric_limits<double>::infinity();

  /// Identical triangles (a, b), equal springs k and equal free lengths L0.
  static SegmentParameters symmetric(double a, double b, double k, double L0);
};

/// Value and first three q-derivatives of a quantity of the joint angle.
struct Jet3 {
  double value = 0, d1 = 0, d2 = 0, d3 = 0;
};

/// A direction in a segment's parameter space (dp/dμ for a second continuation parameter μ):
/// all zero by default.
struct SegmentParameterDirection {
  double a1 = 0, b1 = 0, a2 = 0, b2 = 0, k1 = 0, k2 = 0, L1_0 = 0, L2_0 = 0;
};

class Segment {
 public:
  /// Validates the parameters; throws std::invalid_argument naming the bad one.
  explicit Segment(const SegmentParameters& p);

  const SegmentParameters& parameters() const { return p_; }

  /// Spring lengths and their q-derivatives (eq 1).
  Jet3 spring1(double q) const;
  Jet3 spring2(double q) const;

  double energy(double q) const;             ///< E(q) = ½ Σ k (L − L⁰)²
  double torque(double q) const;             ///< M = −dE/dq
  double torqueDerivative(double q) const;   ///< dM/dq = −K_q
  double torqueSecondDerivative(double q) const;  ///< d²M/dq²
  double stiffness(double q) const;          ///< K_q = d²E/dq²
  /// E and its first three derivatives in one pass (hot loop).
  Jet3 energyJet(double q) const;
  /// The same with sinHalf = sin(q/2) and cosHalf = cos(q/2) given by the caller (who needs that
  /// sincos anyway: the equilibrium problem and the dynamics share it with the kinematics,
  /// forwardKinematics from half angles in chain.h). energyJet(q) is
  /// this with std::sin / std::cos of q/2: bit for bit the same values.
  Jet3 energyJet(double q, double sinHalf, double cosHalf) const;
  /// The same with the free lengths L1⁰, L2⁰ given in place of the parameters' (the control
  /// inputs moved along a path, control_path.h), and into `rate` its derivative when they move
  /// at (r1, r2) per unit of the path parameter: ∂E/∂L⁰_s = −k_s(L_s − L⁰_s) and, for j ≥ 1,
  /// ∂E^(j)/∂L⁰_s = −k_s L_s^(j) (the q-derivatives of L do not depend on L⁰).
  Jet3 energyJet(double q, double sinHalf, double cosHalf, double L1_0, double L2_0, double r1, double r2,
                 Jet3& rate) const;

  /// d/dμ of energyJet(q) (E, E′, E″, E‴ at fixed q) when the parameters move along `dp`: exact
  /// (forward-mode derivative of eq 1 in the form L² = c1² + c2² + 2c1c2 cos(β12 ± q)), so away
  /// from a spring's zero length (the geometric limit), where that form loses accuracy.
  Jet3 energyJetParameterDerivative(double q, const SegmentParameterDirection& dp) const;

  /// Straight-state joint stiffness K_q(0) (κ in the symmetric case).
  double straightStiffness() const { return stiffness(0.0); }

  /// Geometric limits: spring 1 (closing for q > 0) reaches zero length — the triangles' spring
  /// attachment points meet — at β12 + q = π, so q_max = π − β12; symmetrically q_min = β12 − π.
  double geometricUpperLimit() const;
  double geometricLowerLimit() const;
  /// Geometric limits intersected with the user's.
  double upperLimit() const;
  double lowerLimit() const;

  double beta12() const { return beta12_; }

 private:
  /// Both spring jets from one sincos of q/2 (the hot path of energyJet).
  void springs(double q, double sinHalf, double cosHalf, Jet3& L1, Jet3& L2) const;
  SegmentParameters p_;
  double c1_, c2_, beta12_, c1c2_, sqrtP_;
  double delta_;                         ///< (c1 − c2)²
  double cosHalfBeta_, sinHalfBeta_;     ///< cos(β12/2), sin(β12/2)
};

}  // namespace buckle::mechanics
