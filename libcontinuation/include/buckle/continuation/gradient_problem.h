// A problem whose equations are the stationarity of a potential, F(u, λ) = ∇_u Π(u, λ) (or the
// restoring force −∇_u Π, as in mechanics): its stability operator is the Hessian, H = ±F_u, with
// no constraints. Derive from GradientProblem and write the residual and Jacobian only (the
// gradient and the Hessian): stability, the inertia and the eigenvalues near zero that the
// branch-point test and certified counting read come with them (as BifurcationKit derives what it
// can by default). A stable state is a strict local minimum of Π: H positive definite.
//
// The Jacobian of a gradient is symmetric; the stability operator takes its symmetric part, so a
// hand-written F_u that is off by rounding stays a valid operator (checkDerivatives,
// derivative_check.h, checks F_u itself).
#pragma once

#include "buckle/continuation/bound_problem.h"

namespace buckle::continuation {

class GradientProblem : public Problem {
 public:
  /// How the residual relates to the potential.
  enum class Residual {
    Gradient,        ///< F = ∇Π: H = F_u
    RestoringForce,  ///< F = −∇Π (a force balance): H = −F_u
  };
  explicit GradientProblem(Residual residual = Residual::Gradient) : residual_(residual) {}

  bool hasStabilityOperator() const final { return true; }
  /// H = ±F_u (symmetrized), C empty. False when the problem refuses the point.
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override;
  Residual residualKind() const { return residual_; }

 private:
  Residual residual_;
};

}  // namespace buckle::continuation
