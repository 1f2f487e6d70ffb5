#include "buckle/continuation/step_control.h"

#include <catch2/catch.hpp>

using namespace buckle::continuation;

namespace {
StepSizeControl control() {
  StepSizeControl c;
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
  const StepSizeControl c = control();
  CHECK(c.next(0.1, 4, 0.0) == 0.1);          // on target: unchanged
  CHECK(c.next(0.1, 2, 0.0) == 0.1 * 2.0);    // 4/2 = 2 = stepGrowth
  CHECK(c.next(0.1, 1, 0.0) == 0.1 * 2.0);    // one iteration: the full growth
  CHECK(c.next(0.1, 5, 0.0) == 0.1 * 0.8);    // 4/5
  CHECK(c.next(0.1, 10, 0.0) == 0.1 * 0.4);   // 4/10
  CHECK(c.next(0.1, 40, 0.0) == 0.1 * 0.25);  // 4/40 clamped to stepShrink
}

TEST_CASE("Slow Newton contraction caps the next step's factor at 0.7", "[step_control]") {
  const StepSizeControl c = control();
  CHECK(c.next(0.1, 1, 0.5) == 0.1 * 0.7);
  CHECK(c.next(0.1, 1, 0.3) == 0.1 * 2.0);    // at the threshold: not slow
  CHECK(c.next(0.1, 10, 0.5) == 0.1 * 0.4);   // already below 0.7
}

TEST_CASE("Steps stay in [minStep, maxStep]; halving below minStep reports failure", "[step_control]") {
  const StepSizeControl c = control();
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
