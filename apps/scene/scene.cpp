#include "scene/scene.h"

#include <algorithm>
#include <iomanip>
#include <set>
#include <sstream>

#include "scene/escape.h"
#include "scene/json_reader.h"
#include "scene/scene_parsing.h"
#include "scene/solver_settings.h"

namespace buckle::scene {

namespace detail {

std::string show(double v) {
  std::ostringstream os;
  os << std::setprecision(6) << v;
  return os.str();
}

}  // namespace detail

using namespace detail;

const char* toString(PlotType t) {
  switch (t) {
    case PlotType::Bifurcation: return "bifurcation";
    case PlotType::Stiffness: return "stiffness";
    case PlotType::EnergyCurves: return "energy_curves";
    case PlotType::TorqueAngle: return "torque_angle";
    case PlotType::Shapes: return "shapes";
    case PlotType::SuddenLoad: return "sudden_load";
    case PlotType::CriticalCurves: return "critical_curves";
    case PlotType::Workspace: return "workspace";
    case PlotType::InputMap: return "input_map";
    case PlotType::EquilibriumShapes: return "equilibrium_shapes";
  }
  return "?";
}

int Scene::maxSegments() const {
  int n = 0;
  for (const CaseSpec& c : cases) n = std::max(n, static_cast<int>(c.chain.segments.size()));
  return n;
}

namespace {

using Reader = JsonReader;

// RFC 7386: `target` patched by `patch`, without first copying the parts of `target` that the
// patch replaces (a case replacing a long list of segments does not copy the base's).
json mergePatched(const json& target, const json& patch) {
  if (!patch.is_object()) return patch;
  json out = json::object();
  if (target.is_object())
    for (auto it = target.begin(); it != target.end(); ++it)
      if (!patch.contains(it.key())) out[it.key()] = *it;
  static const json kNone;
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it->is_null()) continue;  // null removes the member
    const bool had = target.is_object() && target.contains(it.key());
    out[it.key()] = mergePatched(had ? target[it.key()] : kNone, *it);
  }
  return out;
}

// Nondimensional numbers are lengths in b and forces in k b only when b = k = 1 throughout.
void requireUnitChain(const Reader& r, const Scene& scene) {
  for (const CaseSpec& c : scene.cases)
    for (size_t i = 0; i < c.chain.segments.size(); ++i) {
      const mechanics::SegmentParameters& p = c.chain.segments[i];
      if (p.b1 != 1.0 || p.b2 != 1.0 || p.k1 != 1.0 || p.k2 != 1.0)
        r.fail(Pointer("/units"), "\"nondimensional\" means lengths in b and forces in k b, so b = k = 1 in every "
                                  "segment, but " + c.label + " has b = " + show(p.b1 != 1.0 ? p.b1 : p.b2) + ", k = " +
                                  show(p.k1 != 1.0 ? p.k1 : p.k2) + " in segment " + std::to_string(i + 1) +
                                  ": name the units instead ({\"length\": \"m\", \"force\": \"N\"}) or remove \"units\"");
    }
}

}  // namespace

