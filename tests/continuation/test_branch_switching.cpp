#include "buckle/continuation/branch_switching.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <vector>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

using toys::vec1;

TEST_CASE("Pitchfork: both bifurcating directions, closed-form branch and its stability", "[branch_switching]") {
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 0.4;
  options.step.maxStep = 0.05;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options, 1);
  REQUIRE(tree.branches.size() == 3);
  const Branch &trivial = tree.branches[0];
  const auto bps = trivial.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  CHECK_THAT(bps[0]->note, Contains("switched"));
  // Beyond the branch point the trivial branch is unstable with one negative eigenvalue.
  for (const ContinuationPoint &p : trivial.points) {
    if (p.lambda > 1e-9) {
      CHECK(p.stability.negative == 1);
    }
    if (p.lambda < -1e-9) {
      CHECK(p.stability.negative == 0);
    }
  }

  int signs = 0;
  for (int k = 1; k <= 2; ++k) {
    const Branch &child = tree.branches[k];
    CHECK(child.id == k);
    CHECK(child.parentId == 0);
    CHECK(trivial.specialPoints[child.parentSpecialPoint].type == SpecialPointType::BranchPoint);
    CHECK(child.stopReason == StopReason::LambdaRange);
    CHECK(std::abs(child.points.back().lambda - 0.4) <= 1e-15);
    REQUIRE(child.points.size() > 5);
    // The child does not re-detect the branch point it starts from.
    CHECK(child.specialPointsOfType(SpecialPointType::BranchPoint).empty());
    const double side = child.points[2].u[0] > 0.0 ? 1.0 : -1.0;
    signs += static_cast<int>(side);
    for (std::size_t i = 1; i < child.points.size(); ++i) {
      const ContinuationPoint &p = child.points[i];
      // u₁² = λ to corrector tolerance (‖G‖∞ ≤ 1e-10 bounds |u₁|·|u₁² − λ|).
      CHECK(std::abs(p.u[0]) * std::abs(p.u[0] * p.u[0] - p.lambda) <= 1e-10);
      CHECK(std::abs(p.u[1]) < 1e-12);
      CHECK(p.u[0] * side > 0.0);
      CHECK(p.lambda > 0.0);
      REQUIRE(p.stability.valid());
      CHECK(p.stability.negative == 0);  // supercritical: the bifurcated branch is stable
    }
  }
  CHECK(signs == 0);  // one branch with u₁ > 0, one with u₁ < 0
  CHECK(tree.branches[1].direction == -tree.branches[2].direction);
}

TEST_CASE("Two levels of switching on the double pitchfork", "[branch_switching]") {
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 0.8;
  options.step.maxStep = 0.05;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options, 2);
  // trivial; 2 from λ=0 (u₁ = ±√λ); 2 from λ=c (u₂ = ±√(λ−c)); 2×2 from λ=c on the u₁ branches.
  REQUIRE(tree.branches.size() == 9);
  int mixed = 0;
  for (const Branch &branch : tree.branches) {
    CHECK(branch.stopReason == StopReason::LambdaRange);
    Vector F(2);
    for (const ContinuationPoint &p : branch.points) {
      BoundProblem(problem).residual(p.u, p.lambda, F);
      CHECK(F.norm() < 1e-10);
    }
    if (branch.parentId > 0) {
      ++mixed;
      for (std::size_t i = 1; i < branch.points.size(); ++i) {
        const ContinuationPoint &p = branch.points[i];
        // To corrector tolerance: ‖G‖∞ ≤ 1e-10 bounds |u_k|·|u_k² − (λ − c_k)|.
        CHECK(std::abs(p.u[0]) * std::abs(p.u[0] * p.u[0] - p.lambda) <= 1e-10);
        CHECK(std::abs(p.u[1]) * std::abs(p.u[1] * p.u[1] - (p.lambda - c)) <= 1e-10);
        CHECK(p.u[1] * p.u[1] > 0.0);
      }
    }
  }
  CHECK(mixed == 4);
}

