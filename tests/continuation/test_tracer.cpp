#include <sstream>
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

using toys::vec1;

TEST_CASE("Bad input to the tracer is reported in the branch, never thrown", "[tracer]") {
  // A problem without unknowns: the tracer cannot build a corrector for it.
  struct Empty : Problem {
    int dimension() const override { return 0; }
    bool residual(ProblemWorkspace &, ConstVectorRef, double, VectorRef) const override { return true; }
    bool jacobian(ProblemWorkspace &, ConstVectorRef, double, MatrixRef, VectorRef) const override { return true; }
  } empty;
  Branch none;
  CHECK_NOTHROW(none = trace(empty, Vector(), 0.0, InitialDirection::increasingLambda()));
  CHECK(none.stopReason == StopReason::InvalidOptions);
  CHECK_THAT(none.stopMessage, Contains("dimension"));

  toys::Circle circle;
  Tracer tracer(circle, TracerOptions());
  const Branch wrongSize = tracer.trace(Vector::Zero(2), 0.0, InitialDirection::increasingLambda());
  CHECK(wrongSize.stopReason == StopReason::InvalidOptions);
  CHECK_THAT(wrongSize.stopMessage, Contains("wrong size"));
  Branch noStart;
  tracer.continueBranch(noStart);
  CHECK(noStart.stopReason == StopReason::InvalidOptions);
  CHECK_THAT(noStart.stopMessage, Contains("start point"));
}

TEST_CASE("Circle: both folds located exactly, points on the circle", "[tracer]") {
  toys::Circle circle;
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.1;
  options.maxArclength = 2.0 * M_PI - 0.3;
  const Branch branch = trace(circle, vec1(1.02), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(branch.points.size() > 10);
  CHECK(branch.stopReason == StopReason::MaxArclength);
  CHECK(std::abs(branch.points.back().arclength - options.maxArclength) < 1e-12);
  // Start polished at fixed λ: u = 1 exactly.
  CHECK(std::abs(branch.points.front().u[0] - 1.0) < 1e-12);
  CHECK(branch.points[1].lambda > 0.0);
  for (const ContinuationPoint &p : branch.points) {
    CHECK(std::abs(p.u[0] * p.u[0] + p.lambda * p.lambda - 1.0) < 1e-9);
    CHECK(std::abs(p.tangent.norm() - 1.0) < 1e-12);
  }
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 2);
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
  CHECK(std::abs(folds[0]->lambda - 1.0) < 1e-12);
  CHECK(std::abs(folds[1]->lambda + 1.0) < 1e-12);
  for (const SpecialPoint *fold : folds) {
    CHECK(fold->refined);
    CHECK(std::abs(fold->u[0]) < 1e-12);
    CHECK(fold->lambdaAccuracy <= 1e-12);
    CHECK(fold->residualNorm < 1e-13);
    CHECK(std::abs(fold->testFunctionValue) < 1e-10);  // t_λ at the fold
    CHECK(std::abs(std::abs(fold->nullVectors(0, 0)) - 1.0) < 1e-12);
    // It lies between the two points it is filed under.
    const ContinuationPoint &p = branch.points[fold->index], &q = branch.points[fold->index + 1];
    CHECK(fold->arclength >= p.arclength);
    CHECK(fold->arclength <= q.arclength);
    CHECK(p.foldTest * q.foldTest < 0.0);
  }
}

TEST_CASE("Second-order predictor: same circle and folds with fewer Newton iterations", "[tracer]") {
  toys::Circle circle;
  TracerOptions options;
  options.step.initialStep = options.step.maxStep = 0.1;  // the same steps for both predictors
  options.maxArclength = 2.0 * M_PI - 0.3;
  const Branch first = trace(circle, vec1(1.02), 0.0, InitialDirection::increasingLambda(), options);
  options.step.secondOrderPredictor = true;
  const Branch second = trace(circle, vec1(1.02), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(first.points.size() > 10);
  REQUIRE(second.points.size() > 10);
  auto iterationsPerPoint = [](const Branch &b) {
    double sum = 0.0;
    for (size_t i = 1; i < b.points.size(); ++i) sum += b.points[i].newtonIterations;
    return sum / double(b.points.size() - 1);
  };
  for (const ContinuationPoint &p : second.points) CHECK(std::abs(p.u[0] * p.u[0] + p.lambda * p.lambda - 1.0) < 1e-9);
  // Euler's predictor is ds²/2 = 5e-3 off the unit circle, the second-order one O(ds³).
  CHECK(iterationsPerPoint(second) < iterationsPerPoint(first));
  const auto folds = second.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 2);
  CHECK(std::abs(folds[0]->lambda - 1.0) < 1e-12);
  CHECK(std::abs(folds[1]->lambda + 1.0) < 1e-12);
}

