// Step-size adaptation of the pseudo-arclength tracer (tracer.h).
//
// After an accepted step the next one is scaled by target/iterations of the corrector's Newton
// count (AUTO-07p's rule), clamped to [stepShrink, stepGrowth], and at most 0.7 when Newton
// contracted slowly (a sign that the predictor was far off); after a failed step the step is
// halved. Steps stay in [minStep, maxStep]; all of them are dimensionless arclengths in the
// tracer's scaled variables.
#pragma once

namespace buckle::continuation {

struct StepSizeControl {
  double minStep = 1e-8;
  double maxStep = 0.1;
  int targetNewtonIterations = 3;
  double stepGrowth = 1.5;
  double stepShrink = 0.5;
  double slowContraction = 0.3;  ///< Newton contraction above this caps the next factor at 0.7

  /// The step after an accepted step of size ds whose corrector took `newtonIterations`
  /// iterations with the given contraction rate.
  double next(double ds, int newtonIterations, double contraction) const;
  /// After a failed step: halves ds; false once it is below minStep (the branch must stop).
  bool halve(double &ds) const;
};

}  // namespace buckle::continuation
