#include "buckle/continuation/step_control.h"

#include "buckle/continuation/internal/finite.h"

#include <algorithm>
#include <cmath>

namespace buckle::continuation {

std::string StepOptions::validate(const std::string &prefix) const {
  if (!(initialStep > 0.0) || !finite(initialStep)) return prefix + "initialStep must be positive and finite";
  if (!(minStep > 0.0) || !finite(minStep)) return prefix + "minStep must be positive and finite";
  if (!(maxStep > 0.0) || !finite(maxStep)) return prefix + "maxStep must be positive and finite";
  if (minStep > maxStep) return prefix + "minStep must not exceed maxStep";
  if (initialStep < minStep || initialStep > maxStep) return prefix + "initialStep must lie in [minStep, maxStep]";
  if (targetNewtonIterations < 1) return prefix + "targetNewtonIterations must be at least 1";
  if (!(stepGrowth >= 1.0) || !finite(stepGrowth)) return prefix + "stepGrowth must be finite and >= 1";
  if (!(stepShrink > 0.0 && stepShrink <= 1.0)) return prefix + "stepShrink must lie in (0, 1]";
  if (!(slowContraction > 0.0) || !finite(slowContraction)) return prefix + "slowContraction must be positive";
  if (!(targetContraction > 0.0 && targetContraction < 1.0)) return prefix + "targetContraction must lie in (0, 1)";
  if (!(targetAngle > 0.0) || !finite(targetAngle)) return prefix + "targetAngle must be positive and finite";
  if (!(minTangentCosine > -1.0 && minTangentCosine <= 1.0)) return prefix + "minTangentCosine must lie in (-1, 1]";
  return {};
}

bool StepOptions::IsValid(std::string *why) const { return reportValidity(validate(), why); }

double StepOptions::next(double ds, const StepObservation &step) const {
  if (rule == Rule::NewtonCount) return next(ds, step.newtonIterations, step.contraction);
  double factor = stepGrowth;
  // Θ ∝ ds^(p+1) (step_control.h): the step that would have contracted at the target.
  if (step.contraction > 0.0)
    factor = std::min(factor, std::pow(targetContraction / step.contraction, 1.0 / (step.predictorOrder + 1)));
  // α ∝ ds: the step that would have turned by the target angle.
  if (step.turningAngle > 0.0) factor = std::min(factor, targetAngle / step.turningAngle);
  factor = std::max(stepShrink, factor);
  return std::min(maxStep, std::max(minStep, ds * factor));
}

double StepOptions::next(double ds, int newtonIterations, double contraction) const {
  // One iteration means the predictor was already on the branch: grow as much as allowed.
  double factor = newtonIterations <= 1 ? stepGrowth : static_cast<double>(targetNewtonIterations) / newtonIterations;
  factor = std::min(stepGrowth, std::max(stepShrink, factor));
  if (contraction > slowContraction) factor = std::min(factor, 0.7);
  return std::min(maxStep, std::max(minStep, ds * factor));
}

bool StepOptions::halve(double &ds) const {
  ds *= 0.5;
  return !(ds < minStep);
}

}  // namespace buckle::continuation

namespace buckle::continuation {

bool foldPairInside(double lambdaA, double slopeA, double lambdaB, double slopeB, double h, double dip) {
  if (!(slopeA * slopeB > 0.0) || !(h > 0.0)) return false;
  const double sign = slopeA > 0.0 ? 1.0 : -1.0;
  // Derivative of the cubic Hermite interpolant in σ = s/h ∈ [0, 1]:
  //   λ'(σ) = (6σ − 6σ²)·D + (3σ² − 4σ + 1)·m_a + (3σ² − 2σ)·m_b,  D = (λ_b − λ_a)/h,
  // a quadratic Aσ² + Bσ + m_a with its ends m_a, m_b of the same sign: it changes sign (twice)
  // only through an interior extremum on the other side of zero.
  const double D = (lambdaB - lambdaA) / h;
  const double A = 3.0 * (slopeA + slopeB) - 6.0 * D;
  const double B = 6.0 * D - 4.0 * slopeA - 2.0 * slopeB;
  // Also the secant alone: λ moving against both end slopes is a fold pair whatever the cubic.
  if (sign * D < -dip) return true;
  if (!(sign * A > 0.0)) return false;  // the extremum is a maximum of sign·λ': no dip
  const double sigma = -B / (2.0 * A);
  if (!(sigma > 0.0 && sigma < 1.0)) return false;
  return sign * ((A * sigma + B) * sigma + slopeA) < -dip;
}

}  // namespace buckle::continuation
