#include "buckle/continuation/branch_point_coefficients.h"

#include "buckle/continuation/tracer.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

namespace {
/// F(u, λ) = A·G(u − u_p(λ), λ) with the reduced normal form G(x, y, λ) = ((1 − λ)x + αx² + xy +
/// βx³ + γx⁵, 2y − x²), a non-trivial parent u_p(λ) = (0.4 sin λ, 0.3λ²) and a non-symmetric A. The
/// child is u = u_p(λ) + (ξ, ξ²/2), λ = 1 + αξ + (½ + β)ξ² + γξ⁴ exactly, ξ = (u − u_p(λ))₀: a
/// transcritical point (α ≠ 0) or a pitchfork (α = 0) on a bent parent, with closed-form a = α,
/// b = ½ + β, u2 = (0, ½), p1 = u_p'(1), p2 = u_p''(1).
class BentNormalForm : public Problem {
 public:
  double alpha = 0.0, beta = 0.0, gamma = 0.0;
  Eigen::Matrix2d A = (Eigen::Matrix2d() << 2.0, 1.0, 0.5, 3.0).finished();
  static Vector up(double l) { return (Vector(2) << 0.4 * std::sin(l), 0.3 * l * l).finished(); }
  static Vector dup(double l) { return (Vector(2) << 0.4 * std::cos(l), 0.6 * l).finished(); }
  static Vector ddup(double l) { return (Vector(2) << -0.4 * std::sin(l), 0.6).finished(); }
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double l, VectorRef F) const override {
    const Vector z = u - up(l);
    const double x = z[0], y = z[1];
    F = A * (Vector(2) << (1.0 - l) * x + alpha * x * x + x * y + beta * x * x * x + gamma * std::pow(x, 5),
                                  2.0 * y - x * x)
                                     .finished();
    return true;
  }
  Eigen::Matrix2d Gz(const Vector &z, double l) const {
    const double x = z[0], y = z[1];
    return (Eigen::Matrix2d() << 1.0 - l + 2.0 * alpha * x + y + 3.0 * beta * x * x + 5.0 * gamma * std::pow(x, 4), x,
            -2.0 * x, 2.0)
        .finished();
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double l, MatrixRef Fu, VectorRef Fl) const override {
    const Vector z = u - up(l);
    Fu = A * Gz(z, l);
    Fl = A * ((Vector(2) << -z[0], 0.0).finished() - Gz(z, l) * dup(l));
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double l, ConstVectorRef du, double dl,
                                     MatrixRef dFu, VectorRef dFl) const override {
    const Vector z = u - up(l), dz = du - dup(l) * dl;
    const Eigen::Matrix2d dGz =
        (Eigen::Matrix2d() << -dl + 2.0 * alpha * dz[0] + dz[1] + 6.0 * beta * z[0] * dz[0] +
                                  20.0 * gamma * std::pow(z[0], 3) * dz[0],
         dz[0], -2.0 * dz[0], 0.0)
            .finished();
    dFu = A * dGz;
    dFl = A * ((Vector(2) << -dz[0], 0.0).finished() - dGz * dup(l) - Gz(z, l) * ddup(l) * dl);
    return true;
  }
};

Vector tangentAt(double l) {
  Vector t(3);
  t << BentNormalForm::dup(l), 1.0;
  return t;
}
}  // namespace

TEST_CASE("Branch-point coefficients: transcritical and pitchfork on a bent parent, closed form",
          "[branch_point_coefficients]") {
  BentNormalForm p;
  const Vector c = (Vector(2) << 1.0, 0.0).finished();
  for (double alpha : {0.0, 0.7, -0.4}) {
    for (double beta : {0.0, -1.3}) {
      p.alpha = alpha;
      p.beta = beta;
      BranchPointCoefficients k;
      std::string why;
      // an inexact null vector and a tilted parent tangent: both are refined
      Vector t = tangentAt(1.0);
      t[0] += 0.05;
      REQUIRE(branchPointCoefficients(p, BentNormalForm::up(1.0), 1.0, -2.0 * t,
                                      (Vector(2) << 1.0, 0.1).finished(), c, k, &why));
      CHECK(std::abs(k.a - alpha) <= 1e-13);
      CHECK(std::abs(k.b - (0.5 + beta)) <= 1e-8);
      CHECK((k.v - c).norm() <= 1e-14);
      CHECK((k.u2 - (Vector(2) << 0.0, 0.5).finished()).norm() <= 1e-13);
      CHECK((k.parentSlope - BentNormalForm::dup(1.0)).norm() <= 1e-13);
      CHECK((k.parentCurvature - BentNormalForm::ddup(1.0)).norm() <= 1e-8);
      // the ABE: the parent is a root (a11 = 0), the child the other, (α, β) ∝ (−a22, 2a12), in
      // the basis t (along the given parent orientation, here −u_p'), φ
      const Vector tp = -tangentAt(1.0).normalized();
      Vector e = Vector::Zero(3);
      e.head(2) = k.v;
      const Vector phi = (e - e.dot(tp) * tp).normalized();
      const double ca = k.childTangent.dot(tp), cb = k.childTangent.dot(phi);
      CHECK(std::abs(k.a11) <= 1e-13 * std::abs(k.a12));
      CHECK(std::abs(2.0 * k.a12 * ca + k.a22 * cb) <= 1e-13 * std::abs(k.a12));
      // the child's exact tangent d/dξ (u_p(λ(ξ)) + (ξ, ξ²/2), λ(ξ)) at ξ = 0
      Vector exact(3);
      exact << alpha * BentNormalForm::dup(1.0) + c, alpha;
      CHECK((k.childTangent - exact.normalized()).norm() <= 1e-13);
    }
  }
}

