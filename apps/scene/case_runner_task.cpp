// A task path (issue 29; mechanics/task_path_trace.h) as the continuation stage of a case: the
// library's report of the path as the case's branch 0.
#include <algorithm>

#include "buckle/mechanics/task_path_trace.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

void CaseRunner::taskPath() {
  mech::TaskSetup setup = spec_.path.taskSetup;
  setup.body = bodyLoads().atParameter(out_.startValue);  // the weight the start was found under
  out_.inputNames.clear();
  for (const mech::TaskInput& in : setup.inputs) out_.inputNames.push_back(mech::taskInputName(in));
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
  mech::BranchReport report = mech::reportTaskPath(r, setup.payload, scene_.analyses.stiffness);
  const size_t points = report.points.size();
  keepPoints(std::move(report.points));
  for (mech::SpecialPointReport& sp : report.specialPoints) {
    run_.worstLocation = std::max(run_.worstLocation, sp.accuracy);
    out_.specials.push_back({std::move(sp), {}});
  }
  run_.worstResidual = std::max(run_.worstResidual, report.worstResidual);
  BranchRecord b;
  b.id = 0;
  b.origin = "start (task path)";
  b.stopReason = report.stopReason;
  b.stopMessage = report.stopMessage;
  b.points = int(points);
  b.finished = report.finished;
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
