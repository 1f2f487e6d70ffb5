// The start of a control path (issue 29): the payload of /end, and the weight and point loads,
// applied to the unloaded shape.
#include <sstream>

#include "buckle/mechanics/load_history.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

// λ: 0 → 1 applies the payload quasi-statically, as a load history would: the loads grow as
// λ·value, a held coordinate moves from the unloaded pose to its value. Where the loading
// itself snaps, the history jumps (load_history.h) and the path starts from the landing, which
// the summary says (start_note).
bool CaseRunner::actuationStart() {
  const int n = out_.chain.size();
  const mech::EndCondition& end = spec_.end.condition;
  mech::EndCondition ramp = end;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  for (int c = 0; c < 3; ++c) {
    const bool held = end.isHeld(static_cast<mech::EndCoordinate>(c));
    ramp.value[c] = held ? out_.pose0[c] : 0.0;
    direction[c] = end.value[c] - ramp.value[c];
  }
  out_.qStart = out_.q0;
  // the weight and point loads grow with the payload, from none at λ = 0 to /gravity's at λ = 1
  const mech::BodyLoads full = bodyLoads().atParameter(out_.startValue);
  mech::BodyLoads body = full;
  body.gravity.setZero();
  body.gravityRate = full.gravity;
  for (mech::PointLoad& p : body.points) {
    p.rate = p.force;
    p.force.setZero();
  }
  // exactly zero, not Eigen's isZero() (1e-12 absolute: a payload of 3e-13 N would count as none)
  if ((direction.array() == 0.0).all() && !full.active()) return true;  // no payload: the unloaded shape
  mech::EquilibriumOptions held;
  held.wallAsBoundary = tracesWall();  // the payload's history is held at the wall as the path is
  held.selfContactAsBoundary = tracesSelf();
  mech::EquilibriumProblem problem(out_.chain, ramp, direction, held, {}, body);
  mech::LoadHistoryOptions opt;
  opt.tracer = solverOptions();
  opt.jump.integration = integrationOptions(mech::jumpIntegrationDefaults(n));
  opt.jump.wall = tracesWall();
  opt.jump.self = tracesSelf();
  mech::LoadHistoryResult h;
  try {
    h = mech::followLoadHistory(problem, out_.q0, {0.0, 1.0}, opt);
  } catch (const std::exception& e) {
    h.message = e.what();
  }
  if (!h.success || h.segments.empty() || h.segments.back().points.empty()) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": the payload of /end could not be applied to the unloaded "
                            "shape (the start of the control path): " + h.message);
    return false;
  }
  out_.qStart = h.segments.back().points.back().u.head(n);
  if (!h.jumps.empty()) {
    std::ostringstream os;
    os.precision(6);
    os << "the chain snapped while the payload was applied (" << h.jumps.size() << " jump(s), the first at "
       << h.jumps.front().lambda << " of the payload); the path starts from where it came to rest";
    out_.startNote = os.str();
  }
  return true;
}

}  // namespace buckle::scene
