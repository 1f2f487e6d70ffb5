// A task path (issue 29; mechanics/task_path_trace.h) as the continuation stage of a case: the
// library's points and special points as the records the writers read.
#include <algorithm>
#include <memory>

#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/task_path_trace.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

namespace {

// The label of a task path's special point (docs/outputs.md): why the path cannot go on stably.
const char* typeOf(mech::TaskPathEvent e) {
  switch (e) {
    case mech::TaskPathEvent::Fold: return "LP";
    case mech::TaskPathEvent::BranchPoint: return "BP";
    case mech::TaskPathEvent::StabilityLoss: return "LS";
    case mech::TaskPathEvent::JointLimit: return "BD";
    case mech::TaskPathEvent::InputBound: return "IB";
    default: return "EP";
  }
}

const char* stabilityOf(const mech::TaskPathPoint& p) {
  return p.stable ? "stable" : (p.inertia.negative > 0 ? "unstable" : "critical");
}

}  // namespace

void CaseRunner::taskPath() {
  const mech::TaskSetup& setup = spec_.path.taskSetup;
  auto names = std::make_shared<std::vector<std::string>>();
  for (const mech::TaskInput& in : setup.inputs) names->push_back(mech::taskInputName(in));
  mech::TaskPathResult r;
  try {
    mech::TaskPathProblem problem(out_.chain, setup);
    mech::TaskPathOptions opt;
    opt.tracer = solverOptions();
    opt.stiffness = scene_.analyses.stiffness;
    r = mech::traceTaskPath(problem, out_.qStart, spec_.path.waypoints, out_.chain.length(), opt);
  } catch (const std::exception& e) {
    r.end = mech::TaskPathEvent::Failed;
    r.message = e.what();
  }
  const auto toPoint = [&](const mech::TaskPathPoint& p, int index) {
    PointRecord rec;
    rec.branch = 0;
    rec.index = index;
    rec.parameter = p.s;
    rec.F = setup.payload;
    rec.pose = p.pose;
    rec.q = p.q;
    rec.stable = p.stable;
    rec.negative = p.inertia.negative;
    rec.minEigenvalue = p.minEigenvalue;
    rec.haveStiffness = scene_.analyses.stiffness;
    rec.K = p.K;
    rec.C = p.C;
    rec.inputs = p.inputs;
    rec.inputNames = names;
    return rec;
  };
  for (size_t i = 0; i < r.points.size(); ++i) out_.points.push_back(toPoint(r.points[i], int(i)));
  for (const mech::TaskPathSpecial& sp : r.specials) {
    SpecialRecord s;
    s.type = typeOf(sp.event);
    s.field = "task path";
    s.branch = 0;
    s.parameter = sp.point.s;
    s.F = setup.payload;
    s.pose = sp.point.pose;
    s.q = sp.point.q;
    s.shape = mech::shapeName(sp.point.q);
    // stability at fixed inputs on the path before the point, and at the point itself
    s.stabilityBefore = r.points.size() > 1 ? stabilityOf(r.points[r.points.size() - 2]) : stabilityOf(sp.point);
    s.stabilityAfter = sp.event == mech::TaskPathEvent::StabilityLoss ? "unstable" : stabilityOf(sp.point);
    s.accuracy = sp.accuracy;
    s.K = sp.point.K;
    s.refined = true;
    s.note = sp.why;
    s.inputs = sp.point.inputs;
    s.inputNames = names;
    out_.specials.push_back(s);
    run_.worstLocation = std::max(run_.worstLocation, sp.accuracy);
  }
  run_.worstResidual = std::max(run_.worstResidual, r.worstResidual);
  BranchRecord b;
  b.id = 0;
  b.origin = "start (task path)";
  b.stopReason = mech::toString(r.end);
  b.stopMessage = r.message;
  b.points = int(r.points.size());
  b.finished = r.end != mech::TaskPathEvent::Failed && r.end != mech::TaskPathEvent::Interrupted &&
               r.end != mech::TaskPathEvent::MaxPoints;
  out_.branches.push_back(b);
  if (r.end == mech::TaskPathEvent::MaxPoints) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": the task path stopped at /solver/max_points: " + r.message);
  }
  if (r.end == mech::TaskPathEvent::Failed) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": the task path could not be followed: " +
                            solverFailureInWords(r.message));
  }
  interrupted();
}

}  // namespace buckle::scene
