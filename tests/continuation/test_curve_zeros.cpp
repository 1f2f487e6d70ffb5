#include "buckle/continuation/curve_zeros.h"
#include "buckle/continuation/branch_point_curve.h"
#include "buckle/continuation/fold_curve.h"
#include "buckle/continuation/tracer.h"

#include "two_parameter_toys.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

TEST_CASE("Curve zeros: the branch-point curve crosses λ = 0 at μ = ±√2", "[curve_zeros]") {
  toys::EigenToy toy;
  Vector c;
  const Vector W0 = toys::eigenToyCurveStart(toy, c);
  BranchPointCurveProblem curve(toy, Vector::Zero(2), c);
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  options.detection.stability = false;
  const CurveTest zeroLoad = [](ConstVectorRef W, double, double& g) {
    g = W[2];
    return true;
  };
  int found = 0;
  for (const InitialDirection& d : {InitialDirection::increasingLambda(), InitialDirection::decreasingLambda()}) {
    const Branch branch = trace(curve, W0, 0.0, d, options);
    for (const CurveZero& z : locateCurveZeros(curve, branch, zeroLoad)) {
      ++found;
      CHECK(z.converged);
      CHECK(std::abs(std::abs(z.lambda) - std::sqrt(2.0)) <= 1e-12);
      CHECK(std::abs(z.u[2]) <= 1e-12);
      CHECK(z.lambda * d.lambdaSign > 0.0);
    }
  }
  CHECK(found == 2);
}

TEST_CASE("Curve zeros: the cusp located on a fold curve, where μ turns", "[curve_zeros]") {
  toys::CuspToy toy;
  toy.mu = 1.5;
  Vector c;
  const Vector U0 = FoldCurveProblem::start(toy, (Vector(2) << 1.0, 0.5).finished(), -1.0,
                                            (Vector(2) << 1.0, 1.0).finished(), c);
  FoldCurveProblem curve(toy, c);
  TracerOptions options;
  options.lambdaMax = 2.0;
  options.detection.stability = false;
  const Branch branch = trace(curve, U0, 1.5, InitialDirection::decreasingLambda(), options);
  const CurveTest cusp = [&](ConstVectorRef U, double mu, double& g) { return curve.cuspTest(U, mu, g); };
  const auto zeros = locateCurveZeros(curve, branch, cusp);
  REQUIRE(zeros.size() == 1);
  CHECK(zeros[0].converged);
  CHECK(std::abs(zeros[0].lambda) <= 1e-12);  // μ
  CHECK(std::abs(zeros[0].u[0]) <= 1e-10);    // x
  CHECK(std::abs(zeros[0].u[2]) <= 1e-12);    // λ
}

TEST_CASE("Curve zeros: none without a sign change, none on a one-point branch", "[curve_zeros]") {
  toys::EigenToy toy;
  Vector c;
  const Vector W0 = toys::eigenToyCurveStart(toy, c);
  BranchPointCurveProblem curve(toy, Vector::Zero(2), c);
  TracerOptions options;
  options.lambdaMax = 1.0;
  options.detection.stability = false;
  const Branch branch = trace(curve, W0, 0.0, InitialDirection::increasingLambda(), options);
  const CurveTest positive = [](ConstVectorRef, double mu, double& g) {
    g = 1.0 + mu * mu;
    return true;
  };
  CHECK(locateCurveZeros(curve, branch, positive).empty());
  Branch single;
  single.points.push_back(branch.points.front());
  CHECK(locateCurveZeros(curve, single, positive).empty());
}
