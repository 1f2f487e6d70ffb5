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
//
// For large N, MinimalFoldCurveProblem below is the same curve with O(N) linear algebra.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/internal/structured_refinement.h"
#include "buckle/continuation/two_parameter.h"

#include <Eigen/LU>
#include <memory>

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
  bool residual(ProblemWorkspace &ws, ConstVectorRef U, double mu, VectorRef G) const override;
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef U, double mu, MatrixRef GU, VectorRef Gmu) const override;
  /// u and v in the problem's scales, λ in its parameter scale; rows: F and F_u v in the
  /// residual scales, the normalisation 1; μ in secondParameterScale().
  ProblemScales scales() const override;

  /// The problem's boundaries g_k(u, λ; μ) (joint limits): the tracer stops where the fold meets one.
  int boundaryCount() const override { return problem_.boundaryCount(); }
  double boundary(ProblemWorkspace &ws, int k, ConstVectorRef U, double mu) const override;
  std::string boundaryName(int k) const override { return problem_.boundaryName(k); }

  /// The cusp test: ψᵀF_uu[v, v] / (‖ψ‖ ‖v‖²) (norms in the scaled variables), ψ from
  /// [[F_uᵀ, c], [vᵀ, 0]] [ψ; s] = [0; 1]. Changes sign at a cusp. False outside the domain or
  /// when that bordered matrix is singular.
  bool cuspTest(ConstVectorRef U, double mu, double &value) const;

 private:
  // A curve problem sets μ on its base problem at every evaluation, so it is one computation's
  // object (not shared between threads), and keeps its scratch itself.
  TwoParameterProblem &problem_;  // μ is set on it at every evaluation
  BoundProblem inner_;            // its evaluations (a workspace of this curve problem's own)
  int n_;
  Vector c_;
  mutable Matrix Fu_, dFu_;
  mutable Vector Flambda_, dFlambda_, Fmu_, FuMuV_, Fv_;
  mutable Eigen::PartialPivLU<Matrix> lu_;
};

/// The fold curve by the minimally augmented system (Govaerts 2000, §4.3; MATCONT's LP curve):
/// unknowns U = (u, λ) (size N + 1), continuation parameter μ,
///     F(u, λ; μ) = 0,   g(u, λ; μ) = 0,   [[F_u, b], [cᵀ, 0]] [v; g] = [0; 1],
/// g vanishing exactly where F_u is singular (v is then its null vector), with the gradient
///     g_x = −wᵀF_xx[(v, 0), ·]  (x = (u, λ)),   g_μ = −wᵀF_uμ v,   [[F_uᵀ, c], [bᵀ, 0]] [w; ·] = [0; 1]
/// (Problem::secondDerivativeTransposeApply, TwoParameterProblem::secondParameterDerivatives).
/// Every linear solve is a bordered solve on F_u by the base problem's structured solver
/// (factorGeneral; g refined on the base problem's O(N) products, structured_refinement.h): the
/// tracer's bordered matrix [[F_u, F_λ, F_μ], [g_uᵀ, g_λ, g_μ], [c̃ᵀ]] is F_u bordered by two
/// columns, solved through the one-bordered [[F_u, b], [cᵀ, 0]] (DeflatedBorderedSolve: F_u is
/// singular on the curve). So a curve point costs what the base problem's structure allows (O(N) for the
/// chain) instead of FoldCurveProblem's (2N+2)² LU; the curve is the same set of points.
/// The borders b, c approximate the left and right null vectors of F_u; adaptBorders() replaces
/// them by those at a point of the curve (g changes by a positive factor near the curve, its zero
/// set and the curve's tangent do not), which keeps the bordered matrices well conditioned as the
/// null vectors turn along the curve. Norms are those of the problem's scaled variables.
class MinimalFoldCurveProblem final : public Problem {
 public:
  /// Starts at a fold (u, λ) with (approximate) null vector v of F_u at the problem's current μ.
  /// Throws std::invalid_argument when the base problem has no structured solver taking general
  /// borders with k ≥ 1, or for vectors of the wrong size.
  MinimalFoldCurveProblem(TwoParameterProblem &problem, ConstVectorRef u, double lambda, ConstVectorRef v);

