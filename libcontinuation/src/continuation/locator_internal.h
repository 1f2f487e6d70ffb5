// What the locator's files share (locator.cpp: sampling and folds, locator_branch_points.cpp:
// branch points): the bracket's crossing eigenvalue and number formatting for the notes.
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>

#include "buckle/continuation/internal/locator.h"

namespace buckle::continuation::locator_detail {

inline int crossingIndex(const ContinuationPoint &lo, const ContinuationPoint &hi) {
  return std::min(lo.stability.negative, hi.stability.negative);
}

// The eigenvalue with this ascending index is the one that passes through zero inside the
// bracket: with k negative eigenvalues on one side and k+m on the other, μ_k changes sign. From
// the point's recorded eigenvalues where they reach it (a sample records the inertia only,
// Locator::sample), else from the problem's stability() with as many.
inline bool crossingEigenvalue(const BoundProblem &problem, const ContinuationPoint &p, int index, double &value) {
  if (!p.stability.valid() || index < 0) return false;
  if (index < p.stability.lowest.size()) {
    value = p.stability.lowest[index];
    return true;
  }
  StabilityInfo info;
  if (!problem.stability(p.u, p.lambda, index + 1, info) || index >= info.lowest.size()) return false;
  value = info.lowest[index];
  return true;
}

inline std::string format(const char *pattern, double value) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

/// A special point located at the traced point `at` (a root of its test function, or a bracket
/// end when none was found): position, tangent and the test function's value there.
inline void placeAt(SpecialPoint &sp, const ContinuationPoint &at, double testValue) {
  sp.arclength = at.arclength;
  sp.u = at.u;
  sp.lambda = at.lambda;
  sp.tangent = at.tangent;
  sp.testFunctionValue = testValue;
}

}  // namespace buckle::continuation::locator_detail
