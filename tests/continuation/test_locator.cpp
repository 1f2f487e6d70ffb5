#include "buckle/continuation/internal/locator.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

namespace {
using toys::vec1;

double tolerance(double lambda) { return 1e-12 * std::max(1.0, std::abs(lambda)); }
}  // namespace

TEST_CASE("Fold normal form: the fold at the origin, both halves traced", "[locator]") {
  toys::FoldNormalForm problem;
  TracerOptions options;
  options.lambdaMax = 1.0;
  const Branch branch = trace(problem, vec1(1.1), 1.0, InitialDirection::decreasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  // Start polished onto u = 1, the branch comes back to λ = 1 on u = −1.
  CHECK(std::abs(branch.points.front().u[0] - 1.0) < 1e-12);
  CHECK(std::abs(branch.points.back().u[0] + 1.0) < 1e-12);
  CHECK(branch.points.back().lambda == 1.0);
  REQUIRE_FALSE(branch.specialPoints.empty());
  CHECK(branch.specialPoints.front().type == SpecialPointType::Endpoint);
  CHECK(branch.specialPoints.front().index == 0);
  CHECK_THAT(branch.specialPoints.front().note, Contains("start"));
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 1);
  CHECK(std::abs(folds[0]->lambda) <= 1e-12);
  CHECK(std::abs(folds[0]->u[0]) <= 1e-12);
  CHECK(folds[0]->refined);
  CHECK(folds[0]->inertiaBefore == -1);  // no stability operator
  // The tangent at the fold is vertical in λ.
  CHECK(std::abs(folds[0]->tangent[1]) < 1e-12);
}

TEST_CASE("Cubic folds at lambda = +-2/3, not reported again as branch points", "[locator]") {
  toys::CubicFold cubic;
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  options.step.maxStep = 0.2;
  const double u0 = -2.5, lambda0 = -u0 + u0 * u0 * u0 / 3.0;
  const Branch branch = trace(cubic, vec1(u0), lambda0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 2);
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
  CHECK(std::abs(folds[0]->lambda - 2.0 / 3.0) <= tolerance(2.0 / 3.0));
  CHECK(std::abs(folds[0]->u[0] + 1.0) < 1e-8);  // u is the square root of the λ accuracy at a fold
  CHECK(std::abs(folds[1]->lambda + 2.0 / 3.0) <= tolerance(2.0 / 3.0));
  CHECK(std::abs(folds[1]->u[0] - 1.0) < 1e-8);
  for (const SpecialPoint *fold : folds) {
    CHECK(fold->refined);
    CHECK(fold->lambdaAccuracy <= tolerance(fold->lambda));
    CHECK(fold->residualNorm < 1e-13);
    CHECK(std::string(label(fold->type)) == "LP");
  }
  // Outer branch stable, middle branch unstable: the fold is where one eigenvalue crosses.
  CHECK(folds[0]->inertiaBefore == 0);
  CHECK(folds[0]->inertiaAfter == 1);
  CHECK(folds[1]->inertiaBefore == 1);
  CHECK(folds[1]->inertiaAfter == 0);
}

