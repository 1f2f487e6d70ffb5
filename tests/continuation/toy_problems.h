// Small analytic problems with closed-form branches and special points, for the core tests.
#pragma once

#include "buckle/continuation/problem.h"

#include <cmath>
#include <limits>

namespace buckle::continuation::toys {

/// A one-entry vector: a point of a one-dimensional problem.
inline Vector vec1(double a) { return (Vector(1) << a).finished(); }

/// The stability operator of a gradient system F = −∇V: H = −F_u, no constraints.
inline bool negatedJacobian(const Problem &problem, ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H,
                            Matrix &C) {
  const int n = problem.dimension();
  Vector Fl(n);
  H = Matrix::Zero(n, n);
  if (!problem.jacobian(ws, u, lambda, H, Fl)) return false;
  H = -H;
  C.resize(0, n);
  return true;
}

/// u² + λ² = 1: folds at λ = ±1 (u = 0).
class Circle : public Problem {
 public:
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = u[0] * u[0] + lambda * lambda - 1.0;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = 2.0 * u[0];
    Fl[0] = 2.0 * lambda;
    return true;
  }
};

/// Fold normal form u² − λ = 0: one fold at (u, λ) = (0, 0).
class FoldNormalForm : public Problem {
 public:
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = u[0] * u[0] - lambda;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = 2.0 * u[0];
    Fl[0] = -1.0;
    return true;
  }
};

/// λ + u − u³/3 = 0, a gradient system (H = −F_u = u² − 1): folds at u = ±1, λ = ∓2/3.
class CubicFold : public Problem {
 public:
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = lambda + u[0] - u[0] * u[0] * u[0] / 3.0;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = 1.0 - u[0] * u[0];
    Fl[0] = 1.0;
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &, ConstVectorRef u, double, Matrix &H, Matrix &C) const override {
    H.resize(1, 1);
    H(0, 0) = u[0] * u[0] - 1.0;
    C.resize(0, 1);
    return true;
  }
};

/// Symmetric pitchforks [λu₁ − u₁³, (λ − c)u₂ − u₂³], H = −F_u: branch points at λ = 0 and
/// λ = c on u = 0, bifurcating branch u₁² = λ (u₂ = 0) stable for 0 < λ < c.
class TwoPitchforks : public Problem {
 public:
  explicit TwoPitchforks(double c) : c_(c) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = lambda * u[0] - u[0] * u[0] * u[0];
    F[1] = (lambda - c_) * u[1] - u[1] * u[1] * u[1];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setZero();
    Fu(0, 0) = lambda - 3.0 * u[0] * u[0];
    Fu(1, 1) = lambda - c_ - 3.0 * u[1] * u[1];
    Fl << u[0], u[1];
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    H = Matrix::Zero(2, 2);
    H(0, 0) = -(lambda - 3.0 * u[0] * u[0]);
    H(1, 1) = -(lambda - c_ - 3.0 * u[1] * u[1]);
    C.resize(0, 2);
    return true;
  }
  double c() const { return c_; }

 private:
  double c_;
};

/// m decoupled symmetric pitchforks (λ − c_j)u_j − u_j³, c_j = j·spacing, H = −F_u: m branch
/// points on u = 0 at λ = c_j, one per step of a long trivial branch (the tree's lazy roots).
/// TwoPitchforks with u scaled by 1e-2 and λ by 1e3 inside the tracer (ProblemScales): what a
/// callback or a result shows must be in the problem's units whatever the tracer works in.
class ScaledTwoPitchforks : public TwoPitchforks {
 public:
  using TwoPitchforks::TwoPitchforks;
  ProblemScales scales() const override {
    ProblemScales s = ProblemScales::ones(2);
    s.parameter = 1e3;
    s.unknowns << 1e-2, 1e-2;
    return s;
  }
};

class ManyPitchforks : public Problem {
 public:
  ManyPitchforks(int m, double spacing) : m_(m), spacing_(spacing) {}
  int dimension() const override { return m_; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    for (int j = 0; j < m_; ++j) F[j] = (lambda - j * spacing_) * u[j] - u[j] * u[j] * u[j];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setZero();
    for (int j = 0; j < m_; ++j) {
      Fu(j, j) = lambda - j * spacing_ - 3.0 * u[j] * u[j];
      Fl[j] = u[j];
    }
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  int m_;
  double spacing_;
};

/// TwoPitchforks in v = u − g(λ), g(λ) = (0.3 sin λ, 0.2 λ²): the same branch points at λ = 0
/// and λ = c, but on a curved trivial branch u = g(λ) with F_λ ≠ 0, so the location and Moore
/// systems see non-trivial geometry. Bifurcated branch: u₁ = 0.3 sin λ ± √λ, u₂ = 0.2 λ².
class CurvedPitchforks : public Problem {
 public:
  explicit CurvedPitchforks(double c) : c_(c) {}
  int dimension() const override { return 2; }
  static Vector shift(double lambda) { return (Vector(2) << 0.3 * std::sin(lambda), 0.2 * lambda * lambda).finished(); }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    const Vector v = u - shift(lambda);
    F[0] = lambda * v[0] - v[0] * v[0] * v[0];
    F[1] = (lambda - c_) * v[1] - v[1] * v[1] * v[1];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    const Vector v = u - shift(lambda);
    const Vector dg = (Vector(2) << 0.3 * std::cos(lambda), 0.4 * lambda).finished();
    Fu.setZero();
    Fu(0, 0) = lambda - 3.0 * v[0] * v[0];
    Fu(1, 1) = lambda - c_ - 3.0 * v[1] * v[1];
    Fl[0] = v[0] - Fu(0, 0) * dg[0];
    Fl[1] = v[1] - Fu(1, 1) * dg[1];
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  double c_;
};

/// [λu₁ − u₁³, λu₂ − u₂³]: both eigenvalues of H = −F_u cross zero at λ = 0 on u = 0 (a double
/// zero; the bordered determinant λ² does not change sign).
class DoubleZero : public TwoPitchforks {
 public:
  DoubleZero() : TwoPitchforks(0.0) {}
};

/// λu − u² (H = −F_u = 2u − λ): transcritical branch point at 0, branches u = 0 and u = λ.
class Transcritical : public Problem {
 public:
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = lambda * u[0] - u[0] * u[0];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = lambda - 2.0 * u[0];
    Fl[0] = u[0];
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    H.resize(1, 1);
    H(0, 0) = 2.0 * u[0] - lambda;
    C.resize(0, 1);
    return true;
  }
};

