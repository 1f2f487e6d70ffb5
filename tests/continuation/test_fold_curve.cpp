#include "buckle/continuation/fold_curve.h"
#include "buckle/continuation/tracer.h"

#include "two_parameter_toys.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

using namespace buckle::continuation;

namespace {
// The fold of the cusp toy at x: (u, λ, v) with v the null vector of F_u.
Vector foldStart(toys::CuspToy& toy, double x, Vector& c) {
  toy.mu = 1.5 * x * x;
  const Vector u = (Vector(2) << x, 0.5 * x * x).finished();
  const Vector v = (Vector(2) << 1.0, x).finished();  // F_u v = (μ − 3x² + y + x², −x + x) = 0
  return FoldCurveProblem::start(toy, u, -x * x * x, v, c);
}

// [G_U, G_μ] of a curve problem against central differences of its residual, to `tolerance`.
void checkJacobian(Problem& curve, const Vector& U, double mu, double tolerance) {
  const int m = curve.dimension();
  Matrix GU(m, m);
  Vector Gmu(m), Gp(m), Gm(m);
  REQUIRE(BoundProblem(curve).jacobian(U, mu, GU, Gmu));
  const double h = 1e-6;
  for (int j = 0; j < m; ++j) {
    Vector Up = U, Um = U;
    Up[j] += h;
    Um[j] -= h;
    REQUIRE(BoundProblem(curve).residual(Up, mu, Gp));
    REQUIRE(BoundProblem(curve).residual(Um, mu, Gm));
    CHECK(((Gp - Gm) / (2 * h) - GU.col(j)).norm() <= tolerance * (1.0 + GU.col(j).norm()));
  }
  REQUIRE(BoundProblem(curve).residual(U, mu + h, Gp));
  REQUIRE(BoundProblem(curve).residual(U, mu - h, Gm));
  CHECK(((Gp - Gm) / (2 * h) - Gmu).norm() <= tolerance * (1.0 + Gmu.norm()));
}
// Every point of a traced fold curve of the cusp toy on its closed form (x, x²/2, −x³) at
// μ = 1.5x² (to 1e-10); returns the smallest x reached.
double checkCuspFoldPoints(const Branch& branch) {
  double xMin = 1.0;
  for (const ContinuationPoint& p : branch.points) {
    const double x = p.u[0];
    xMin = std::min(xMin, x);
    CHECK(std::abs(p.lambda - 1.5 * x * x) <= 1e-10);
    CHECK(std::abs(p.u[2] + x * x * x) <= 1e-10);
    CHECK(std::abs(p.u[1] - 0.5 * x * x) <= 1e-10);
  }
  return xMin;
}
}  // namespace

TEST_CASE("Fold curve: the exact Jacobian against central differences of the residual", "[fold_curve]") {
  toys::CuspToy toy;
  Vector c;
  Vector U = foldStart(toy, 0.8, c);
  U += (Vector(5) << 0.01, -0.02, 0.03, 0.2, -0.1).finished();  // off the curve: every block counts
  FoldCurveProblem curve(toy, c);
  checkJacobian(curve, U, 0.7, 1e-8);
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
  options.corrector.tolerance = 1e-12;
  options.step.maxStep = 0.05;
  options.detection.branchPoints = false;
  options.detection.stability = false;
  const Branch branch = trace(curve, U0, 0.96, InitialDirection::decreasingLambda(), options);
  REQUIRE(branch.stopReason == StopReason::LambdaRange);
  const double xMin = checkCuspFoldPoints(branch);
  for (const ContinuationPoint& p : branch.points) CHECK(std::abs(p.u[4] - p.u[0] * p.u[3]) <= 1e-10);  // v ∥ (1, x)
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

namespace {
// The cusp toy with a "structured" solver: the dense one, which takes general borders.
class BorderedCuspToy : public toys::CuspToy {
 public:
  std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace&) const override {
    return std::make_unique<DenseBorderedSolver>(*this);
  }
};
}  // namespace

TEST_CASE("Minimal fold curve: the Jacobian against central differences, g = 0 on the fold curve", "[fold_curve]") {
  BorderedCuspToy toy;
  toy.mu = 1.5 * 0.64;
  const Vector u = (Vector(2) << 0.8, 0.32).finished();
  MinimalFoldCurveProblem curve(toy, u, -0.512, (Vector(2) << 1.0, 0.8).finished());
  Vector G(3);
  REQUIRE(BoundProblem(curve).residual(MinimalFoldCurveProblem::start(u, -0.512), toy.mu, G));
  CHECK(G.norm() <= 1e-14);  // F = 0 and g = 0 at the fold
  Vector U = MinimalFoldCurveProblem::start(u, -0.512);
  U += (Vector(3) << 0.01, -0.02, 0.03).finished();
  const double mu = 0.7;
  // g_x from central differences of F_u inside the core (h ~ ε^{1/3}): ~1e-9
  checkJacobian(curve, U, mu, 1e-7);
  Matrix GU(3, 3);
  Vector Gmu(3), y(3), yt(4), x(4), w(3);
  REQUIRE(BoundProblem(curve).jacobian(U, mu, GU, Gmu));
  // the O(N) products are the dense Jacobian's
  x << 0.3, -0.2, 0.5, 0.7;
  w << -0.4, 0.1, 0.9;
  REQUIRE(BoundProblem(curve).jacobianApply(U, mu, x, y));
  REQUIRE(BoundProblem(curve).jacobianTransposeApply(U, mu, w, yt));
  Matrix Gx(3, 4);
  Gx << GU, Gmu;
  CHECK((y - Gx * x).norm() <= 1e-13);
  CHECK((yt - Gx.transpose() * w).norm() <= 1e-13);
}

TEST_CASE("Minimal fold curve: traced with the bordered solver through the cusp, on mu = 3x^2/2, lambda = -x^3",
          "[fold_curve]") {
  BorderedCuspToy toy;
  toy.mu = 0.96;
  const Vector u = (Vector(2) << 0.8, 0.32).finished();
  MinimalFoldCurveProblem curve(toy, u, -0.512, (Vector(2) << 1.0, 0.8).finished());
  TracerOptions options;
  options.maxPoints = 500;
  options.lambdaMax = 0.97;
  options.corrector.tolerance = 1e-12;
  options.step.maxStep = 0.05;
  options.detection.branchPoints = false;
  options.detection.folds = false;
  options.detection.stability = false;
  options.linearAlgebra = TracerOptions::LinearAlgebra::Structured;
  options.onStep = [&curve](const StepInfo& step) {
    curve.adaptBorders(step.point.u, step.point.lambda);
    return StepAction::Continue;
  };
  const Branch branch = trace(curve, MinimalFoldCurveProblem::start(u, -0.512), 0.96,
                              InitialDirection::decreasingLambda(), options);
  REQUIRE(branch.stopReason == StopReason::LambdaRange);
  const double xMin = checkCuspFoldPoints(branch);
  CHECK(xMin < -0.8);
  // the cusp test changes sign once, at x = 0
  curve.resetBorders();
  int changes = 0;
  double previous = 0.0;
  for (const ContinuationPoint& p : branch.points) {
    double g = 0.0;
    REQUIRE(curve.cuspTest(p.u, p.lambda, g));
    REQUIRE(curve.adaptBorders(p.u, p.lambda));
    if (previous != 0.0 && g * previous < 0.0) ++changes;
    previous = g;
  }
  CHECK(changes == 1);
}
