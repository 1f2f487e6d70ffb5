// Branch-point curves of a trivial branch: when F(u0, λ; μ) = 0 for every λ and μ (a symmetric
// state that stays an equilibrium, e.g. the straight column under an axial load), its branch
// points are where F_u(u0, λ; μ) is singular, and they form a curve in (λ, μ). The
// symmetry-preserving system (the trivial branch is known, so no Moore system is needed)
//     F_u(u0, λ; μ) w = 0,   cᵀw − 1 = 0,
// unknowns W = (w, λ) (size N + 1), continuation parameter μ, with the exact Jacobian
//     [[F_u, F_uλ w], [cᵀ, 0]],   ∂/∂μ = [F_uμ w; 0]
// (F_uλ w from Problem::jacobianDirectionalDerivative in the direction (w, 0); F_uμ w from
// TwoParameterProblem). Regular where the zero eigenvalue is simple and crosses transversally
// in λ (ψᵀF_uλ w ≠ 0).
//
// Structured linear algebra (useStructuredSolver): the tracer's bordered matrix of this system,
//     [[F_u, F_uλ w, F_uμ w], [cᵀ, 0, 0], [t_wᵀ, t_λ, t_μ]],
// is F_u bordered by two columns, so the base problem's structured solver factors it
// (BorderedSolver::factorGeneral, O(N) for the chain) and the residual takes F_u w from
// Problem::jacobianApply: a curve point costs O(N) instead of the (N+1)² LU. F_uλ w comes from
// TwoParameterProblem::parameterJacobianApply, F_uμ w from secondParameterDerivatives.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/two_parameter.h"

#include <memory>

namespace buckle::continuation {

class BranchPointCurveProblem final : public Problem {
 public:
  /// u0: the trivial solution (size N); c: the normalisation cᵀw = 1.
  BranchPointCurveProblem(TwoParameterProblem &problem, const Vector &u0, const Vector &c);

  /// The start W = (w, λ) from a null vector w of F_u(u0, λ) at the current μ: w of unit length
  /// in the problem's scaled variables, c = D_u⁻² w so that cᵀw = 1.
  static Vector start(const Problem &problem, double lambda, ConstVectorRef w, Vector &c);

  const Vector &trivialSolution() const { return u0_; }
  int base() const { return n_; }

  int dimension() const override { return n_ + 1; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef W, double mu, VectorRef G) const override;
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef W, double mu, MatrixRef GW, VectorRef Gmu) const override;
  ProblemScales scales() const override;

  /// On: the residual through Problem::jacobianApply and makeStructuredSolver() from the base
  /// problem's structured solver (header comment). Off (the default): dense, as documented above.
  void useStructuredSolver(bool on) { structured_ = on; }
  /// The curve's bordered solver on the base problem's (which must take general borders with
  /// k ≥ 1); null when off or when the base problem has none.
  std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace &ws) const override;

 private:
  TwoParameterProblem &problem_;  // μ is set on it at every evaluation
  BoundProblem inner_;            // its evaluations (a workspace of this curve problem's own)
  int n_;
  Vector u0_, c_;
  // As FoldCurveProblem (fold_curve.h): one computation's object, its scratch its own.
  mutable Matrix Fu_, dFu_;
  mutable Vector Flambda_, dFlambda_, Fmu_, FuMuW_;
  mutable Vector x_;  // (w, 0) of the structured residual
  bool structured_ = false;
};

}  // namespace buckle::continuation