/// u = λ, refusing points with u > limit (a domain the corrector must not leave), with one
/// boundary g = 0.5 − u.
class LineWithDomain : public Problem {
 public:
  explicit LineWithDomain(double limit = std::numeric_limits<double>::infinity(), bool boundary = false)
      : limit_(limit), boundary_(boundary) {}
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    if (u[0] > limit_) return false;
    F[0] = u[0] - lambda;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    if (u[0] > limit_) return false;
    Fu(0, 0) = 1.0;
    Fl[0] = -1.0;
    return true;
  }
  int boundaryCount() const override { return boundary_ ? 1 : 0; }
  double boundary(ProblemWorkspace &, int, ConstVectorRef u, double) const override { return 0.5 - u[0]; }
  std::string boundaryName(int) const override { return "u limit"; }

 private:
  double limit_;
  bool boundary_;
};

/// Bratu problem u'' + λ eᵘ = 0 on (0, 1), u(0) = u(1) = 0, central differences on n interior
/// nodes; symmetric F_u, gradient system (H = −F_u). One fold near λ ≈ 3.51.
class Bratu : public Problem {
 public:
  explicit Bratu(int n) : n_(n), h_(1.0 / (n + 1)) {}
  int dimension() const override { return n_; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    for (int i = 0; i < n_; ++i) {
      const double left = i > 0 ? u[i - 1] : 0.0, right = i + 1 < n_ ? u[i + 1] : 0.0;
      F[i] = (left - 2.0 * u[i] + right) / (h_ * h_) + lambda * std::exp(u[i]);
    }
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setZero();
    for (int i = 0; i < n_; ++i) {
      Fu(i, i) = -2.0 / (h_ * h_) + lambda * std::exp(u[i]);
      if (i > 0) Fu(i, i - 1) = 1.0 / (h_ * h_);
      if (i + 1 < n_) Fu(i, i + 1) = 1.0 / (h_ * h_);
      Fl[i] = std::exp(u[i]);
    }
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  int n_;
  double h_;
};

/// F = Φ·F̃(u₀/U₀, u₁/U₁, λ/Λ) with F̃ = (λ̃e^{ũ₀} + ũ₀ũ₁² − 1, λ̃²ũ₁ + ũ₁ sin ũ₀ − ũ₀³): a
/// problem with exact first and second derivatives in units of choice (scales() says which), for
/// checks of derivatives that must not depend on the units.
class ScaledExponentials : public Problem {
 public:
  ScaledExponentials(double U0 = 1.0, double U1 = 1.0, double Lambda = 1.0, double Phi = 1.0)
      : U0_(U0), U1_(U1), L_(Lambda), P_(Phi) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    const double a = u[0] / U0_, b = u[1] / U1_, l = lambda / L_;
    F[0] = P_ * (l * std::exp(a) + a * b * b - 1.0);
    F[1] = P_ * (l * l * b + b * std::sin(a) - a * a * a);
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    const double a = u[0] / U0_, b = u[1] / U1_, l = lambda / L_;
    Fu << P_ / U0_ * (l * std::exp(a) + b * b), P_ / U1_ * 2.0 * a * b,
        P_ / U0_ * (b * std::cos(a) - 3.0 * a * a), P_ / U1_ * (l * l + std::sin(a));
    Fl << P_ / L_ * std::exp(a), P_ / L_ * 2.0 * l * b;
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double lambda, ConstVectorRef du,
                                     double dlambda, MatrixRef dFu, VectorRef dFl) const override {
    const double a = u[0] / U0_, b = u[1] / U1_, l = lambda / L_;
    const double da = du[0] / U0_, db = du[1] / U1_, dl = dlambda / L_;
    dFu << P_ / U0_ * ((dl + l * da) * std::exp(a) + 2.0 * b * db), P_ / U1_ * 2.0 * (da * b + a * db),
        P_ / U0_ * (-std::sin(a) * b * da + std::cos(a) * db - 6.0 * a * da),
        P_ / U1_ * (2.0 * l * dl + std::cos(a) * da);
    dFl << P_ / L_ * std::exp(a) * da, P_ / L_ * 2.0 * (dl * b + l * db);
    return true;
  }
  ProblemScales scales() const override {
    ProblemScales s = ProblemScales::ones(2);
    s.unknowns << U0_, U1_;
    s.residuals << P_, P_;
    s.parameter = L_;
    return s;
  }

 private:
  double U0_, U1_, L_, P_;
};

}  // namespace buckle::continuation::toys
