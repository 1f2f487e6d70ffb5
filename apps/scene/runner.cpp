#include "scene/runner.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "scene/case_runner.h"

// Stage dispatch: which analyses run, in which order, under which time limit; each stage of a
// case is one CaseRunner call (case_runner.h).
namespace buckle::scene {

namespace mech = buckle::mechanics;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

RunResult runScene(const Scene& scene, const RunControl& given) {
  RunResult run;
  const Clock::time_point start = Clock::now();
  RunControl control = given;
  if (!control.interrupt.hasDeadline()) {
    // The limit bounds the whole run, writing the results included: the computation stops a
    // fifth of the limit (at most 1 s) before it, room for writing a long chain's points and
    // plots (a 50-segment tree stopped at 4.5 s writes its 19 000 points in 0.45 s on an idle
    // machine, twice that on a loaded one).
    const double limit = std::min(scene.solver.timeLimit, 1e9);
    const double compute = limit - std::min(0.2 * limit, 1.0);
    control.interrupt.setDeadline(
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(compute)), limit);
  }
  const AnalysesSpec& a = scene.analyses;
  const bool task = std::any_of(scene.cases.begin(), scene.cases.end(), [](const CaseSpec& c) { return c.path.task; });
  if (task)
    run.computed.push_back("task-space path (inverse statics): the inputs that move the end along the path, "
                           "stability at fixed inputs");
  else if (a.continuation.enabled) {
    const bool reaction =
        std::any_of(scene.cases.begin(), scene.cases.end(), [](const CaseSpec& c) { return c.path.throughReaction; });
    const int depth = a.continuation.depth(reaction);
    run.computed.push_back(depth > 0 ? "continuation with branch switching (depth " + std::to_string(depth) + ")"
                                     : "continuation of the primary branch");
  }
  if (a.stiffness) run.computed.push_back("loaded stiffness K_F along the branches (eq 29)");
  if (a.frequencies.enabled)
    run.computed.push_back("the lowest " + std::to_string(a.frequencies.count) +
                           " natural frequencies along the branches (uniform rods, mechanics/vibration.h)");
  if (a.jump.enabled) run.computed.push_back("jumps from the folds (gradient-flow dynamics, landing polished)");
  if (a.loadHistory.enabled)
    run.computed.push_back("quasi-static load history with jumps (hysteresis), " +
                           std::to_string(a.loadHistory.waypoints.size()) + " waypoints");
  if (a.suddenLoad.enabled)
    run.computed.push_back(std::string("sudden load: ") +
                           (a.suddenLoad.massPerLength > 0 ? "inertial dynamics (uniform rods)" : "gradient flow") +
                           ", compared with the quasi-static load history");
  if (a.criticalForces.enabled) run.computed.push_back("critical forces of the start configuration (linear buckling)");
  if (a.twoParameter.enabled)
    run.computed.push_back("critical curves in " + a.twoParameter.parameter + " (two-parameter continuation)");
  if (a.energyCurves.enabled) run.computed.push_back("energy curves E(q1) with the end held (eq 6-8)");
  if (a.torqueAngle.enabled) run.computed.push_back("torque-angle curves M(q) of the first segment (eq 1)");
  if (a.equilibria.enabled) run.computed.push_back("every equilibrium at one state of the controls (deflated Newton)");
  if (a.equilibria.enabled && a.equilibria.branches)
    run.computed.push_back("the branches through the equilibria the continuation does not reach");

  std::vector<std::pair<std::string, std::function<void(CaseRunner&)>>> stages;
  if (a.torqueAngle.enabled) stages.emplace_back("torque_angle", [](CaseRunner& r) { r.torqueAngle(); });
  if (a.criticalForces.enabled) stages.emplace_back("critical_forces", [](CaseRunner& r) { r.criticalForces(); });
  if (a.twoParameter.enabled) stages.emplace_back("two_parameter", [](CaseRunner& r) { r.twoParameter(); });
  if (a.energyCurves.enabled) stages.emplace_back("energy_curves", [](CaseRunner& r) { r.energyCurves(); });
  if (a.equilibria.enabled) stages.emplace_back("equilibria", [](CaseRunner& r) { r.equilibria(); });
  if (a.continuation.enabled) stages.emplace_back("continuation", [](CaseRunner& r) { r.continuation(); });
  if (a.equilibria.enabled && a.equilibria.branches)
    stages.emplace_back("disconnected_branches", [](CaseRunner& r) { r.disconnectedBranches(); });
  if (a.loadHistory.enabled) stages.emplace_back("load_history", [](CaseRunner& r) { r.loadHistory(); });
  if (a.suddenLoad.enabled) stages.emplace_back("sudden_load", [](CaseRunner& r) { r.suddenLoad(); });
  std::vector<double> stageSeconds(stages.size(), 0.0);

  std::vector<std::string> skipped;
  run.cases.reserve(scene.cases.size());
  for (const CaseSpec& spec : scene.cases) {
    mech::Chain chain(spec.chain.segments);
    CaseResult& out = run.cases.emplace_back(chain);
    out.label = spec.label;
    out.q0 = spec.chain.q0;
    out.pose0 = mech::endPose(chain, out.q0);
    out.startValue = spec.startValue();
    out.qStart = out.q0;
    CaseRunner runner(scene, spec, out, run, control);
    // recorded in run.problems
    if ((spec.path.control || spec.path.task) && !runner.actuationStart()) continue;
    for (size_t s = 0; s < stages.size(); ++s) {
      if (runner.interrupted()) {
        skipped.push_back(stages[s].first + (scene.cases.size() > 1 ? " (case \"" + spec.label + "\")" : ""));
        continue;
      }
      if (control.progress)
        control.progress->stage(stages[s].first, spec.label, int(&spec - scene.cases.data()), int(scene.cases.size()));
      const Clock::time_point t0 = Clock::now();
      stages[s].second(runner);
      stageSeconds[s] += secondsSince(t0);
    }
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& k : skipped) list += (list.empty() ? "" : ", ") + k;
    run.problems.push_back("not run after the stop: " + list);
  }
  for (size_t s = 0; s < stages.size(); ++s) run.timings.emplace_back(stages[s].first, stageSeconds[s]);
  run.totalSeconds = secondsSince(start);
  return run;
}

}  // namespace buckle::scene
