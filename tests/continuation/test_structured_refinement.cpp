// The O(N) refinement path of the locator (structured_refinement.h), on problems with closed
// forms and against the dense augmented systems of the same tracer: the crossover
// maxDenseLocationDimension is forced below N so that the structured path runs (here through
// DenseBorderedSolver::factorGeneral, the problems having no structured solver).
#include "buckle/continuation/internal/structured_refinement.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

namespace {

double tolerance(double lambda) { return 1e-12 * std::max(1.0, std::abs(lambda)); }

TracerOptions structuredOptions(TracerOptions options) {
  options.location.maxDenseDimension = 1;  // every N is "large": the O(N) path
  return options;
}

}  // namespace

TEST_CASE("DenseBorderedSolver::factorGeneral solves [[F_u, B], [C^T, D]] and its transposed form",
          "[structured_refinement]") {
  const int n = 6;
  toys::Bratu bratu(n);
  DenseBorderedSolver solver(bratu);
  const Vector u = Vector::LinSpaced(n, 0.2, 0.5);
  const double lambda = 2.0;
  Matrix Fu(n, n);
  Vector Fl(n);
  REQUIRE(BoundProblem(bratu).jacobian(u, lambda, Fu, Fl));
  Matrix B = Matrix::Random(n, 2), C = Matrix::Random(n, 2), D = Matrix::Random(2, 2);
  const Vector b = Vector::LinSpaced(n + 2, -1.0, 1.0);
  for (bool transposed : {false, true}) {
    Matrix G(n + 2, n + 2);
    G << (transposed ? Matrix(Fu.transpose()) : Fu), B, C.transpose(), D;
    REQUIRE(solver.factorGeneral(u, lambda, B, C, D, transposed) == Factorization::Regular);
    Vector x(n + 2);
    REQUIRE(solver.solve(b, x));
    CHECK((G * x - b).norm() <= 1e-13 * G.norm() * x.norm());
  }
  // factor() afterwards is the bordered Jacobian again.
  const Vector c = Vector::LinSpaced(n + 1, 1.0, 2.0);
  REQUIRE(solver.factor(u, lambda, c) == Factorization::Regular);
  Vector x(n + 1), rhs = Vector::Ones(n + 1);
  REQUIRE(solver.solve(rhs, x));
  Matrix A(n + 1, n + 1);
  A << Fu, Fl, c.transpose();
  CHECK((A * x - rhs).norm() <= 1e-13 * A.norm() * x.norm());
}

TEST_CASE("Problem's dense product defaults equal F_x, F_x^T and the directional derivative",
          "[structured_refinement]") {
  toys::CurvedPitchforks problem(0.5);
  const Vector u = (Vector(2) << 0.3, -0.2).finished(), x = (Vector(3) << 0.7, -0.4, 0.9).finished();
  const Vector w = (Vector(2) << -0.6, 1.1).finished();
  const double lambda = 0.37;
  Matrix Fx(2, 3), dFx(2, 3);
  REQUIRE(BoundProblem(problem).jacobian(u, lambda, Fx.leftCols(2), Fx.col(2)));
  Vector y(2), yt(3), y2(3);
  REQUIRE(BoundProblem(problem).jacobianApply(u, lambda, x, y));
  CHECK((y - Fx * x).norm() <= 1e-15 * Fx.norm() * x.norm());
  REQUIRE(BoundProblem(problem).jacobianTransposeApply(u, lambda, w, yt));
  CHECK((yt - Fx.transpose() * w).norm() <= 1e-15 * Fx.norm() * w.norm());
  // (F_xx[x, ·])ᵀw by central differences against the directional derivative of F_x along x.
  REQUIRE(BoundProblem(problem).secondDerivativeTransposeApply(u, lambda, x, w, y2));
  REQUIRE(problem.Problem::jacobianDirectionalDerivative(*problem.createWorkspace(), u, lambda, x.head(2), x[2],
                                                         dFx.leftCols(2), dFx.col(2)));
  CHECK((y2 - dFx.transpose() * w).norm() <= 1e-8 * std::max(1.0, y2.norm()));
}

TEST_CASE("Structured path: Bratu fold equals the dense refinement, with its null vector",
          "[structured_refinement]") {
  const int n = 20;
  toys::Bratu bratu(n);
  TracerOptions options;
  options.step.maxStep = 0.5;
  options.maxPoints = 60;
  options.lambdaMin = -1.0;
  const Branch dense = trace(bratu, Vector::Zero(n), 0.0, InitialDirection::increasingLambda(), options);
  const Branch fast =
      trace(bratu, Vector::Zero(n), 0.0, InitialDirection::increasingLambda(), structuredOptions(options));
  const auto dFolds = dense.specialPointsOfType(SpecialPointType::Fold);
  const auto sFolds = fast.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(dFolds.size() == 1);
  REQUIRE(sFolds.size() == 1);
  const SpecialPoint &d = *dFolds[0], &s = *sFolds[0];
  CHECK(s.refined);
  CHECK(d.refined);
  CHECK(std::abs(s.lambda - d.lambda) <= 1e-12 * std::abs(d.lambda));
  CHECK((s.u - d.u).norm() <= 1e-7 * d.u.norm());  // u is the square root of the λ accuracy along v
  REQUIRE(s.nullVectors.rows() == n);
  Matrix Fu(n, n);
  Vector Fl(n), F(n);
  REQUIRE(BoundProblem(bratu).jacobian(s.u, s.lambda, Fu, Fl));
  REQUIRE(BoundProblem(bratu).residual(s.u, s.lambda, F));
  CHECK(F.norm() <= 1e-12 * Fu.norm());
  CHECK((Fu * s.nullVectors.col(0)).norm() <= 1e-9 * Fu.norm());
  CHECK(std::abs(s.nullVectors.col(0).dot(d.nullVectors.col(0))) >= 1.0 - 1e-10);
  CHECK(std::abs(s.tangent[n]) <= 1e-6);  // vertical in λ at the fold
}

