#include "buckle/continuation/bordered_solver.h"

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/tracer.h"
#include "toy_problems.h"
#include "two_parameter_toys.h"

#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <cmath>

using namespace buckle::continuation;

namespace {

/// A "structured" solver for the core's plumbing tests: the dense one, counting its calls, as a
/// problem would hand it out through makeStructuredSolver().
class CountingSolver final : public BorderedSolver {
 public:
  explicit CountingSolver(const BoundProblem &problem) : dense_(problem) {}
  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override {
    ++factors;
    return dense_.factor(u, lambda, c);
  }
  bool solve(ConstVectorRef b, VectorRef x) override {
    ++solves;
    return dense_.solve(b, x);
  }
  int determinantSign() const override { return dense_.determinantSign(); }
  double logAbsDeterminant() const override { return dense_.logAbsDeterminant(); }
  int factors = 0, solves = 0;

 private:
  DenseBorderedSolver dense_;
};

/// Bratu with the counting solver as its structured one.
class StructuredBratu final : public toys::Bratu {
 public:
  using Bratu::Bratu;
  std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace &ws) const override {
    auto solver = std::make_unique<CountingSolver>(BoundProblem(*this, ws));
    last = solver.get();
    return solver;
  }
  mutable CountingSolver *last = nullptr;  // a probe of this single-threaded test
};

}  // namespace

TEST_CASE("DenseBorderedSolver: determinant and solve of [[F_u, F_λ], [cᵀ]]", "[bordered_solver]") {
  toys::Bratu bratu(7);
  DenseBorderedSolver solver(bratu);
  const int n = bratu.dimension();
  Vector u = Vector::LinSpaced(n, 0.1, 0.4), c = Vector::LinSpaced(n + 1, -1.0, 2.0);
  const double lambda = 1.3;
  REQUIRE(solver.factor(u, lambda, c) == Factorization::Regular);
  Matrix A = Matrix::Zero(n + 1, n + 1);
  REQUIRE(BoundProblem(bratu).jacobian(u, lambda, A.topLeftCorner(n, n), A.col(n).head(n)));
  A.row(n) = c.transpose();
  const double det = A.determinant();
  CHECK(solver.determinantSign() == (det > 0 ? 1 : -1));
  CHECK(std::abs(solver.logAbsDeterminant() - std::log(std::abs(det))) < 1e-12);
  const Vector b = Vector::LinSpaced(n + 1, 1.0, -1.0);
  Vector x(n + 1);
  REQUIRE(solver.solve(b, x));
  CHECK((A * x - b).norm() <= 1e-12 * b.norm() * A.norm() * x.norm());

  // A zero border row makes A exactly singular; a refused point is reported as such.
  REQUIRE(solver.factor(u, lambda, Vector::Zero(n + 1)) == Factorization::Singular);
  CHECK(solver.determinantSign() == 0);
  CHECK_FALSE(solver.solve(b, x));
  toys::LineWithDomain line(0.5);
  DenseBorderedSolver lineSolver(line);
  CHECK(lineSolver.factor((Vector(1) << 0.7).finished(), 0.7, Vector::Ones(2)) == Factorization::Refused);
}

TEST_CASE("Corrector with a problem-supplied solver: KINSOL drives it and lands where the dense corrector does",
          "[bordered_solver]") {
  StructuredBratu bratu(9);
  const int n = bratu.dimension();
  CountingSolver counting(bratu);
  Corrector structured(bratu, CorrectorOptions(), &counting);
  Corrector dense(bratu);
  // A predictor off the branch near λ = 2; tangent e_λ: a solve at fixed λ.
  Vector predictor = Vector::Constant(n + 1, 0.3);
  predictor[n] = 2.0;
  Vector tangent = Vector::Zero(n + 1);
  tangent[n] = 1.0;
  Vector xs(n + 1), xd(n + 1);
  const CorrectorSummary s = structured.correct(predictor, tangent, xs);
  const CorrectorSummary d = dense.correct(predictor, tangent, xd);
  REQUIRE(s.converged);
  REQUIRE(d.converged);
  CHECK(s.iterations == d.iterations);
  CHECK((xs - xd).lpNorm<Eigen::Infinity>() < 1e-12);
  // One factorization and one solve per Newton iteration: exact Newton through our solver.
  CHECK(counting.factors == s.iterations);
  CHECK(counting.solves == s.iterations);

  // A solver that cannot factor makes the solve fail with KINSOL's set-up flag, not crash.
  Vector zero = Vector::Zero(n + 1);
  const CorrectorSummary bad = structured.correct(predictor, zero, xs);
  CHECK_FALSE(bad.converged);
  CHECK(std::string(bad.flagName) == "KIN_LSETUP_FAIL");
}

