#include "buckle/continuation/branch_point_coefficients.h"

#include "buckle/continuation/tracer.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

namespace {
/// F(u, λ) = A·G(u − u_p(λ), λ) with the reduced normal form G(x, y, λ) = ((1 − λ)x + αx² + xy +
/// βx³, 2y − x²), a non-trivial parent u_p(λ) = (0.4 sin λ, 0.3λ²) and a non-symmetric A. The
/// child is u = u_p(λ) + (ξ, ξ²/2), λ = 1 + αξ + (½ + β)ξ² exactly, ξ = (u − u_p(λ))₀: a
/// transcritical point (α ≠ 0) or a pitchfork (α = 0) on a bent parent, with closed-form a = α,
/// b = ½ + β, u2 = (0, ½), p1 = u_p'(1), p2 = u_p''(1).
class BentNormalForm : public Problem {
 public:
  double alpha = 0.0, beta = 0.0;
  Eigen::Matrix2d A = (Eigen::Matrix2d() << 2.0, 1.0, 0.5, 3.0).finished();
  static Vector up(double l) { return (Vector(2) << 0.4 * std::sin(l), 0.3 * l * l).finished(); }
  static Vector dup(double l) { return (Vector(2) << 0.4 * std::cos(l), 0.6 * l).finished(); }
  static Vector ddup(double l) { return (Vector(2) << -0.4 * std::sin(l), 0.6).finished(); }
  int dimension() const override { return 2; }
  bool residual(ConstVectorRef u, double l, VectorRef F) override {
    const Vector z = u - up(l);
    const double x = z[0], y = z[1];
    F = A * (Vector(2) << (1.0 - l) * x + alpha * x * x + x * y + beta * x * x * x, 2.0 * y - x * x).finished();
    return true;
  }
  Eigen::Matrix2d Gz(const Vector &z, double l) const {
    const double x = z[0], y = z[1];
    return (Eigen::Matrix2d() << 1.0 - l + 2.0 * alpha * x + y + 3.0 * beta * x * x, x, -2.0 * x, 2.0).finished();
  }
  bool jacobian(ConstVectorRef u, double l, MatrixRef Fu, VectorRef Fl) override {
    const Vector z = u - up(l);
    Fu = A * Gz(z, l);
    Fl = A * ((Vector(2) << -z[0], 0.0).finished() - Gz(z, l) * dup(l));
    return true;
  }
  bool jacobianDirectionalDerivative(ConstVectorRef u, double l, ConstVectorRef du, double dl, MatrixRef dFu,
                                     VectorRef dFl) override {
    const Vector z = u - up(l), dz = du - dup(l) * dl;
    const Eigen::Matrix2d dGz =
        (Eigen::Matrix2d() << -dl + 2.0 * alpha * dz[0] + dz[1] + 6.0 * beta * z[0] * dz[0], dz[0], -2.0 * dz[0], 0.0)
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
  options.maxStep = 0.05;
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
