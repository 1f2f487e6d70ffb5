// A reflection symmetry of a problem, and the images of branches under it.
//
// A reflection S = diag(s), s_i = ±1, of the unknowns (λ fixed) is a symmetry of F(u, λ) = 0
// when the equations are equivariant with the same S on their rows:
//     F(S u, λ) = S F(u, λ)         for all (u, λ)
// (e.g. the mirror q → −q of a chain under loads that are symmetric about its axis). Then
// differentiating, F_u(S u, λ) = S F_u(u, λ) S and F_λ(S u, λ) = S F_λ(u, λ), so S maps every
// solution branch onto a solution branch with the same λ at every point and
//   - tangents, fold null vectors and branch-point kernels mapped by diag(S, 1), left null
//     vectors by S (ψᵀF_x = 0 ⇔ (Sψ)ᵀ(S F_x diag(S, 1)) = 0);
//   - the same determinant of the bordered Jacobian [[F_u, F_λ], [tᵀ]] (it is multiplied by
//     det(S)² = 1), hence the same branch-point test and fold test t_λ;
//   - the same spectrum of the stability operator when it transforms the same way (a Hessian of
//     an S-invariant potential: H(S u) = S H(u) S, similar to H(u)): the same inertia, the same
//     eigenvalues next to zero and their rates.
// The tracer's operations (corrector, step control, detection, location) are equivariant too: its
// norms are invariant under sign changes and its scaling is diagonal. So the branch traced from
// S x₀ along diag(S, 1)·t₀ is, up to rounding, the image of the branch traced from x₀ along t₀.
//
// At a branch point fixed by S (S u_BP = u_BP) whose bifurcating direction d is reversed by it
// (diag(S, 1) d = −d: a symmetric pitchfork, e.g. the buckling of a straight column), the child
// leaving along −d is the image of the child leaving along +d; the tree driver
// (branch_switching.h, TreeOptions::symmetry) traces one and mirrors the other.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/problem.h"

#include <functional>
#include <string>

namespace buckle::continuation {

struct Reflection {
  /// s (size N, every entry +1 or −1); empty: no symmetry.
  Vector signs;
  /// The text of the image of a boundary name, note or stop message (e.g. a joint's "upper"
  /// limit becomes its "lower" one); empty: the text is kept.
  std::function<std::string(const std::string &)> text;
  /// Relative distance (in the tracer's scaled variables) within which a branch point counts as
  /// fixed by S and its bifurcating direction as reversed by it.
  double tolerance = 1e-8;

  bool enabled() const { return signs.size() > 0; }
  /// Empty, or every sign ±1 and size n, tolerance in (0, 1).
  bool IsValid(int n, std::string *why) const;
  /// x ← diag(S, 1)·x for x of size N + 1 (a state or a tangent), S·x for size N.
  void apply(VectorRef x) const;
  std::string mapText(const std::string &s) const { return text ? text(s) : s; }
  /// ‖diag(S, 1)·x − sign·x‖ ≤ tolerance·max(1, ‖x‖) in the scaled vector x (size N + 1):
  /// sign +1, x fixed by S; sign −1, x reversed by it.
  bool maps(ConstVectorRef x, int sign) const;
};

/// The image of a point, a special point, a branch under the reflection (the file comment):
/// unknowns, tangents and (left) null vectors mapped, λ, arclength, stability and test functions
/// kept, texts mapped by Reflection::text. The branch keeps its id, parent and direction.
void reflect(const Reflection &reflection, ContinuationPoint &point);
void reflect(const Reflection &reflection, SpecialPoint &point);
Branch reflected(const Reflection &reflection, const Branch &branch);

}  // namespace buckle::continuation
