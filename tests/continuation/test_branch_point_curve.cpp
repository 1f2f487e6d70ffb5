#include "buckle/continuation/branch_point_curve.h"
#include "buckle/continuation/tracer.h"

#include "two_parameter_toys.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

TEST_CASE("Branch-point curve: the lower eigenvalue of A(μ), λ = 3/2 − √(1/4 + μ²)", "[branch_point_curve]") {
  toys::EigenToy toy;
  Vector c;
  const Vector W0 = toys::eigenToyCurveStart(toy, c);
  BranchPointCurveProblem curve(toy, Vector::Zero(2), c);
  TracerOptions options;
  options.lambdaMin = -2.0;
  options.lambdaMax = 2.0;
  options.maxPoints = 400;
  options.detection.stability = false;
  options.corrector.tolerance = 1e-13;
  for (const InitialDirection& d : {InitialDirection::increasingLambda(), InitialDirection::decreasingLambda()}) {
    const Branch branch = trace(curve, W0, 0.0, d, options);
    REQUIRE(branch.stopReason == StopReason::LambdaRange);
    REQUIRE(branch.points.size() > 10);
    for (const ContinuationPoint& p : branch.points) {
      const double mu = p.lambda;
      CHECK(std::abs(p.u[2] - (1.5 - std::sqrt(0.25 + mu * mu))) <= 1e-12);
      // w is the eigenvector: A w = λ w
      CHECK(std::abs(2.0 * p.u[0] + mu * p.u[1] - p.u[2] * p.u[0]) <= 1e-12);
    }
    CHECK(std::abs(std::abs(branch.points.back().lambda) - 2.0) <= 1e-12);
  }
}

TEST_CASE("Branch-point curve: the exact Jacobian against central differences", "[branch_point_curve]") {
  toys::EigenToy toy;
  toy.mu = 0.3;
  Vector c = (Vector(2) << 0.4, 0.9).finished();
  BranchPointCurveProblem curve(toy, (Vector(2) << 0.1, -0.2).finished(), c);
  const Vector W = (Vector(3) << 0.3, 0.8, 0.6).finished();
  Matrix GW(3, 3);
  Vector Gmu(3), Gp(3), Gm(3);
  REQUIRE(BoundProblem(curve).jacobian(W, 0.3, GW, Gmu));
  const double h = 1e-6;
  for (int j = 0; j < 3; ++j) {
    Vector Wp = W, Wm = W;
    Wp[j] += h;
    Wm[j] -= h;
    REQUIRE(BoundProblem(curve).residual(Wp, 0.3, Gp));
    REQUIRE(BoundProblem(curve).residual(Wm, 0.3, Gm));
    CHECK(((Gp - Gm) / (2 * h) - GW.col(j)).norm() <= 1e-8);
  }
  REQUIRE(BoundProblem(curve).residual(W, 0.3 + h, Gp));
  REQUIRE(BoundProblem(curve).residual(W, 0.3 - h, Gm));
  CHECK(((Gp - Gm) / (2 * h) - Gmu).norm() <= 1e-8);
}

TEST_CASE("Branch-point curve: bad sizes", "[branch_point_curve]") {
  toys::EigenToy toy;
  CHECK_THROWS_WITH(BranchPointCurveProblem(toy, Vector::Zero(3), Vector::Ones(2)),
                    Catch::Matchers::Contains("dimension 2"));
}