TEST_CASE("TracerOptions::leanNewton: the same branch and special points, bit for bit, as KINSOL's Newton", "[tracer]") {
  // The opt-in lean corrector reproduces KINSOL's full Newton; a whole branch with folds and
  // branch points must come out identical, point by point and bit by bit.
  auto same = [](const Branch &a, const Branch &b) {
    REQUIRE(a.points.size() == b.points.size());
    for (size_t i = 0; i < a.points.size(); ++i) {
      CHECK(a.points[i].lambda == b.points[i].lambda);
      CHECK(a.points[i].newtonIterations == b.points[i].newtonIterations);
      CHECK((a.points[i].u.array() == b.points[i].u.array()).all());
    }
    REQUIRE(a.specialPoints.size() == b.specialPoints.size());
    for (size_t i = 0; i < a.specialPoints.size(); ++i) {
      CHECK(a.specialPoints[i].type == b.specialPoints[i].type);
      CHECK(a.specialPoints[i].lambda == b.specialPoints[i].lambda);
    }
  };
  TracerOptions options;
  options.maxArclength = 2.0 * M_PI - 0.3;
  toys::Circle circle;
  const Branch kinsol = trace(circle, vec1(1.02), 0.0, InitialDirection::increasingLambda(), options);
  options.corrector.leanNewton = true;
  const Branch lean = trace(circle, vec1(1.02), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(kinsol.specialPointsOfType(SpecialPointType::Fold).size() == 2);
  same(kinsol, lean);

  toys::TwoPitchforks pitchforks(0.5);
  TracerOptions p;
  p.lambdaMin = -3.0;
  p.lambdaMax = 3.0;
  const Vector u0 = Vector::Zero(pitchforks.dimension());
  const Branch k2 = trace(pitchforks, u0, -3.0, InitialDirection::increasingLambda(), p);
  p.corrector.leanNewton = true;
  const Branch l2 = trace(pitchforks, u0, -3.0, InitialDirection::increasingLambda(), p);
  REQUIRE(!k2.specialPointsOfType(SpecialPointType::BranchPoint).empty());
  same(k2, l2);
}

namespace {
/// λ + e²u − u³/3 = 0: folds at u = ±e, λ = ∓2e³/3, a distance ≈ 2e apart along a branch that is
/// nearly perpendicular to λ there (λ' = e² − u² is small): the tangents at the ends of a step
/// over both folds are almost equal, so neither the turning angle nor the sign of t_λ sees them.
class CloseFolds : public Problem {
 public:
  explicit CloseFolds(double e) : e_(e) {}
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = lambda + e_ * e_ * u[0] - u[0] * u[0] * u[0] / 3.0;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu(0, 0) = e_ * e_ - u[0] * u[0];
    Fl[0] = 1.0;
    return true;
  }

 private:
  double e_;
};

// Every setting of the step control: the rule, the predictor, the growth factor, the largest
// step (0.1, 0.2, 0.3, 1, 1.5 divide the distance 3 from the start to the first branch point of
// the pitchforks below: whole steps land on it to rounding).
template <class Check>
void forEveryStepSetting(Check check) {
  for (const auto rule : {StepOptions::Rule::Curvature, StepOptions::Rule::NewtonCount})
    for (const bool secondOrder : {false, true})
      for (const double growth : {1.5, 3.0})
        for (const double maxStep : {0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0}) {
          TracerOptions options;
          options.step.rule = rule;
          options.step.foldPairGuard = true;
          options.step.secondOrderPredictor = secondOrder;
          options.step.stepGrowth = growth;
          options.step.maxStep = maxStep;
          options.step.initialStep = std::min(0.1, maxStep);
          check(options);
        }
}
}  // namespace