TEST_CASE("Tracer: Automatic picks the structured solver from structuredFromDimension on, same branch as dense",
          "[bordered_solver]") {
  TracerOptions options;
  options.maxPoints = 60;
  options.step.maxStep = 0.2;
  options.structuredFromDimension = 5;
  StructuredBratu big(9), small(4);
  Tracer structuredTracer(big, options);
  CHECK(structuredTracer.structured());
  Tracer smallTracer(small, options);
  CHECK_FALSE(smallTracer.structured());

  options.linearAlgebra = TracerOptions::LinearAlgebra::Dense;
  StructuredBratu reference(9);
  Tracer denseTracer(reference, options);
  CHECK_FALSE(denseTracer.structured());

  const Vector u0 = Vector::Zero(9);
  const Branch a = structuredTracer.trace(u0, 0.0, InitialDirection::increasingLambda());
  const Branch b = denseTracer.trace(u0, 0.0, InitialDirection::increasingLambda());
  REQUIRE(big.last != nullptr);
  CHECK(big.last->factors > 0);
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t k = 0; k < a.points.size(); ++k) {
    CHECK(std::abs(a.points[k].lambda - b.points[k].lambda) < 1e-10);
    CHECK(a.points[k].determinantSign == b.points[k].determinantSign);
  }
  // The Bratu fold (λ ≈ 3.51) is found by both, at the same place.
  auto fold = [](const Branch &br) {
    for (const SpecialPoint &sp : br.specialPoints)
      if (sp.type == SpecialPointType::Fold) return sp.lambda;
    return -1.0;
  };
  REQUIRE(fold(a) > 3.0);
  CHECK(std::abs(fold(a) - fold(b)) < 1e-11);

  // Structured demanded of a problem that has none: invalid options, with the reason.
  toys::Bratu plain(9);
  options.linearAlgebra = TracerOptions::LinearAlgebra::Structured;
  Tracer invalid(plain, options);
  const Branch none = invalid.trace(u0, 0.0, InitialDirection::increasingLambda());
  CHECK(none.stopReason == StopReason::InvalidOptions);
  CHECK(none.stopMessage.find("structured") != std::string::npos);
}

TEST_CASE("Deflated bordered solve: G through [[F_u, b], [c^T, 0]] equals the dense solve, also at singular F_u",
          "[fold_curve]") {
  toys::CuspToy toy;
  for (double x : {0.8, 0.0}) {  // x = 0: F_u = [[μ, 0], [0, 1]] with μ = 0, singular
    toy.mu = 1.5 * x * x;
    const Vector u = (Vector(2) << x, 0.5 * x * x).finished();
    DenseBorderedSolver base(toy);
    DeflatedBorderedSolve deflated(base, 2);
    Matrix B(2, 2), C(2, 2), D(2, 2);
    B << 1.0, 0.3, -0.5, 2.0;
    C << 0.7, -1.0, 0.2, 0.4;
    D << 0.1, -0.2, 0.3, 0.05;
    const Vector v = (Vector(2) << 1.0, x).finished();
    REQUIRE(deflated.factor(u, -x * x * x, v, v, B, C, D) == Factorization::Regular);
    Matrix G = Matrix::Zero(4, 4);
    Vector Fl(2);
    REQUIRE(BoundProblem(toy).jacobian(u, -x * x * x, G.topLeftCorner(2, 2), Fl));
    G.topRightCorner(2, 2) = B;
    G.bottomLeftCorner(2, 2) = C.transpose();
    G.bottomRightCorner(2, 2) = D;
    const Vector r = (Vector(4) << 0.3, -1.1, 0.6, 0.25).finished();
    Vector z(4);
    REQUIRE(deflated.solve(r, z));
    CHECK((G * z - r).norm() <= 1e-14);
    // det of the extended matrix is ±det G = ±det M · det S (the dense base reports log|det M| = 0)
    Matrix M = Matrix::Zero(3, 3);
    M.topLeftCorner(2, 2) = G.topLeftCorner(2, 2);
    M.topRightCorner(2, 1) = v;
    M.bottomLeftCorner(1, 2) = v.transpose();
    CHECK(std::abs(std::exp(deflated.logAbsDeterminant()) * std::abs(M.determinant()) - std::abs(G.determinant())) <=
          1e-13 * std::abs(G.determinant()));
  }
}
