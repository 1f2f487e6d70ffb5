// One singularity, one report: a branch point that is also a turning point of the traced branch
// (the tip of a bifurcated branch, reached along it: λ = λc + bξ² turns at ξ = 0, and the branch
// touches the other without crossing it) satisfies the fold system too (F_u is singular there),
// and a landing point within rounding of the tip can flip the count's parity, so a step near it
// may report a fold (whose refinement then fails: the fold system is singular at a branch point)
// beside the branch point. They are one point: the branch point is kept, with the stability before
// the first and after the last, and the fold dropped.
#include "buckle/continuation/tracer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace buckle::continuation {

namespace {

// Length of the step [points[i], points[i+1]] (0 past the last point).
double stepLength(const Branch &branch, int index) {
  if (index < 0 || size_t(index) + 1 >= branch.points.size()) return 0.0;
  return branch.points[size_t(index) + 1].arclength - branch.points[size_t(index)].arclength;
}

double distance(const SpecialPoint &p, const SpecialPoint &q) {
  return std::sqrt((p.u - q.u).squaredNorm() + (p.lambda - q.lambda) * (p.lambda - q.lambda));
}

}  // namespace

void mergeCoincidentSpecialPoints(Branch &branch, size_t firstNew) {
  std::vector<SpecialPoint> &sps = branch.specialPoints;
  if (firstNew >= sps.size()) return;
  // the new points and those of the step before them: a fold and a branch point may fall in
  // adjacent steps when a point lands on the tip
  const int newest = sps.back().index;
  size_t from = firstNew;
  while (from > 0 && sps[from - 1].index >= newest - 1) --from;
  for (size_t i = from; i < sps.size(); ++i) {
    if (sps[i].type != SpecialPointType::BranchPoint || sps[i].multiplicity != 1) continue;
    for (size_t j = from; j < sps.size(); ++j) {
      const SpecialPoint &fold = sps[j];
      if (fold.type != SpecialPointType::Fold || fold.u.size() != sps[i].u.size()) continue;
      // the same point: closer than a thousandth of the steps that hold them (scaled variables)
      const double step = std::max(stepLength(branch, fold.index), stepLength(branch, sps[i].index));
      if (!(distance(fold, sps[i]) <= 1e-3 * step)) continue;
      SpecialPoint &bp = sps[i];
      const bool foldFirst = fold.arclength < bp.arclength;
      if (foldFirst) bp.inertiaBefore = fold.inertiaBefore;
      else bp.inertiaAfter = fold.inertiaAfter;
      bp.note += (bp.note.empty() ? "" : "; ") +
                 std::string("the traced branch turns in lambda here (the branch point reached along a bifurcated "
                             "branch, at its tip): one point, not also a fold");
      sps.erase(sps.begin() + std::ptrdiff_t(j));
      if (j < i) --i;
      break;
    }
  }
}

}  // namespace buckle::continuation
