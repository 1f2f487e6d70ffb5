// /path with a control input as its parameter (issue 29; mechanics/control_path.h): the springs'
// free lengths move, the end stays at /end's values.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

Eigen::VectorXd parseControlDirection(const JsonReader& r, const json& d, const Pointer& pd,
                                      mechanics::ControlInput input) {
  r.requireObject(d, pd);
  const std::string own = mechanics::controlInputName(input);
  const std::string allowed = mechanics::controlInputName(mechanics::complementaryInput(input));
  for (auto it = d.begin(); it != d.end(); ++it)
    if (it.key() != allowed)
      r.fail(pd / it.key(), "unknown key \"" + it.key() + "\" (allowed here: " + allowed + ", the input that with " +
                                own + " sets both free lengths; " + own + "'s own rate is 1)");
  if (!d.contains(allowed)) return Eigen::VectorXd();  // {}: the named input alone
  const Pointer pk = pd / allowed;
  const json& v = d[allowed];
  if (!v.is_array()) return Eigen::VectorXd::Constant(1, r.number(v, pk));
  if (v.empty()) r.fail(pk, "expected a number or a list of rates (one per segment), got an empty list");
  Eigen::VectorXd rates(Eigen::Index(v.size()));
  for (size_t i = 0; i < v.size(); ++i) rates[Eigen::Index(i)] = r.number(v[i], pk / i);
  return rates;
}


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
  if (path.contains("direction")) {
    const Eigen::VectorXd rates = parseControlDirection(r, path["direction"], p / "direction", input);
    const std::string key = mechanics::controlInputName(mechanics::complementaryInput(input));
    if (rates.size() > 1 && rates.size() != n)
      r.fail(p / "direction" / key, "expected a number or a list of " + std::to_string(n) +
                                        " rates (one per segment), got " + std::to_string(rates.size()));
    if (rates.size() > 0) mechanics::addComplementaryRates(spec.controlDirection, input, rates);
  }
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
