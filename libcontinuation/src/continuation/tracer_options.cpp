#include "buckle/continuation/tracer_options.h"

#include "buckle/continuation/internal/finite.h"
#include "buckle/continuation/options_validity.h"

#include <cmath>

namespace buckle::continuation {

std::string LocationOptions::validate(const std::string &prefix) const {
  if (!(tolerance > 0.0) || !finite(tolerance)) return prefix + "tolerance must be positive and finite";
  if (!(coarseTolerance > 0.0) || !finite(coarseTolerance)) return prefix + "coarseTolerance must be positive and finite";
  if (!(newtonTolerance > 0.0) || !finite(newtonTolerance)) return prefix + "newtonTolerance must be positive and finite";
  if (maxIterations < 1) return prefix + "maxIterations must be at least 1";
  if (maxRefinementIterations < 1) return prefix + "maxRefinementIterations must be at least 1";
  if (!(separationFraction > 0.0 && separationFraction < 1.0)) return prefix + "separationFraction must lie in (0, 1)";
  if (maxDenseDimension < 1) return prefix + "maxDenseDimension must be at least 1";
  return {};
}

bool LocationOptions::IsValid(std::string *why) const { return reportValidity(validate(), why); }

std::string DetectionOptions::validate(const std::string &prefix) const {
  if (lowestEigenvalues < 0) return prefix + "lowestEigenvalues must be >= 0";
  if (!(touchTolerance > 0.0) || !finite(touchTolerance)) return prefix + "touchTolerance must be positive and finite";
  return {};
}

bool DetectionOptions::IsValid(std::string *why) const { return reportValidity(validate(), why); }

std::string TracerOptions::validate(const std::string &prefix) const {
  const std::string &p = prefix;
  for (const std::string &group : {step.validate(p + "step."), corrector.validate(p + "corrector."),
                                   location.validate(p + "location."), detection.validate(p + "detection.")})
    if (!group.empty()) return group;
  if (maxPoints < 2) return p + "maxPoints must be at least 2";
  if (std::isnan(lambdaMin) || std::isnan(lambdaMax)) return p + "lambdaMin/lambdaMax must not be NaN";
  if (!(lambdaMin < lambdaMax)) return p + "lambdaMin must be smaller than lambdaMax";
  if (!(maxArclength > 0.0)) return p + "maxArclength must be positive";
  if (boxLower.size() != boxUpper.size()) return p + "boxLower and boxUpper must have the same size";
  for (Eigen::Index i = 0; i < boxLower.size(); ++i)
    if (std::isnan(boxLower[i]) || std::isnan(boxUpper[i]) || !(boxLower[i] < boxUpper[i]))
      return p + "boxLower[" + std::to_string(i) + "] must be smaller than boxUpper[" + std::to_string(i) + "]";
  if (structuredFromDimension < 1) return p + "structuredFromDimension must be at least 1";
  return {};
}

bool TracerOptions::IsValid(std::string *why) const { return reportValidity(validate(), why); }

}  // namespace buckle::continuation
