// A problem F(u, λ; μ) = 0 with a second parameter μ: what two-parameter continuation needs
// beyond Problem (fold_curve.h, branch_point_curve.h). The first parameter λ stays the one of
// Problem; μ is a state of the problem, set before evaluating (AUTO's ICP(2), MATCONT's ap).
#pragma once

#include "buckle/continuation/bound_problem.h"

#include <algorithm>
#include <cmath>

namespace buckle::continuation {

class TwoParameterProblem : public Problem {
 public:
  /// The current μ.
  virtual double secondParameter() const = 0;
  /// Sets μ for the following evaluations; false (μ unchanged) when μ is outside the domain.
  virtual bool setSecondParameter(double mu) = 0;
  /// Exact F_μ (size N) and (∂F_u/∂μ)·v (size N) at (u, λ) and the current μ.
  virtual bool secondParameterDerivatives(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef v,
                                          VectorRef Fmu, VectorRef FuMuV) const = 0;
  /// (∂F_u/∂λ)·v (size N) at (u, λ) and the current μ: the λ-column of the branch-point curve's
  /// Jacobian (branch_point_curve.h) without forming F_u. Default: central differences of
  /// jacobianApply() in λ (O(N) with the problem's products; exact to rounding when F_u is
  /// affine in λ, as for dead loads). Override with the exact product.
  virtual bool parameterJacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef v,
                                      VectorRef FuLambdaV) const {
    const int n = dimension();
    const double scale = scales().parameter;
    const double h = 6e-6 * std::max(scale, std::abs(lambda));
    Vector x(n + 1), yp(n), ym(n);
    x << v, 0.0;
    if (!jacobianApply(ws, u, lambda + h, x, yp) || !jacobianApply(ws, u, lambda - h, x, ym)) return false;
    FuLambdaV = (yp - ym) / (2.0 * h);
    return FuLambdaV.allFinite();
  }
  /// Typical |μ| (the unit of μ for the continuation of a curve, ProblemScales::parameter).
  virtual double secondParameterScale() const { return 1.0; }
};

/// Scales of a curve problem whose unknowns are (u, λ) and whose rows are F and one normalised
/// row (branch_point_curve.h, fold_curve.h's MinimalFoldCurveProblem): u and F in the problem's
/// scales, λ in its parameter scale, the extra row 1, μ in secondParameterScale().
inline ProblemScales stateAndParameterScales(const TwoParameterProblem &problem) {
  const ProblemScales s = problem.scales();
  const Eigen::Index n = s.unknowns.size();
  ProblemScales out;
  out.unknowns.resize(n + 1);
  out.unknowns << s.unknowns, s.parameter;
  out.residuals.resize(n + 1);
  out.residuals << s.residuals, 1.0;
  out.parameter = problem.secondParameterScale();
  return out;
}

}  // namespace buckle::continuation
