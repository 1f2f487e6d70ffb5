// /path with a "task" (issue 29; mechanics/task_path.h): the end pose on chosen coordinates
// follows straight legs through waypoints under /end's payload, chosen control inputs are the
// unknowns, and a rule resolves the redundancy.
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

namespace {

// One point of the task path: as many numbers as task coordinates.
Eigen::VectorXd taskPoint(const JsonReader& r, const json& v, const Pointer& p, const std::vector<int>& coordinates) {
  const size_t m = coordinates.size();
  std::string names;
  for (int c : coordinates) names += std::string(names.empty() ? "" : ", ") + kEndCoordinateNames[c];
  if (!v.is_array() || v.size() != m)
    r.expected(p, v, "an array of " + std::to_string(m) + " number(s): " + names + " (the task coordinates)");
  Eigen::VectorXd out(static_cast<Eigen::Index>(m));
  for (size_t k = 0; k < m; ++k) out[Eigen::Index(k)] = r.number(v[k], p / k);
  return out;
}

mechanics::TaskInput parseInput(const JsonReader& r, const json& v, const Pointer& p, const mechanics::Chain& chain,
                                bool minChange) {
  mechanics::TaskInput in;
  const auto inputName = [&](const json& s, const Pointer& ps) {
    const std::string name = r.string(s, ps);
    if (!mechanics::parseControlInput(name, in.input)) r.expected(ps, s, "one of L1_0, L2_0, L0, dL0");
  };
  if (v.is_string()) {
    inputName(v, p);
    return in;
  }
  r.requireObject(v, p);
  r.onlyKeys(v, p, {"input", "segment", "weight", "min", "max"});
  inputName(r.required(v, p, "input"), p / "input");
  if (v.contains("segment")) in.segment = r.integer(v["segment"], p / "segment", 1, chain.size()) - 1;
  if (v.contains("weight")) {
    if (!minChange)
      r.fail(p / "weight", "a weight only applies to the rules \"min_change\" and \"most_stable\"; remove this key");
    in.weight = r.positive(v["weight"], p / "weight");
  }
  if (v.contains("min")) in.lower = r.number(v["min"], p / "min");
  if (v.contains("max")) in.upper = r.number(v["max"], p / "max");
  if (!(in.lower < in.upper)) r.fail(p / "max", "expected a value above /min (" + show(in.lower) + ")");
  const double start = mechanics::controlInputValue(chain, in.input, in.segment);
  if (!(start >= in.lower && start <= in.upper)) {
    std::ostringstream os;
    os << "expected bounds that contain the input's start value " << mechanics::taskInputName(in) << " = "
       << show(start) << " (set by /chain), got [" << show(in.lower) << ", " << show(in.upper) << "]";
    r.fail(p / (start < in.lower ? "min" : "max"), os.str());
  }
  return in;
}
}  // namespace

bool isTaskPath(const json& path) { return path.is_object() && path.contains("task"); }

