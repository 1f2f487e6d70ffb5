#include "buckle/continuation/internal/test_functions.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

TEST_CASE("PointEvaluator: tangent, fold test and bordered determinant on the circle", "[test_functions]") {
  toys::Circle circle;
  DenseBorderedSolver solver(circle);
  PointEvaluator evaluator(circle, solver, true);
  ContinuationPoint p;
  p.u = (Vector(1) << 0.6).finished();
  p.lambda = 0.8;
  const Vector reference = (Vector(2) << -1.0, 0.0).finished();
  REQUIRE(evaluator.complete(p, reference));
  // ker [2u, 2λ] = span(−0.8, 0.6), oriented along the reference.
  CHECK(std::abs(p.tangent[0] + 0.8) < 1e-15);
  CHECK(std::abs(p.tangent[1] - 0.6) < 1e-15);
  CHECK(p.foldTest == p.tangent[1]);
  // det [[1.2, 1.6], [−0.8, 0.6]] = 2.
  CHECK(p.determinantSign == 1);
  CHECK(std::abs(p.logAbsDeterminant - std::log(2.0)) < 1e-14);
  CHECK_FALSE(p.stability.valid());  // the circle has no stability operator

  // Reversed reference: reversed tangent, and the determinant with the point's own tangent
  // flips sign with it.
  ContinuationPoint q = p;
  REQUIRE(evaluator.complete(q, -reference));
  CHECK((q.tangent + p.tangent).norm() < 1e-15);
  CHECK(q.determinantSign == -1);
}

TEST_CASE("PointEvaluator records stability and flags exact singularity", "[test_functions]") {
  toys::TwoPitchforks problem(0.5);
  DenseBorderedSolver solver(problem);
  PointEvaluator evaluator(problem, solver, true);
  ContinuationPoint p;
  p.u = Vector::Zero(2);
  p.lambda = 0.25;
  const Vector eLambda = (Vector(3) << 0.0, 0.0, 1.0).finished();
  REQUIRE(evaluator.complete(p, eLambda));
  REQUIRE(p.stability.valid());
  CHECK(p.stability.negative == 1);
  // det [[λ, 0, 0], [0, λ − c, 0], [0, 0, 1]] = λ(λ − c) < 0.
  CHECK(p.determinantSign == -1);

  p.lambda = 0.0;
  CHECK_FALSE(evaluator.complete(p, eLambda));
  CHECK(evaluator.lastWasSingular());
  CHECK(p.determinantSign == 0);
  CHECK(p.stability.valid());

  PointEvaluator without(problem, solver, false);
  p.lambda = 0.25;
  REQUIRE(without.complete(p, eLambda));
  CHECK_FALSE(p.stability.valid());
}

TEST_CASE("Minimally augmented test function changes sign with the singular value", "[test_functions]") {
  MinimallyAugmentedTest test;
  Matrix A = Matrix::Identity(3, 3);
  A(0, 0) = 0.01;
  test.initialize(A);
  // With b = c = e₁: ψ = −μ exactly for A = diag(μ, 1, 1).
  for (double mu : {0.3, 0.01, 1e-9, -1e-9, -0.2}) {
    A(0, 0) = mu;
    double psi = 0.0;
    Vector v;
    REQUIRE(test.evaluate(A, psi, &v));
    CHECK(std::abs(std::abs(psi) - std::abs(mu)) < 1e-15);
    CHECK(std::abs(v[0]) == Approx(1.0));
  }
  double a = 0.0, b = 0.0;
  A(0, 0) = 0.1;
  test.evaluate(A, a);
  A(0, 0) = -0.1;
  test.evaluate(A, b);
  CHECK(a * b < 0.0);
}

TEST_CASE("classifyInterval separates folds, determinant changes and inertia", "[test_functions]") {
  ContinuationPoint a, b;
  a.foldTest = 0.5;
  b.foldTest = -0.5;
  a.determinantSign = b.determinantSign = 1;
  a.stability.negative = 0;
  b.stability.negative = 1;
  IntervalCrossings fold = classifyInterval(a, b, true, true);
  CHECK(fold.fold);
  CHECK_FALSE(fold.determinantChange);
  CHECK(fold.inertiaChange == 1);
  CHECK(fold.branchPointCrossings == 0);  // the fold explains the eigenvalue crossing
  IntervalCrossings foldNotReported = classifyInterval(a, b, false, true);
  CHECK_FALSE(foldNotReported.fold);
  CHECK(foldNotReported.branchPointCrossings == 0);  // still explained by the fold

  b.foldTest = 0.4;
  b.stability.negative = 2;
  IntervalCrossings even = classifyInterval(a, b, true, true);
  CHECK_FALSE(even.fold);
  CHECK(even.branchPointCrossings == 2);

  b.stability.negative = 1;
  b.determinantSign = -1;
  IntervalCrossings simple = classifyInterval(a, b, true, true);
  CHECK(simple.determinantChange);
  CHECK(simple.branchPointCrossings == 1);

  b.stability = StabilityInfo();  // unknown inertia: the determinant alone decides
  IntervalCrossings noInertia = classifyInterval(a, b, true, true);
  CHECK(noInertia.inertiaChange == -1);
  CHECK(noInertia.branchPointCrossings == 1);
  CHECK(classifyInterval(a, b, true, false).branchPointCrossings == 0);
}

