// One singularity, one report: a branch point that is also a turning point of the traced branch
// (the tip of a bifurcated branch, reached along it: λ = λc + bξ² turns at ξ = 0, and the branch
// touches the other without crossing it) satisfies the fold system too (F_u is singular there),
// and a landing point within rounding of the tip can flip the count's parity, so a step near it
// may report a fold (whose refinement then fails: the fold system is singular at a branch point)
// beside the branch point. They are one point: the branch point is kept, with the stability before
// the first and after the last, and the fold dropped.
// Likewise a multiple branch point whose crossings rounding split over two adjacent steps (one
// eigenvalue of the cluster a step early, by 1e-15 of λ's scale): the simple point of the first
// step is within rounding of the multiple one, whose verified kernel holds its direction too. One
// point of the larger multiplicity is kept, with the stability before the first and after the last.
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

// Among the new points (from `firstNew`) and those of the step before them (a fold and a branch
// point may fall in adjacent steps when a point lands on the tip): every point that `keeps` absorbs
// one point that is `part` of it and closer than a thousandth of the steps that hold them (scaled
// variables): the kept point takes the stability before the first and after the last, and `note`.
template <class Keeps, class Part>
void absorb(Branch &branch, size_t firstNew, Keeps keeps, Part part, const char *note) {
  std::vector<SpecialPoint> &sps = branch.specialPoints;
  if (firstNew >= sps.size()) return;
  const int newest = sps.back().index;
  size_t from = firstNew;
  while (from > 0 && sps[from - 1].index >= newest - 1) --from;
  for (size_t i = from; i < sps.size(); ++i) {
    if (!keeps(sps[i])) continue;
    for (size_t j = from; j < sps.size(); ++j) {
      const SpecialPoint &other = sps[j];
      if (j == i || other.u.size() != sps[i].u.size() || !part(other, sps[i])) continue;
      const double step = std::max(stepLength(branch, other.index), stepLength(branch, sps[i].index));
      if (!(distance(other, sps[i]) <= 1e-3 * step)) continue;
      SpecialPoint &kept = sps[i];
      if (other.arclength < kept.arclength) kept.inertiaBefore = other.inertiaBefore;
      else kept.inertiaAfter = other.inertiaAfter;
      kept.note += (kept.note.empty() ? "" : "; ") + std::string(note);
      sps.erase(sps.begin() + std::ptrdiff_t(j));
      if (j < i) --i;
      break;
    }
  }
}

}  // namespace

void mergeCoincidentSpecialPoints(Branch &branch, size_t firstNew) {
  auto isBranchPoint = [](const SpecialPoint &p) { return p.type == SpecialPointType::BranchPoint; };
  absorb(
      branch, firstNew, [&](const SpecialPoint &p) { return isBranchPoint(p) && p.multiplicity == 1; },
      [](const SpecialPoint &p, const SpecialPoint &) { return p.type == SpecialPointType::Fold; },
      "the traced branch turns in lambda here (the branch point reached along a bifurcated branch, at its tip): one "
      "point, not also a fold");
  absorb(
      branch, std::min(firstNew, branch.specialPoints.size()),
      [&](const SpecialPoint &p) { return isBranchPoint(p) && p.multiplicity >= 2; },
      [&](const SpecialPoint &p, const SpecialPoint &multiple) {
        return isBranchPoint(p) && p.multiplicity < multiple.multiplicity && std::abs(p.index - multiple.index) <= 1;
      },
      "one crossing of it counted in the adjacent step (within rounding): one point");
}

}  // namespace buckle::continuation
