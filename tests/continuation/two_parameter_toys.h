// Small two-parameter problems with closed-form critical curves, for the core's tests.
#pragma once

#include "buckle/continuation/branch_point_curve.h"
#include "buckle/continuation/two_parameter.h"

#include <cmath>

namespace buckle::continuation::toys {

/// μ as a plain member: what both toys share.
class ToyTwoParameter : public TwoParameterProblem {
 public:
  double mu = 0.0;
  int dimension() const override { return 2; }
  double secondParameter() const override { return mu; }
  bool setSecondParameter(double m) override {
    mu = m;
    return std::isfinite(m);
  }
};

/// F = (λ + μx − x³ + xy, y − x²/2): with y = x²/2, λ + μx − x³/2 = 0, the cusp normal form.
/// Fold curve μ = 3x²/2, λ = −x³ (y = x²/2); cusp at the origin.
class CuspToy : public ToyTwoParameter {
 public:
  CuspToy() { mu = 1.5; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = lambda + mu * u[0] - u[0] * u[0] * u[0] + u[0] * u[1];
    F[1] = u[1] - 0.5 * u[0] * u[0];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu << mu - 3.0 * u[0] * u[0] + u[1], u[0], -u[0], 1.0;
    Fl << 1.0, 0.0;
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef du, double,
                                     MatrixRef dFu, VectorRef dFl) const override {
    dFu << -6.0 * u[0] * du[0] + du[1], du[0], -du[0], 0.0;
    dFl.setZero();
    return true;
  }
  bool secondParameterDerivatives(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef v, VectorRef Fmu,
                                  VectorRef FuMuV) const override {
    Fmu << u[0], 0.0;
    FuMuV << v[0], 0.0;
    return true;
  }
};

/// F = (A(μ) − λI)u + (u1³, u2³), A = [[2, μ], [μ, 1]]: the trivial branch u = 0 has branch
/// points at the eigenvalues of A, the lower one λ = 3/2 − √(1/4 + μ²).
class EigenToy : public ToyTwoParameter {
 public:
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = (2.0 - lambda) * u[0] + mu * u[1] + u[0] * u[0] * u[0];
    F[1] = mu * u[0] + (1.0 - lambda) * u[1] + u[1] * u[1] * u[1];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu << 2.0 - lambda + 3.0 * u[0] * u[0], mu, mu, 1.0 - lambda + 3.0 * u[1] * u[1];
    Fl = -u;
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef du, double dl,
                                     MatrixRef dFu, VectorRef dFl) const override {
    dFu << 6.0 * u[0] * du[0] - dl, 0.0, 0.0, 6.0 * u[1] * du[1] - dl;
    dFl = -du;
    return true;
  }
  bool secondParameterDerivatives(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef v, VectorRef Fmu,
                                  VectorRef FuMuV) const override {
    Fmu << u[1], u[0];
    FuMuV << v[1], v[0];
    return true;
  }
};

/// The start of the EigenToy's branch-point curve at μ = 0 (λ = 1, w = (0, 1)); c receives the
/// normalisation.
inline Vector eigenToyCurveStart(EigenToy &toy, Vector &c) {
  toy.mu = 0.0;
  return BranchPointCurveProblem::start(toy, 1.0, (Vector(2) << 0.0, 1.0).finished(), c);
}

}  // namespace buckle::continuation::toys