Scene parseScene(const std::string& text, const std::string& file) {
  const Reader r(file);
  const json doc = parseJsonDocument(text, file);
  r.onlyKeys(doc, Pointer(""), {"description", "units", "chain", "end", "path", "gravity", "point_loads", "cases",
                                "analyses", "solver", "plots"});
  Scene scene;
  scene.file = file;
  if (doc.contains("description")) scene.description = r.string(doc["description"], Pointer("/description"));

  if (!doc.contains("analyses")) r.fail(Pointer("/analyses"), "missing (required): what to compute");
  scene.analyses = parseAnalyses(r, doc["analyses"], Pointer("/analyses"));
  const bool needPath = scene.analyses.continuation.enabled || scene.analyses.criticalForces.enabled ||
                        scene.analyses.twoParameter.enabled || scene.analyses.loadHistory.enabled || scene.analyses.suddenLoad.enabled ||
                        (scene.analyses.equilibria.enabled && !scene.analyses.equilibria.at.empty());

  // chain, end and path: what a case patches (copied key by key, not with the cases)
  json base = json::object();
  for (const char* key : {"chain", "end", "path", "gravity", "point_loads"})
    if (doc.contains(key)) base[key] = doc[key];
  int totalSegments = 0;
  if (doc.contains("cases")) {
    const json& cases = doc["cases"];
    if (!cases.is_array() || cases.empty()) r.expected(Pointer("/cases"), cases, "a non-empty array of case objects");
    for (size_t i = 0; i < cases.size(); ++i) {
      const Pointer pi = Pointer("/cases") / i;
      r.onlyKeys(cases[i], pi, {"label", "chain", "end", "path", "gravity", "point_loads"});
      std::string label = "case " + std::to_string(i + 1);
      if (cases[i].contains("label")) label = r.string(cases[i]["label"], pi / "label");
      json patch = cases[i];
      patch.erase("label");
      try {
        scene.cases.push_back(parseCase(r, mergePatched(base, patch), label, needPath));
      } catch (const SceneError& e) {
        // point into the case when the bad value came from it
        const Pointer bad(e.path().empty() ? "" : e.path());
        if (!e.path().empty() && patch.contains(bad)) throw SceneError(file, (pi / bad).to_string(), e.message());
        throw SceneError(file, e.path(), e.message() + " (in " + pi.to_string() + ", \"" + escape::commentText(label) + "\")");
      }
      totalSegments += static_cast<int>(scene.cases.back().chain.segments.size());
      if (totalSegments > kMaxSegments)
        r.fail(pi, "expected at most " + std::to_string(kMaxSegments) + " segments in all cases together, got " +
                       std::to_string(totalSegments) + " up to this case");
    }
  } else {
    scene.cases.push_back(parseCase(r, base, "main", needPath));
  }

  checkAnalysesAgainstCases(r, scene);
  checkBodyAnalyses(r, scene);
  if (doc.contains("units")) {
    scene.units = parseUnits(r, doc["units"], Pointer("/units"));
    if (scene.units.kind == UnitSystem::Kind::Nondimensional) requireUnitChain(r, scene);
    // named length and force units fix no time unit without a mass unit: the frequencies'
    // unit √(mass·length/force) would be a guess
    if (scene.units.kind == UnitSystem::Kind::Named && scene.units.mass.empty() && scene.analyses.frequencies.enabled)
      r.fail(Pointer("/units/mass"),
             "missing: the natural frequencies need the mass unit of /analyses/frequencies/mass_per_length (mass per "
             "length); e.g. \"kg\" with length \"m\" and force \"N\" gives frequencies in rad/s");
    for (const CaseSpec& c : scene.cases)
      if (scene.units.kind == UnitSystem::Kind::Named && scene.units.mass.empty() && c.body.haveGravity)
        r.fail(Pointer("/units/mass"), "missing: /gravity's masses need a mass unit (e.g. \"kg\" with length \"m\" "
                                       "and force \"N\": then g is in m/s^2)");
  }
  if (doc.contains("solver")) scene.solver = parseSolver(r, doc["solver"], Pointer("/solver"));
  if (doc.contains("plots")) {
    const json& plots = doc["plots"];
    if (!plots.is_array()) r.expected(Pointer("/plots"), plots, "an array of plot names or plot objects");
    std::set<std::string> names;
    for (size_t i = 0; i < plots.size(); ++i) {
      PlotSpec ps = parsePlot(r, plots[i], Pointer("/plots") / i, scene.analyses, scene.maxSegments(),
                              static_cast<int>(scene.cases.size()), scene.inputColumns());
      if (!names.insert(ps.name).second)
        r.fail(Pointer("/plots") / i, "two plots named \"" + ps.name + "\": give one a distinct \"name\"");
      scene.plots.push_back(ps);
    }
  } else {
    scene.plots = defaultPlots(scene.analyses, static_cast<int>(scene.cases.size()));
  }
  return scene;
}

Scene loadScene(const std::string& file) { return parseScene(readInputFile(file), file); }

}  // namespace buckle::scene
