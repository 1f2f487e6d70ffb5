// Zeros of a scalar test function along a traced curve: codimension-two points on a fold or
// branch-point curve (a cusp, a degenerate pitchfork, a branch point at zero load, a joint
// limit), where the test function changes sign between two accepted points.
//
// Each sign change is located on the curve itself: the Illinois iteration (root_finding.h) on the
// position σ ∈ [0, 1] along the chord between the two points, every sample corrected back onto
// the curve by Keller's system with the chord as its normal (corrector.h), in the curve problem's
// scaled variables (scaled_problem.h). So it works where the curve turns in μ (a cusp is such a
// turning point), and its accuracy is a distance along the curve in the scaled variables.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/tracer_options.h"

#include <functional>
#include <string>
#include <vector>

namespace buckle::continuation {

/// g at a point (u, λ) of the curve problem (user units). False: not evaluable there.
using CurveTest = std::function<bool(ConstVectorRef u, double lambda, double &g)>;

struct CurveZero {
  int index = 0;            ///< between points[index] and points[index + 1] of the branch
  Vector u;                 ///< the located point (user units)
  double lambda = 0.0;
  double value = 0.0;       ///< g there
  double accuracy = 0.0;    ///< last bracket width along the chord, in the scaled variables
  int iterations = 0;
  bool converged = false;
};

struct CurveZeroOptions {
  double tolerance = 1e-12;  ///< bracket width along the chord (scaled variables)
  int maxIterations = 80;    ///< of the Illinois iteration
  /// The corrector of each sample (its tolerance bounds ‖G̃‖∞ of the scaled Keller system).
  CorrectorOptions corrector = [] {
    CorrectorOptions tight;
    tight.tolerance = 1e-13;
    tight.maxIterations = 20;
    return tight;
  }();

  /// Empty when valid, else what is wrong, the field named by its path.
  std::string validate(const std::string &prefix = "") const {
    return firstProblem({requirePositive(prefix, "tolerance", tolerance),
                         require(maxIterations >= 1, prefix, "maxIterations", "must be at least 1"),
                         corrector.validate(prefix + "corrector.")});
  }
  bool IsValid(std::string *why) const { return reportValidity(validate(), why); }
};

/// Every sign change of g between consecutive points of `branch` (traced on `curve`), located.
/// Intervals where g is not evaluable at an end are skipped. Throws std::invalid_argument on
/// invalid options.
std::vector<CurveZero> locateCurveZeros(const BoundProblem &curve, const Branch &branch, const CurveTest &g,
                                        const CurveZeroOptions &options = CurveZeroOptions());

}  // namespace buckle::continuation
