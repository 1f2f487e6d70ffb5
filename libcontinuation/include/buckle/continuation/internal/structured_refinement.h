// Refinement of folds and simple branch points with O(N) algebra: the locator's path above
// TracerOptions::maxDenseLocationDimension (a speed crossover; below it the dense augmented
// systems of locator.h do the same job).
//
// Minimally augmented systems (Govaerts 2000, ch. 4; MATCONT's LP and BP on curves), solved by
// Newton with every linear solve a bordered solve on F_u (BorderedSolver::factorGeneral, O(N) for
// a structured problem):
//   fold          unknowns x = (u, λ):     F(x) = 0, g(x) = 0, with [[F_u, b], [cᵀ, 0]] [v; g] = [0; 1]
//   branch point  unknowns (x, β):         F(x) + βψ̂ = 0, h(x) = 0 ∈ R², with
//                 [[F_x, ψ̂], [Kᵀ, 0]] [ξ_i; h_i] = [0; e_i]   (K: (N+1)×2)
// The derivatives of g and h need only the adjoint solution w ([[F_uᵀ, c], [bᵀ, 0]] resp. the
// transposed BP matrix) and one second-derivative product each: g_x = −wᵀF_xx[(v, 0), ·],
// h_i,x = −wᵀF_xx[ξ_i, ·] (Problem::secondDerivativeTransposeApply). The borders b, c (ψ̂, K)
// are replaced by the latest adjoint and null vectors after every step, which keeps the
// bordered matrices well conditioned.
//
// Accuracy: a structured solve may be far less accurate than the problem is well conditioned
// (the chain's tridiagonal T loses ~n² relative to the joint coordinates, mechanics). Newton
// converges to the zero of its residual as it is evaluated, whatever its linear solves, so the
// residuals are evaluated exactly: F by Problem::residual, and g, h from solves iteratively
// refined with the problem's own O(N) products (Problem::jacobianApply / jacobianTransposeApply),
// i.e. to the accuracy of those products in the problem's coordinates.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/bound_problem.h"

#include <string>

namespace buckle::continuation {

/// G = [[F_u, B], [Cᵀ, D]] (or [[F_uᵀ, B], [Cᵀ, D]]) at one point (u, λ), factored by a
/// BorderedSolver (factorGeneral) and solved with iterative refinement on the residual b − G x
/// evaluated with the problem's own O(N) products: the building block of the refinements below
/// and of the minimally augmented curve systems (fold_curve.h).
class RefinedBorderedSystem {
 public:
  /// `problem` and `solver` are not owned and must outlive the system.
  RefinedBorderedSystem(const BoundProblem &problem, BorderedSolver &solver);

  /// Factors G at (u, λ) (B, C N×k, D k×k) and remembers it for solve(). False when the solver
  /// refuses the point or G is singular.
  bool factor(ConstVectorRef u, double lambda, const Matrix &B, const Matrix &C, const Matrix &D, bool transposed);
  /// x = G⁻¹ b (size N + k), refined on the exactly evaluated residual.
  bool solve(const Vector &b, Vector &x);

 private:
  bool applyG(const Vector &x, Vector &y);

  BoundProblem problem_;
  BorderedSolver &solver_;
  int n_;
  Vector u_;
  double lambda_ = 0.0;
  Matrix B_, C_, D_;
  bool transposed_ = false;
  Vector ex_, prod_, Gx_, r_, dx_;  // workspace of applyG and solve
};

struct StructuredRefinementResult {
  bool converged = false;
  int iterations = 0;
  double lastDLambda = 0.0;   ///< |Δλ| of the last Newton step
  double residualNorm = 0.0;  ///< ‖(F, g)‖ or ‖(F + βψ̂, h)‖ at the result
  double testValue = 0.0;     ///< g (fold) or ‖h‖ (branch point) at the result
  std::string message;
};

class StructuredRefinement {
 public:
  /// `solver` must support factorGeneral() with k ≥ 2 (not owned; its factorizations are
  /// replaced). Tolerance: Newton stops when |Δλ| ≤ tolerance·max(1, |λ|), after one more step.
  StructuredRefinement(const BoundProblem &problem, BorderedSolver &solver, double tolerance, int maxIterations);

  /// Fold near (u, λ) with tangent t there (t_u ≈ the null vector). On success u, λ are the
  /// fold and v the unit null vector of F_u. An iterate farther than maxDistance from the
  /// start is a failure (u, λ restored).
  StructuredRefinementResult fold(Vector &u, double &lambda, ConstVectorRef tangent, Vector &v, double maxDistance);

  /// Simple branch point near (u, λ) with the branch's tangent t there. On success u, λ are the
  /// point, kernel ((N+1)×2, orthonormal) spans ker F_x and psi (unit) spans ker F_xᵀ.
  StructuredRefinementResult branchPoint(Vector &u, double &lambda, ConstVectorRef tangent, Matrix &kernel,
                                         Vector &psi, double maxDistance);

  /// Null vectors of F_x near a simple branch point without refining it: inverse iteration with
  /// [[F_x], [tᵀ]] and its transpose. kernel = orthonormal (t, φ), psi unit.
  bool approximateKernel(ConstVectorRef u, double lambda, ConstVectorRef tangent, Matrix &kernel, Vector &psi);

 private:
  /// Factors G = [[F_u (F_uᵀ), B], [Cᵀ, D]] at (u, λ) and remembers it for refinedSolve().
  bool factor(ConstVectorRef u, double lambda, const Matrix &B, const Matrix &C, const Matrix &D, bool transposed) {
    return system_.factor(u, lambda, B, C, D, transposed);
  }
  /// x = G⁻¹ b with iterative refinement on the residual b − G x from the problem's products.
  bool refinedSolve(const Vector &b, Vector &x) { return system_.solve(b, x); }
  bool parameterDerivative(ConstVectorRef u, double lambda, Vector &Fl);

  BoundProblem problem_;
  BorderedSolver &solver_;
  RefinedBorderedSystem system_;
  double tolerance_;
  int maxIterations_;
  int n_;
  Vector ex_;  // workspace of parameterDerivative
};

}  // namespace buckle::continuation
