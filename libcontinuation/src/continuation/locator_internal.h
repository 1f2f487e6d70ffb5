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
// bracket: with k negative eigenvalues on one side and k+m on the other, μ_k changes sign.
inline bool crossingEigenvalue(const ContinuationPoint &p, int index, double &value) {
  if (!p.stability.valid() || index < 0 || index >= p.stability.lowest.size()) return false;
  value = p.stability.lowest[index];
  return true;
}

// The crossing eigenvalue's index may exceed what the tracer recorded (it may record the inertia
// only): recompute the stability of a bracket end with enough eigenvalues.
inline void ensureEigenvalues(const BoundProblem &problem, ContinuationPoint &p, int count) {
  if (!p.stability.valid() || p.stability.lowest.size() >= count) return;
  StabilityInfo info;
  if (problem.stability(p.u, p.lambda, count, info)) p.stability = info;
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