TEST_CASE("No step jumps over two close folds undetected, at any step setting", "[tracer]") {
  const double e = 0.05, fold = 2.0 * e * e * e / 3.0;
  CloseFolds problem(e);
  const double u0 = -2.0, lambda0 = -e * e * u0 + u0 * u0 * u0 / 3.0;
  int stepsOverBoth = 0;
  forEveryStepSetting([&](TracerOptions options) {
    options.lambdaMax = -lambda0;
    const Branch branch = trace(problem, vec1(u0), lambda0, InitialDirection::increasingLambda(), options);
    CHECK(branch.stopReason == StopReason::LambdaRange);
    const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
    REQUIRE(folds.size() == 2);
    CHECK(std::abs(folds[0]->lambda - fold) <= 1e-12);
    CHECK(std::abs(folds[1]->lambda + fold) <= 1e-12);
    // The same settings without the guard: a step may well span both folds and see neither.
    options.step.foldPairGuard = false;
    const Branch blind = trace(problem, vec1(u0), lambda0, InitialDirection::increasingLambda(), options);
    if (blind.specialPointsOfType(SpecialPointType::Fold).empty()) ++stepsOverBoth;
  });
  CHECK(stepsOverBoth > 0);  // the guard is what finds them there
}

// Exactly the two branch points, at their closed-form λ (0 and c), each once.
void checkTwoBranchPoints(const Branch &branch, double c, double tolerance) {
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  std::ostringstream found;
  for (const SpecialPoint *bp : bps)
    found << "\n  branch point at " << bp->lambda << " after point " << bp->index << (bp->refined ? " (refined) " : " ")
          << bp->note;
  INFO("found:" << found.str());
  REQUIRE(bps.size() == 2);
  CHECK(std::abs(bps[0]->lambda) <= tolerance);
  CHECK(std::abs(bps[1]->lambda - c) <= tolerance);
  CHECK(bps[0]->multiplicity == 1);
  CHECK(bps[1]->multiplicity == 1);
}

TEST_CASE("No step jumps over two close branch points undetected, at any step setting", "[tracer]") {
  // Before, steps landing on λ = 0 to rounding (maxStep 0.1, 0.2, 0.3, 1, 1.5 from λ = −3) reported
  // the first branch point twice: the step ending there from the determinant's sign change, the
  // next from the inertia, the crossing eigenvalue being in the count's zero band at the shared
  // point (classifyInterval). c = 0.5 as well: there the two points are in different steps.
  for (const double c : {1e-3, 0.5}) {
    toys::TwoPitchforks problem(c);
    forEveryStepSetting([&](TracerOptions options) {
      options.lambdaMax = 3.0;
      const Branch branch = trace(problem, Vector::Zero(2), -3.0, InitialDirection::increasingLambda(), options);
      INFO("c " << c << " rule " << int(options.step.rule) << " P2 " << options.step.secondOrderPredictor << " growth "
                << options.step.stepGrowth << " maxStep " << options.step.maxStep);
      CHECK(branch.stopReason == StopReason::LambdaRange);
      checkTwoBranchPoints(branch, c, 1e-12);
    });
  }
  // The same on a curved trivial branch (F_λ ≠ 0), where the steps follow its curvature.
  toys::CurvedPitchforks curved(1e-3);
  forEveryStepSetting([&](TracerOptions options) {
    options.lambdaMax = 2.0;
    const Vector u0 = toys::CurvedPitchforks::shift(-2.0);
    const Branch branch = trace(curved, u0, -2.0, InitialDirection::increasingLambda(), options);
    INFO("rule " << int(options.step.rule) << " P2 " << options.step.secondOrderPredictor << " growth " << options.step.stepGrowth
                 << " maxStep " << options.step.maxStep);
    checkTwoBranchPoints(branch, 1e-3, 1e-11);
  });
}

