#include "buckle/continuation/step_control.h"

#include <algorithm>

namespace buckle::continuation {

double StepSizeControl::next(double ds, int newtonIterations, double contraction) const {
  // One iteration means the predictor was already on the branch: grow as much as allowed.
  double factor = newtonIterations <= 1 ? stepGrowth : static_cast<double>(targetNewtonIterations) / newtonIterations;
  factor = std::min(stepGrowth, std::max(stepShrink, factor));
  if (contraction > slowContraction) factor = std::min(factor, 0.7);
  return std::min(maxStep, std::max(minStep, ds * factor));
}

bool StepSizeControl::halve(double &ds) const {
  ds *= 0.5;
  return !(ds < minStep);
}

}  // namespace buckle::continuation
