#include "scene/point_sample.h"

#include <climits>
#include <utility>

namespace buckle::scene {

size_t sampleBytes(const mechanics::PointReport& p) {
  const auto values =
      size_t(p.q.size() + p.omega.size() + p.inputs.size() + p.wallForces.size() + p.selfForces.size());
  return sizeof(mechanics::PointReport) + sizeof(double) * values;
}

namespace {

// Drops the points of `pts` from `from` on that the stride does not keep; a run of points of one
// branch keeps its ends and the points on either side of a change of stability.
void thin(std::vector<mechanics::PointReport>& pts, size_t from, size_t stride, size_t& bytes) {
  size_t out = from;
  int prevBranch = INT_MIN;
  bool prevStable = false;
  for (size_t i = from; i < pts.size(); ++i) {
    const mechanics::PointReport& p = pts[i];
    const bool first = i == from || p.branch != prevBranch;
    const bool last = i + 1 == pts.size() || pts[i + 1].branch != p.branch;
    const bool change = (!first && prevStable != p.stable) || (!last && pts[i + 1].stable != p.stable);
    const bool keep = first || last || change || size_t(p.index) % stride == 0;
    prevBranch = p.branch;
    prevStable = p.stable;
    if (!keep) {
      bytes -= sampleBytes(p);
      continue;
    }
    if (out != i) pts[out] = std::move(pts[i]);
    ++out;
  }
  pts.resize(out);
}

}  // namespace

void keepSample(std::vector<mechanics::PointReport>& kept, std::vector<mechanics::PointReport>&& branch,
                size_t& stride, size_t& bytes, size_t budget) {
  const size_t from = kept.size();
  for (mechanics::PointReport& p : branch) {
    bytes += sampleBytes(p);
    kept.push_back(std::move(p));
  }
  thin(kept, from, stride, bytes);
  while (bytes > budget) {
    const size_t before = kept.size();
    stride *= 2;
    thin(kept, 0, stride, bytes);
    if (kept.size() == before) break;  // the ends and the changes of stability only
  }
}

}  // namespace buckle::scene