TEST_CASE("onLocated tells of every special point as it is located, in the problem's units", "[tracer]") {
  // TwoPitchforks with λ scaled by 1e3 inside the tracer: the callback must convert back
  const double c = 1e-3;
  for (bool scaled : {false, true}) {
    INFO("scaled " << scaled);
    toys::TwoPitchforks plain(c);
    toys::ScaledTwoPitchforks big(c);
    Problem &problem = scaled ? static_cast<Problem &>(big) : plain;
    TracerOptions options;
    options.lambdaMax = 3.0;
    options.step.maxStep = 2.0;  // one step over both branch points
    std::vector<double> located;
    std::vector<SpecialPointType> types;
    int steps = 0;
    options.onLocated = [&](const SpecialPoint &sp) {
      located.push_back(sp.lambda);
      types.push_back(sp.type);
    };
    options.onStep = [&](const StepInfo &) {
      ++steps;
      return StepAction::Continue;
    };
    const Branch branch = trace(problem, Vector::Zero(2), -3.0, InitialDirection::increasingLambda(), options);
    const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
    REQUIRE(bps.size() == 2);
    // every branch point of the branch was announced, with its λ to the last bit and its type
    for (const SpecialPoint *bp : bps) {
      const auto it = std::find(located.begin(), located.end(), bp->lambda);
      CHECK(it != located.end());
      if (it != located.end()) CHECK(types[size_t(it - located.begin())] == SpecialPointType::BranchPoint);
    }
    CHECK(located.size() >= bps.size());
    CHECK(steps > 0);
  }
}

TEST_CASE("Curvature step control: tighter tolerances take the same steps, not more", "[tracer]") {
  // The Newton count rule shrinks the steps when the tolerance asks for more iterations; the
  // contraction does not depend on the tolerance.
  toys::Circle circle;
  auto pointsAt = [&](StepOptions::Rule rule, double tolerance) {
    TracerOptions options;
    options.step.rule = rule;
    options.step.maxStep = 1.0;
    options.step.minTangentCosine = 0.5;
    options.step.targetAngle = 0.3;
    options.corrector.tolerance = tolerance;
    options.maxArclength = 2.0 * M_PI - 0.3;
    const Branch b = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), options);
    for (const ContinuationPoint &p : b.points) CHECK(std::abs(p.u[0] * p.u[0] + p.lambda * p.lambda - 1.0) < 10 * tolerance);
    CHECK(b.specialPointsOfType(SpecialPointType::Fold).size() == 2);
    return b.points.size();
  };
  const auto curvatureLoose = pointsAt(StepOptions::Rule::Curvature, 1e-6);
  const auto curvatureTight = pointsAt(StepOptions::Rule::Curvature, 1e-13);
  const auto countLoose = pointsAt(StepOptions::Rule::NewtonCount, 1e-6);
  const auto countTight = pointsAt(StepOptions::Rule::NewtonCount, 1e-13);
  CHECK(curvatureTight <= curvatureLoose + 2);
  CHECK(countTight > countLoose + 2);
  // The circle turns by 1 rad per unit arclength: about 2π/0.3 ≈ 20 steps at the target angle,
  // and ≈ 8 more while the first step 0.01 grows to 0.3 by factors of 1.5.
  CHECK(curvatureTight <= 35);
}

TEST_CASE("Consecutive tangents respect the branch-jump guard", "[tracer]") {
  toys::Circle circle;
  TracerOptions options;
  options.step.initialStep = 0.4;
  options.step.maxStep = 0.8;  // 0.8 rad turns per step would violate cos ≥ 0.9
  options.maxPoints = 40;
  const Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(branch.points.size() == 40);
  CHECK(branch.stopReason == StopReason::MaxPoints);
  for (std::size_t i = 1; i < branch.points.size(); ++i)
    CHECK(branch.points[i].tangent.dot(branch.points[i - 1].tangent) >= options.step.minTangentCosine);
}

