#include "scene/analyses.h"

#include <algorithm>

#include "scene/case_runner.h"
#include "scene/scene_parsing.h"

namespace buckle::scene {

namespace {

std::string continuationComputed(const Scene& scene) {
  const auto any = [&scene](bool PathSpec::*flag) {
    return std::any_of(scene.cases.begin(), scene.cases.end(), [flag](const CaseSpec& c) { return c.path.*flag; });
  };
  if (any(&PathSpec::task))
    return "task-space path (inverse statics): the inputs that move the end along the path, stability at fixed inputs";
  const int depth = scene.analyses.continuation.depth(any(&PathSpec::throughReaction));
  return depth > 0 ? "continuation with branch switching (depth " + std::to_string(depth) + ")"
                   : "continuation of the primary branch";
}

}  // namespace

const std::vector<Analysis>& analyses() {
  using S = const Scene&;
  using A = const AnalysesSpec&;
  static const std::vector<Analysis> table = {
      {"torque_angle", detail::parseTorqueAngle, [](A a) { return a.torqueAngle.enabled; },
       [](S) -> std::string { return "torque-angle curves M(q) of the first segment (eq 1)"; }, "torque_angle",
       [](CaseRunner& r) { r.torqueAngle(); }, true},
      {"critical_forces", detail::parseCriticalForces, [](A a) { return a.criticalForces.enabled; },
       [](S) -> std::string { return "critical forces of the start configuration (linear buckling)"; },
       "critical_forces", [](CaseRunner& r) { r.criticalForces(); }, true},
      {"two_parameter", detail::parseTwoParameterBlock, [](A a) { return a.twoParameter.enabled; },
       [](S s) { return "critical curves in " + s.analyses.twoParameter.parameter + " (two-parameter continuation)"; },
       "two_parameter", [](CaseRunner& r) { r.twoParameter(); }, true},
      {"energy_curves", detail::parseEnergyCurves, [](A a) { return a.energyCurves.enabled; },
       [](S) -> std::string { return "energy curves E(q1) with the end held (eq 6-8)"; }, "energy_curves",
       [](CaseRunner& r) { r.energyCurves(); }, true},
      {"equilibria", detail::parseEquilibriaBlock, [](A a) { return a.equilibria.enabled; },
       [](S) -> std::string { return "every equilibrium at one state of the controls (deflated Newton)"; }, "equilibria",
       [](CaseRunner& r) { r.equilibria(); }, true},
      {"continuation", detail::parseContinuation, [](A a) { return a.continuation.enabled; }, continuationComputed,
       "continuation", [](CaseRunner& r) { r.continuation(); }, true},
      {nullptr, nullptr, [](A a) { return a.equilibria.enabled && a.equilibria.branches; },
       [](S) -> std::string { return "the branches through the equilibria the continuation does not reach"; },
       "disconnected_branches", [](CaseRunner& r) { r.disconnectedBranches(); }, false},
      {"workspace", detail::parseWorkspace, [](A a) { return a.workspace.enabled; },
       [](S s) {
         return "workspace and stability maps over " + s.analyses.workspace.options.first.input.name() + " and " +
                s.analyses.workspace.options.second.input.name() + " under the payload, bounding curves traced";
       },
       "workspace", [](CaseRunner& r) { r.workspaceMap(); }, true, true},
      {"load_history", detail::parseLoadHistory, [](A a) { return a.loadHistory.enabled; },
       [](S s) {
         return "quasi-static load history with jumps (hysteresis), " +
                std::to_string(s.analyses.loadHistory.waypoints.size()) + " waypoints";
       },
       "load_history", [](CaseRunner& r) { r.loadHistory(); }, true},
      {"sudden_load", detail::parseSuddenLoad, [](A a) { return a.suddenLoad.enabled; },
       [](S s) {
         return std::string("sudden load: ") +
                (s.analyses.suddenLoad.massPerLength > 0 ? "inertial dynamics (uniform rods)" : "gradient flow") +
                ", compared with the quasi-static load history";
       },
       "sudden_load", [](CaseRunner& r) { r.suddenLoad(); }, true},
      {"stiffness", detail::parseStiffness, [](A a) { return a.stiffness; },
       [](S) -> std::string { return "loaded stiffness K_F along the branches (eq 29)"; }, nullptr, nullptr, false},
      {"frequencies", detail::parseFrequenciesBlock, [](A a) { return a.frequencies.enabled; },
       [](S s) {
         return "the lowest " + std::to_string(s.analyses.frequencies.count) +
                " natural frequencies along the branches (uniform rods, mechanics/vibration.h)";
       },
       nullptr, nullptr, false},
      {"jump", detail::parseJump, [](A a) { return a.jump.enabled; },
       [](S) -> std::string { return "jumps from the folds (gradient-flow dynamics, landing polished)"; }, "jump",
       [](CaseRunner& r) { r.jumps(); }, false},
  };
  return table;
}

}  // namespace buckle::scene
