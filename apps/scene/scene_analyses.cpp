#include "scene/scene_parsing.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/stiffness_extremum.h"
#include "scene/analyses.h"
#include "scene/columns.h"

namespace buckle::scene::detail {

using Reader = JsonReader;

namespace {

std::set<std::string> branchColumns(int maxN, const AnalysesSpec& a) {
  std::set<std::string> c = {"parameter", "Fx", "Fy", "Me", "x", "y", "phi", "dx", "dy", "min_eig"};
  for (int i = 1; i <= maxN; ++i) c.insert("q" + std::to_string(i));
  if (a.stiffness) c.insert(stiffnessColumns().begin(), stiffnessColumns().end());
  if (a.frequencies.enabled)
    for (const std::string& column : frequencyColumns(a.frequencies.count)) c.insert(column);
  return c;
}

// The inertial model and the frequencies divide by the rods' masses m = ρ l and inertias m l²/12:
// both must be ordinary (normal, finite) numbers.
void checkRodMasses(const Reader& r, const CaseSpec& c, double rho, const Pointer& p) {
  for (const mechanics::LinkInertia& link : mechanics::InertiaData::uniformRods(mechanics::Chain(c.chain.segments), rho).links)
    if (!std::isnormal(link.mass) || !std::isnormal(link.inertia))
      r.fail(p, "out of the range the inertial model can compute: the rods' masses rho l or inertias rho l^3/12 "
                "(l the link lengths of case \"" + c.label + "\") are not ordinary finite numbers; got " + show(rho));
}

FrequenciesSpec parseFrequencies(const Reader& r, const json& f, const Pointer& p) {
  r.onlyKeys(f, p, {"count", "mass_per_length"});
  FrequenciesSpec s;
  s.enabled = true;
  if (f.contains("count")) s.count = r.integer(f["count"], p / "count", 1, kMaxFrequencies);
  s.massPerLength = r.positive(r.required(f, p, "mass_per_length"), p / "mass_per_length");
  return s;
}

}  // namespace

void parseContinuation(const Reader& r, const json& c, const Pointer& pc, AnalysesSpec& s) {
  if (c.is_boolean()) {
    s.continuation.enabled = c.get<bool>();
  } else {
    r.onlyKeys(c, pc, {"branch_switching", "contact", "wall", "self", "branch_points", "child_points", "mirror", "threads"});
    s.continuation.enabled = true;
    if (c.contains("branch_switching"))
      s.continuation.branchSwitching = r.integer(c["branch_switching"], pc / "branch_switching", 0, 4);
    if (c.contains("contact")) s.continuation.contact = r.boolean(c["contact"], pc / "contact");
    if (c.contains("wall")) s.continuation.wall = r.boolean(c["wall"], pc / "wall");
    if (c.contains("self")) s.continuation.self = r.boolean(c["self"], pc / "self");
    if (c.contains("mirror")) s.continuation.mirror = r.boolean(c["mirror"], pc / "mirror");
    if (c.contains("branch_points"))
      s.continuation.branchPoints = r.integer(c["branch_points"], pc / "branch_points", 1, 10000000);
    if (c.contains("child_points"))
      s.continuation.childPoints = r.integer(c["child_points"], pc / "child_points", 2, 10000000);
    if (c.contains("threads")) s.continuation.threads = r.integer(c["threads"], pc / "threads", 0, 4096);
  }
}

void parseStiffness(const Reader& r, const json& k, const Pointer& pk, AnalysesSpec& s) {
  if (k.is_object()) {
    // {"measure": M}: the stiffness measure whose deep minima are quasi-buckling (KMIN)
    r.onlyKeys(k, pk, {"measure"});
    s.stiffness = true;
    if (k.contains("measure")) {
      const std::string m = r.string(k["measure"], pk / "measure");
      if (!mechanics::parseStiffnessMeasure(m, s.stiffnessMeasure))
        r.expected(pk / "measure", k["measure"], "one of Kxx, Kyy, Kmin (the smallest eigenvalue of K_F)");
    }
  } else {
    s.stiffness = r.boolean(k, pk);
  }
  if (s.stiffness && !s.continuation.enabled)
    r.fail(pk, "stiffness is computed along the traced branches: it needs /analyses/continuation");
}

void parseEnergyCurves(const Reader& r, const json& e, const Pointer& pe, AnalysesSpec& s) {
  r.onlyKeys(e, pe, {"x", "y", "q1_from", "q1_to", "points", "torque"});
  s.energyCurves.enabled = true;
  if (!e.contains("x") || !e.contains("y")) r.fail(pe / (e.contains("x") ? "y" : "x"), "missing (required): the held end position");
  s.energyCurves.x = r.number(e["x"], pe / "x");
  s.energyCurves.y = r.number(e["y"], pe / "y");
  if (e.contains("q1_from")) s.energyCurves.q1From = r.number(e["q1_from"], pe / "q1_from");
  if (e.contains("q1_to")) s.energyCurves.q1To = r.number(e["q1_to"], pe / "q1_to");
  if (!(s.energyCurves.q1From < s.energyCurves.q1To)) r.fail(pe / "q1_to", "expected q1_to > q1_from");
  if (e.contains("points")) s.energyCurves.points = r.integer(e["points"], pe / "points", 3, 1000000);
  if (e.contains("torque")) s.energyCurves.torque = r.boolean(e["torque"], pe / "torque");
}

void parseTorqueAngle(const Reader& r, const json& t, const Pointer& pt, AnalysesSpec& s) {
  if (t.is_boolean()) {
    s.torqueAngle.enabled = t.get<bool>();
  } else {
    r.onlyKeys(t, pt, {"q_from", "q_to", "points"});
    s.torqueAngle.enabled = true;
    if (t.contains("q_from")) s.torqueAngle.qFrom = r.number(t["q_from"], pt / "q_from");
    if (t.contains("q_to")) s.torqueAngle.qTo = r.number(t["q_to"], pt / "q_to");
    if (!(s.torqueAngle.qFrom < s.torqueAngle.qTo)) r.fail(pt / "q_to", "expected q_to > q_from");
    if (t.contains("points")) s.torqueAngle.points = r.integer(t["points"], pt / "points", 3, 1000000);
  }
}

void parseCriticalForces(const Reader& r, const json& c, const Pointer& pc, AnalysesSpec& s) {
  if (c.is_boolean()) {
    s.criticalForces.enabled = c.get<bool>();
  } else {
    r.onlyKeys(c, pc, {"modes"});
    s.criticalForces.enabled = true;
    if (c.contains("modes")) s.criticalForces.modes = r.integer(c["modes"], pc / "modes", 1, 100000);
  }
}

void parseJump(const Reader& r, const json& j, const Pointer& pj, AnalysesSpec& s) {
  if (j.is_boolean()) {
    s.jump.enabled = j.get<bool>();
  } else {
    r.onlyKeys(j, pj, {"perturbation"});
    s.jump.enabled = true;
    if (j.contains("perturbation")) s.jump.perturbation = r.positive(j["perturbation"], pj / "perturbation");
  }
  if (s.jump.enabled && !s.continuation.enabled)
    r.fail(pj, "jumps are simulated from the folds of the traced branches: it needs /analyses/continuation");
}

void parseLoadHistory(const Reader& r, const json& h, const Pointer& ph, AnalysesSpec& s) {
  r.onlyKeys(h, ph, {"waypoints", "perturbation"});
  if (!h.contains("waypoints")) r.fail(ph / "waypoints", "missing (required): the path-parameter values to visit");
  const json& w = h["waypoints"];
  if (!w.is_array() || w.size() < 2) r.expected(ph / "waypoints", w, "an array of at least two numbers");
  for (size_t i = 0; i < w.size(); ++i) s.loadHistory.waypoints.push_back(r.number(w[i], ph / "waypoints" / i));
  if (h.contains("perturbation")) s.loadHistory.perturbation = r.positive(h["perturbation"], ph / "perturbation");
  s.loadHistory.enabled = true;
}

void parseSuddenLoad(const Reader& r, const json& d, const Pointer& pd, AnalysesSpec& s) {
  r.onlyKeys(d, pd, {"value", "mass_per_length", "damping"});
  if (!d.contains("value")) r.fail(pd / "value", "missing (required): the path-parameter value applied at once");
  s.suddenLoad.value = r.number(d["value"], pd / "value");
  if (d.contains("mass_per_length")) s.suddenLoad.massPerLength = r.positive(d["mass_per_length"], pd / "mass_per_length");
  if (d.contains("damping")) s.suddenLoad.damping = r.nonNegative(d["damping"], pd / "damping");
  if (d.contains("damping") && !d.contains("mass_per_length"))
    r.fail(pd / "damping", "joint damping belongs to the inertial model: give mass_per_length too");
  s.suddenLoad.enabled = true;
}

void parseFrequenciesBlock(const Reader& r, const json& f, const Pointer& p, AnalysesSpec& s) {
  s.frequencies = parseFrequencies(r, f, p);
  if (!s.continuation.enabled && !s.loadHistory.enabled)
    r.fail(p, "frequencies are computed along the traced branches: it needs /analyses/continuation or load_history");
}

void parseTwoParameterBlock(const Reader& r, const json& v, const Pointer& p, AnalysesSpec& s) {
  s.twoParameter = parseTwoParameter(r, v, p);
}

void parseEquilibriaBlock(const Reader& r, const json& v, const Pointer& p, AnalysesSpec& s) {
  s.equilibria = parseEquilibria(r, v, p);
}

AnalysesSpec parseAnalyses(const Reader& r, const json& a, const Pointer& p) {
  std::set<std::string> keys;
  std::vector<std::string> standalone;
  for (const Analysis& x : analyses())
    if (x.key) {
      keys.insert(x.key);
      if (x.standalone) standalone.push_back(x.key);
    }
  r.onlyKeys(a, p, keys);
  AnalysesSpec s;
  // in the registry's order: an analysis that needs another one's branches comes after it
  for (const Analysis& x : analyses())
    if (x.key && a.contains(x.key)) x.parse(r, a[x.key], p / x.key, s);
  bool any = false;
  for (const Analysis& x : analyses()) any = any || (x.standalone && x.asked(s));
  if (!any) {
    std::string list;
    for (const std::string& k : standalone) list += (list.empty() ? "" : ", ") + k;
    r.fail(p, "expected at least one analysis (" + list + ")");
  }
  return s;
}

PlotSpec parsePlot(const Reader& r, const json& v, const Pointer& p, const AnalysesSpec& a, int maxN, int nCases,
                   const std::vector<std::string>& inputColumns) {
  PlotSpec s;
  json obj = v;
  if (v.is_string()) obj = json{{"type", v}};
  r.onlyKeys(obj, p, {"type", "name", "x", "y", "at", "title", "cases", "labels"});
  if (obj.contains("cases")) {
    const json& cs = obj["cases"];
    if (!cs.is_array() || cs.empty()) r.expected(p / "cases", cs, "a non-empty array of case indices (0-based)");
    for (size_t i = 0; i < cs.size(); ++i) s.cases.push_back(r.integer(cs[i], p / "cases" / i, 0, nCases - 1));
  } else {
    for (int i = 0; i < nCases; ++i) s.cases.push_back(i);
  }
  if (!obj.contains("type")) r.fail(p / "type", "missing (required)");
  const Pointer pt = v.is_string() ? p : p / "type";
  const std::string type = r.string(obj["type"], pt);
  const std::map<std::string, PlotType> types = {{"bifurcation", PlotType::Bifurcation},
                                                 {"stiffness", PlotType::Stiffness},
                                                 {"energy_curves", PlotType::EnergyCurves},
                                                 {"torque_angle", PlotType::TorqueAngle},
                                                 {"shapes", PlotType::Shapes},
                                                 {"sudden_load", PlotType::SuddenLoad},
                                                 {"critical_curves", PlotType::CriticalCurves},
                                                 {"equilibrium_shapes", PlotType::EquilibriumShapes},
                                                 {"workspace", PlotType::Workspace},
                                                 {"input_map", PlotType::InputMap}};
  auto it = types.find(type);
  if (it == types.end())
    r.expected(pt, obj["type"],
               "one of bifurcation, stiffness, energy_curves, torque_angle, shapes, sudden_load, critical_curves, "
               "equilibrium_shapes, workspace, input_map");
  s.type = it->second;
  auto needs = [&](bool have, const char* analysis) {
    if (!have) r.fail(pt, std::string("a ") + type + " plot needs /analyses/" + analysis);
  };
  switch (s.type) {
    case PlotType::Bifurcation:
    case PlotType::Shapes: needs(a.continuation.enabled || a.loadHistory.enabled, "continuation (or load_history)"); break;
    case PlotType::Stiffness: needs(a.stiffness, "stiffness"); break;
    case PlotType::EnergyCurves: needs(a.energyCurves.enabled, "energy_curves"); break;
    case PlotType::TorqueAngle: needs(a.torqueAngle.enabled, "torque_angle"); break;
    case PlotType::SuddenLoad: needs(a.suddenLoad.enabled, "sudden_load"); break;
    case PlotType::CriticalCurves: needs(a.twoParameter.enabled, "two_parameter"); break;
    case PlotType::EquilibriumShapes: needs(a.equilibria.enabled, "equilibria"); break;
    case PlotType::Workspace:
    case PlotType::InputMap: needs(a.workspace.enabled, "workspace"); break;
  }
  s.name = type;
  if (obj.contains("name")) {
    s.name = r.string(obj["name"], p / "name");
    const bool ok = !s.name.empty() && std::all_of(s.name.begin(), s.name.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
    });
    if (!ok) r.expected(p / "name", obj["name"], "a file stem of letters, digits, '_' and '-'");
  }
  if (obj.contains("title")) s.title = r.string(obj["title"], p / "title");
  const bool columns = s.type == PlotType::Bifurcation || s.type == PlotType::Stiffness;
  if (!columns) {
    for (const char* key : {"x", "y"})
      if (obj.contains(key)) r.fail(p / key, std::string("a ") + type + " plot has fixed axes; remove this key");
    if (obj.contains("labels"))
      r.fail(p / "labels", "only bifurcation and stiffness plots label special points; remove this key");
  } else {
    if (obj.contains("labels")) {
      const std::map<std::string, PlotLabels> modes = {
          {"auto", PlotLabels::Auto}, {"all", PlotLabels::All}, {"summary", PlotLabels::Summary}};
      const auto mode = modes.find(r.string(obj["labels"], p / "labels"));
      if (mode == modes.end()) r.expected(p / "labels", obj["labels"], "one of auto, all, summary");
      s.labels = mode->second;
    }
    std::set<std::string> allowed = branchColumns(maxN, a);
    allowed.insert(inputColumns.begin(), inputColumns.end());
    std::string list;
    for (const std::string& c : allowed) list += (list.empty() ? "" : ", ") + c;
    auto column = [&](const json& c, const Pointer& pc) {
      const std::string name = r.string(c, pc);
      if (!allowed.count(name)) r.expected(pc, c, "a column of branches.csv (" + list + ")");
      return name;
    };
    s.x = obj.contains("x") ? column(obj["x"], p / "x") : "parameter";
    if (obj.contains("y")) {
      const json& y = obj["y"];
      if (y.is_array()) {
        if (y.empty()) r.expected(p / "y", y, "a column name or a non-empty list of them");
        for (size_t i = 0; i < y.size(); ++i) s.y.push_back(column(y[i], p / "y" / i));
      } else {
        s.y.push_back(column(y, p / "y"));
      }
    } else if (s.type == PlotType::Stiffness) {
      s.y = {"Kxx", "Kyy"};
    } else {
      s.y = {"q1"};
    }
  }
  if (s.type == PlotType::Shapes) {
    if (!obj.contains("at")) r.fail(p / "at", "missing (required): parameter values at which to draw the chain");
    const json& at = obj["at"];
    if (!at.is_array() || at.empty()) r.expected(p / "at", at, "a non-empty array of parameter values");
    for (size_t i = 0; i < at.size(); ++i) s.at.push_back(r.number(at[i], p / "at" / i));
  } else if (obj.contains("at")) {
    r.fail(p / "at", "only a shapes plot takes \"at\"");
  }
  return s;
}

