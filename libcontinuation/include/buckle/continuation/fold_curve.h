// Fold (limit point) curves: the standard augmented fold system (Moore–Spence; AUTO's LP
// continuation, MATCONT's LP curve) as a Problem of its own, so the generic tracer follows a
// fold of F(u, λ; μ) = 0 in the second parameter μ:
//     F(u, λ; μ) = 0,   F_u(u, λ; μ) v = 0,   cᵀv − 1 = 0,
// unknowns U = (u, λ, v) (size 2N + 1), continuation parameter μ. Its Jacobian is exact:
//     [[F_u, F_λ, 0], [F_uu[v, ·], F_uλ v, F_u], [0, 0, cᵀ]],   ∂/∂μ = [F_μ; F_uμ v; 0],
// with F_uu[v, ·] and F_uλ v from Problem::jacobianDirectionalDerivative in the direction v and
// the μ-derivatives from TwoParameterProblem. The system is regular at a quadratic fold whose
// fold is transversal in μ (Govaerts 2000, §4.2).
//
// Codimension-two points on a fold curve:
//   cusp   the quadratic coefficient ψᵀF_uu[v, v] of the fold vanishes (ψ the left null vector):
//          two fold curves meet, and the curve turns in μ there (a fold of the fold curve);
//   others are the caller's test functions (curve_zeros.h), e.g. a joint limit g(u) = 0.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/problem.h"
#include "buckle/continuation/two_parameter.h"

#include <Eigen/LU>

namespace buckle::continuation {

class FoldCurveProblem final : public Problem {
 public:
  /// c (size N): the normalisation cᵀv = 1, c not orthogonal to the null vector.
  FoldCurveProblem(TwoParameterProblem &problem, const Vector &c);

  /// The start of the curve at a fold (u, λ) with null vector v of F_u, at the problem's current
  /// μ: v is rescaled to unit length in the problem's scaled variables and c chosen so that
  /// cᵀv = 1 (c = D_u⁻² v). Returns U = (u, λ, v); c in `c`.
  static Vector start(const Problem &problem, ConstVectorRef u, double lambda, ConstVectorRef v, Vector &c);

  int base() const { return n_; }
  /// Parts of U = (u, λ, v).
  static Vector stateU(ConstVectorRef U, int n) { return U.head(n); }
  static double stateLambda(ConstVectorRef U, int n) { return U[n]; }
  static Vector stateV(ConstVectorRef U, int n) { return U.tail(n); }

  int dimension() const override { return 2 * n_ + 1; }
  bool residual(ConstVectorRef U, double mu, VectorRef G) override;
  bool jacobian(ConstVectorRef U, double mu, MatrixRef GU, VectorRef Gmu) override;
  /// u and v in the problem's scales, λ in its parameter scale; rows: F and F_u v in the
  /// residual scales, the normalisation 1; μ in secondParameterScale().
  ProblemScales scales() const override;

  /// The problem's boundaries g_k(u, λ; μ) (joint limits): the tracer stops where the fold meets one.
  int boundaryCount() const override { return problem_.boundaryCount(); }
  double boundary(int k, ConstVectorRef U, double mu) override;
  std::string boundaryName(int k) const override { return problem_.boundaryName(k); }

  /// The cusp test: ψᵀF_uu[v, v] / (‖ψ‖ ‖v‖²) (norms in the scaled variables), ψ from
  /// [[F_uᵀ, c], [vᵀ, 0]] [ψ; s] = [0; 1]. Changes sign at a cusp. False outside the domain or
  /// when that bordered matrix is singular.
  bool cuspTest(ConstVectorRef U, double mu, double &value);

 private:
  TwoParameterProblem &problem_;
  int n_;
  Vector c_;
  Matrix Fu_, dFu_;
  Vector Flambda_, dFlambda_, Fmu_, FuMuV_, Fv_;
  Eigen::PartialPivLU<Matrix> lu_;
};

}  // namespace buckle::continuation
