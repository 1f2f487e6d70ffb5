// Stopping early: the Interrupt itself, the tracer (per-step check and callback), the locator and
// the branch tree. Every stopped computation must keep what it computed and say why.
#include "buckle/continuation/interrupt.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

namespace {

/// The points of a branch lie on the circle u² + λ² = 1 (the computation stopped, the points
/// kept are still solutions).
void requireOnCircle(const Branch &b) {
  for (const ContinuationPoint &p : b.points) REQUIRE(std::abs(p.u[0] * p.u[0] + p.lambda * p.lambda - 1.0) < 1e-9);
}

/// Counts residual evaluations: a stopped tracer must stop evaluating.
class CountingCircle : public toys::Circle {
 public:
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
    ++evaluations;
    return toys::Circle::residual(ws, u, lambda, F);
  }
  mutable long evaluations = 0;  // a probe of this single-threaded test
};

}  // namespace

TEST_CASE("Interrupt: never, a deadline, a flag, and copies share the flag", "[interrupt]") {
  const Interrupt never;
  CHECK_FALSE(never.requested());
  CHECK(never.describe().empty());
  CHECK(std::isinf(never.secondsLeft()));

  const Interrupt past = Interrupt::after(0.0);
  CHECK(past.requested());
  CHECK(past.reason() == Interrupt::Reason::TimeLimit);
  CHECK_THAT(past.describe(), Contains("time limit of 0 s"));

  const Interrupt future = Interrupt::after(3600.0);
  CHECK_FALSE(future.requested());
  CHECK(future.secondsLeft() > 3500.0);
  CHECK_FALSE(Interrupt::after(std::numeric_limits<double>::infinity()).hasDeadline());
  CHECK_FALSE(Interrupt::after(1e300).requested());  // far-future limits do not overflow

  std::atomic<bool> flag{false};
  Interrupt a;
  a.watch(&flag, "SIGINT received");
  const Interrupt b = a;  // a copy handed to another stage
  CHECK_FALSE(b.requested());
  flag = true;
  CHECK(b.requested());
  CHECK(b.reason() == Interrupt::Reason::Flag);
  CHECK(b.describe() == "SIGINT received");
}

TEST_CASE("Interrupt: time kept before the deadline moves it for every copy, never later again", "[interrupt]") {
  const Interrupt original = Interrupt::after(3600.0);
  const Interrupt copy = original;
  CHECK_FALSE(copy.requested());
  CHECK(copy.secondsLeft() > 3599.0);
  original.keepBeforeDeadline(600.0);
  CHECK(copy.secondsLeft() < 3000.1);
  CHECK(copy.secondsLeft() > 2999.0);
  CHECK_FALSE(copy.requested());
  original.keepBeforeDeadline(10.0);  // less than kept already: no change
  CHECK(copy.secondsLeft() < 3000.1);
  copy.keepBeforeDeadline(3600.0 - 0.001);  // from a copy too: now within a millisecond
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  CHECK(original.requested());
  CHECK(original.reason() == Interrupt::Reason::TimeLimit);
  // a new deadline starts afresh, for itself and its copies only
  Interrupt fresh = copy;
  fresh.setDeadline(Interrupt::Clock::now() + std::chrono::hours(1), 3600.0);
  CHECK_FALSE(fresh.requested());
  CHECK(copy.requested());
  // without a deadline nothing is kept
  const Interrupt never;
  never.keepBeforeDeadline(1.0);
  CHECK_FALSE(never.requested());
}

TEST_CASE("Interrupt: a stop well before the limit says when computing stopped", "[interrupt]") {
  // 3600 s given, 3599.95 s of it kept for writing: computing stops 0.05 s from now
  const Interrupt early = Interrupt::after(3600.0);
  early.keepBeforeDeadline(3599.95);
  CHECK_FALSE(early.requested());
  std::this_thread::sleep_for(std::chrono::milliseconds(80));
  REQUIRE(early.requested());
  const std::string why = early.describe();
  CHECK_THAT(why, Contains("time limit of 3600 s reached (computing stopped at 0.05 s"));
  CHECK_THAT(why, Contains("kept for writing the results"));
  // at the limit itself (nothing kept): the limit alone
  const Interrupt atLimit = Interrupt::after(0.05);
  std::this_thread::sleep_for(std::chrono::milliseconds(80));
  REQUIRE(atLimit.requested());
  CHECK(atLimit.describe() == "time limit of 0.05 s reached");
}

