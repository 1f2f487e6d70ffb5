// Displacement control traced through the held coordinate's reaction (PathSpec::throughReaction,
// mechanics/reaction_path.h): the load limit, as given or derived from the critical reactions,
// and the check that the end moved at all.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "buckle/mechanics/reaction_path.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

double CaseRunner::reactionLoadLimit() {
  const int c = spec_.path.coordinate;
  const std::string unit = scene_.units.suffix(c < 2 ? Dimension::Force : Dimension::Moment);
  // the limit covers the critical reactions of the branch points the tree switches at
  const int modes = std::max(1, scene_.analyses.continuation.branchPoints);
  out_.loadLimit = spec_.path.loadLimit;
  out_.loadLimitDerived = !(spec_.path.loadLimit > 0.0);
  try {
    const mech::ReactionLimit rl = mech::reactionLimit(out_.chain, out_.qStart, spec_.end.condition, c, modes);
    out_.firstCriticalReaction = rl.firstCritical;
    if (out_.loadLimitDerived) out_.loadLimit = rl.limit;
  } catch (const std::exception& e) {
    if (!out_.loadLimitDerived) return out_.loadLimit;  // the scene's limit stands; nothing to check it by
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": displacement control of " + kEndCoordinateNames[c] +
                            " from a start that cannot move it to first order is traced through the reaction " +
                            kEndLoadNames[c] + ", up to a load limit that could not be derived: " + e.what() +
                            "; give /path/load_limit, the largest |" + kEndLoadNames[c] + "| to trace" + unit);
    return 0.0;
  }
  return out_.loadLimit;
}

// After the continuation: the held coordinate moved on some reported point, or the run says why
// not (a load limit below the first critical reaction, or no branch switching).
void CaseRunner::checkHeldCoordinateMoved(size_t firstPoint) {
  const int c = spec_.path.coordinate;
  const double start = out_.pose0[c];
  const double width = std::abs(spec_.path.to - spec_.path.from);
  double moved = 0.0;
  for (size_t i = firstPoint; i < out_.points.size(); ++i)
    moved = std::max(moved, std::abs(out_.points[i].pose[c] - start));
  // a displacement of 1e-9 of the requested range is rounding of the straight chain's pose
  if (moved > 1e-9 * width) return;
  const std::string unit = scene_.units.suffix(c < 2 ? Dimension::Force : Dimension::Moment);
  std::ostringstream os;
  os.precision(10);
  os << "case \"" << spec_.label << "\": the end never moved along " << kEndCoordinateNames[c] << " (every equilibrium found has "
     << kEndCoordinateNames[c] << " = " << start << "): the chain carried the reaction " << kEndLoadNames[c]
     << " without buckling up to the load limit " << out_.loadLimit << unit << (out_.loadLimitDerived ? " (derived)" : "")
     << ". ";
  if (std::isfinite(out_.firstCriticalReaction) && out_.loadLimit < std::abs(out_.firstCriticalReaction))
    os << "It buckles, and " << kEndCoordinateNames[c] << " can move, only at the critical reaction "
       << out_.firstCriticalReaction << unit << ": raise /path/load_limit above " << std::abs(out_.firstCriticalReaction)
       << ", or leave it out to have it derived from the critical reactions";
  else if (scene_.analyses.continuation.depth(true) == 0)
    os << "The branches that move the end leave the straight one at its branch points: set "
          "/analyses/continuation/branch_switching to 1 or more (the default on such a path)";
  else
    os << "No branch point was switched at within the load limit: check /analyses/continuation and the path range";
  run_.complete = false;
  run_.problems.push_back(os.str());
}

}  // namespace buckle::scene