TEST_CASE("Structured path: branch points on a curved trivial branch, geometry and switching",
          "[structured_refinement]") {
  const double c = 0.5;
  toys::CurvedPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 1.0;
  const TracerOptions fastOptions = structuredOptions(options);
  const Branch branch = trace(problem, toys::CurvedPitchforks::shift(-0.3), -0.3,
                              InitialDirection::increasingLambda(), fastOptions);
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  const double expected[2] = {0.0, c};
  for (int k = 0; k < 2; ++k) {
    const SpecialPoint &bp = *bps[k];
    INFO("branch point " << k);
    CHECK(bp.refined);
    CHECK(std::abs(bp.lambda - expected[k]) <= tolerance(expected[k]));
    CHECK((bp.u - toys::CurvedPitchforks::shift(expected[k])).norm() < 1e-12);
    // Kernel: the trivial branch's tangent (0.3 cos λ, 0.4 λ, 1)/‖·‖ and e_k (the bifurcating
    // direction in v = u − g); left null vector e_k.
    Vector t(3), e = Vector::Zero(3);
    t << 0.3 * std::cos(expected[k]), 0.4 * expected[k], 1.0;
    t.normalize();
    e[k] = 1.0;
    REQUIRE(bp.nullVectors.cols() == 2);
    CHECK(std::abs(bp.nullVectors.col(0).dot(t)) > 1.0 - 1e-10);
    const Vector phi = bp.nullVectors.col(1);
    CHECK((phi - phi.dot(t) * t).normalized().cwiseAbs().isApprox((e - e.dot(t) * t).normalized().cwiseAbs(), 1e-8));
    REQUIRE(bp.leftNullVector.size() == 2);
    CHECK(std::abs(bp.leftNullVector[k]) > 1.0 - 1e-10);
  }
  // The bifurcating direction from the O(N) bifurcation equation: the pitchfork's u_k axis
  // (dλ = 0, d(v_k) ≠ 0), the same as the dense route's.
  Vector structured, dense;
  std::string how;
  REQUIRE(bifurcatingDirection(problem, *bps[0], structured, &how, true));
  CHECK(how == "algebraic bifurcation equation");
  REQUIRE(bifurcatingDirection(problem, *bps[0], dense, &how, false));
  CHECK(std::abs(structured.dot(dense)) > 1.0 - 1e-8);
  CHECK(std::abs(structured[2]) < 1e-8);
  // Switched on both sides from the structured point: u₁ = 0.3 sin λ ± √λ.
  Tracer tracer(problem, fastOptions);
  const std::vector<Branch> sides = switchBothSides(tracer, *bps[0], BranchSwitchingOptions(), &how);
  REQUIRE(sides.size() == 2);
  for (const Branch &side : sides) {
    REQUIRE(side.points.size() > 3);
    const ContinuationPoint &p = side.points[3];
    CHECK(std::abs(std::abs(p.u[0] - 0.3 * std::sin(p.lambda)) - std::sqrt(std::max(0.0, p.lambda))) < 1e-8);
  }
  CHECK(sides[0].points[3].u[0] - 0.3 * std::sin(sides[0].points[3].lambda) > 0.0);
  CHECK(sides[1].points[3].u[0] - 0.3 * std::sin(sides[1].points[3].lambda) < 0.0);
}

TEST_CASE("StructuredRefinement converges from a rough start to the pitchfork and reports failures",
          "[structured_refinement]") {
  toys::TwoPitchforks problem(0.5);
  DenseBorderedSolver solver(problem);
  StructuredRefinement refinement(problem, solver, 1e-12, 15);
  Vector u = Vector::Zero(2), psi;
  double lambda = 0.03;
  const Vector t = (Vector(3) << 0.0, 0.0, 1.0).finished();
  Matrix K;
  const StructuredRefinementResult r = refinement.branchPoint(u, lambda, t, K, psi, 1.0);
  REQUIRE(r.converged);
  CHECK(std::abs(lambda) <= 1e-15);
  CHECK(u.norm() <= 1e-15);
  CHECK(std::abs(psi[0]) > 1.0 - 1e-12);
  // A fold refinement from a point with no fold nearby (the trivial branch of TwoPitchforks has
  // a regular F_x away from its branch points) leaves the step: a failure, the start restored.
  Vector v;
  u.setZero();
  lambda = 0.25;
  const Vector tu = (Vector(3) << 1.0, 0.0, 0.0).finished();
  const StructuredRefinementResult f = refinement.fold(u, lambda, tu, v, 0.1);
  CHECK_FALSE(f.converged);
  CHECK_FALSE(f.message.empty());
  CHECK(lambda == 0.25);
  CHECK(u.norm() == 0.0);
}
