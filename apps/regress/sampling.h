// Branch samples that do not depend on the step sizes the tracer happened to take: a branch is
// read at a given value of its path parameter λ (the k-th time it crosses that value), with
// cubic interpolation in λ between the neighbouring points, plus an estimate of the
// interpolation error that sets the sample's tolerance.
#pragma once

#include <vector>

#include "regress/measurement.h"

namespace buckle::regress {

/// Where to read a branch: λ and which crossing of that value along the branch (0: first).
struct SampleSite {
  double lambda = 0.0;
  int crossing = 0;
};

/// Up to `count` sites spread along the branch (about 1/4, 1/2, 3/4 of its points), each in
/// the middle of a stretch where λ is strictly monotone over four consecutive points, so the
/// value is well defined and the cubic is accurate. None on branches of fewer than 5 points.
std::vector<SampleSite> chooseSites(const MeasuredBranch& branch, int count);

struct SampleValue {
  bool found = false;
  std::vector<double> values;  ///< one per requested coordinate
  double errorEstimate = 0.0;  ///< max |cubic − quadratic| over the coordinates
};

/// Reads joint angles `coordinates` (0-based) of the branch at the site.
SampleValue sampleAt(const MeasuredBranch& branch, const SampleSite& site, const std::vector<int>& coordinates);

}  // namespace buckle::regress
