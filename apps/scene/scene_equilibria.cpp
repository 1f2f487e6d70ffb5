// /analyses/equilibria of a scene (docs/scenes.md): every equilibrium at one state of the
// controls (mechanics/all_equilibria.h), with the search's options.
#include <algorithm>
#include <string>

#include "scene/scene_parsing.h"

namespace buckle::scene::detail {

EquilibriaSpec parseEquilibria(const JsonReader& r, const json& v, const Pointer& p) {
  EquilibriaSpec s;
  if (v.is_boolean()) {
    s.enabled = v.get<bool>();
    return s;
  }
  if (!v.is_object())
    r.expected(p, v,
               "true, false or an object {\"starts\", \"smooth_starts\", \"seed\", \"at\", \"sweep_points\", "
               "\"branches\"}");
  r.onlyKeys(v, p, {"starts", "smooth_starts", "seed", "at", "sweep_points", "branches"});
  s.enabled = true;
  if (v.contains("starts")) s.starts = r.integer(v["starts"], p / "starts", 0, 1000000);
  if (v.contains("smooth_starts")) s.smoothStarts = r.integer(v["smooth_starts"], p / "smooth_starts", 0, 1000000);
  if (v.contains("seed")) s.seed = unsigned(r.integer(v["seed"], p / "seed", 0, 2147483647));
  if (v.contains("sweep_points")) s.sweepPoints = r.integer(v["sweep_points"], p / "sweep_points", 3, 10000000);
  if (v.contains("branches")) s.branches = r.boolean(v["branches"], p / "branches");
  if (v.contains("at")) {
    const json& at = v["at"];
    if (at.is_array()) {
      if (at.empty() || at.size() > size_t(EquilibriaSpec::kMaxAt))
        r.expected(p / "at", at,
                   "a number or a list of 1 to " + std::to_string(EquilibriaSpec::kMaxAt) + " numbers");
      for (size_t i = 0; i < at.size(); ++i) s.at.push_back(r.number(at[i], p / "at" / i));
    } else {
      s.at.push_back(r.number(at, p / "at"));
    }
  }
  return s;
}

void checkEquilibriaAgainstCases(const JsonReader& r, const Scene& scene) {
  const EquilibriaSpec& e = scene.analyses.equilibria;
  if (e.enabled && e.branches && !scene.analyses.continuation.enabled)
    r.fail(Pointer("/analyses/equilibria/branches"),
           "the branches through the equilibria are traced as the continuation's: it needs /analyses/continuation");
  if (e.enabled && e.branches)
    for (const CaseSpec& c : scene.cases)
      if (c.path.throughReaction)
        r.fail(Pointer("/analyses/equilibria/branches"),
               "expected a path in a load or a held coordinate traced directly (case \"" + c.label +
                   "\" is displacement control traced through the reaction)");
  if (!e.enabled) return;
  const bool list = e.at.size() > 1;
  for (size_t i = 0; i < e.at.size(); ++i)
    for (const CaseSpec& c : scene.cases) {
      const double lo = std::min(c.path.from, c.path.to), hi = std::max(c.path.from, c.path.to);
      const Pointer where = list ? Pointer("/analyses/equilibria/at") / i : Pointer("/analyses/equilibria/at");
      if (!(e.at[i] >= lo && e.at[i] <= hi))
        r.fail(where, "expected a value of the path parameter " + c.path.parameter + " in [" + show(lo) + ", " +
                          show(hi) + "] (case \"" + c.label + "\"), got " + show(e.at[i]));
    }
}

}  // namespace buckle::scene::detail