TEST_CASE("Tracer: a requested interrupt stops the branch at once and keeps the start", "[interrupt]") {
  CountingCircle problem;
  TracerOptions options;
  options.interrupt = Interrupt::after(0.0);
  const Branch b = trace(problem, Vector::Constant(1, 1.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(b.stopReason == StopReason::Interrupted);
  CHECK_THAT(b.stopMessage, Contains("time limit"));
  REQUIRE(b.points.size() == 1);  // the polished start, nothing else
  requireOnCircle(b);
  CHECK(b.specialPoints.back().type == SpecialPointType::Endpoint);
  CHECK(b.specialPoints.back().boundaryName == "interrupted");
  CHECK(problem.evaluations < 20);  // the start polish only: no step was tried
}

TEST_CASE("Tracer: a flag set while tracing stops within one step", "[interrupt]") {
  toys::Circle problem;
  std::atomic<bool> flag{false};
  TracerOptions options;
  options.step.maxStep = 0.01;
  options.step.initialStep = 0.01;
  options.maxPoints = 100000;  // the whole circle many times over: only the flag ends it
  options.interrupt.watch(&flag, "stop requested");
  int calls = 0;
  options.onStep = [&](const StepInfo &step) {
    ++calls;
    if (step.pointCount == 20) flag = true;  // as a signal handler would
    return StepAction::Continue;
  };
  const Branch b = trace(problem, Vector::Constant(1, 1.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(b.stopReason == StopReason::Interrupted);
  CHECK(b.stopMessage == "stop requested");
  CHECK(b.points.size() == 20);  // checked before the next step
  CHECK(calls == 19);            // once per accepted point after the start
  requireOnCircle(b);
}

TEST_CASE("Tracer: the step callback sees every point and can stop the branch", "[interrupt]") {
  toys::Circle problem;
  TracerOptions options;
  options.step.maxStep = 0.05;
  std::vector<double> seen;
  options.onStep = [&](const StepInfo &step) {
    seen.push_back(step.point.lambda);
    return step.pointCount >= 7 ? StepAction::Stop : StepAction::Continue;
  };
  const Branch b = trace(problem, Vector::Constant(1, 1.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(b.stopReason == StopReason::Interrupted);
  CHECK_THAT(b.stopMessage, Contains("callback"));
  REQUIRE(b.points.size() == 7);
  REQUIRE(seen.size() == 6);
  for (size_t i = 0; i < seen.size(); ++i) CHECK(seen[i] == b.points[i + 1].lambda);
}

TEST_CASE("Tracer: the step callback's Join ends the branch as a regular end, and the tree goes on", "[interrupt]") {
  // The circle traced once round from (1, 0): the callback joins where the branch is back at its
  // start (within its last step), as deflated continuation closes an isola.
  toys::Circle problem;
  TracerOptions options;
  options.step.maxStep = 0.05;
  options.maxPoints = 10000;
  bool below = false;  // the branch has been at λ < 0 (past half way round)
  options.onStep = [&](const StepInfo &step) {
    const ContinuationPoint &p = step.point;
    below = below || p.lambda < 0.0;
    return below && p.lambda >= 0.0 && p.u[0] > 0.0 ? StepAction::Join : StepAction::Continue;
  };
  const Branch b = trace(problem, Vector::Constant(1, 1.0), 0.0, InitialDirection::increasingLambda(), options);
  REQUIRE(b.stopReason == StopReason::Joined);
  CHECK_THAT(b.stopMessage, Contains("joined"));
  requireOnCircle(b);
  // once round: the last point is past the start by at most a step, the one before short of it
  const ContinuationPoint &last = b.points.back(), &before = b.points[b.points.size() - 2];
  CHECK(last.lambda >= 0.0);
  CHECK(before.lambda < 0.0);
  CHECK(last.arclength > 2.0 * M_PI * 0.9);
  CHECK(last.arclength < 2.0 * M_PI + 0.06);

  // In a tree, a joined branch does not stop the others (an interrupted one would).
  TracerOptions joinAtFive = options, stopAtFive = options;
  joinAtFive.onStep = [](const StepInfo &step) {
    return step.pointCount >= 5 ? StepAction::Join : StepAction::Continue;
  };
  stopAtFive.onStep = [](const StepInfo &step) {
    return step.pointCount >= 5 ? StepAction::Stop : StepAction::Continue;
  };
  const std::vector<InitialDirection> both{InitialDirection::increasingLambda(), InitialDirection::decreasingLambda()};
  const BranchTree joined = traceTree(problem, Vector::Constant(1, 1.0), 0.0, both, joinAtFive, TreeOptions());
  CHECK_FALSE(joined.interrupted);
  REQUIRE(joined.branches.size() == 2);
  for (const Branch &j : joined.branches) CHECK(j.stopReason == StopReason::Joined);
  CHECK(joined.branches[1].points.back().lambda < 0.0);
  const BranchTree stopped = traceTree(problem, Vector::Constant(1, 1.0), 0.0, both, stopAtFive, TreeOptions());
  CHECK(stopped.interrupted);
  CHECK(stopped.branches.size() == 1);
}

TEST_CASE("Tracer: without an interrupt the same branch runs to its regular end", "[interrupt]") {
  // The control for the cases above: the circle traced from (1, 0) up to λ = 0.5.
  toys::Circle problem;
  TracerOptions options;
  options.lambdaMax = 0.5;
  const Branch b = trace(problem, Vector::Constant(1, 1.0), 0.0, InitialDirection::increasingLambda(), options);
  CHECK(b.stopReason == StopReason::LambdaRange);
  CHECK(b.points.back().lambda == Approx(0.5).margin(1e-12));
}

TEST_CASE("traceTree: both start directions, and an interrupt stops the tree with what it has", "[interrupt]") {
  toys::TwoPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMin = -0.3;
  options.lambdaMax = 0.8;
  options.step.maxStep = 0.05;
  TreeOptions treeOptions;
  treeOptions.branchSwitching = 1;
  std::set<int> finished;
  treeOptions.onBranch = [&](const BranchTree &tree, const Branch &b) {
    // a branch as it joins the tree; a root again each time it went on (traced lazily)
    if (finished.insert(b.id).second) {
      CHECK(b.id == static_cast<int>(tree.branches.size()) - 1);
    } else {
      CHECK(b.parentId < 0);
    }
  };
  const std::vector<InitialDirection> both{InitialDirection::increasingLambda(), InitialDirection::decreasingLambda()};
  const BranchTree full = traceTree(problem, Vector::Zero(2), 0.2, both, options, treeOptions);
  // Roots in the order asked: up (through the BP at λ = 0.5) and down (through λ = 0).
  REQUIRE(full.branches.size() == 6);
  CHECK_FALSE(full.interrupted);
  CHECK(finished.size() == 6);
  CHECK(full.branches[0].direction == 1);
  CHECK(full.branches[1].direction == -1);
  CHECK(full.branches[0].points.back().lambda == Approx(0.8));
  CHECK(full.branches[1].points.back().lambda == Approx(-0.3));
  for (size_t i = 2; i < full.branches.size(); ++i) CHECK(full.branches[i].parentId >= 0);

  // Stop after the first root joined (traced up to its branch point at λ = 0.5): the second root
  // and every switch are not traced, the first root ends where it stood, a prefix of the full one.
  std::atomic<bool> flag{false};
  options.interrupt.watch(&flag, "enough");
  treeOptions.onBranch = [&](const BranchTree &, const Branch &) { flag = true; };
  const BranchTree partial = traceTree(problem, Vector::Zero(2), 0.2, both, options, treeOptions);
  REQUIRE(partial.branches.size() == 1);
  CHECK(partial.interrupted);
  CHECK(partial.message == "enough");
  const Branch &root = partial.branches[0];
  CHECK(root.stopReason == StopReason::Interrupted);
  REQUIRE(root.points.size() < full.branches[0].points.size());
  CHECK(root.points.back().lambda > 0.5);  // just past its branch point
  for (size_t i = 0; i < root.points.size(); ++i) CHECK(root.points[i].u == full.branches[0].points[i].u);
}