TEST_CASE("Transcritical: the bifurcation equation gives the u = lambda direction", "[branch_switching]") {
  toys::Transcritical problem;
  TracerOptions options;
  options.lambdaMin = -0.5;
  options.lambdaMax = 0.5;
  Tracer tracer(problem, options);
  const Branch trivial = tracer.trace(vec1(0.0), -0.45, InitialDirection::increasingLambda());
  const auto bps = trivial.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  Vector direction;
  std::string how;
  REQUIRE(bifurcatingDirection(problem, *bps[0], direction, &how));
  CHECK(how == "algebraic bifurcation equation");
  CHECK(std::abs(std::abs(direction[0]) - std::sqrt(0.5)) < 1e-6);
  CHECK(std::abs(direction[0] - direction[1]) < 1e-6);

  int reachedUpper = 0, reachedLower = 0;
  for (int sign : {1, -1}) {
    const Branch child = switchBranch(tracer, *bps[0], direction, sign);
    REQUIRE(child.points.size() > 5);
    for (const ContinuationPoint &p : child.points) CHECK(std::abs(p.u[0] - p.lambda) < 1e-10);
    if (std::abs(child.points.back().lambda - 0.5) <= 1e-15) ++reachedUpper;
    if (std::abs(child.points.back().lambda + 0.5) <= 1e-15) ++reachedLower;
    // Stability of u = λ: H = 2u − λ = λ, stable for λ > 0.
    for (std::size_t i = 1; i < child.points.size(); ++i)
      CHECK(child.points[i].stability.negative == (child.points[i].lambda < 0.0 ? 1 : 0));
  }
  CHECK(reachedUpper == 1);
  CHECK(reachedLower == 1);
}

TEST_CASE("Switching on a curved trivial branch follows u1 = 0.3 sin(lambda) +- sqrt(lambda)", "[branch_switching]") {
  toys::CurvedPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMax = 0.4;
  const BranchTree tree = traceTree(problem, toys::CurvedPitchforks::shift(-0.3), -0.3,
                                    InitialDirection::increasingLambda(), options, 1);
  REQUIRE(tree.branches.size() == 3);
  for (int k = 1; k <= 2; ++k) {
    const Branch &child = tree.branches[k];
    CHECK(child.stopReason == StopReason::LambdaRange);
    REQUIRE(child.points.size() > 5);
    for (std::size_t i = 1; i < child.points.size(); ++i) {
      const ContinuationPoint &p = child.points[i];
      const Vector v = p.u - toys::CurvedPitchforks::shift(p.lambda);
      CHECK(std::abs(v[0]) * std::abs(v[0] * v[0] - p.lambda) <= 1e-10);
      CHECK(std::abs(v[1]) < 1e-10);
      CHECK(p.stability.negative == 0);
    }
  }
}

TEST_CASE("Multiplicity-2 points are switched along every direction of the reduced equation", "[branch_switching]") {
  toys::DoubleZero problem;
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.05;
  options.lambdaMax = 0.2;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), options, 3);
  // [λu₁ − u₁³, λu₂ − u₂³]: the lines u₁ = 0, u₂ = 0, u₁ = ±u₂, both sides each (the children's own
  // branch points are each other's, switched once)
  const auto bps = tree.branches[0].specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  CHECK(bps[0]->multiplicity == 2);
  CHECK(bps[0]->branchesPredicted == 8);
  CHECK(bps[0]->branchesFound == 8);
  CHECK_THAT(bps[0]->note, Contains("switched"));
  REQUIRE(tree.branches.size() >= 9);
  for (size_t b = 1; b <= 8; ++b) CHECK(tree.branches[b].parentId == 0);
}

TEST_CASE("Switching from a point that is not a branch point is refused", "[branch_switching]") {
  toys::Circle circle;
  SpecialPoint fake;
  fake.type = SpecialPointType::Fold;
  fake.u = vec1(0.0);
  fake.lambda = 1.0;
  fake.nullVectors = Matrix::Identity(2, 1);
  Vector direction;
  std::string why;
  CHECK_FALSE(bifurcatingDirection(circle, fake, direction, &why));
  CHECK_THAT(why, Contains("not a branch point"));
  BranchSwitchingOptions bad;
  bad.minOffBranchFraction = 2.0;
  CHECK_FALSE(bad.IsValid(&why));
  CHECK_THAT(why, Contains("minOffBranchFraction"));
}
