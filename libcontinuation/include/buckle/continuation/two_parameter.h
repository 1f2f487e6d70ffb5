// A problem F(u, λ; μ) = 0 with a second parameter μ: what two-parameter continuation needs
// beyond Problem (fold_curve.h, branch_point_curve.h). The first parameter λ stays the one of
// Problem; μ is a state of the problem, set before evaluating (AUTO's ICP(2), MATCONT's ap).
#pragma once

#include "buckle/continuation/problem.h"

namespace buckle::continuation {

class TwoParameterProblem : public Problem {
 public:
  /// The current μ.
  virtual double secondParameter() const = 0;
  /// Sets μ for the following evaluations; false (μ unchanged) when μ is outside the domain.
  virtual bool setSecondParameter(double mu) = 0;
  /// Exact F_μ (size N) and (∂F_u/∂μ)·v (size N) at (u, λ) and the current μ.
  virtual bool secondParameterDerivatives(ConstVectorRef u, double lambda, ConstVectorRef v, VectorRef Fmu,
                                          VectorRef FuMuV) = 0;
  /// Typical |μ| (the unit of μ for the continuation of a curve, ProblemScales::parameter).
  virtual double secondParameterScale() const { return 1.0; }
};

}  // namespace buckle::continuation
