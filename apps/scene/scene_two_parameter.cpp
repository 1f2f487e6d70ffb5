// /analyses/two_parameter of a scene (docs/scenes.md): which second parameter, its range, and
// which critical curves (mechanics/critical_curves.h).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "buckle/mechanics/chain.h"

#include "buckle/mechanics/critical_curves.h"
#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

TwoParameterSpec parseTwoParameter(const JsonReader& r, const json& v, const Pointer& p) {
  if (!v.is_object()) r.expected(p, v, "an object {\"parameter\", \"from\", \"to\", ...}");
  r.onlyKeys(v, p, {"parameter", "segment", "from", "to", "modes", "folds"});
  TwoParameterSpec s;
  s.enabled = true;
  if (!v.contains("parameter"))
    r.fail(p / "parameter", "missing (required): the second parameter (a, b, k, L0, dL0, x, y or phi)");
  s.parameter = r.string(v["parameter"], p / "parameter");
  if (v.contains("segment")) s.segment = r.integer(v["segment"], p / "segment", 1, 1000000) - 1;
  try {
    mechanics::SecondParameter::parse(s.parameter, s.segment);
  } catch (const std::invalid_argument& e) {
    const bool segmentWrong = std::string(e.what()).find("no segment") != std::string::npos;
    r.fail(segmentWrong ? p / "segment" : p / "parameter", e.what());
  }
  for (const char* key : {"from", "to"})
    if (!v.contains(key)) r.fail(p / key, "missing (required): the range of the second parameter");
  s.from = r.number(v["from"], p / "from");
  s.to = r.number(v["to"], p / "to");
  if (!(s.from < s.to)) r.fail(p / "to", "expected to > from");
  if (v.contains("modes")) s.modes = r.integer(v["modes"], p / "modes", 0, 100);
  if (v.contains("folds")) s.folds = r.boolean(v["folds"], p / "folds");
  if (s.modes == 0 && !s.folds) r.fail(p / "modes", "no curve asked: give modes >= 1 (branch points) or folds: true");
  return s;
}

void checkTwoParameterAgainstCases(const JsonReader& r, const Scene& scene) {
  const TwoParameterSpec& t = scene.analyses.twoParameter;
  if (!t.enabled) return;
  const Pointer p("/analyses/two_parameter");
  for (const CaseSpec& c : scene.cases) {
    const int n = int(c.chain.segments.size());
    if (t.segment >= n)
      r.fail(p / "segment", "expected a segment of case \"" + c.label + "\" (1.." + std::to_string(n) + ")");
    double mu = 0.0;
    try {
      mechanics::ChainParameterProblem problem(c.chain.segments, c.end.condition, c.path.direction,
                                               mechanics::SecondParameter::parse(t.parameter, t.segment));
      mu = problem.secondParameter();
    } catch (const std::invalid_argument& e) {
      r.fail(p / "parameter", std::string("case \"") + c.label + "\": " + e.what());
    }
    // a range far beyond the case's own scale (|μ|, or the chain's length when μ = 0) is no
    // curve to trace: ±1e308 overflows its width
    const double scale = std::max(std::abs(mu), mechanics::Chain(c.chain.segments).length());
    if (!std::isfinite(t.to - t.from) || std::max(std::abs(t.from), std::abs(t.to)) > 1e6 * scale)
      r.fail(p / (std::abs(t.from) >= std::abs(t.to) ? "from" : "to"),
             "expected a range within 1e6 times the scale of case \"" + c.label + "\" (|from|, |to| <= " +
                 show(1e6 * scale) + ": " + t.parameter + " = " + show(mu) + ", chain length " +
                 show(mechanics::Chain(c.chain.segments).length()) + "), got [" + show(t.from) + ", " + show(t.to) + "]");
    if (mu < t.from || mu > t.to)
      r.fail(p / "from", "expected a range containing " + t.parameter + " = " + show(mu) + " of case \"" + c.label +
                             "\" (the curves start there)");
  }
}

}  // namespace buckle::scene::detail
