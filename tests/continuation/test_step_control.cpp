#include "buckle/continuation/step_control.h"

#include <catch2/catch.hpp>
#include <cmath>

using namespace buckle::continuation;

namespace {
StepOptions control() {
  StepOptions c;
  c.minStep = 1e-6;
  c.maxStep = 1.0;
  c.targetNewtonIterations = 4;
  c.stepGrowth = 2.0;
  c.stepShrink = 0.25;
  c.slowContraction = 0.3;
  return c;
}
}  // namespace

TEST_CASE("Next step scales by target/iterations within [stepShrink, stepGrowth]", "[step_control]") {
  const StepOptions c = control();
  CHECK(c.next(0.1, 4, 0.0) == 0.1);          // on target: unchanged
  CHECK(c.next(0.1, 2, 0.0) == 0.1 * 2.0);    // 4/2 = 2 = stepGrowth
  CHECK(c.next(0.1, 1, 0.0) == 0.1 * 2.0);    // one iteration: the full growth
  CHECK(c.next(0.1, 5, 0.0) == 0.1 * 0.8);    // 4/5
  CHECK(c.next(0.1, 10, 0.0) == 0.1 * 0.4);   // 4/10
  CHECK(c.next(0.1, 40, 0.0) == 0.1 * 0.25);  // 4/40 clamped to stepShrink
}

TEST_CASE("Slow Newton contraction caps the next step's factor at 0.7", "[step_control]") {
  const StepOptions c = control();
  CHECK(c.next(0.1, 1, 0.5) == 0.1 * 0.7);
  CHECK(c.next(0.1, 1, 0.3) == 0.1 * 2.0);    // at the threshold: not slow
  CHECK(c.next(0.1, 10, 0.5) == 0.1 * 0.4);   // already below 0.7
}

TEST_CASE("Steps stay in [minStep, maxStep], halving below minStep reports failure", "[step_control]") {
  const StepOptions c = control();
  CHECK(c.next(0.8, 1, 0.0) == 1.0);
  CHECK(c.next(2e-6, 40, 0.0) == 1e-6);
  double ds = 4e-6;
  CHECK(c.halve(ds));
  CHECK(ds == 2e-6);
  CHECK(c.halve(ds));
  CHECK(ds == 1e-6);  // equal to minStep is still allowed
  CHECK_FALSE(c.halve(ds));
  CHECK(ds == 5e-7);
}

TEST_CASE("Curvature rule: the next step aims at the target contraction and turning angle", "[step_control]") {
  StepOptions c = control();
  c.rule = StepOptions::Rule::Curvature;
  c.targetContraction = 0.2;
  c.targetAngle = 0.2;
  StepObservation s;
  s.newtonIterations = 3;
  // Θ ∝ ds² for the Euler predictor: four times the target contraction halves the step.
  s.contraction = 0.8;
  CHECK(c.next(0.1, s) == Approx(0.1 * 0.5).epsilon(1e-15));
  // Θ ∝ ds³ for the second-order predictor.
  s.predictorOrder = 2;
  CHECK(c.next(0.1, s) == Approx(0.1 * std::cbrt(0.25)).epsilon(1e-15));
  // Independent of the iteration count (a tighter tolerance needs more iterations from the same start).
  s.newtonIterations = 7;
  CHECK(c.next(0.1, s) == Approx(0.1 * std::cbrt(0.25)).epsilon(1e-15));
  // The tangent turned by twice the target angle: half the step, whatever Newton said.
  s.contraction = 1e-3;
  s.turningAngle = 0.4;
  CHECK(c.next(0.1, s) == Approx(0.05).epsilon(1e-15));
  // Neither limits: the full growth; one iteration (no contraction) and a straight branch.
  s.turningAngle = 0.0;
  s.contraction = 0.0;
  s.newtonIterations = 1;
  CHECK(c.next(0.1, s) == 0.1 * 2.0);
  // Clamped to [stepShrink, stepGrowth] and to [minStep, maxStep].
  s.contraction = 50.0;
  CHECK(c.next(0.1, s) == 0.1 * 0.25);
  s.contraction = 0.0;
  CHECK(c.next(0.8, s) == 1.0);
}

TEST_CASE("NewtonCount rule through the observation is the iteration-count rule", "[step_control]") {
  StepOptions c = control();
  c.rule = StepOptions::Rule::NewtonCount;
  StepObservation s;
  s.newtonIterations = 5;
  s.turningAngle = 1.0;  // ignored by this rule
  CHECK(c.next(0.1, s) == c.next(0.1, 5, 0.0));
  s.contraction = 0.5;
  CHECK(c.next(0.1, s) == c.next(0.1, 5, 0.5));
}

TEST_CASE("foldPairInside sees two folds of lambda(s) inside a step, and only then", "[step_control]") {
  // λ(s) = (s − ½)³ − e(s − ½) on [0, 1]: λ' = 3(s − ½)² − e is 0.75 − e at both ends and −e at
  // the middle; the cubic is its own Hermite interpolant.
  auto lambda = [](double s, double e) { return std::pow(s - 0.5, 3) - e * (s - 0.5); };
  auto slope = [](double s, double e) { return 3.0 * (s - 0.5) * (s - 0.5) - e; };
  for (double e : {0.5, 0.01, 1e-4}) {
    CHECK(foldPairInside(lambda(0, e), slope(0, e), lambda(1, e), slope(1, e), 1.0));
    // The same mirrored (λ decreasing at both ends) and over a step of another length.
    CHECK(foldPairInside(-lambda(0, e), -slope(0, e), -lambda(1, e), -slope(1, e), 1.0));
    CHECK(foldPairInside(3.0 * lambda(0, e), slope(0, e), 3.0 * lambda(1, e), slope(1, e), 3.0));
  }
  // No fold inside (e < 0: λ' > 0 throughout), a dip that stays above zero.
  CHECK_FALSE(foldPairInside(lambda(0, -0.01), slope(0, -0.01), lambda(1, -0.01), slope(1, -0.01), 1.0));
  // One fold: the end slopes differ in sign (the fold test's own case), not a pair.
  CHECK_FALSE(foldPairInside(0.0, 1.0, -0.5, -1.0, 1.0));
  // λ constant to rounding along the step: no fold pair from noise.
  CHECK_FALSE(foldPairInside(1.0, 1e-17, 1.0 - 2e-16, 3e-17, 0.5));
  // A dip of −1e-8 is below the default threshold, above a finer one.
  const double e = 1e-8;
  CHECK_FALSE(foldPairInside(lambda(0, e), slope(0, e), lambda(1, e), slope(1, e), 1.0));
  CHECK(foldPairInside(lambda(0, e), slope(0, e), lambda(1, e), slope(1, e), 1.0, 1e-9));
}