TEST_CASE("Parameter range end is landed on exactly", "[tracer]") {
  toys::Circle circle;
  TracerOptions options;
  options.step.initialStep = 0.03;
  options.lambdaMax = 0.5;
  const Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  const ContinuationPoint &last = branch.points.back();
  CHECK(std::abs(last.lambda - 0.5) <= 1e-15);
  CHECK(std::abs(last.u[0] - std::sqrt(0.75)) < 1e-12);
  const SpecialPoint &ep = branch.specialPoints.back();
  CHECK(ep.type == SpecialPointType::Endpoint);
  CHECK(std::string(label(ep.type)) == "EP");
  CHECK(ep.boundaryName == "lambda max");
  CHECK(ep.index == static_cast<int>(branch.points.size()) - 1);
  for (const ContinuationPoint &p : branch.points) CHECK(p.lambda <= 0.5);

  SECTION("decreasing direction stops on lambdaMin") {
    TracerOptions down = options;
    down.lambdaMin = -0.25;
    const Branch other = trace(circle, vec1(1.0), 0.0, InitialDirection::decreasingLambda(), down);
    CHECK(other.direction == -1);
    CHECK(other.points[1].lambda < 0.0);
    CHECK(other.stopReason == StopReason::LambdaRange);
    CHECK(std::abs(other.points.back().lambda + 0.25) <= 1e-15);
  }
}

TEST_CASE("Boundary g = 0.5 - u is located exactly", "[tracer]") {
  toys::LineWithDomain line(std::numeric_limits<double>::infinity(), true);
  TracerOptions options;
  options.step.initialStep = 0.07;
  options.step.maxStep = 0.07;
  const Branch branch = trace(line, vec1(0.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::Boundary);
  const SpecialPoint &bd = branch.specialPoints.back();
  CHECK(bd.type == SpecialPointType::Boundary);
  CHECK(std::string(label(bd.type)) == "BD");
  CHECK(bd.boundaryName == "u limit");
  CHECK(std::abs(bd.lambda - 0.5) < 1e-12);
  CHECK(std::abs(branch.points.back().u[0] - 0.5) < 1e-12);
  CHECK(std::abs(bd.testFunctionValue) < 1e-12);
  CHECK(bd.lambdaAccuracy < 1e-12);
}

TEST_CASE("Box on (u, lambda) stops on its face", "[tracer]") {
  toys::Circle circle;
  TracerOptions options;
  const double inf = std::numeric_limits<double>::infinity();
  options.boxLower = (Vector(2) << 0.5, -inf).finished();
  options.boxUpper = (Vector(2) << inf, inf).finished();
  const Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::Box);
  CHECK(branch.points.back().u[0] == 0.5);
  CHECK(std::abs(branch.points.back().lambda - std::sqrt(0.75)) < 1e-12);
  CHECK(branch.specialPoints.back().boundaryName == "box lower u[0]");

  TracerOptions wrongSize;
  wrongSize.boxLower = Vector::Constant(5, -1.0);
  wrongSize.boxUpper = Vector::Constant(5, 1.0);
  const Branch rejected = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), wrongSize);
  CHECK(rejected.stopReason == StopReason::InvalidOptions);
  CHECK_THAT(rejected.stopMessage, Contains("boxLower"));
}

