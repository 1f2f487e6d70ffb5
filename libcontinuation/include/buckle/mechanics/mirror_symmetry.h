// The mirror q → −q of a chain about its base axis as a reflection symmetry of its equilibrium
// (continuation/symmetry.h), so that the bifurcation tree traces one child of every symmetric
// pitchfork and mirrors the other (docs/continuation.md, "Mirror symmetry").
//
// The two springs of a segment are mirror images of each other whatever its triangles: spring 1
// has the length of eq 1 with θ = β12 + q, spring 2 with θ = β12 − q, the same c1, c2 and β12
// (segment.h). So E_i(−q) = E_i(q) exactly when k1 = k2 and L1_0 = L2_0. The kinematics mirror:
// θ_m → −θ_m, (x, y, φ) → (x, −y, −φ), and the end Jacobian's rows (−S_j, C_j, 1) (eq 11) become
// (S_j, C_j, 1), i.e. J(−q) = −diag(1, −1, −1) J(q). With the y and φ loads or held values zero
// along the whole path, the wrench maps as (Fx, Fy, Me) → (Fx, −Fy, −Me), every torque row
// ∂E/∂q_j − (JᵀF)_j changes sign, and the equations of EquilibriumProblem (and of ContactProblem
// with the mirrored joints locked on the other side) satisfy F(S u, λ) = S F(u, λ) with
//   S = −1 on every joint angle and on the reactions of a held y or φ, +1 on a held x's.
#pragma once

#include <string>
#include <vector>

#include "buckle/continuation/symmetry.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/landing.h"

namespace buckle::mechanics {

/// The mirror as a reflection of `problem`'s unknowns (q, r), or an empty one (no symmetry)
/// unless the problem is exactly mirror symmetric: every segment with k1 = k2 and L1_0 = L2_0,
/// joint limits q_min = −q_max (geometric and user), and the y and φ entries of the prescribed
/// values and of the load direction zero (no transverse load, moment or offset at any λ).
/// Body loads (weight, point loads: body_loads.h) are taken as breaking the symmetry.
/// Exact comparisons: a scene that is symmetric only to rounding is traced in full.
continuation::Reflection mirrorSymmetry(const EquilibriumProblem& problem);

/// The mirror image of a text: the words "upper" and "lower" (a joint's limits) exchanged, and
/// the ± corner of a wall vertex's label ("3d+" ↔ "3d-", wall_contact.h).
std::string mirrorText(const std::string& text);

/// The mirror image of a branch's contact stretches: the same joints locked on the other side.
std::vector<ContactStretch> mirrored(const std::vector<ContactStretch>& stretches);

/// The mirror image of a jump's landing: q → −q, (Fx, Fy, Me) → (Fx, −Fy, −Me),
/// (x, y, φ) → (x, −y, −φ), contacts on the other side with opposite torques (the gradient flow
/// and its side choice, the lower Π, are mirror invariant: jump.h).
Landing mirrored(const Landing& landing);

/// The mirror image of a base or self contact located on a branch (contact_geometry.h): the
/// unknowns u → S u by `mirror`, the contact point (x, y) → (x, −y); λ, the interval, the
/// touching segment or links, the accuracy and whether it was located kept. The wall x = 0 and
/// the links' distances are mirror invariant (every vertex and link has a mirror twin at the same
/// x and distance), so the image branch's contacts are these: reportBranch need not locate them
/// again on the image (its Newton solves at fixed λ are the mirrored ones).
GeometricContact mirrored(const continuation::Reflection& mirror, const GeometricContact& contact);

}  // namespace buckle::mechanics
