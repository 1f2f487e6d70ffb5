// The tree's size ahead (docs/scenes.md, "Progress"): the branch points the tree has found and
// not yet switched at, shown with the progress line; and the warning at the start when the path
// crosses hundreds of critical loads, each a branch point the tree would switch at; and the warning
// when the start shape already overlaps itself.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "buckle/mechanics/contact_geometry.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace cont = buckle::continuation;
namespace mech = buckle::mechanics;

namespace {

/// Above this many predicted branch points a tree is worth a warning before it is traced.
constexpr int kManyBranchPoints = 100;

}  // namespace

void CaseRunner::branchAdded(const cont::Branch& b, int maxDepth) {
  if (b.id < 0) return;
  const size_t id = size_t(b.id);
  const bool again = id < ahead_.paused.size() && ahead_.paused[id];  // a paused root traced further
  if (id == 0 && !again) ahead_ = TreeAhead();  // a new tree
  if (ahead_.depth.size() <= id) {
    ahead_.depth.resize(id + 1, 0);
    ahead_.found.resize(id + 1, 0);
    ahead_.settled.resize(id + 1, 0);
    ahead_.paused.resize(id + 1, 0);
  }
  ahead_.paused[id] = b.stopReason == cont::StopReason::Paused;
  const bool child = b.parentId >= 0 && size_t(b.parentId) < id;
  ahead_.depth[id] = child ? ahead_.depth[size_t(b.parentId)] + 1 : 0;
  if (ahead_.depth[id] < maxDepth) {
    // the simple and multiple branch points past the branch's start (a child's first one is its parent's)
    const double s0 = b.points.empty() ? 0.0 : b.points.front().arclength;
    int found = 0;
    for (const cont::SpecialPoint& sp : b.specialPoints)
      if (sp.type == cont::SpecialPointType::BranchPoint && (!child || sp.arclength > s0)) ++found;
    if (const int first = scene_.analyses.continuation.branchPoints; first > 0) found = std::min(found, first);
    ahead_.queued += found - ahead_.found[id];  // the branch points found since it was last reported
    ahead_.found[id] = found;
  }
  // a child is the first of its branch point's (its other side comes next): one more switched at
  if (child && (id == 0 || b.parentId != tracedParent_.first || b.parentSpecialPoint != tracedParent_.second)) {
    const size_t parent = size_t(b.parentId);
    if (ahead_.settled[parent] < ahead_.found[parent]) {
      ++ahead_.settled[parent];
      --ahead_.queued;
    }
  }
  tracedParent_ = {b.parentId, b.parentSpecialPoint};
}

void CaseRunner::branchSettled(int id) {
  if (id < 0 || size_t(id) >= ahead_.found.size()) return;
  // final: every branch point on it was switched at, found switched already, or left
  ahead_.queued -= ahead_.found[size_t(id)] - ahead_.settled[size_t(id)];
  ahead_.settled[size_t(id)] = ahead_.found[size_t(id)];
}

void CaseRunner::warnOfLargeTree(const mech::CriticalLoading& loading, const std::vector<double>& ends, int depth) {
  if (loading.direction.isZero()) return;
  int predicted = 0;
  try {
    for (double end : ends) predicted += mech::criticalLoadCount(out_.chain, out_.q0, loading, end);
  } catch (const std::exception&) {
    return;  // only an estimate: the tracer says what is wrong with the start, if anything
  }
  const int first = scene_.analyses.continuation.branchPoints;
  if (predicted <= kManyBranchPoints || (first > 0 && first <= kManyBranchPoints)) return;
  std::ostringstream os;
  os << "case \"" << spec_.label << "\": the path crosses " << predicted
     << " critical loads of the unloaded shape (linear buckling), and the continuation switches at every "
        "branch point it meets (branch_switching "
     << depth << "): " << predicted
     << " branches or more to trace. Give /analyses/continuation/branch_points (switch at the first k on each "
        "branch), a shorter path range or --time-limit; under a limit the weakest branch points are switched "
        "first";
  run_.warnings.push_back(os.str());
  if (control_.progress) control_.progress->warn(os.str());
}

void CaseRunner::warnOfOverlappingStart() {
  const mech::SelfClearance c = mech::selfClearance(out_.chain, out_.qStart.head(out_.chain.size()));
  if (!(c.distance < -mech::kTouchingBand * out_.chain.length())) return;
  std::ostringstream os;
  os.precision(6);
  os << "case \"" << spec_.label << "\": the start shape overlaps itself: the bodies of links " << c.linkA << " and "
     << c.linkB << " (0: the clamped base link) overlap by " << -c.distance << scene_.units.suffix(Dimension::Length)
     << " near (" << c.point.x() << ", " << c.point.y()
     << "); self contact is detected, not enforced, so the chain passes through itself there until they separate (SC)";
  run_.warnings.push_back(os.str());
  if (control_.progress) control_.progress->warn(os.str());
}

}  // namespace buckle::scene
