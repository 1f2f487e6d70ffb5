// Sign conventions of the mechanics layer, stated once (explained in docs/mechanics.md, "Conventions" and "Errata").
//
// Geometry
//   Segment i: two rigid triangles, proximal (a_i1, b_i1) and distal (a_i2, b_i2), on a passive
//   joint q_i, held by two springs (k_i1, L_i1⁰) and (k_i2, L_i2⁰). Spring 1 closes for q > 0.
//   With c_j = √(a_j² + b_j²) and β12 = atan(a1/b1) + atan(a2/b2) the spring lengths are
//   L_1(q) = √(c1² + c2² + 2c1c2 cos(β12 + q)),  L_2(q) = √(c1² + c2² + 2c1c2 cos(β12 − q))  (eq 1);
//   in the symmetric case L_1,2 = 2(b cos(q/2) ∓ a sin(q/2)).
//   Links (base, between joints, end) have lengths b_11, b_12 + b_21, …, b_n2: (b, 2b, …, 2b, b)
//   for identical segments. The base is clamped along +x; the straight chain ends at (Σ links, 0).
//   Absolute link angles θ_m = q_1 + … + q_m; end pose p = (x, y, φ) with φ = θ_n.
//
// Energy and torques
//   E = ½ Σ k (L − L⁰)²                                                     (eq 7)
//   restoring joint torque M = −∂E/∂q                                       (eq 1, 3, 10, 19)
//   joint stiffness K_q = ∂²E/∂q² = −dM/dq  (positive for a stable segment). The paper's eq 20
//   prints dM/dq and calls it stiffness: that sign is NOT used here (docs/mechanics.md, erratum 1).
//   Straight-state stiffness with equal preloads: κ = k (b·L⁰ − 2(b² − a²)); κ > 0 ⇔ eq 4.
//
// Loads
//   F = (Fx, Fy, Me) acts on the end effector, in base axes. Compression is Fx < 0.
//   Equilibrium M + Jᵀ F = 0 (eq 9); total potential Π = E − F·p.
//   Hessian of Π: K_q − K_g, K_g = ∂(JᵀF)/∂q = Fx ∂²x/∂q² + Fy ∂²y/∂q² (eq 26–27), whose
//   entry (i, j) depends on max(i, j) only.
//   A held end coordinate turns its force into a Lagrange multiplier; stability then means
//   K_q − K_g positive definite on the null space of the held rows of J.
//
// Stiffness
//   unloaded K_F⁰ = (J K_q⁻¹ Jᵀ)⁻¹ (eq 21); loaded K_F = [J (K_q − K_g)⁻¹ Jᵀ]⁻¹ (eq 29),
//   2×2 for the end position with the end rotation free (Me = 0).
#pragma once

namespace buckle::mechanics {

/// Index of an end coordinate in p = (x, y, φ) and F = (Fx, Fy, Me).
enum class EndCoordinate : int { X = 0, Y = 1, Phi = 2 };

}  // namespace buckle::mechanics
