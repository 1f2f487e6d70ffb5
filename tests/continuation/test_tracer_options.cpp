// The core's settings (tracer_options.h): every group validates itself and names a bad field by
// its path; the tracer reads the nested groups (not copies of them); the step callback sees
// every new point and its step's special points in the problem's units.
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace buckle::continuation;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

using toys::vec1;

// One bad setting: the options refuse it, naming `field` (its path), and a tracer built with them
// says so in the branch instead of running.
void requireRefused(const std::function<void(TracerOptions &)> &spoil, const std::string &field) {
  INFO(field);
  TracerOptions o;
  spoil(o);
  std::string why;
  CHECK_FALSE(o.IsValid(&why));
  CHECK_THAT(why, StartsWith(field));
  CHECK(o.validate() == why);
  toys::Circle circle;
  const Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
  CHECK(branch.stopReason == StopReason::InvalidOptions);
  CHECK_THAT(branch.stopMessage, Contains(field));
  CHECK(branch.points.empty());
}

}  // namespace

TEST_CASE("TracerOptions: the defaults are valid, group by group", "[tracer_options]") {
  std::string why = "unset";
  CHECK(TracerOptions().IsValid(&why));
  CHECK(why.empty());
  CHECK(StepOptions().validate().empty());
  CHECK(CorrectorOptions().validate().empty());
  CHECK(LocationOptions().validate().empty());
  CHECK(DetectionOptions().validate().empty());
}

TEST_CASE("TracerOptions: a bad setting is named by its path in the nested options", "[tracer_options]") {
  requireRefused([](TracerOptions &o) { o.step.initialStep = -0.1; }, "step.initialStep");
  requireRefused([](TracerOptions &o) { o.step.initialStep = std::nan(""); }, "step.initialStep");
  requireRefused([](TracerOptions &o) { o.step.minStep = -1e-3; }, "step.minStep");
  requireRefused(
      [](TracerOptions &o) {
        o.step.minStep = 0.5;
        o.step.maxStep = 0.1;
      },
      "step.minStep must not exceed maxStep");
  requireRefused([](TracerOptions &o) { o.step.maxStep = std::nan(""); }, "step.maxStep");
  requireRefused([](TracerOptions &o) { o.step.minTangentCosine = -1.0; }, "step.minTangentCosine");
  requireRefused([](TracerOptions &o) { o.corrector.tolerance = 0.0; }, "corrector.tolerance");
  requireRefused([](TracerOptions &o) { o.corrector.maxIterations = 0; }, "corrector.maxIterations");
  requireRefused([](TracerOptions &o) { o.location.tolerance = 0.0; }, "location.tolerance");
  requireRefused([](TracerOptions &o) { o.location.coarseTolerance = 0.0; }, "location.coarseTolerance");
  requireRefused([](TracerOptions &o) { o.location.separationFraction = 1.0; }, "location.separationFraction");
  requireRefused([](TracerOptions &o) { o.location.maxDenseDimension = 0; }, "location.maxDenseDimension");
  requireRefused([](TracerOptions &o) { o.detection.lowestEigenvalues = -1; }, "detection.lowestEigenvalues");
  requireRefused([](TracerOptions &o) { o.detection.touchTolerance = -1.0; }, "detection.touchTolerance");
  requireRefused([](TracerOptions &o) { o.maxPoints = 1; }, "maxPoints");
  requireRefused([](TracerOptions &o) { o.lambdaMin = std::nan(""); }, "lambdaMin");
  requireRefused(
      [](TracerOptions &o) {
        o.lambdaMin = 2.0;
        o.lambdaMax = 1.0;
      },
      "lambdaMin");
  requireRefused([](TracerOptions &o) { o.boxLower = Vector::Zero(2); }, "boxLower");
  // a group checked on its own names its fields under the prefix asked for
  CorrectorOptions c;
  c.stagnationFactor = 0.5;
  CHECK(c.validate() == "corrector.stagnationFactor must be finite and >= 1");
  CHECK(c.validate("") == "stagnationFactor must be finite and >= 1");
}

