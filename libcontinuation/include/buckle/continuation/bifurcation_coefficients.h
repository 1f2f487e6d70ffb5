// The bifurcated branch at a simple branch point of a trivial branch, by the Lyapunov–Schmidt
// reduction (Koiter's post-buckling coefficients; Golubitsky & Schaeffer ch. I, Seydel §5.6).
//
// With F(u0, λ) = 0 for every λ, F_u(u0, λc) v = 0, ψᵀF_u = 0 and the amplitude ξ = cᵀ(u − u0)
// (cᵀv = 1), the branch born at λc is u = u0 + ξv + ξ²u2 + O(ξ³), λ = λc + aξ + bξ² + O(ξ³):
//   order ξ²:  F_u u2 + a F_uλ v + ½F_uu[v, v] = 0, so  a = −½ψᵀF_uu[v, v] / ψᵀF_uλ v,
//              and u2 (cᵀu2 = 0) from the bordered system;
//   order ξ³:  b ψᵀF_uλ v = −ψᵀ(a F_uλ u2 + F_uu[v, u2] + ⅙F_uuu[v, v, v] + ½a F_uuλ[v, v]
//                               + ½a² F_uλλ v).
// a = 0 for a symmetric pitchfork; then b > 0 (< 0) means the branch exists for λ > λc
// (λ < λc). F_uu comes exact from Problem::jacobianDirectionalDerivative; the third derivatives
// F_uuu[v, v, v], F_uuλ[v, v] and F_uλλ v are central differences of those exact second
// derivatives with one Richardson extrapolation (error O(h⁴), h = 10⁻² in the scaled variables).
#pragma once

#include "buckle/continuation/bound_problem.h"

#include <string>

namespace buckle::continuation {

struct BifurcationCoefficients {
  double a = 0.0;               ///< dλ/dξ at the branch point (0: symmetric pitchfork)
  double b = 0.0;               ///< ½ d²λ/dξ²
  double transversality = 0.0; ///< ψᵀF_uλ v (the eigenvalue's crossing speed; ≠ 0 required)
  Vector v;                     ///< the null vector, scaled so that cᵀv = 1
  Vector psi;                   ///< left null vector, ψᵀv = 1
  Vector u2;                    ///< second-order shape correction, cᵀu2 = 0
};

/// Coefficients of the branch bifurcating from the trivial branch u0 at λc; v approximates the
/// null vector of F_u(u0, λc) (rescaled so that cᵀv = 1). False with the reason in `why` when
/// the problem refuses a point, the branch point is not simple or not transversal.
bool bifurcationCoefficients(const BoundProblem &problem, ConstVectorRef u0, double lambdaC, ConstVectorRef v,
                             ConstVectorRef c, BifurcationCoefficients &out, std::string *why = nullptr);

}  // namespace buckle::continuation
