// /analyses/workspace of a scene (docs/scenes.md): the workspace and stability maps over two
// control inputs under the payload of /end (mechanics/workspace_map.h).
#include <sstream>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

namespace {

mechanics::InputAxisRange parseAxis(const JsonReader& r, const json& v, const Pointer& p,
                                    const mechanics::InputAxisRange& defaults) {
  r.requireObject(v, p);
  r.onlyKeys(v, p, {"input", "segment", "direction", "from", "to", "count"});
  mechanics::InputAxisRange a = defaults;
  const std::string name = r.string(r.required(v, p, "input"), p / "input");
  if (!mechanics::parseControlInput(name, a.input.input))
    r.fail(p / "input", "expected one of L1_0, L2_0, L0, dL0 (a control input), got \"" + name + "\"");
  // the segment's upper bound is checked against every case's chain (checkWorkspaceAgainstCases)
  if (v.contains("segment")) a.input.segment = r.integer(v["segment"], p / "segment", 1, 1000000000) - 1;
  // its count is checked against every case's chain (checkWorkspaceAgainstCases)
  if (v.contains("direction")) a.input.along = parseControlDirection(r, v["direction"], p / "direction", a.input.input);
  a.from = r.number(r.required(v, p, "from"), p / "from");
  a.to = r.number(r.required(v, p, "to"), p / "to");
  if (!(a.from < a.to)) r.fail(p / "to", "expected to > from, got " + show(a.to) + " <= " + show(a.from));
  if (v.contains("count")) a.count = r.integer(v["count"], p / "count", 2, 1000);
  return a;
}

}  // namespace

void parseWorkspace(const JsonReader& r, const json& v, const Pointer& p, AnalysesSpec& s) {
  WorkspaceSpec& w = s.workspace;
  if (v.is_boolean() && !v.get<bool>()) return;
  if (!v.is_object())
    r.expected(p, v,
               "false or an object {\"first\", \"second\", \"folds\", \"singular\", \"limits\", \"max_curves\", "
               "\"max_curve_points\", \"threads\"}");
  r.onlyKeys(v, p, {"first", "second", "folds", "singular", "limits", "max_curves", "max_curve_points", "threads"});
  w.enabled = true;
  mechanics::WorkspaceMapOptions& o = w.options;
  o.first = parseAxis(r, r.required(v, p, "first"), p / "first", o.first);
  o.second = parseAxis(r, r.required(v, p, "second"), p / "second", o.second);
  if (v.contains("folds")) o.folds = r.boolean(v["folds"], p / "folds");
  if (v.contains("singular")) o.singular = r.boolean(v["singular"], p / "singular");
  if (v.contains("limits")) o.limits = r.boolean(v["limits"], p / "limits");
  if (v.contains("max_curves")) o.maxCurves = r.integer(v["max_curves"], p / "max_curves", 0, 1000);
  if (v.contains("max_curve_points"))
    o.maxCurvePoints = r.integer(v["max_curve_points"], p / "max_curve_points", 2, 1000000);
  if (v.contains("threads")) o.threads = r.integer(v["threads"], p / "threads", 0, 4096);
}

void checkWorkspaceAgainstCases(const JsonReader& r, const Scene& scene) {
  const WorkspaceSpec& w = scene.analyses.workspace;
  if (!w.enabled) return;
  const Pointer at("/analyses/workspace");
  for (const CaseSpec& c : scene.cases) {
    const std::string which = "case \"" + c.label + "\"";
    if (c.end.condition.heldCount() > 0)
      r.fail(at, "the workspace map moves the end over its workspace under a payload: /end must hold no coordinate (" +
                     which + " holds one; give loads)");
    const int n = int(c.chain.segments.size());
    const mechanics::Chain chain(c.chain.segments);
    for (int axis = 0; axis < 2; ++axis) {
      const mechanics::InputAxisRange& a = axis == 0 ? w.options.first : w.options.second;
      const Pointer pa = at / (axis == 0 ? "first" : "second");
      if (a.input.segment >= n)
        r.fail(pa / "segment", "expected a segment in 1.." + std::to_string(n) + " (" + which + "), got " +
                                   std::to_string(a.input.segment + 1));
      if (a.input.along.size() > 1 && a.input.along.size() != n)
        r.fail(pa / "direction" / mechanics::controlInputName(mechanics::complementaryInput(a.input.input)),
               "expected a number or a list of " + std::to_string(n) + " rates (one per segment, " + which + "), got " +
                   std::to_string(a.input.along.size()));
      const double value = mechanics::controlInputValue(chain, a.input.input, a.input.segment);
      const double tol = 1e-12 * std::max(1.0, std::abs(value));
      if (value < a.from - tol || value > a.to + tol) {
        std::ostringstream os;
        os << "expected a range [from, to] that contains the chain's own " << a.input.name() << " = " << show(value)
           << " (" << which << "; the map starts there), got [" << show(a.from) << ", " << show(a.to) << "]";
        r.fail(pa / (value < a.from ? "from" : "to"), os.str());
      }
    }
    try {
      const mechanics::InputPlane plane(chain, c.end.condition, {}, w.options.first.input, w.options.second.input);
      for (int axis = 0; axis < 2; ++axis) {
        const mechanics::InputAxisRange& a = axis == 0 ? w.options.first : w.options.second;
        const auto [lo, hi] = plane.admissibleRange(axis);
        if (!(a.from > lo && a.to < hi))
          r.fail(at / (axis == 0 ? "first" : "second") / (a.from <= lo ? "from" : "to"),
                 "expected a range inside (" + show(lo) + ", " + show(hi) + "), where every free length " +
                     a.input.name() + " moves stays > 0 (" + which + ")");
      }
    } catch (const std::invalid_argument& e) {
      r.fail(at / "second" / "input", std::string(e.what()) + " (" + which + ")");
    }
  }
}

}  // namespace buckle::scene::detail