  int base() const { return n_; }
  /// U = (u, λ).
  static Vector start(ConstVectorRef u, double lambda);

  int dimension() const override { return n_ + 1; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef U, double mu, VectorRef G) const override;
  /// Dense [[F_u, F_λ], [g_xᵀ]] (for dense callers; the tracer uses makeStructuredSolver()).
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef U, double mu, MatrixRef GU, VectorRef Gmu) const override;
  /// O(N) products with [[F_u, F_λ, F_μ], [g_uᵀ, g_λ, g_μ]] and its transpose.
  bool jacobianApply(ProblemWorkspace &ws, ConstVectorRef U, double mu, ConstVectorRef x, VectorRef y) const override;
  bool jacobianTransposeApply(ProblemWorkspace &ws, ConstVectorRef U, double mu, ConstVectorRef w,
                              VectorRef y) const override;
  /// u in the problem's scales, λ in its parameter scale; rows: F in the residual scales, g 1;
  /// μ in secondParameterScale().
  ProblemScales scales() const override;
  std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace &ws) const override;

  int boundaryCount() const override { return problem_.boundaryCount(); }
  double boundary(ProblemWorkspace &ws, int k, ConstVectorRef U, double mu) const override;
  std::string boundaryName(int k) const override { return problem_.boundaryName(k); }

  /// Right null vector v (cᵀv = 1) and left one w at (U, μ) (null vectors of F_u on the curve).
  bool nullVectors(ConstVectorRef U, double mu, Vector &v, Vector &w) const;
  /// Borders from the null vectors at (U, μ): c ∝ D_u⁻²v, b ∝ D_F²w, unit in the scaled variables.
  bool adaptBorders(ConstVectorRef U, double mu);
  /// The current borders b (≈ left null vector) and c (≈ right null vector).
  const Vector &leftBorder() const { return b_; }
  const Vector &rightBorder() const { return c_; }
  /// Back to the borders of the start point (before tracing or revisiting a curve from there).
  void resetBorders();
  /// The cusp test of FoldCurveProblem::cuspTest, ψᵀF_uu[v, v] / (‖ψ‖ ‖v‖²) with ψ = w.
  bool cuspTest(ConstVectorRef U, double mu, double &value) const;

  /// g and its gradient (g_x, g_μ) at (U, μ), F_λ and F_μ there (the curve solver's borders).
  bool gradient(ConstVectorRef U, double mu, double &g, Vector &gx, double &gmu, Vector &Flambda, Vector &Fmu) const;

 private:
  /// v, w, g at (U, μ) into the cache (nothing recomputed for the same U, μ and borders).
  bool evaluate(ConstVectorRef U, double mu) const;
  bool evaluateGradient(ConstVectorRef U, double mu) const;
  void setBorders(const Vector &v, const Vector &w);

  // As FoldCurveProblem: one computation's object, its scratch and caches its own.
  TwoParameterProblem &problem_;  // μ is set on it at every evaluation
  BoundProblem inner_;            // its evaluations (a workspace of this curve problem's own)
  int n_;
  std::unique_ptr<BorderedSolver> solver_;  // the base problem's, for g, v, w
  std::unique_ptr<RefinedBorderedSystem> system_;
  Vector b_, c_;
  Vector b0_, c0_;  // the start's
  // Cache of evaluate() / evaluateGradient().
  mutable Vector cachedU_;
  mutable double cachedMu_ = 0.0;
  mutable bool cached_ = false, cachedGradient_ = false;
  mutable Vector v_, w_, gx_, Fmu_, FuMuV_, Flambda_, ex_;
  mutable double g_ = 0.0, gmu_ = 0.0;
  mutable Matrix Bm_, Cm_, Dm_;
  mutable Vector rhs_, z_, y_;
};

}  // namespace buckle::continuation