TEST_CASE("A refused domain stops with the KINSOL flag and keeps the points", "[tracer]") {
  toys::LineWithDomain line(0.3);
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.05;
  options.step.minStep = 1e-6;
  const Branch branch = trace(line, vec1(0.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(branch.stopReason == StopReason::StepSizeTooSmall);
  CHECK_THAT(branch.stopMessage, Contains("step size below minimum after KIN_FIRST_SYSFUNC_ERR"));
  REQUIRE(branch.points.size() >= 6);
  for (const ContinuationPoint &p : branch.points) CHECK(p.u[0] <= 0.3);
  CHECK(branch.points.back().u[0] > 0.3 - 1e-5);
}

TEST_CASE("Start point that cannot be polished is reported", "[tracer]") {
  toys::Circle circle;
  const Branch branch = trace(circle, vec1(0.5), 1.5, InitialDirection::increasingLambda());
  CHECK(branch.stopReason == StopReason::StartFailed);
  CHECK_THAT(branch.stopMessage, Contains("KIN_"));
  CHECK(branch.points.empty());
}

TEST_CASE("Stability is recorded at every point when asked", "[tracer]") {
  toys::CubicFold cubic;
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  // u = 2.5: λ = −u + u³/3 > 0; decreasing λ goes down the stable outer branch (H = u² − 1 > 0).
  const double u0 = 2.5, lambda0 = -u0 + u0 * u0 * u0 / 3.0;
  const Branch branch = trace(cubic, vec1(u0), lambda0, InitialDirection::decreasingLambda(), options);
  REQUIRE(branch.points.size() > 10);
  for (const ContinuationPoint &p : branch.points) {
    REQUIRE(p.stability.valid());
    CHECK(p.stability.negative == (p.u[0] * p.u[0] < 1.0 ? 1 : 0));
  }
  options.detection.stability = false;
  const Branch without = trace(cubic, vec1(u0), lambda0, InitialDirection::decreasingLambda(), options);
  REQUIRE(without.points.size() > 2);
  for (const ContinuationPoint &p : without.points) CHECK_FALSE(p.stability.valid());
}

TEST_CASE("Step size grows on an easy branch and is clamped to maxStep", "[tracer]") {
  toys::LineWithDomain line;
  TracerOptions options;
  options.step.initialStep = 0.001;
  options.step.maxStep = 0.2;
  options.maxPoints = 40;
  const Branch branch = trace(line, vec1(0.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(branch.points.size() == 40);
  CHECK(branch.points[1].stepSize == Approx(0.001));
  CHECK(branch.points.back().stepSize == Approx(0.2));
  for (const ContinuationPoint &p : branch.points) CHECK(p.stepSize <= 0.2 + 1e-15);
}

TEST_CASE("Per-point cost on a 50-unknown Bratu problem", "[.][timing]") {
  toys::Bratu bratu(50);
  TracerOptions options;
  options.maxPoints = 200;
  options.step.maxStep = 0.5;
  options.step.initialStep = 0.05;
  const auto t0 = std::chrono::steady_clock::now();
  const Branch branch = trace(bratu, Vector::Zero(50), 0.0, InitialDirection::increasingLambda(), options);
  const auto t1 = std::chrono::steady_clock::now();
  const double us = std::chrono::duration<double, std::micro>(t1 - t0).count();
  std::cout << "Bratu N=50: " << branch.points.size() << " points, " << us / branch.points.size()
            << " us/point (stability on), stop: " << branch.stopMessage << "\n";
  options.detection.stability = false;
  options.detection.branchPoints = false;
  options.detection.folds = false;
  const auto t2 = std::chrono::steady_clock::now();
  const Branch plain = trace(bratu, Vector::Zero(50), 0.0, InitialDirection::increasingLambda(), options);
  const auto t3 = std::chrono::steady_clock::now();
  const double us2 = std::chrono::duration<double, std::micro>(t3 - t2).count();
  std::cout << "Bratu N=50: " << plain.points.size() << " points, " << us2 / plain.points.size()
            << " us/point (no stability, no detection)\n";
  CHECK(branch.points.size() > 10);
}

TEST_CASE("A Tracer (one KINSOL instance) can be reused for many runs", "[tracer]") {
  toys::CubicFold cubic;
  TracerOptions options;
  options.lambdaMin = -3.0;
  options.lambdaMax = 3.0;
  Tracer tracer(cubic, options);
  const double u0 = -2.5, lambda0 = -u0 + u0 * u0 * u0 / 3.0;
  const Branch first = tracer.trace(vec1(u0), lambda0, InitialDirection::increasingLambda());
  for (int k = 0; k < 5; ++k) {
    const Branch again = tracer.trace(vec1(u0), lambda0, InitialDirection::increasingLambda());
    REQUIRE(again.points.size() == first.points.size());
    REQUIRE(again.specialPoints.size() == first.specialPoints.size());
    for (std::size_t i = 0; i < first.points.size(); ++i) CHECK(again.points[i].lambda == first.points[i].lambda);
  }
}

TEST_CASE("Starting on a branch point along a chosen kernel direction", "[tracer]") {
  toys::TwoPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMax = 0.3;
  // ker F_x at the origin is span(e_u1, e_λ); e_u1 picks the bifurcated branch u1² = λ.
  const Vector direction = (Vector(3) << 1.0, 0.0, 0.0).finished();
  const Branch branch = trace(problem, Vector::Zero(2), 0.0, InitialDirection::along(direction), options);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  REQUIRE(branch.points.size() > 5);
  CHECK_THAT(branch.specialPoints.front().note, Contains("2-dimensional kernel"));
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
  for (std::size_t i = 1; i < branch.points.size(); ++i) {
    const ContinuationPoint &p = branch.points[i];
    CHECK(p.u[0] > 0.0);
    CHECK(std::abs(p.u[0]) * std::abs(p.u[0] * p.u[0] - p.lambda) <= 1e-10);
  }
  // Without a direction the start on the branch point is refused, not guessed.
  const Branch refused = trace(problem, Vector::Zero(2), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(refused.stopReason == StopReason::StartFailed);
}

TEST_CASE("Tiny steps: the fold of the cubic is still found to 1e-12, in scaled units too", "[tracer]") {
  // The fold test's resolution (classifyInterval: a turning of λ below the rounding of the
  // equations' λ terms is not reported) must not lose real folds at small steps: steps of 1e−6 of
  // the problem's scale across the fold of λ/P + u/L − (u/L)³/3 = 0 at u = −L, λ = 2P/3, in units
  // L = P = 1 and L = 1e−3, P = 1e3 (declared as the problem's scales).
  class UnitCubic : public Problem {
   public:
    UnitCubic(double L, double P) : L_(L), P_(P) {}
    int dimension() const override { return 1; }
    bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
      const double v = u[0] / L_;
      F[0] = lambda / P_ + v - v * v * v / 3.0;
      return true;
    }
    bool jacobian(ProblemWorkspace &, ConstVectorRef u, double, MatrixRef Fu, VectorRef Fl) const override {
      const double v = u[0] / L_;
      Fu(0, 0) = (1.0 - v * v) / L_;
      Fl[0] = 1.0 / P_;
      return true;
    }
    bool hasStabilityOperator() const override { return true; }
    bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
      return toys::negatedJacobian(*this, ws, u, lambda, H, C);
    }
    ProblemScales scales() const override {
      ProblemScales s = ProblemScales::ones(1);
      s.unknowns << L_;
      s.parameter = P_;
      s.stability = 1.0 / L_;
      return s;
    }

   private:
    double L_, P_;
  };
  for (const double L : {1.0, 1e-3}) {
    const double P = 1.0 / L;
    INFO("L " << L << " P " << P);
    UnitCubic problem(L, P);
    TracerOptions options;
    options.step.initialStep = options.step.maxStep = 1e-6;
    options.step.minStep = 1e-9;
    options.maxPoints = 400;
    const double v0 = -1.0 - 1e-4;  // 100 steps before the fold
    const double lambda0 = P * (-v0 + v0 * v0 * v0 / 3.0);
    const Branch branch =
        trace(problem, vec1(L * v0), lambda0, InitialDirection::along((Vector(2) << 1.0, 0.0).finished()), options);
    REQUIRE(branch.points.size() == 400);
    REQUIRE(branch.points.back().u[0] > L * (-1.0 + 1e-4));  // across the fold
    const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
    REQUIRE(folds.size() == 1);
    CHECK(std::abs(folds[0]->lambda - 2.0 * P / 3.0) <= 1e-12 * P);
    CHECK(std::abs(folds[0]->u[0] + L) <= 1e-6 * L);
    CHECK(folds[0]->refined);
  }
}

namespace {

// Bitwise equality of two branches' points and special points (the pause must change nothing).
void requireSameBranch(const Branch &a, const Branch &b) {
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    INFO("point " << i);
    const ContinuationPoint &p = a.points[i], &q = b.points[i];
    CHECK(p.u == q.u);
    CHECK(p.lambda == q.lambda);
    CHECK(p.tangent == q.tangent);
    CHECK(p.arclength == q.arclength);
    CHECK(p.stepSize == q.stepSize);
    CHECK(p.stability.negative == q.stability.negative);
  }
  REQUIRE(a.specialPoints.size() == b.specialPoints.size());
  for (std::size_t k = 0; k < a.specialPoints.size(); ++k) {
    INFO("special point " << k);
    CHECK(a.specialPoints[k].type == b.specialPoints[k].type);
    CHECK(a.specialPoints[k].lambda == b.specialPoints[k].lambda);
    CHECK(a.specialPoints[k].u == b.specialPoints[k].u);
    CHECK(a.specialPoints[k].index == b.specialPoints[k].index);
  }
}

}  // namespace

TEST_CASE("A branch paused at each branch point and continued is the branch traced whole, bit for bit", "[tracer]") {
  toys::ManyPitchforks problem(6, 0.1);  // branch points at λ = 0, 0.1, …, 0.5
  TracerOptions options;
  options.lambdaMax = 0.75;
  options.step.maxStep = 0.05;
  Tracer whole(problem, options);
  const Branch reference = whole.trace(Vector::Zero(6), -0.2, InitialDirection::increasingLambda());
  REQUIRE(reference.stopReason == StopReason::LambdaRange);
  REQUIRE(reference.specialPointsOfType(SpecialPointType::BranchPoint).size() == 6);

  Tracer tracer(problem, options);
  tracer.pauseAtBranchPoints(true);
  Branch branch = tracer.trace(Vector::Zero(6), -0.2, InitialDirection::increasingLambda());
  int pauses = 0;
  while (branch.stopReason == StopReason::Paused) {
    ++pauses;
    // paused right after the step that located the next branch point, with the step to take next
    CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).size() == std::size_t(pauses));
    CHECK(branch.specialPoints.back().type == SpecialPointType::BranchPoint);
    CHECK(branch.resumeStep > 0.0);
    tracer.continueBranch(branch);
  }
  CHECK(pauses == 6);
  CHECK(branch.stopReason == StopReason::LambdaRange);
  requireSameBranch(branch, reference);
}