void checkAnalysesAgainstCases(const Reader& r, const Scene& scene) {
  checkControlPathAnalyses(r, scene);
  checkTaskPathAnalyses(r, scene);
  checkTwoParameterAgainstCases(r, scene);
  checkEquilibriaAgainstCases(r, scene);
  checkWorkspaceAgainstCases(r, scene);
  if (scene.analyses.energyCurves.enabled)
    for (size_t i = 0; i < scene.cases.size(); ++i)
      if (scene.cases[i].chain.segments.size() != 3)
        r.fail(Pointer("/analyses/energy_curves"),
               "energy curves E(q1) with the end held use the 3-segment inverse kinematics (eq 6): case \"" +
                   scene.cases[i].label + "\" has " + std::to_string(scene.cases[i].chain.segments.size()) +
                   " segments");
  if (scene.analyses.loadHistory.enabled) {
    // The history starts where the path starts and stays inside its range.
    const std::vector<double>& w = scene.analyses.loadHistory.waypoints;
    const Pointer pw = Pointer("/analyses/load_history/waypoints");
    for (const CaseSpec& c : scene.cases) {
      const double start = c.startValue();
      const double lo = std::min(c.path.from, c.path.to), hi = std::max(c.path.from, c.path.to);
      if (std::abs(w[0] - start) > 1e-12 * std::max(1.0, std::abs(start)))
        r.fail(pw / 0, "expected the start value " + c.path.parameter + " = " + std::to_string(start) + " of case \"" +
                           c.label + "\"");
      for (size_t i = 0; i < w.size(); ++i)
        if (w[i] < lo - 1e-12 || w[i] > hi + 1e-12)
          r.fail(pw / i, "expected a value inside the path range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
  }
  if (scene.analyses.suddenLoad.enabled)
    for (const CaseSpec& c : scene.cases) {
      const double lo = std::min(c.path.from, c.path.to), hi = std::max(c.path.from, c.path.to);
      const double v = scene.analyses.suddenLoad.value;
      if (v < lo - 1e-12 || v > hi + 1e-12)
        r.fail(Pointer("/analyses/sudden_load/value"),
               "expected a value inside the path range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      const double rho = scene.analyses.suddenLoad.massPerLength;
      if (rho > 0.0) checkRodMasses(r, c, rho, Pointer("/analyses/sudden_load/mass_per_length"));
    }
  if (scene.analyses.frequencies.enabled)
    for (const CaseSpec& c : scene.cases)
      checkRodMasses(r, c, scene.analyses.frequencies.massPerLength, Pointer("/analyses/frequencies/mass_per_length"));
}

std::vector<PlotSpec> defaultPlots(const AnalysesSpec& a, int nCases) {
  std::vector<int> all;
  for (int i = 0; i < nCases; ++i) all.push_back(i);
  std::vector<PlotSpec> out;
  if (a.continuation.enabled || a.loadHistory.enabled)
    out.push_back({PlotType::Bifurcation, "bifurcation", "parameter", {"q1"}, {}, "", all});
  if (a.stiffness) out.push_back({PlotType::Stiffness, "stiffness", "parameter", {"Kxx", "Kyy"}, {}, "", all});
  if (a.energyCurves.enabled) out.push_back({PlotType::EnergyCurves, "energy_curves", "", {}, {}, "", all});
  if (a.torqueAngle.enabled) out.push_back({PlotType::TorqueAngle, "torque_angle", "", {}, {}, "", all});
  if (a.suddenLoad.enabled) out.push_back({PlotType::SuddenLoad, "sudden_load", "", {}, {}, "", all});
  if (a.twoParameter.enabled) out.push_back({PlotType::CriticalCurves, "critical_curves", "", {}, {}, "", all});
  if (a.equilibria.enabled) out.push_back({PlotType::EquilibriumShapes, "equilibrium_shapes", "", {}, {}, "", all});
  if (a.workspace.enabled) {
    out.push_back({PlotType::Workspace, "workspace", "", {}, {}, "", all});
    out.push_back({PlotType::InputMap, "input_map", "", {}, {}, "", all});
  }
  return out;
}

}  // namespace buckle::scene::detail
