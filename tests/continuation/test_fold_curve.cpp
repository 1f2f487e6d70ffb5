#include "buckle/continuation/fold_curve.h"
#include "buckle/continuation/tracer.h"

#include "two_parameter_toys.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

namespace {
// The fold of the cusp toy at x: (u, λ, v) with v the null vector of F_u.
Vector foldStart(toys::CuspToy& toy, double x, Vector& c) {
  toy.mu = 1.5 * x * x;
  const Vector u = (Vector(2) << x, 0.5 * x * x).finished();
  const Vector v = (Vector(2) << 1.0, x).finished();  // F_u v = (μ − 3x² + y + x², −x + x) = 0
  return FoldCurveProblem::start(toy, u, -x * x * x, v, c);
}
}  // namespace

TEST_CASE("Fold curve: the exact Jacobian against central differences of the residual", "[fold_curve]") {
  toys::CuspToy toy;
  Vector c;
  Vector U = foldStart(toy, 0.8, c);
  U += (Vector(5) << 0.01, -0.02, 0.03, 0.2, -0.1).finished();  // off the curve: every block counts
  FoldCurveProblem curve(toy, c);
  const double mu = 0.7;
  Matrix GU(5, 5);
  Vector Gmu(5), Gp(5), Gm(5);
  REQUIRE(curve.jacobian(U, mu, GU, Gmu));
  const double h = 1e-6;
  for (int j = 0; j < 5; ++j) {
    Vector Up = U, Um = U;
    Up[j] += h;
    Um[j] -= h;
    REQUIRE(curve.residual(Up, mu, Gp));
    REQUIRE(curve.residual(Um, mu, Gm));
    CHECK(((Gp - Gm) / (2 * h) - GU.col(j)).norm() <= 1e-8 * (1.0 + GU.col(j).norm()));
  }
  REQUIRE(curve.residual(U, mu + h, Gp));
  REQUIRE(curve.residual(U, mu - h, Gm));
  CHECK(((Gp - Gm) / (2 * h) - Gmu).norm() <= 1e-8 * (1.0 + Gmu.norm()));
}

TEST_CASE("Fold curve: traced through the cusp, on μ = 3x²/2, λ = −x³", "[fold_curve]") {
  toys::CuspToy toy;
  Vector c;
  // c ∥ (1, 1) from the start at x = 0.8: the normalisation cᵀv = 1 holds down to x > −1
  const Vector U0 = foldStart(toy, 0.8, c);
  FoldCurveProblem curve(toy, c);
  TracerOptions options;
  options.maxPoints = 500;
  options.lambdaMax = 0.97;  // μ: back out to x ≈ −0.804
  options.newtonTolerance = 1e-12;
  options.maxStep = 0.05;
  options.detectBranchPoints = false;
  options.computeStability = false;
  const Branch branch = trace(curve, U0, 0.96, InitialDirection::decreasingLambda(), options);
  REQUIRE(branch.stopReason == StopReason::LambdaRange);
  double xMin = 1.0;
  for (const ContinuationPoint& p : branch.points) {
    const double x = p.u[0];
    xMin = std::min(xMin, x);
    CHECK(std::abs(p.lambda - 1.5 * x * x) <= 1e-10);
    CHECK(std::abs(p.u[2] + x * x * x) <= 1e-10);
    CHECK(std::abs(p.u[1] - 0.5 * x * x) <= 1e-10);
    CHECK(std::abs(p.u[4] - x * p.u[3]) <= 1e-10);  // v ∥ (1, x)
  }
  CHECK(xMin < -0.8);  // past the cusp onto the other fold
  // the cusp is a fold of the fold curve (μ turns there)
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 1);
  CHECK(std::abs(folds[0]->lambda) <= 1e-10);
  CHECK(std::abs(folds[0]->u[0]) <= 1e-5);
}

TEST_CASE("Fold curve: the cusp test changes sign with x, zero exactly at the cusp", "[fold_curve]") {
  toys::CuspToy toy;
  Vector c;
  foldStart(toy, 1.0, c);
  FoldCurveProblem curve(toy, c);
  double gPlus = 0.0, gMinus = 0.0, gZero = 1.0;
  Vector cm;
  const Vector Up = foldStart(toy, 0.3, cm), Um = foldStart(toy, -0.3, cm), U00 = foldStart(toy, 0.0, cm);
  REQUIRE(curve.cuspTest(Up, 1.5 * 0.09, gPlus));
  REQUIRE(curve.cuspTest(Um, 1.5 * 0.09, gMinus));
  REQUIRE(curve.cuspTest(U00, 0.0, gZero));
  CHECK(gPlus * gMinus < 0.0);
  CHECK(std::abs(gZero) <= 1e-15);
  // ψ ∥ (1, −x), F_uu[v, v] = (−4x, −1) at v = (1, x): ψᵀF_uu[v, v] ∥ −3x
  CHECK(gPlus < 0.0);
}

TEST_CASE("Fold curve: bad input", "[fold_curve]") {
  toys::CuspToy toy;
  CHECK_THROWS_WITH(FoldCurveProblem(toy, Vector::Ones(3)), Catch::Matchers::Contains("normalisation"));
}