TEST_CASE("Branch-point coefficients at the branch point the tracer located on the bent parent",
          "[branch_point_coefficients]") {
  BentNormalForm p;
  p.alpha = 0.7;
  p.beta = -1.3;
  TracerOptions options;
  options.step.maxStep = 0.05;
  options.lambdaMax = 1.5;
  const Branch b = trace(p, BentNormalForm::up(0.5), 0.5, InitialDirection::increasingLambda(), options);
  const auto bps = b.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  BranchPointCoefficients k;
  std::string why;
  REQUIRE(branchPointCoefficients(p, *bps[0], (Vector(2) << 1.0, 0.0).finished(), k, &why));
  // to the location accuracy of the branch point
  const double tol = 1e-6 + 100.0 * std::abs(bps[0]->lambda - 1.0);
  CHECK(std::abs(k.a - 0.7) <= tol);
  CHECK(std::abs(k.b + 0.8) <= tol);
}

TEST_CASE("Branch-point coefficients: refused input", "[branch_point_coefficients]") {
  BentNormalForm p;
  BranchPointCoefficients k;
  std::string why;
  const Vector c = (Vector(2) << 1.0, 0.0).finished(), u0 = BentNormalForm::up(1.0);
  CHECK_FALSE(branchPointCoefficients(p, u0, 1.0, Vector::Ones(2), c, c, k, &why));
  CHECK_THAT(why, Contains("dimension"));
  CHECK_FALSE(branchPointCoefficients(p, u0, 1.0, (Vector(3) << 1.0, 0.0, 0.0).finished(), c, c, k, &why));
  CHECK_THAT(why, Contains("vertical"));
  CHECK_FALSE(branchPointCoefficients(p, BentNormalForm::up(3.0), 3.0, tangentAt(3.0), c, c, k, &why));
  CHECK_THAT(why, Contains("not singular"));
  SpecialPoint fold;
  fold.type = SpecialPointType::Fold;
  CHECK_FALSE(branchPointCoefficients(p, fold, c, k, &why));
  CHECK_THAT(why, Contains("not a located simple branch point"));
}

TEST_CASE("Degenerate pitchfork: b zero to its accuracy, the quartic term from the child", "[branch_point_coefficients]") {
  BentNormalForm p;
  const Vector c = (Vector(2) << 1.0, 0.0).finished();
  p.beta = -0.5;  // b = ½ + β = 0: λ = 1 + γξ⁴ (closed form)
  for (double gamma : {0.3, -0.3}) {
    p.gamma = gamma;
    BranchPointCoefficients k;
    std::string why;
    REQUIRE(branchPointCoefficients(p, BentNormalForm::up(1.0), 1.0, tangentAt(1.0), c, c, k, &why));
    // the estimate bounds the actual error, and b = 0 lies within it
    CHECK(std::abs(k.b) <= k.bAccuracy);
    CHECK(k.bAccuracy > 0.0);
    CHECK(k.bAccuracy <= 1e-10 * k.bScale);
    ChildBranchExpansion ex;
    REQUIRE(childBranchExpansion(p, BentNormalForm::up(1.0), 1.0, k, c, ex, &why));
    INFO("c4 = " << ex.c4 << " +- " << ex.c4Accuracy << ", c2 = " << ex.c2);
    // ξ here is u₀ − u_p(1)₀, not u₀ − u_p(λ)₀: they differ by O(λ − 1) = O(ξ⁴), which moves λ(ξ) at O(ξ⁷) only
    CHECK(std::abs(ex.c4 - gamma) <= ex.c4Accuracy + 1e-9);
    CHECK(ex.c4Accuracy <= 1e-4 * std::abs(gamma));
    CHECK(std::abs(ex.c2) <= ex.c2Accuracy + 1e-9);
    CHECK(std::abs(ex.c1) <= 1e-6);  // the odd part: O(ξ⁷) from the amplitude measured from u_p(1)
  }
}

