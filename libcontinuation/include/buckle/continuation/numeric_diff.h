// A Problem from its residual alone: every derivative by finite differences (in the spirit of
// Ceres' NumericDiffCostFunction). The user writes dimension() and residual() — and, when the
// unknowns are not O(1), scales() — and derives from NumericDiffProblem instead of Problem; the
// core then gets
//   - F_u and F_λ by central differences, column j with the step h_j = δ·max(|u_j|, s_j)
//     (s_j = scales().unknowns[j], s_λ = scales().parameter, δ = NumericDiffOptions::relativeStep
//     ≈ ε^{1/3}, which balances the O(h²) truncation against the O(ε/h) rounding: F_u to ~ε^{2/3}
//     of the size of the terms of F);
//   - the second derivative (jacobianDirectionalDerivative, secondDerivativeApply,
//     secondDerivativeTransposeApply) by second differences of the residual with steps
//     ~ε^{1/4} relative (not by differences of the differenced F_u, whose rounding would be
//     divided by a second small step): ~ε^{1/2} of the size of the terms.
// Folds and branch points are then located where the *differenced* F_u is singular: λ of a
// fold to second order in F_u's error (λ is stationary there), u and branch-point λ to first
// order, i.e. ~ε^{2/3} relative in the problem's scales (tests/continuation/test_numeric_diff.cpp).
// Everything else a Problem may offer (stability operator, boundaries, scales, a structured
// solver) the derived class adds exactly as on a Problem. A point where a perturbed residual is
// refused (outside the domain) is refused as a whole: the tracer then halves its step.
//
// To check a hand-written Jacobian against these differences, see derivative_check.h.
#pragma once

#include "buckle/continuation/options_validity.h"
#include "buckle/continuation/bound_problem.h"

#include <string>

namespace buckle::continuation {

struct NumericDiffOptions {
  /// δ of the first-derivative step h_j = δ·max(|u_j|, s_j): ε^{1/3} by default.
  double relativeStep = 6.0554544523933395e-06;
  /// δ of the second-derivative steps: ε^{1/4} by default.
  double secondRelativeStep = 1.2207031250000000e-04;
  /// Empty when valid, else which field is wrong and why (both steps in (0, 0.1]), the field
  /// named as `prefix` + its name.
  std::string validate(const std::string &prefix = "") const;
  bool IsValid(std::string *why) const { return reportValidity(validate(), why); }
};

/// Central-difference F_u, F_λ (step relative to each variable's scale) into Fu (N×N) and Fl:
/// 2(N+1) evaluations of problem.residual(). `scales` as returned by problem.scales() (passed in
/// so that a hot loop does not rebuild them). False when a perturbed point is refused. The
/// workspace vectors (size N) are the caller's, so nothing is allocated.
bool differenceJacobian(const BoundProblem &problem, const ProblemScales &scales, double relativeStep, ConstVectorRef u,
                        double lambda, MatrixRef Fu, VectorRef Fl, VectorRef work, VectorRef Fplus, VectorRef Fminus);

class NumericDiffProblem : public Problem {
 public:
  explicit NumericDiffProblem(const NumericDiffOptions &options = NumericDiffOptions());

  /// F_u and F_λ by central differences of residual().
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Flambda) const override;
  bool jacobianWritesAllEntries() const override { return true; }
  /// d/dε [F_u, F_λ](z + εx): second differences of residual() along x and each coordinate.
  bool jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                     double dlambda, MatrixRef dFu, VectorRef dFlambda) const override;
  /// F_xx[x, z]: one second difference of residual() along x and z (four evaluations).
  bool secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x, ConstVectorRef z,
                             VectorRef y) const override;
  /// (F_xx[x, ·])ᵀw = [dF_u, dF_λ]ᵀw with the directional derivative above.
  bool secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                      ConstVectorRef w, VectorRef y) const override;

  const NumericDiffOptions &numericDiffOptions() const { return options_; }

  /// The differences' scratch. A problem with a workspace of its own derives it from this one.
  struct Workspace : ProblemWorkspace {
    ProblemScales scales;  // scales() as first evaluated in this workspace (the steps use them)
    bool scalesValid = false;
    Vector work, Fplus, Fminus, corner;  // size N
    Matrix Jplus, Jminus, second;        // N×(N+1)
  };
  std::unique_ptr<ProblemWorkspace> createWorkspace() const override { return std::make_unique<Workspace>(); }

 private:
  const ProblemScales &cachedScales(Workspace &nd) const;
  // Step along the (N+1)-direction (dx, dλ) of relative size `relative`, 0 for a zero direction.
  double directionStep(Workspace &nd, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda,
                       double relative) const;

  NumericDiffOptions options_;
};

}  // namespace buckle::continuation