TEST_CASE("TracerOptions: the tracer reads the nested groups", "[tracer_options]") {
  // The circle u² + λ² = 1 from (1, 0): each group's setting shows in the branch it traces.
  toys::Circle circle;
  TracerOptions o;
  o.step.initialStep = o.step.maxStep = 0.01;
  o.maxPoints = 40;
  const Branch fine = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
  REQUIRE(fine.points.size() == 40);
  for (size_t i = 1; i < fine.points.size(); ++i)
    CHECK(fine.points[i].arclength - fine.points[i - 1].arclength <= 0.01 * (1.0 + 1e-12));
  // detection.folds off: the folds at λ = ±1 are passed without a point
  o = TracerOptions();
  o.maxPoints = 2000;
  o.maxArclength = 7.0;  // once round and a little
  const Branch withFolds = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
  CHECK(withFolds.specialPointsOfType(SpecialPointType::Fold).size() == 2);
  o.detection.folds = false;
  const Branch withoutFolds = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
  CHECK(withoutFolds.specialPointsOfType(SpecialPointType::Fold).empty());
  // detection.stability off: no inertia recorded
  o.detection.stability = false;
  const Branch noStability = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
  for (const ContinuationPoint &p : noStability.points) CHECK_FALSE(p.stability.valid());
  // location.tolerance: the folds' achieved accuracy is within the one asked for
  for (double tolerance : {1e-6, 1e-13}) {
    o = TracerOptions();
    o.maxArclength = 7.0;
    o.maxPoints = 2000;
    o.location.tolerance = tolerance;
    const Branch b = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), o);
    for (const SpecialPoint *fold : b.specialPointsOfType(SpecialPointType::Fold)) {
      CHECK(fold->lambdaAccuracy <= tolerance);
      CHECK(std::abs(std::abs(fold->lambda) - 1.0) <= 10.0 * tolerance);
    }
  }
}

TEST_CASE("onStep sees every new point and its step's special points in the problem's units", "[tracer_options]") {
  // TwoPitchforks with u scaled by 1e-2 and λ by 1e3 inside the tracer: the callback's points and
  // special points must be those the tracer returns, bit for bit.
  for (bool scaled : {false, true}) {
    INFO("scaled " << scaled);
    toys::TwoPitchforks plain(1e-3);
    toys::ScaledTwoPitchforks big(1e-3);
    Problem &problem = scaled ? static_cast<Problem &>(big) : plain;
    TracerOptions options;
    options.lambdaMax = 3.0;
    options.step.maxStep = 0.3;
    std::vector<ContinuationPoint> seen;
    std::vector<SpecialPoint> seenSpecial;
    std::vector<int> counts, specialCounts;
    const void *identity = nullptr;
    bool sameBranch = true;
    options.onStep = [&](const StepInfo &step) {
      seen.push_back(step.point);
      seenSpecial.insert(seenSpecial.end(), step.specialPoints.begin(), step.specialPoints.end());
      counts.push_back(step.pointCount);
      specialCounts.push_back(step.specialPointCount);
      if (identity && identity != step.branch) sameBranch = false;
      identity = step.branch;
      return StepAction::Continue;
    };
    const Branch branch = trace(problem, Vector::Zero(2), -3.0, InitialDirection::increasingLambda(), options);
    REQUIRE(branch.specialPointsOfType(SpecialPointType::BranchPoint).size() == 2);
    CHECK(sameBranch);
    // one call per accepted point after the start, the range's end included
    REQUIRE(seen.size() + 1 == branch.points.size());
    for (size_t k = 0; k < seen.size(); ++k) {
      const ContinuationPoint &p = branch.points[k + 1];
      CHECK(counts[k] == int(k + 2));
      CHECK(seen[k].lambda == p.lambda);
      CHECK(seen[k].u == p.u);
      CHECK(seen[k].tangent == p.tangent);
    }
    // every special point once, as the branch holds it (the endpoint is not a step's)
    std::vector<const SpecialPoint *> interior;
    for (const SpecialPoint &sp : branch.specialPoints)
      if (sp.type != SpecialPointType::Endpoint) interior.push_back(&sp);
    REQUIRE(seenSpecial.size() == interior.size());
    for (size_t k = 0; k < interior.size(); ++k) {
      CHECK(seenSpecial[k].type == interior[k]->type);
      CHECK(seenSpecial[k].lambda == interior[k]->lambda);
      CHECK(seenSpecial[k].u == interior[k]->u);
    }
    // the running count: the branch's special points so far, its start's endpoint included and
    // the final endpoint (appended once the last step is taken) not yet
    REQUIRE(branch.specialPoints.front().type == SpecialPointType::Endpoint);
    REQUIRE(branch.specialPoints.back().type == SpecialPointType::Endpoint);
    for (size_t k = 1; k < specialCounts.size(); ++k) CHECK(specialCounts[k] >= specialCounts[k - 1]);
    CHECK(specialCounts.front() >= 1);
    CHECK(specialCounts.back() == int(branch.specialPoints.size()) - 1);
  }
}