TEST_CASE("Folds with detection off are not mistaken for branch points", "[locator]") {
  toys::CubicFold cubic;
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  options.detection.folds = false;
  const double u0 = -2.5, lambda0 = -u0 + u0 * u0 * u0 / 3.0;
  const Branch branch = trace(cubic, vec1(u0), lambda0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  CHECK(branch.specialPointsOfType(SpecialPointType::Fold).empty());
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
}

TEST_CASE("Bratu fold: F = 0 and F_u singular to the reported accuracy", "[locator]") {
  const int n = 20;
  toys::Bratu bratu(n);
  TracerOptions options;
  options.step.maxStep = 0.5;
  options.maxPoints = 60;
  options.lambdaMin = -1.0;
  const Branch branch = trace(bratu, Vector::Zero(n), 0.0, InitialDirection::increasingLambda(), options);
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 1);
  const SpecialPoint &fold = *folds[0];
  CHECK(fold.refined);
  CHECK(fold.lambdaAccuracy <= tolerance(fold.lambda));
  CHECK(std::abs(fold.lambda - 3.5138) < 0.02);  // continuum value 3.513830719
  for (const ContinuationPoint &p : branch.points) CHECK(p.lambda <= fold.lambda + tolerance(fold.lambda));
  Vector F(n);
  BoundProblem(bratu).residual(fold.u, fold.lambda, F);
  Matrix Fu(n, n);
  Vector Fl(n);
  BoundProblem(bratu).jacobian(fold.u, fold.lambda, Fu, Fl);
  CHECK(F.norm() < 1e-10 * Fu.norm());
  Eigen::SelfAdjointEigenSolver<Matrix> eig(Fu);
  const double smallest = eig.eigenvalues().cwiseAbs().minCoeff();
  CHECK(smallest < 1e-9 * eig.eigenvalues().cwiseAbs().maxCoeff());
  // The reported null vector is the eigenvector of that eigenvalue.
  CHECK((Fu * fold.nullVectors.col(0)).norm() < 1e-9 * Fu.norm());
  CHECK(fold.inertiaBefore == 0);
  CHECK(fold.inertiaAfter == 1);
}

TEST_CASE("Symmetric pitchforks located at lambda = 0 and lambda = c", "[locator]") {
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 1.0;
  options.step.maxStep = 0.07;
  const Branch branch = trace(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  CHECK(branch.specialPointsOfType(SpecialPointType::Fold).empty());
  const double expected[2] = {0.0, c};
  for (int k = 0; k < 2; ++k) {
    const SpecialPoint &bp = *bps[k];
    CHECK(std::string(label(bp.type)) == "BP");
    CHECK(bp.refined);
    CHECK(bp.multiplicity == 1);
    CHECK(std::abs(bp.lambda - expected[k]) <= tolerance(expected[k]));
    CHECK(bp.lambdaAccuracy <= tolerance(expected[k]));
    CHECK(bp.u.norm() < 1e-12);
    CHECK(bp.inertiaBefore == k);
    CHECK(bp.inertiaAfter == k + 1);
    REQUIRE(bp.nullVectors.cols() == 2);
    // Kernel of F_x: the traced direction e_λ and the bifurcating u_k direction.
    CHECK(std::abs(std::abs(bp.nullVectors(2, 0)) - 1.0) < 1e-10);
    CHECK(std::abs(std::abs(bp.nullVectors(k, 1)) - 1.0) < 1e-10);
    CHECK(std::abs(std::abs(bp.leftNullVector[k]) - 1.0) < 1e-10);
    CHECK(bp.testFunctionValue < 1e-12);  // smallest singular value of F_x
  }
}

TEST_CASE("Two branch points inside one step are separated and each located once", "[locator]") {
  const double c = 1e-3;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.05;
  options.lambdaMax = 0.2;
  const Branch branch = trace(problem, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), options);
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  // Both inside the same step: the determinant sign is equal at its ends.
  REQUIRE(bps[0]->index == bps[1]->index);
  const ContinuationPoint &p = branch.points[bps[0]->index], &q = branch.points[bps[0]->index + 1];
  CHECK(p.determinantSign == q.determinantSign);
  CHECK(q.stability.negative - p.stability.negative == 2);
  CHECK(std::abs(bps[0]->lambda) <= 1e-12);
  CHECK(std::abs(bps[1]->lambda - c) <= 1e-12);
  for (const SpecialPoint *bp : bps) {
    CHECK(bp->multiplicity == 1);
    CHECK(bp->refined);
    CHECK(bp->lambdaAccuracy <= 1e-12);
  }
  CHECK(bps[0]->inertiaBefore == 0);
  CHECK(bps[0]->inertiaAfter == 1);
  CHECK(bps[1]->inertiaBefore == 1);
  CHECK(bps[1]->inertiaAfter == 2);
}

