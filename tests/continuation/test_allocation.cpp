// The corrector's hot loop (KINSOL iterations, residual and Jacobian callbacks on mapped
// SUNDIALS storage) must not touch the heap once the Corrector exists (malloc_counter.h).
#include "buckle/continuation/corrector.h"
#include "buckle/continuation/internal/locator.h"
#include "buckle/continuation/numeric_diff.h"
#include "buckle/continuation/internal/spectral_monitor.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>

#include "../malloc_counter_definition.h"

using namespace buckle::continuation;
using buckle::testing::mallocCalls;

namespace {
/// TwoPitchforks with its two eigenvalues in closed form (H is diagonal), sorted without the
/// heap: the stability evaluations the certified counting asks for allocate nothing themselves,
/// so what the tests below count is the monitor's and the locator's own work.
class DiagonalPitchforks : public toys::TwoPitchforks {
 public:
  using TwoPitchforks::TwoPitchforks;
  bool stabilityEigenvalues(ProblemWorkspace &, ConstVectorRef u, double lambda, int first,
                            VectorRef values) const override {
    const double a = -(lambda - 3.0 * u[0] * u[0]), b = -(lambda - c() - 3.0 * u[1] * u[1]);
    const double sorted[2] = {std::min(a, b), std::max(a, b)};
    if (first < 0 || first + values.size() > 2) return false;
    for (Eigen::Index k = 0; k < values.size(); ++k) values[k] = sorted[first + k];
    return true;
  }
};
}  // namespace

TEST_CASE("Corrector solves allocate nothing after construction", "[allocation]") {
#if BUCKLE_COUNT_MALLOC
  const int n = 30;
  toys::Bratu bratu(n);
  Corrector corrector(bratu);
  Vector predictor = Vector::Zero(n + 1), tangent = Vector::Zero(n + 1), x = Vector::Zero(n + 1);
  Vector u0 = Vector::Zero(n), u = Vector::Zero(n);
  tangent[n] = 1.0;
  predictor[n] = 0.5;
  REQUIRE(corrector.correct(predictor, tangent, x).converged);  // warm-up

  const long before = mallocCalls.load();
  int iterations = 0;
  bool converged = true;
  for (int k = 0; k < 20; ++k) {
    predictor[n] = 0.1 + 0.1 * k;
    tangent.setConstant(0.1);
    tangent[n] = 1.0;
    tangent.normalize();
    const CorrectorSummary keller = corrector.correct(predictor, tangent, x);
    const CorrectorSummary fixed = corrector.solveAtFixedParameter(u0, 0.05 * k, u);
    converged = converged && keller.converged && fixed.converged;
    iterations += keller.iterations + fixed.iterations;
  }
  const long after = mallocCalls.load();
  CHECK(converged);
  CHECK(iterations > 20);
  CHECK(after - before == 0);

  // The counter itself works: a fresh Eigen vector is one malloc.
  const long probe = mallocCalls.load();
  Vector fresh(100);
  fresh.setZero();
  CHECK(mallocCalls.load() - probe >= 1);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}

TEST_CASE("Certified counting's slopes and the locator's residual norm allocate nothing", "[allocation]") {
#if BUCKLE_COUNT_MALLOC
  DiagonalPitchforks model(0.5);
  const BoundProblem problem(model);  // one workspace for every call below
  // A point on the trivial branch between the two branch points (ν = 1: both eigenvalues tracked).
  ContinuationPoint p;
  p.u = Vector::Zero(2);
  p.lambda = 0.2;
  p.tangent = Vector::Unit(3, 2);
  REQUIRE(problem.stability(p.u, p.lambda, 2, p.stability));
  REQUIRE(p.stability.negative == 1);
  Vector workspace(2);
  REQUIRE(measureNearZeroValues(problem, p));
  REQUIRE(measureNearZeroSlopes(problem, p, workspace));  // warm-up
  // dμ/ds along e_λ: H = diag(−λ, c − λ), both slopes −1 (the difference is exact for linear μ).
  CHECK(std::abs(p.spectrum.slopes[0] + 1.0) <= 1e-9);
  CHECK(std::abs(p.spectrum.slopes[1] + 1.0) <= 1e-9);

  Corrector corrector(problem);
  DenseBorderedSolver solver(problem);
  PointEvaluator evaluator(problem, solver, true);
  Locator locator(problem, corrector, evaluator, LocatorOptions());
  const Vector u = (Vector(2) << 0.3, -0.4).finished();
  const double lambda = 0.7;
  Vector F(2);
  REQUIRE(problem.residual(u, lambda, F));
  const double expected = F.norm();

  const long before = mallocCalls.load();
  bool measured = true, sameNorm = true;
  for (int k = 0; k < 20; ++k) {
    p.lambda = 0.1 + 0.01 * k;
    REQUIRE(measureNearZeroValues(problem, p));  // resets the slopes (values alone)
    measured = measured && measureNearZeroSlopes(problem, p, workspace) && p.spectrum.slopesMeasured;
    sameNorm = sameNorm && locator.residualNorm(u, lambda) == expected;
  }
  const long after = mallocCalls.load();
  CHECK(measured);
  CHECK(sameNorm);
  CHECK(after - before == 0);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}

TEST_CASE("NumericDiffProblem's derivatives allocate nothing after the first call", "[allocation][numeric_diff]") {
#if BUCKLE_COUNT_MALLOC
  class NumericBratu : public NumericDiffProblem {
   public:
    int dimension() const override { return exact.dimension(); }
    bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
      return exact.residual(ws, u, lambda, F);
    }
    toys::Bratu exact{12};
  } model;
  const BoundProblem problem(model);  // one workspace for every call below
  const int n = problem.dimension();
  const Vector u = Vector::Constant(n, 0.3), x = Vector::Constant(n + 1, 0.2), z = Vector::Constant(n + 1, -0.1);
  const Vector w = Vector::Constant(n, 0.5);
  Matrix Fu(n, n), dFu(n, n);
  Vector Fl(n), dFl(n), y(n), yt(n + 1);
  REQUIRE(problem.jacobian(u, 1.0, Fu, Fl));  // warm-up: the scales and workspaces
  REQUIRE(problem.secondDerivativeTransposeApply(u, 1.0, x, w, yt));
  const long before = mallocCalls.load();
  bool ok = true;
  for (int k = 0; k < 5; ++k) {
    ok = ok && problem.jacobian(u, 1.0 + 0.1 * k, Fu, Fl);
    ok = ok && problem.jacobianDirectionalDerivative(u, 1.0, x.head(n), x[n], dFu, dFl);
    ok = ok && problem.secondDerivativeApply(u, 1.0, x, z, y);
    ok = ok && problem.secondDerivativeTransposeApply(u, 1.0, x, w, yt);
  }
  const long after = mallocCalls.load();
  CHECK(ok);
  CHECK(after - before == 0);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}
