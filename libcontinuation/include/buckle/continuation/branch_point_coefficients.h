// Koiter's post-buckling coefficients at a simple branch point of ANY branch (trivial or bent),
// by the Lyapunov–Schmidt reduction relative to the branch being traced, the "parent"
// (Koiter's fundamental path; Keller 1977, Seydel §5.6, Govaerts §3.3).
//
// x = (u, λ), F_x = [F_u F_λ] (N×(N+1)). At a simple branch point x0 of a parent with tangent t
// (t_λ ≠ 0: not also a fold of the parent), F_u has the one-dimensional kernel v (cᵀv = 1),
// ψᵀF_u = 0 (ψᵀv = 1), ψᵀF_λ = 0, and ker F_x = span{d, e} with e = (v, 0) and d = (p1, 1),
// p1 = du_p/dλ the parent's slope. Algebraic bifurcation equation (ABE): with t, φ an orthonormal
// basis of ker F_x (t along the parent), a11 = ψᵀF_xx[t,t], a12 = ψᵀF_xx[t,φ], a22 = ψᵀF_xx[φ,φ],
//     a11 α² + 2 a12 αβ + a22 β² = 0,
// and a11 = 0 because t is a root (the parent solves F = 0). The child's tangent is the other
// root, (α, β) ∝ (−a22, 2 a12); in the basis {d, e} it is e + a·d.
//
// The amplitude is measured against the parent: ξ = cᵀ(u − u_p(λ)). Then G(z, λ) =
// F(u_p(λ) + z, λ) has the trivial branch z = 0 and bifurcation_coefficients.h applies to G; its
// derivatives at the point in terms of F (D³F by differences of the exact F_xx):
//   G_zλ v = F_xx[e, d]                    τ = ψᵀG_zλ v (transversality, ≠ 0 required)
//   a = −½ ψᵀF_xx[e, e] / τ,   G_z u2 = −(a G_zλ v + ½F_xx[e, e]),  cᵀu2 = 0
//   b τ = −ψᵀ(a F_xx[(u2, 0), d] + F_xx[e, (u2, 0)] + ⅙D³F[e,e,e] + ½a D³F[e,e,d]
//            + ½a² (D³F[e,d,d] + F_xx[e, (p2, 0)]))
// with p2 = d²u_p/dλ²: F_u p2 = −F_xx[d, d] (solvable: ψᵀF_xx[d, d] ∝ a11 = 0), its component
// along v from the third derivative of F(u_p(λ), λ) = 0: ψᵀ(D³F[d,d,d] + 3 F_xx[d, (p2, 0)]) = 0.
// The component of p1 along v is the root of ψᵀF_xx[d, d] = 0 (a quadratic in it, the ABE)
// nearest to the given tangent's, so the result does not inherit the tangent's location error.
// On a trivial branch (p1 = p2 = 0) this is exactly bifurcationCoefficients.
//
// So the child is u = u_p(λ) + ξv + ξ²u2 + O(ξ³), λ = λc + aξ + bξ² + O(ξ³): a ≠ 0 is an
// asymmetric (transcritical) point, a = 0 a symmetric pitchfork whose branch lies on the side
// sign(b) of λc.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"

#include <string>

