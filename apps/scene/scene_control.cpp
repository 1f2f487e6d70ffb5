// /path with a control input as its parameter (issue 29; mechanics/control_path.h): the springs'
// free lengths move, the end stays at /end's values.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

namespace {
// The other input of the parameter's pair: (L1_0, L2_0) and (L0, dL0) each span a segment's two
// free lengths, so moving the complement leaves the parameter's own value λ.
std::string complementOf(const std::string& parameter) {
  if (parameter == "L1_0") return "L2_0";
  if (parameter == "L2_0") return "L1_0";
  return parameter == "L0" ? "dL0" : "L0";
}

// /path/direction of a control path: the rate of the complementary input per unit of the
// parameter, a number (every segment) or a list of one per segment, added to the named rates.
void addDirection(const JsonReader& r, const json& d, const Pointer& pd, const std::string& parameter, int n,
                  mechanics::ControlDirection& out) {
  r.requireObject(d, pd);
  const std::string allowed = complementOf(parameter);
  for (auto it = d.begin(); it != d.end(); ++it) {
    mechanics::ControlInput input;
    if (it.key() != allowed || !mechanics::parseControlInput(it.key(), input))
      r.fail(pd / it.key(), "unknown key \"" + it.key() + "\" (allowed here: " + allowed + ", the input that with " +
                                parameter + " sets both free lengths; " + parameter + "'s own rate is 1)");
    const Pointer pk = pd / it.key();
    const mechanics::ControlDirection unit = mechanics::ControlDirection::named(n, input);
    const json& v = it.value();
    if (v.is_array()) {
      if (int(v.size()) != n)
        r.fail(pk, "expected a number or a list of " + std::to_string(n) + " rates (one per segment), got " +
                       std::to_string(v.size()));
      for (int i = 0; i < n; ++i) out.rates.row(i) += r.number(v[size_t(i)], pk / size_t(i)) * unit.rates.row(i);
    } else {
      out.rates += r.number(v, pk) * unit.rates;
    }
  }
}
}  // namespace

bool isControlPath(const json& path) {
  mechanics::ControlInput input;
  return path.is_object() && path.contains("parameter") && path["parameter"].is_string() &&
         mechanics::parseControlInput(path["parameter"].get<std::string>(), input);
}

PathSpec parseControlPath(const JsonReader& r, const json& path, const Pointer& p, const mechanics::Chain& chain) {
  r.onlyKeys(path, p, {"parameter", "from", "to", "segment", "direction", "load_limit"});
  for (const char* key : {"parameter", "from", "to"})
    if (!path.contains(key)) r.fail(p / key, "missing (required)");
  PathSpec spec;
  spec.control = true;
  spec.parameter = r.string(path["parameter"], p / "parameter");
  mechanics::ControlInput input = mechanics::ControlInput::dL0;
  mechanics::parseControlInput(spec.parameter, input);
  if (path.contains("load_limit"))
    r.fail(p / "load_limit", "only a displacement-controlled path (parameter x, y or phi) takes a load_limit");
  const int n = chain.size();
  if (path.contains("segment")) spec.segment = r.integer(path["segment"], p / "segment", 1, n) - 1;
  spec.controlDirection = mechanics::ControlDirection::named(n, input, spec.segment);
  if (path.contains("direction")) addDirection(r, path["direction"], p / "direction", spec.parameter, n, spec.controlDirection);
  spec.start = mechanics::controlInputValue(chain, input, spec.segment);
  spec.controlDirection.origin = spec.start;
  spec.direction.setZero();
  spec.from = r.number(path["from"], p / "from");
  spec.to = r.number(path["to"], p / "to");
  if (spec.from == spec.to) r.fail(p / "to", "expected a value different from /path/from (an empty range)");
  const std::string which = spec.segment >= 0 ? " of segment " + std::to_string(spec.segment + 1) : " (mean over the segments)";
  const double lo = std::min(spec.from, spec.to), hi = std::max(spec.from, spec.to);
  if (!(spec.start >= lo - 1e-12 * std::max(1.0, std::abs(spec.start)) &&
        spec.start <= hi + 1e-12 * std::max(1.0, std::abs(spec.start)))) {
    std::ostringstream os;
    os << "expected a range [from, to] that contains the start value " << spec.parameter << which << " = "
       << show(spec.start) << " (set by /chain), got [" << show(spec.from) << ", " << show(spec.to) << "]";
    r.fail(p / (std::abs(spec.from - spec.start) <= std::abs(spec.to - spec.start) ? "from" : "to"), os.str());
  }
  const auto [admLo, admHi] = mechanics::admissibleRange(chain, spec.controlDirection);
  for (const char* key : {"from", "to"}) {
    const double v = std::string(key) == "from" ? spec.from : spec.to;
    if (v > admLo && v < admHi) continue;
    std::ostringstream os;
    os << "expected a value in (" << show(admLo) << ", " << show(admHi) << "), where every free length L1_0, L2_0 "
       << "the path moves stays > 0; got " << spec.parameter << " = " << show(v);
    r.fail(p / key, os.str());
  }
  return spec;
}

void checkControlPathAnalyses(const JsonReader& r, const Scene& scene) {
  for (const CaseSpec& c : scene.cases) {
    if (!c.path.control) continue;
    const auto refuse = [&](const char* key, const char* what) {
      r.fail(Pointer("/analyses") / key, std::string(what) + " are computed along a load path; /path/parameter " +
                                             c.path.parameter + " of case \"" + c.label +
                                             "\" is a control input (remove this analysis or use a load parameter)");
    };
    if (scene.analyses.criticalForces.enabled) refuse("critical_forces", "critical forces (linear buckling)");
    if (scene.analyses.twoParameter.enabled) refuse("two_parameter", "two-parameter critical curves");
    if (scene.analyses.suddenLoad.enabled) refuse("sudden_load", "sudden loads");
  }
}

}  // namespace buckle::scene::detail
