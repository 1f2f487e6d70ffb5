// Hidden report (run with "[report]"): the accuracy each located point actually reached.
#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

using namespace buckle::continuation;

namespace {
void print(const char *name, const Branch &branch, const double *exact, int count) {
  int k = 0;
  for (const SpecialPoint &sp : branch.specialPoints) {
    if (sp.type != SpecialPointType::Fold && sp.type != SpecialPointType::BranchPoint) continue;
    const double error = k < count ? std::abs(sp.lambda - exact[k]) : std::nan("");
    std::printf("%-26s %s m=%d lambda=%+.16f |err|=%.2e reported|dl|=%.2e |F|=%.2e aug=%.2e it=%d refined=%d\n", name,
                label(sp.type), sp.multiplicity, sp.lambda, error, sp.lambdaAccuracy, sp.residualNorm,
                sp.augmentedResidualNorm, sp.locationIterations, sp.refined ? 1 : 0);
    ++k;
  }
}
}  // namespace

TEST_CASE("Accuracy report", "[.][report]") {
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  {
    toys::Circle circle;
    TracerOptions o = options;
    o.maxArclength = 6.0;
    const double exact[] = {1.0, -1.0};
    print("circle", trace(circle, Vector::Ones(1), 0.0, InitialDirection::increasingLambda(), o), exact, 2);
  }
  {
    toys::CubicFold cubic;
    const double exact[] = {2.0 / 3.0, -2.0 / 3.0};
    const double u0 = -2.5;
    print("cubic", trace(cubic, Vector::Constant(1, u0), -u0 + u0 * u0 * u0 / 3.0,
                         InitialDirection::increasingLambda(), options),
          exact, 2);
  }
  {
    toys::TwoPitchforks pitchfork(0.5);
    const double exact[] = {0.0, 0.5};
    print("pitchforks c=0.5", trace(pitchfork, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options),
          exact, 2);
  }
  {
    toys::TwoPitchforks pitchfork(1e-3);
    TracerOptions o = options;
    o.step.initialStep = o.step.maxStep = 0.05;
    o.lambdaMax = 0.2;
    const double exact[] = {0.0, 1e-3};
    print("pitchforks c=1e-3 (1 step)", trace(pitchfork, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), o),
          exact, 2);
  }
  {
    toys::DoubleZero dz;
    TracerOptions o = options;
    o.step.initialStep = o.step.maxStep = 0.05;
    o.lambdaMax = 0.2;
    const double exact[] = {0.0};
    print("double zero", trace(dz, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), o), exact, 1);
  }
  {
    toys::CurvedPitchforks curved(0.5);
    const double exact[] = {0.0, 0.5};
    print("curved pitchforks c=0.5", trace(curved, toys::CurvedPitchforks::shift(-0.3), -0.3,
                                           InitialDirection::increasingLambda(), options),
          exact, 2);
  }
  {
    toys::Transcritical tc;
    const double exact[] = {0.0};
    print("transcritical", trace(tc, Vector::Zero(1), -0.5, InitialDirection::increasingLambda(), options), exact, 1);
  }
  {
    toys::Bratu bratu(20);
    TracerOptions o = options;
    o.step.maxStep = 0.5;
    o.maxPoints = 60;
    o.lambdaMax = 5.0;
    const Branch b = trace(bratu, Vector::Zero(20), 0.0, InitialDirection::increasingLambda(), o);
    print("bratu N=20", b, nullptr, 0);
  }
  SUCCEED();
}