TEST_CASE("classifyInterval: a crossing at a shared point is counted in one of its two steps", "[test_functions]") {
  // TwoPitchforks traced in whole steps from λ = −3 reaches the branch point λ = 0 to rounding:
  // there the crossing eigenvalue lies in the count's zero band (ν = 0, one zero), and the
  // determinant may have changed sign already (λ = +3e−16) or not yet (λ = −3e−16). The steps
  // before (a → p) and after (p → b) must see the one crossing once between them.
  ContinuationPoint a, p, b;
  a.foldTest = p.foldTest = b.foldTest = 1.0;  // the trivial branch: t = e_λ
  a.stability.negative = 0;
  p.stability.negative = 0;
  p.stability.zero = 1;
  b.stability.negative = 1;
  a.determinantSign = 1;
  b.determinantSign = -1;
  for (const int atPoint : {-1, 1}) {
    INFO("determinant sign at the crossing point " << atPoint);
    p.determinantSign = atPoint;
    const int before = classifyInterval(a, p, true, true).branchPointCrossings;
    const int after = classifyInterval(p, b, true, true).branchPointCrossings;
    CHECK(before + after == 1);
    CHECK(before == (atPoint == b.determinantSign ? 1 : 0));
    // The same traced the other way (b → p → a: the eigenvalue leaves the negative side).
    CHECK(classifyInterval(b, p, true, true).branchPointCrossings + classifyInterval(p, a, true, true).branchPointCrossings == 1);
  }
  // Two eigenvalues in the zero band (a double zero) are not settled by a parity: both kept.
  p.stability.zero = 2;
  b.stability.negative = 2;
  b.determinantSign = 1;
  p.determinantSign = 1;
  CHECK(classifyInterval(a, p, true, true).branchPointCrossings + classifyInterval(p, b, true, true).branchPointCrossings == 2);
}

TEST_CASE("classifyInterval: a turning of lambda below the rounding of lambda is not a fold", "[test_functions]") {
  // t_λ and the count flip together while λ moves by ~1e−17 over a step of 4e−9 (the children of a
  // branch point of the n = 10 000 chain): the parity check confirms the sign change, but the
  // step does not resolve a turning of λ. The inertia change comes with it and is no BP either.
  ContinuationPoint a, b;
  a.u = Vector::Zero(2);
  b.u = (Vector(2) << 4e-9, 0.0).finished();
  a.lambda = -7.5715230938837343e-08;
  b.lambda = -7.5715230906755335e-08;
  a.tangent = (Vector(3) << 1.0, 0.0, 8e-9).finished();
  b.tangent = (Vector(3) << 1.0, 0.0, -1e-8).finished();
  a.foldTest = a.tangent[2];
  b.foldTest = b.tangent[2];
  a.determinantSign = b.determinantSign = 1;
  a.stability.negative = 1;
  b.stability.negative = 0;
  const IntervalCrossings noise = classifyInterval(a, b, true, true);
  CHECK(foldBetween(a, b));  // the sign change itself is confirmed by the determinants
  CHECK_FALSE(noise.fold);
  CHECK(noise.branchPointCrossings == 0);
  // The same sign change over a step of 1e−6 moves λ by ~1e−14: resolved, a fold.
  b.u[0] = 1e-6;
  b.tangent[2] = -1e-6;
  b.foldTest = b.tangent[2];
  const IntervalCrossings fold = classifyInterval(a, b, true, true);
  CHECK(fold.fold);
  CHECK(fold.branchPointCrossings == 0);
}

TEST_CASE("jacobianKernel: two-dimensional kernel at a pitchfork", "[test_functions]") {
  toys::TwoPitchforks problem(0.5);
  KernelInfo kernel;
  REQUIRE(jacobianKernel(problem, Vector::Zero(2), 0.0, kernel));
  REQUIRE(kernel.singularValues.size() == 3);
  CHECK(kernel.singularValues[0] == 0.0);
  CHECK(kernel.singularValues[1] < 1e-15);
  CHECK(std::abs(kernel.singularValues[2] - 0.5) < 1e-15);
  // Right singular vectors of the zero values span (u₁, λ); the left one is e₁.
  CHECK(std::abs(kernel.right(1, 0)) < 1e-15);
  CHECK(std::abs(kernel.right(1, 1)) < 1e-15);
  CHECK(std::abs(std::abs(kernel.left(0, 0)) - 1.0) < 1e-15);
}