namespace buckle::continuation {

struct BranchPointCoefficients {
  double a = 0.0;                ///< dλ/dξ of the child at the branch point
  double b = 0.0;                ///< ½ d²λ/dξ²
  double transversality = 0.0;   ///< τ = ψᵀF_xx[e, d]: the zero eigenvalue's crossing speed
  /// Σ|ψ_i|·|terms_i| / |τ| over the terms of b (the size b would have without cancellation)
  double bScale = 0.0;
  /// What |b| may be in error by: its terms' rounding and the differences' for the third
  /// derivatives, plus (the SpecialPoint overload) bScale times the point's relative location
  /// error. |b| ≤ bAccuracy: b is zero to its accuracy, a degenerate pitchfork (childExpansion).
  double bAccuracy = 0.0;
  double a11 = 0.0, a12 = 0.0, a22 = 0.0;  ///< ABE coefficients in the orthonormal basis {t, φ}
  Vector v;                      ///< null vector of F_u, cᵀv = 1
  Vector psi;                    ///< left null vector, ψᵀv = 1
  Vector parentSlope;            ///< p1 = du_p/dλ of the parent at the point
  Vector parentCurvature;        ///< p2 = d²u_p/dλ²
  Vector u2;                     ///< second-order shape of the child relative to the parent, cᵀu2 = 0
  Vector childTangent;           ///< unit (N+1) tangent of the child, ∝ e + a·d, along +ξ
};

/// The linear algebra of the reduction. Dense: F_u and F_xx[x, ·] as N×N matrices
/// (jacobianDirectionalDerivative), partial-pivoting LU; O(N³). Structured: the second
/// derivatives as vectors (Problem::secondDerivativeApply) and every solve with F_u through the
/// problem's bordered solver with a one-column border (BorderedSolver::factorGeneral),
/// iteratively refined on the problem's exact products (RefinedBorderedSystem); O(N) for a chain.
/// Automatic: structured above kDenseCoefficientDimension unknowns when the problem has a
/// structured solver that takes general borders, dense otherwise (a speed crossover only: both
/// give the same coefficients, to ~1e-10 relative on the chain).
enum class CoefficientAlgebra { Automatic, Dense, Structured };
constexpr int kDenseCoefficientDimension = 60;

/// The coefficients at the simple branch point (u0, λc) of the branch with tangent
/// `parentTangent` (size N+1, any length and sign); v approximates the null vector of F_u (it is
/// refined, then rescaled so that cᵀv = 1). False with the reason in `why` when the problem
/// refuses a point, F_u is not singular there, the parent is vertical (a fold), the point is
/// not transversal, or (structured) the problem's solver cannot factor the bordered F_u.
bool branchPointCoefficients(const BoundProblem &problem, ConstVectorRef u0, double lambdaC,
                             ConstVectorRef parentTangent, ConstVectorRef v, ConstVectorRef c,
                             BranchPointCoefficients &out, std::string *why = nullptr,
                             CoefficientAlgebra algebra = CoefficientAlgebra::Automatic);

/// Same at a branch point located by the tracer (bp.tangent the parent's, v from bp.nullVectors).
bool branchPointCoefficients(const BoundProblem &problem, const SpecialPoint &bp, ConstVectorRef c,
                             BranchPointCoefficients &out, std::string *why = nullptr,
                             CoefficientAlgebra algebra = CoefficientAlgebra::Automatic);

/// λ(s) = λ0 + ½λ''s² + … through a located fold (u = u0 + s v, |v| = 1): λ'' = −ψᵀF_uu[v, v] /
/// ψᵀF_λ. Where λ'' is zero to its accuracy (its terms' rounding and the point's location error)
/// the fold is a cusp of the fold curve, two folds merged (Govaerts §6.2): `cusp`.
struct FoldCoefficient {
  double curvature = 0.0;  ///< λ''
  double scale = 0.0;      ///< Σ|ψ_i|·|F_uu[v, v]_i| / |ψᵀF_λ|: λ'' without cancellation
  double accuracy = 0.0;
  bool cusp = false;
};
bool foldCoefficient(const BoundProblem &problem, const SpecialPoint &fold, FoldCoefficient &out,
                     std::string *why = nullptr);

/// The child's λ(ξ) beyond b, from the child itself: at a degenerate pitchfork (|b| ≤ bAccuracy)
/// the quartic term decides which side the branch lies on (Golubitsky & Schaeffer ch. VI: the
/// pitchfork's unfolding is λ = bξ² + c₄ξ⁴). Points of the child at the amplitudes
/// ξ = cᵀ(u − u0) = ±h, ±2h, ±3h (each a corrector solve on the hyperplane of that ξ from the
/// predictor u0 + ξv + ξ²u2, λc + aξ + bξ²), then the even part ½(λ(ξ) + λ(−ξ)) − λc =
/// c₂ξ² + c₄ξ⁴ + c₆ξ⁶ and the odd part ½(λ(ξ) − λ(−ξ)) = c₁ξ + c₃ξ³ + c₅ξ⁵ solved exactly. The
/// fit is repeated at h/2; c₄'s accuracy is the difference of the two fits plus their
/// rounding. h: 0.05 of the problem's scales along v (`amplitude` > 0 overrides).
struct ChildBranchExpansion {
  double c1 = 0.0, c2 = 0.0, c3 = 0.0, c4 = 0.0;  ///< λ = λc + c₁ξ + c₂ξ² + c₃ξ³ + c₄ξ⁴ + …
  double c2Accuracy = 0.0, c4Accuracy = 0.0;       ///< the two fits' difference plus rounding
  double amplitude = 0.0;                          ///< h, in the units of ξ = cᵀ(u − u0)
};

bool childBranchExpansion(const BoundProblem &problem, ConstVectorRef u0, double lambdaC,
                          const BranchPointCoefficients &g, ConstVectorRef c, ChildBranchExpansion &out,
                          std::string *why = nullptr, double amplitude = 0.0);

}  // namespace buckle::continuation