TEST_CASE("Non-degenerate pitchfork: b above its accuracy, and the child's own λ(ξ) agrees",
          "[branch_point_coefficients]") {
  BentNormalForm p;
  const Vector c = (Vector(2) << 1.0, 0.0).finished();
  p.beta = 0.2;
  p.gamma = 0.1;
  BranchPointCoefficients k;
  std::string why;
  REQUIRE(branchPointCoefficients(p, BentNormalForm::up(1.0), 1.0, tangentAt(1.0), c, c, k, &why));
  CHECK(std::abs(k.b - 0.7) <= k.bAccuracy + 1e-9);
  CHECK(std::abs(k.b) > 1e6 * k.bAccuracy);
  ChildBranchExpansion ex;
  REQUIRE(childBranchExpansion(p, BentNormalForm::up(1.0), 1.0, k, c, ex, &why));
  // an independent formulation of b: the even part of λ at points of the child
  CHECK(std::abs(ex.c2 - 0.7) <= ex.c2Accuracy + 1e-9);
  CHECK(ex.c2Accuracy <= 1e-6);
}

namespace {
/// u³ + μu − λ = 0 (exact second derivatives): folds at u = ±√(−μ/3) for μ < 0, with
/// λ'' = ∓6√(−μ/3)·… → 0 as μ → 0, where the two folds merge in the cusp u = λ = 0.
class CuspFamily : public Problem {
 public:
  double mu = 0.0;
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double l, VectorRef F) const override {
    F[0] = u[0] * u[0] * u[0] + mu * u[0] - l;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = 3.0 * u[0] * u[0] + mu;
    Fl[0] = -1.0;
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef du, double,
                                     MatrixRef dFu, VectorRef dFl) const override {
    dFu(0, 0) = 6.0 * u[0] * du[0];
    dFl[0] = 0.0;
    return true;
  }
};

SpecialPoint foldAt(double u, double lambda) {
  SpecialPoint sp;
  sp.type = SpecialPointType::Fold;
  sp.u = Vector::Constant(1, u);
  sp.lambda = lambda;
  sp.nullVectors = Matrix::Ones(1, 1);
  return sp;
}
}  // namespace

TEST_CASE("Fold coefficient: λ'' in closed form, and a cusp named where it vanishes", "[branch_point_coefficients]") {
  CuspFamily p;
  FoldCoefficient fc;
  std::string why;
  // μ = −3: folds at u = ±1, λ = ∓2; λ = u³ − 3u along the branch, λ'' = 6u
  p.mu = -3.0;
  REQUIRE(foldCoefficient(p, foldAt(1.0, -2.0), fc, &why));
  CHECK(std::abs(fc.curvature - 6.0) <= 1e-14);
  CHECK_FALSE(fc.cusp);
  REQUIRE(foldCoefficient(p, foldAt(-1.0, 2.0), fc, &why));
  CHECK(std::abs(fc.curvature + 6.0) <= 1e-14);
  CHECK_FALSE(fc.cusp);
  // μ = 0: the cusp, λ = u³, λ'' = 0 exactly
  p.mu = 0.0;
  REQUIRE(foldCoefficient(p, foldAt(0.0, 0.0), fc, &why));
  CHECK(fc.cusp);
  // a location error makes the accuracy grow with it: a fold 1e-6 off the cusp (λ'' = 6e-6)
  // located to |Δλ| = 1 is not resolved, located to 1e-12 it is
  SpecialPoint near = foldAt(1e-6, 0.0);
  p.mu = -3e-12;
  near.lambdaAccuracy = 1e-12;
  REQUIRE(foldCoefficient(p, near, fc, &why));
  CHECK(std::abs(fc.curvature - 6e-6) <= 1e-18);
  CHECK_FALSE(fc.cusp);
  near.lambdaAccuracy = 1.0;
  REQUIRE(foldCoefficient(p, near, fc, &why));
  CHECK(fc.cusp);
  CHECK_FALSE(foldCoefficient(p, SpecialPoint(), fc, &why));
  CHECK_THAT(why, Contains("not a located fold"));
}