TEST_CASE("Double zero: one branch point of multiplicity 2", "[locator]") {
  toys::DoubleZero problem;
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.05;
  options.lambdaMax = 0.2;
  const Branch branch = trace(problem, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), options);
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  const SpecialPoint &bp = *bps[0];
  CHECK(bp.multiplicity == 2);
  CHECK(bp.refined);  // ker F_x is 3-dimensional at the located point
  CHECK(bp.inertiaBefore == 0);
  CHECK(bp.inertiaAfter == 2);
  CHECK(std::abs(bp.lambda) <= 1e-9 * 0.05);
  CHECK(bp.lambdaAccuracy <= 1e-9 * 0.05);
  CHECK(bp.nullVectors.cols() == 3);  // F_x = 0 at the double zero
  CHECK_THAT(bp.note, Contains("kernel of F_x 3-dimensional"));
  const ContinuationPoint &p = branch.points[bp.index], &q = branch.points[bp.index + 1];
  CHECK(p.determinantSign == q.determinantSign);
}

TEST_CASE("Transcritical branch point at the origin", "[locator]") {
  toys::Transcritical problem;
  TracerOptions options;
  options.lambdaMax = 0.5;
  const Branch branch = trace(problem, vec1(0.0), -0.5, InitialDirection::increasingLambda(), options);
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  CHECK(std::abs(bps[0]->lambda) <= 1e-12);
  CHECK(std::abs(bps[0]->u[0]) <= 1e-12);
  CHECK(bps[0]->refined);
  CHECK(bps[0]->inertiaBefore == 0);
  CHECK(bps[0]->inertiaAfter == 1);

  SECTION("detection toggles") {
    options.detection.branchPoints = false;
    const Branch quiet = trace(problem, vec1(0.0), -0.5, InitialDirection::increasingLambda(), options);
    CHECK(quiet.specialPointsOfType(SpecialPointType::BranchPoint).empty());
    CHECK(quiet.stopReason == StopReason::LambdaRange);
  }
}

TEST_CASE("Fold detection can be switched off", "[locator]") {
  toys::Circle circle;
  TracerOptions options;
  options.detection.folds = false;
  options.maxArclength = 3.0;
  const Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(branch.specialPointsOfType(SpecialPointType::Fold).empty());
  CHECK(branch.stopReason == StopReason::MaxArclength);
}

TEST_CASE("Branch points on a curved trivial branch (F_lambda != 0)", "[locator]") {
  const double c = 0.5;
  toys::CurvedPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 1.0;
  const Branch branch = trace(problem, toys::CurvedPitchforks::shift(-0.3), -0.3,
                              InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  // Every point on u = g(λ) to corrector tolerance: ‖G‖∞ ≤ 1e-10 bounds |λ − c_k|·|v_k| (v = u − g).
  for (const ContinuationPoint &p : branch.points) {
    const Vector v = p.u - toys::CurvedPitchforks::shift(p.lambda);
    CHECK(std::abs(p.lambda * v[0]) <= 1e-10);
    CHECK(std::abs((p.lambda - c) * v[1]) <= 1e-10);
  }
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  const double expected[2] = {0.0, c};
  for (int k = 0; k < 2; ++k) {
    const SpecialPoint &bp = *bps[k];
    CHECK(bp.refined);
    CHECK(std::abs(bp.lambda - expected[k]) <= tolerance(expected[k]));
    CHECK(bp.lambdaAccuracy <= tolerance(expected[k]));
    CHECK((bp.u - toys::CurvedPitchforks::shift(expected[k])).norm() < 1e-12);
    CHECK(bp.augmentedResidualNorm < 1e-12);
    CHECK(bp.locationIterations < 20);
    // First null vector is the branch tangent (0.3 cos λ, 0.4 λ, 1)/‖·‖.
    Vector t(3);
    t << 0.3 * std::cos(expected[k]), 0.4 * expected[k], 1.0;
    t.normalize();
    CHECK(std::abs(bp.nullVectors.col(0).dot(t)) > 1.0 - 1e-10);
  }
}