TEST_CASE("A paused branch ended where it stands is interrupted there, with its endpoint", "[tracer]") {
  toys::ManyPitchforks problem(3, 0.1);
  TracerOptions options;
  options.lambdaMax = 0.5;
  options.step.maxStep = 0.05;
  Tracer tracer(problem, options);
  tracer.pauseAtBranchPoints(true);
  Branch branch = tracer.trace(Vector::Zero(3), -0.2, InitialDirection::increasingLambda());
  REQUIRE(branch.stopReason == StopReason::Paused);
  const std::size_t points = branch.points.size();
  Tracer::endPaused(branch, "time limit");
  CHECK(branch.stopReason == StopReason::Interrupted);
  CHECK(branch.stopMessage == "time limit");
  CHECK(branch.points.size() == points);
  REQUIRE(branch.specialPoints.back().type == SpecialPointType::Endpoint);
  CHECK(branch.specialPoints.back().boundaryName == "interrupted");
  CHECK(branch.specialPoints.back().lambda == branch.points.back().lambda);
  CHECK(branch.specialPoints.back().lambda < 0.1);  // only the first branch point (λ = 0) was reached
  // only a paused branch is ended so
  Tracer::endPaused(branch, "again");
  CHECK(branch.stopMessage == "time limit");
}

TEST_CASE("A paused trace steps over at most kPausedCrossings branch points at a time", "[tracer]") {
  // 40 branch points 0.001 apart: the first step of 0.02 alone would cross 20 of them
  toys::ManyPitchforks problem(40, 0.001);
  TracerOptions options;
  options.lambdaMax = 0.05;
  options.step.initialStep = 0.02;
  options.step.maxStep = 0.05;
  Tracer tracer(problem, options);
  tracer.pauseAtBranchPoints(true);
  Branch branch = tracer.trace(Vector::Zero(40), -0.0005, InitialDirection::increasingLambda());
  std::size_t before = 0;
  int pauses = 0;
  while (branch.stopReason == StopReason::Paused) {
    ++pauses;
    const std::size_t found = branch.specialPointsOfType(SpecialPointType::BranchPoint).size();
    CHECK(found > before);
    CHECK(found - before <= std::size_t(Tracer::kPausedCrossings));
    before = found;
    tracer.continueBranch(branch);
  }
  CHECK(branch.stopReason == StopReason::LambdaRange);
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).size() == 40);  // each once
  CHECK(pauses >= 5);
}