PathSpec parseTaskPath(const JsonReader& r, const json& path, const Pointer& p, const mechanics::Chain& chain,
                       const EndSpec& end) {
  r.onlyKeys(path, p, {"task", "inputs", "rule"});
  for (int c = 0; c < 3; ++c)
    if (end.condition.isHeld(static_cast<mechanics::EndCoordinate>(c)))
      r.fail(Pointer("/end") / kEndCoordinateNames[c],
             "a task path moves the end by its inputs under a payload: /end/" + std::string(kEndCoordinateNames[c]) +
                 " must be a load, not held");
  PathSpec spec;
  spec.task = true;
  spec.parameter = "s";
  mechanics::TaskSetup& setup = spec.taskSetup;
  setup.payload = end.condition.value;
  const Pointer pt = p / "task";
  const json& task = path["task"];
  r.requireObject(task, pt);
  r.onlyKeys(task, pt, {"coordinates", "from", "to", "waypoints"});
  const json& coords = r.required(task, pt, "coordinates");
  if (!coords.is_array() || coords.empty() || coords.size() > 3)
    r.expected(pt / "coordinates", coords, "an array of 1 to 3 of \"x\", \"y\", \"phi\" in that order");
  for (size_t k = 0; k < coords.size(); ++k) {
    const std::string name = r.string(coords[k], pt / "coordinates" / k);
    const int c = int(std::find(kEndCoordinateNames.begin(), kEndCoordinateNames.end(), name) - kEndCoordinateNames.begin());
    if (c == 3 || (!setup.coordinates.empty() && c <= setup.coordinates.back()))
      r.expected(pt / "coordinates" / k, coords[k], "one of \"x\", \"y\", \"phi\", each once and in that order");
    setup.coordinates.push_back(c);
  }
  if (task.contains("to") == task.contains("waypoints"))
    r.fail(pt / "to", "expected exactly one of /path/task/to (a straight path) and /path/task/waypoints");
  if (task.contains("from")) spec.waypoints.push_back(taskPoint(r, task["from"], pt / "from", setup.coordinates));
  if (task.contains("to")) spec.waypoints.push_back(taskPoint(r, task["to"], pt / "to", setup.coordinates));
  if (task.contains("waypoints")) {
    const json& w = task["waypoints"];
    if (!w.is_array() || w.empty()) r.expected(pt / "waypoints", w, "a non-empty array of points");
    for (size_t i = 0; i < w.size(); ++i) spec.waypoints.push_back(taskPoint(r, w[i], pt / "waypoints" / i, setup.coordinates));
  }
  const double reach = chain.length();
  for (size_t i = 0; i < spec.waypoints.size(); ++i) {
    double r2 = 0.0;
    for (size_t k = 0; k < setup.coordinates.size(); ++k)
      if (setup.coordinates[k] < 2) r2 += spec.waypoints[i][Eigen::Index(k)] * spec.waypoints[i][Eigen::Index(k)];
    if (std::sqrt(r2) > reach * (1.0 + 1e-12)) {
      const bool from = task.contains("from");
      const Pointer at = from && i == 0            ? pt / "from"
                         : task.contains("waypoints") ? pt / "waypoints" / (from ? i - 1 : i)
                                                      : pt / "to";
      r.fail(at, "expected a position the end can reach: within " + show(reach) +
                     " of the base (the length of the straight chain)");
    }
  }
  std::string rule = "chosen";
  if (path.contains("rule")) rule = r.string(path["rule"], p / "rule");
  if (rule != "chosen" && rule != "min_change" && rule != "most_stable")
    r.expected(p / "rule", path["rule"], "one of chosen, min_change, most_stable");
  setup.rule = rule == "chosen"       ? mechanics::TaskRule::Chosen
               : rule == "min_change" ? mechanics::TaskRule::MinimumChange
                                      : mechanics::TaskRule::MostStable;
  const json& inputs = r.required(path, p, "inputs");
  if (!inputs.is_array() || inputs.empty()) r.expected(p / "inputs", inputs, "a non-empty array of inputs");
  std::set<std::string> seen;
  for (size_t j = 0; j < inputs.size(); ++j) {
    setup.inputs.push_back(
        parseInput(r, inputs[j], p / "inputs" / j, chain, setup.rule != mechanics::TaskRule::Chosen));
    if (!seen.insert(mechanics::taskInputName(setup.inputs.back())).second)
      r.fail(p / "inputs" / j, "the input " + mechanics::taskInputName(setup.inputs.back()) + " is listed twice");
  }
  const size_t m = setup.coordinates.size();
  if (setup.rule == mechanics::TaskRule::Chosen && setup.inputs.size() != m)
    r.fail(p / "inputs", "the rule \"chosen\" needs as many inputs as task coordinates (" + std::to_string(m) +
                             "), got " + std::to_string(setup.inputs.size()) + " (or use \"rule\": \"min_change\")");
  if (setup.rule != mechanics::TaskRule::Chosen && setup.inputs.size() < m)
    r.fail(p / "inputs", "the rule \"" + rule + "\" needs at least as many inputs as task coordinates (" +
                             std::to_string(m) + "), got " + std::to_string(setup.inputs.size()));
  spec.from = 0.0;
  spec.to = 0.0;  // the path's length is known once the start pose is (case runner)
  return spec;
}

void checkTaskPathAnalyses(const JsonReader& r, const Scene& scene) {
  for (const CaseSpec& c : scene.cases) {
    if (!c.path.task) continue;
    const AnalysesSpec& a = scene.analyses;
    const auto refuse = [&](const char* key, const char* what) {
      r.fail(Pointer("/analyses") / key, std::string(what) + " are not computed along a task path (case \"" + c.label +
                                             "\"): remove this analysis or use a load or control path");
    };
    if (!a.continuation.enabled)
      r.fail(Pointer("/analyses/continuation"), "missing: a task path (case \"" + c.label +
                                                    "\") is followed by the continuation; add \"continuation\": true");
    if (a.continuation.branchSwitching > 0) refuse("continuation", "switched branches (branch_switching)");
    if (a.criticalForces.enabled) refuse("critical_forces", "critical forces (linear buckling)");
    if (a.twoParameter.enabled) refuse("two_parameter", "two-parameter critical curves");
    if (a.suddenLoad.enabled) refuse("sudden_load", "sudden loads");
    if (a.loadHistory.enabled) refuse("load_history", "load histories");
    if (a.equilibria.enabled) refuse("equilibria", "all equilibria");
    if (a.frequencies.enabled) refuse("frequencies", "natural frequencies");
    if (a.jump.enabled) refuse("jump", "jumps");
    if (a.energyCurves.enabled) refuse("energy_curves", "energy curves");
  }
}

}  // namespace buckle::scene::detail

namespace buckle::scene {

std::vector<std::string> Scene::inputColumns() const {
  std::vector<std::string> out;
  for (const CaseSpec& c : cases)
    for (const mechanics::TaskInput& in : c.path.taskSetup.inputs)
      if (std::find(out.begin(), out.end(), mechanics::taskInputName(in)) == out.end())
        out.push_back(mechanics::taskInputName(in));
  return out;
}

}  // namespace buckle::scene
