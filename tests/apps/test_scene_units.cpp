// The same answer in any units (issue 12): every scene in data/scenes/, rewritten in other unit
// systems — every length × L, every spring stiffness × K, so forces × K·L, torques and energies
// × K·L², masses per length × K/L and joint damping × K·L² (the time unit unchanged), angles and
// the solver settings as shipped — run through `buckle run` (runSceneCommand) must give the same
// special points: same count, order, types, fields, shapes and stabilities, parameters, loads and
// positions equal after rescaling to 1e-10 relative (to the quantity's own unit: the shipped
// scenes have b = k = 1), joint angles to 1e-10, the same jumps and landings, the same critical
// loads, energy-curve equilibria, torque zeros and sudden-load answers.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "read_output.h"
#include "sanitized_build.h"
#include "scene/command.h"
#include "scene/json_reader.h"
#include "scene/scene.h"
#include "scene/units.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

fs::path sceneDir() { return fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes"; }

fs::path unitsDir() { return buckle::test::scratchDirectory("scene_units"); }

using buckle::test::readJson;

struct Units {
  const char* name;
  double length, stiffness;
  double force() const { return stiffness * length; }
  double torque() const { return stiffness * length * length; }
  /// Unit of a load name (Fx, Fy, Me), an end coordinate (x, y, phi) or a control input (free lengths).
  double of(const std::string& key) const {
    if (key == "Fx" || key == "Fy") return force();
    if (key == "Me") return torque();
    if (key == "x" || key == "y") return length;
    if (key == "L1_0" || key == "L2_0" || key == "L0" || key == "dL0") return length;  // control inputs
    if (key == "gravity") return length;  // masses × k/L per length keep the time unit: m g × k L
    if (key == "s") return length;  // a task path's arclength
    return 1.0;  // phi
  }
  /// Unit of the reaction of a held coordinate.
  double reactionOf(const std::string& coordinate) const { return coordinate == "phi" ? torque() : force(); }
};

// The unit systems of the issues, relative to the shipped scenes (b = 1, k = 1): b = 20 mm with
// k = 2 N/mm; b = 0.02 m with k = 2000 N/m; lengths × 1e3 with stiffness × 1e-6; and the two
// extremes, lengths × 1e-4 with stiffness × 1e-8 and lengths × 1e4 with stiffness × 1e8.
const Units kSystems[] = {{"mm, N/mm", 20.0, 2.0},
                          {"m, N/m", 0.02, 2000.0},
                          {"x1e3, x1e-6", 1e3, 1e-6},
                          {"x1e-4, x1e-8", 1e-4, 1e-8},
                          {"x1e4, x1e8", 1e4, 1e8}};

void scaleChain(json& chain, const Units& u) {
  for (const char* key : {"a", "b", "L0", "a1", "a2", "b1", "b2", "L1_0", "L2_0"})
    if (chain.contains(key)) chain[key] = chain[key].get<double>() * u.length;
  for (const char* key : {"k", "k1", "k2"})
    if (chain.contains(key)) chain[key] = chain[key].get<double>() * u.stiffness;
  if (chain.contains("segments") && chain["segments"].is_array())
    for (json& s : chain["segments"]) scaleChain(s, u);
}

void scaleEnd(json& end, const Units& u) {
  for (const char* c : {"x", "y", "phi"}) {
    if (!end.contains(c) || !end[c].is_object()) continue;
    json& v = end[c];
    const std::string coordinate = c;
    if (v.contains("load")) v["load"] = v["load"].get<double>() * (coordinate == "phi" ? u.torque() : u.force());
    if (v.contains("held") && v["held"].is_number()) v["held"] = v["held"].get<double>() * u.of(coordinate);
  }
}

void scalePath(json& path, const std::string& parameter, const Units& u) {
  if (path.contains("task")) {  // a task path: its points on the task coordinates, the inputs' bounds
    json& t = path["task"];
    const json coordinates = t["coordinates"];
    const auto scalePoint = [&](json& point) {
      for (size_t k = 0; k < point.size(); ++k) point[k] = point[k].get<double>() * u.of(coordinates[k].get<std::string>());
    };
    for (const char* key : {"from", "to"})
      if (t.contains(key)) scalePoint(t[key]);
    if (t.contains("waypoints"))
      for (json& w : t["waypoints"]) scalePoint(w);
    if (path.contains("inputs"))
      for (json& in : path["inputs"])
        for (const char* key : {"min", "max"})
          if (in.is_object() && in.contains(key)) in[key] = in[key].get<double>() * u.length;
    return;
  }
  const double unit = u.of(parameter);
  for (const char* key : {"from", "to"})
    if (path.contains(key)) path[key] = path[key].get<double>() * unit;
  if (path.contains("load_limit")) path["load_limit"] = path["load_limit"].get<double>() * u.reactionOf(parameter);
  if (path.contains("direction"))
    for (auto& [key, rate] : path["direction"].items()) rate = rate.get<double>() * u.of(key) / unit;
}

// /gravity and /point_loads: masses × k (per length × k/L), g × L, so weights scale as forces
// and the time unit √(mass·length/force) is unchanged; point forces as forces.
void scaleBody(json& doc, const std::string& parameter, const Units& u) {
  if (doc.contains("gravity")) {
    json& g = doc["gravity"];
    if (g.contains("value")) g["value"] = g["value"].get<double>() * u.length;
    if (g.contains("mass_per_length")) g["mass_per_length"] = g["mass_per_length"].get<double>() * u.stiffness / u.length;
    if (g.contains("payload")) g["payload"] = g["payload"].get<double>() * u.stiffness;
  }
  if (doc.contains("point_loads"))
    for (json& p : doc["point_loads"]) {
      for (const char* key : {"Fx", "Fy"})
        if (p.contains(key)) p[key] = p[key].get<double>() * u.force();
      if (p.contains("rate"))
        for (auto& [key, rate] : p["rate"].items()) rate = rate.get<double>() * u.force() / u.of(parameter);
    }
}

std::string parameterOf(const json& scene, const json& patch) {
  if (patch.contains("path") && patch["path"].contains("task")) return "s";
  if (scene.contains("path") && scene["path"].contains("task") && !(patch.contains("path") && patch["path"].contains("parameter")))
    return "s";
  if (patch.contains("path") && patch["path"].contains("parameter")) return patch["path"]["parameter"];
  if (scene.contains("path") && scene["path"].contains("parameter")) return scene["path"]["parameter"];
  return "";
}

/// Unit of the two_parameter analysis' second parameter μ (docs/scenes.md): a length for the
/// triangle sizes and free lengths, a stiffness for k, and for an end coordinate the unit of its
/// value (a load or a held coordinate).
double secondParameterUnit(const json& scene, const Units& u) {
  const std::string p = scene["analyses"]["two_parameter"]["parameter"];
  if (p == "a" || p == "b" || p == "L0" || p == "dL0") return u.length;
  if (p == "k") return u.stiffness;
  const json& v = scene["end"][p];
  if (v.is_object() && v.contains("load")) return p == "phi" ? u.torque() : u.force();
  return u.of(p);
}

/// The scene in the unit system u (the module comment); plots off (they are not compared).
json rewrite(json scene, const Units& u) {
  scene.erase("units");  // rescaled numbers are no longer in the units the scene named
  const json original = scene;
  const std::string parameter = parameterOf(original, json::object());
  if (scene.contains("chain")) scaleChain(scene["chain"], u);
  if (scene.contains("end")) scaleEnd(scene["end"], u);
  if (scene.contains("path")) scalePath(scene["path"], parameter, u);
  scaleBody(scene, parameter, u);
  if (scene.contains("cases"))
    for (json& c : scene["cases"]) {
      scaleBody(c, parameterOf(original, c), u);
      if (c.contains("chain")) scaleChain(c["chain"], u);
      if (c.contains("end")) scaleEnd(c["end"], u);
      if (c.contains("path")) scalePath(c["path"], parameterOf(original, c), u);
    }
  json& a = scene["analyses"];
  if (a.contains("energy_curves"))
    for (const char* key : {"x", "y"})
      if (a["energy_curves"].contains(key)) a["energy_curves"][key] = a["energy_curves"][key].get<double>() * u.length;
  if (a.contains("load_history"))
    for (json& w : a["load_history"]["waypoints"]) w = w.get<double>() * u.of(parameter);
  if (a.contains("equilibria") && a["equilibria"].is_object() && a["equilibria"].contains("at"))
    a["equilibria"]["at"] = a["equilibria"]["at"].get<double>() * u.of(parameter);
  if (a.contains("two_parameter")) {
    const double unit = secondParameterUnit(original, u);
    for (const char* key : {"from", "to"}) a["two_parameter"][key] = a["two_parameter"][key].get<double>() * unit;
  }
  if (a.contains("sudden_load")) {
    json& s = a["sudden_load"];
    s["value"] = s["value"].get<double>() * u.of(parameter);
    if (s.contains("mass_per_length")) s["mass_per_length"] = s["mass_per_length"].get<double>() * u.stiffness / u.length;
    if (s.contains("damping")) s["damping"] = s["damping"].get<double>() * u.torque();
  }
  if (a.contains("workspace"))  // the inputs are free lengths
    for (const char* axis : {"first", "second"})
      for (const char* key : {"from", "to"})
        a["workspace"][axis][key] = a["workspace"][axis][key].get<double>() * u.length;
  if (a.contains("frequencies"))  // the same masses per length as the sudden load: time unit unchanged
    a["frequencies"]["mass_per_length"] = a["frequencies"]["mass_per_length"].get<double>() * u.stiffness / u.length;
  scene["plots"] = json::array();
  return scene;
}

json runInUnits(const json& scene, const fs::path& dir, const std::string& name) {
  fs::create_directories(dir);
  const fs::path file = dir / (name + ".json");
  {
    std::ofstream out(file);
    out << scene.dump(2);
  }
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = file.string();
  opt.out = (dir / name).string();
  opt.quiet = true;
  const int rc = buckle::scene::runSceneCommand(opt, log, err);
  INFO(name << ": " << err.str());
  REQUIRE(rc == 0);
  json result = readJson(dir / name / "special_points.json");
  result["complete"] = readJson(dir / name / "summary.json")["complete"];
  return result;
}

// |a/unit − b| within 1e-10 of the quantity's unit (and of |b|): "1e-10 relative".
void same(const json& a, const json& b, double unit, const std::string& what, double tolerance = 1e-10) {
  INFO(what);
  REQUIRE(a.is_number() == b.is_number());
  if (!b.is_number()) return;
  const double x = a.get<double>() / unit, y = b.get<double>();
  CHECK(std::abs(x - y) <= tolerance * std::max(1.0, std::abs(y)));
}

void sameVector(const json& a, const json& b, double unit, const std::string& what, double tolerance = 1e-10) {
  INFO(what);
  REQUIRE(a.size() == b.size());
  for (size_t i = 0; i < b.size(); ++i) same(a[i], b[i], unit, what + "[" + std::to_string(i) + "]", tolerance);
}

void sameWrench(const json& a, const json& b, const Units& u, const std::string& what) {
  same(a["Fx"], b["Fx"], u.force(), what + " Fx");
  same(a["Fy"], b["Fy"], u.force(), what + " Fy");
  same(a["Me"], b["Me"], u.torque(), what + " Me");
}

void samePose(const json& a, const json& b, const Units& u, const std::string& what, double tolerance = 1e-10) {
  same(a["x"], b["x"], u.length, what + " x", tolerance);
  same(a["y"], b["y"], u.length, what + " y", tolerance);
  same(a["phi"], b["phi"], 1.0, what + " phi", tolerance);
}

// A branch point of multiplicity ≥ 2 has no regular augmented system (it is located by the secant
// on its crossing eigenvalues, then only verified): it is the sample of the branch inside a
// bracket of |ds| ~ 1e-11, where the Keller system is singular
// to that order, so its joint angles are determined only to ~eps/|ds| ≈ 1e-5·(scale) in any unit
// system (its λ still to rounding). Such points, and the jumps released from them (same q),
// are compared to 1e-6 in q and position.
bool nearMultiplePoint(const json& point, const json& all) {
  for (const json& p : all) {
    if (p["type"] != "BP") continue;
    if (!p.contains("note") || p["note"].get<std::string>().find("multiplicity") == std::string::npos) continue;
    double d = 0.0;
    for (size_t i = 0; i < p["q"].size(); ++i) d = std::max(d, std::abs(p["q"][i].get<double>() - point["q"][i].get<double>()));
    if (d <= 1e-5) return true;
  }
  return false;
}

void compare(const json& got, const json& ref, const json& scene, const Units& u) {
  CHECK(got["complete"] == ref["complete"]);
  const json& gs = got["special_points"];
  const json& rs = ref["special_points"];
  REQUIRE(gs.size() == rs.size());
  for (size_t i = 0; i < rs.size(); ++i) {
    const json &g = gs[i], &r = rs[i];
    const std::string what = "special point " + std::to_string(i) + " (" + r["type"].get<std::string>() + ")";
    INFO(what << ": " << r.dump());
    const bool degenerate = r["q"].size() == g["q"].size() && nearMultiplePoint(r, rs);
    for (const char* key : {"type", "field", "case", "branch", "shape", "stability_before", "stability_after"}) {
      INFO(key << ": " << g[key].dump() << " vs " << r[key].dump());
      // At the hysteresis scene's symmetric point a fold and a double branch point coincide
      // exactly (free end under Me, equal joints: H = K_q(q)·I, all three eigenvalues cross at
      // the fold). Which branch through it the tracer continues on, and so whether the point is
      // reported as BP (multiplicity 3) or LP, is decided by rounding in any unit system: there
      // the location (λ, and q to 1e-6) is compared, not the classification.
      const bool classification = std::string(key) == "type" || std::string(key) == "field" ||
                                  std::string(key) == "shape" || std::string(key) == "stability_after";
      if (degenerate && classification && r["type"] == "BP") {
        CHECK((g["type"] == "BP" || g["type"] == "LP"));
        continue;
      }
      CHECK(g[key] == r[key]);
    }
    const std::string parameter = parameterOf(scene, scene.contains("cases") ? scene["cases"][r["case"].get<size_t>()] : json::object());
    same(g["parameter"], r["parameter"], u.of(parameter), what + " parameter");
    const double angleTolerance = degenerate ? 1e-6 : 1e-10;
    sameVector(g["q"], r["q"], 1.0, what + " q", angleTolerance);
    sameWrench(g["loads"], r["loads"], u, what);
    samePose(g["position"], r["position"], u, what, angleTolerance);
    REQUIRE(g.contains("jump_to") == r.contains("jump_to"));
    if (!r.contains("jump_to")) continue;
    const json &gj = g["jump_to"], &rj = r["jump_to"];
    CHECK(gj["success"] == rj["success"]);
    CHECK(gj["landing"] == rj["landing"]);
    REQUIRE(gj.contains("q") == rj.contains("q"));
    if (!rj.contains("q")) continue;
    CHECK(gj["shape"] == rj["shape"]);
    // A polished landing is an equilibrium: 1e-10. A joint-limit landing is where the
    // integration stopped on the limit: the trajectory's own accuracy (1e-10 per step).
    const double qTolerance = rj["landing"] == "joint limit" ? 1e-6 : 1e-10;
    sameVector(gj["q"], rj["q"], 1.0, what + " landing q", qTolerance);
    sameWrench(gj["loads"], rj["loads"], u, what + " landing");
    same(gj["energy_released"], rj["energy_released"], u.torque(), what + " energy released", 1e-8);
  }
  if (ref.contains("workspace")) {
    // the grid's counts and the curves by cause and name are the same; the stable workspace's
    // extent scales with the lengths
    REQUIRE(got["workspace"].size() == ref["workspace"].size());
    for (size_t c = 0; c < ref["workspace"].size(); ++c) {
      const json &g = got["workspace"][c], &r = ref["workspace"][c];
      for (const char* key : {"reached", "grid", "inputs"}) CHECK(g[key] == r[key]);
      // a grid value next to a fold of its row is taken where the row first reaches it, which
      // depends on the tracer's steps near the fold: at most 1 % of the values may change sheet
      CHECK(std::abs(g["stable"].get<int>() - r["stable"].get<int>()) <= r["reached"].get<int>() / 100);
      REQUIRE(g["curves"].size() == r["curves"].size());
      for (size_t k = 0; k < r["curves"].size(); ++k)
        for (const char* key : {"cause", "name", "stable_points"}) CHECK(g["curves"][k][key] == r["curves"][k][key]);
      for (const char* axis : {"x", "y"})
        for (size_t e = 0; e < 2; ++e)
          same(g["stable_extent"][axis][e], r["stable_extent"][axis][e], u.length, std::string("workspace extent ") + axis);
    }
  }
  if (ref.contains("critical_loads")) {
    REQUIRE(got["critical_loads"].size() == ref["critical_loads"].size());
    for (size_t i = 0; i < ref["critical_loads"].size(); ++i) {
      const json &g = got["critical_loads"][i], &r = ref["critical_loads"][i];
      CHECK(g["shape"] == r["shape"]);
      // the load of the path's coordinate (a force for x, y, Fx, Fy)
      const std::string parameter = parameterOf(scene, json::object());
      const double unit = parameter == "phi" || parameter == "Me" ? u.torque() : u.force();
      same(g["load_factor"], r["load_factor"], unit, "critical load " + std::to_string(i));
    }
  }
  if (ref.contains("critical_curves")) {
    // the codimension-two points of every critical curve: μ in its own unit, λ in the path's
    const json &gc = got["critical_curves"], &rc = ref["critical_curves"];
    REQUIRE(gc.size() == rc.size());
    const double muUnit = secondParameterUnit(scene, u);
    const double lambdaUnit = u.of(parameterOf(scene, json::object()));
    for (size_t i = 0; i < rc.size(); ++i) {
      const std::string what = "critical curve " + std::to_string(i);
      for (const char* key : {"case", "curve", "type", "stop"}) CHECK(gc[i][key] == rc[i][key]);
      REQUIRE(gc[i]["codim2"].size() == rc[i]["codim2"].size());
      for (size_t k = 0; k < rc[i]["codim2"].size(); ++k) {
        const json &g = gc[i]["codim2"][k], &r = rc[i]["codim2"][k];
        CHECK(g["label"] == r["label"]);
        same(g["mu"], r["mu"], muUnit, what + " " + r["label"].get<std::string>() + " mu");
        same(g["lambda"], r["lambda"], lambdaUnit, what + " " + r["label"].get<std::string>() + " lambda");
      }
    }
  }
  if (ref.contains("energy_equilibria")) {
    REQUIRE(got["energy_equilibria"].size() == ref["energy_equilibria"].size());
    for (size_t i = 0; i < ref["energy_equilibria"].size(); ++i) {
      const json &g = got["energy_equilibria"][i], &r = ref["energy_equilibria"][i];
      CHECK(g["stable"] == r["stable"]);
      CHECK(g["ik_branch"] == r["ik_branch"]);
      same(g["q1"], r["q1"], 1.0, "energy equilibrium q1");
      sameVector(g["q"], r["q"], 1.0, "energy equilibrium q");
      same(g["energy"], r["energy"], u.torque(), "energy equilibrium energy");
    }
  }
  if (ref.contains("equilibria")) {  // every equilibrium at one state: the same set, scaled
    REQUIRE(got["equilibria"].size() == ref["equilibria"].size());
    for (size_t i = 0; i < ref["equilibria"].size(); ++i) {
      const json &g = got["equilibria"][i]["equilibria"], &r = ref["equilibria"][i]["equilibria"];
      REQUIRE(g.size() == r.size());
      for (size_t k = 0; k < r.size(); ++k) {
        // matched by q: a mirror pair's two members have the same Π, so their order is rounding's
        size_t match = g.size();
        for (size_t j = 0; j < g.size() && match == g.size(); ++j) {
          double d = 0.0;
          for (size_t c = 0; c < r[k]["q"].size(); ++c)
            d = std::max(d, std::abs(g[j]["q"][c].get<double>() - r[k]["q"][c].get<double>()));
          if (d <= 1e-8) match = j;
        }
        INFO("equilibrium " << k << " of case " << i);
        REQUIRE(match < g.size());
        CHECK(g[match]["index"] == r[k]["index"]);
        CHECK(g[match]["stable"] == r[k]["stable"]);
        same(g[match]["potential"], r[k]["potential"], u.torque(), "equilibrium potential");
      }
    }
  }
  if (ref.contains("torque_zeros")) {
    REQUIRE(got["torque_zeros"].size() == ref["torque_zeros"].size());
    for (size_t i = 0; i < ref["torque_zeros"].size(); ++i) {
      CHECK(got["torque_zeros"][i]["stable"] == ref["torque_zeros"][i]["stable"]);
      same(got["torque_zeros"][i]["q"], ref["torque_zeros"][i]["q"], 1.0, "torque zero");
    }
  }
  if (ref.contains("sudden_load")) {
    REQUIRE(got["sudden_load"].size() == ref["sudden_load"].size());
    for (size_t i = 0; i < ref["sudden_load"].size(); ++i) {
      const json &g = got["sudden_load"][i], &r = ref["sudden_load"][i];
      for (const char* key : {"success", "model", "stable"}) CHECK(g[key] == r[key]);
      REQUIRE(g.contains("rest") == r.contains("rest"));
      if (r.contains("rest")) sameVector(g["rest"]["q"], r["rest"]["q"], 1.0, "sudden-load rest q");
      REQUIRE(g["quasi_static"].is_null() == r["quasi_static"].is_null());
      if (!r["quasi_static"].is_null()) {
        CHECK(g["quasi_static"]["differs"] == r["quasi_static"]["differs"]);
        CHECK(g["quasi_static"]["lower"] == r["quasi_static"]["lower"]);
        sameVector(g["quasi_static"]["q"], r["quasi_static"]["q"], 1.0, "quasi-static q");
      }
    }
  }
}

}  // namespace

TEST_CASE("every shipped scene gives the same special points in five other unit systems", "[scene][units][slow]") {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(sceneDir()))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  REQUIRE(scenes.size() >= 10);
  const fs::path dir = unitsDir();
  for (const fs::path& file : scenes) {
    DYNAMIC_SECTION(file.stem().string()) {
      const json shipped = readJson(file);
      const json reference = runInUnits(rewrite(shipped, Units{"shipped", 1.0, 1.0}), dir, file.stem().string());
      // the comparison must have something to compare
      CHECK((!reference["special_points"].empty() || reference.contains("critical_curves") ||
             reference.contains("energy_equilibria") || reference.contains("equilibria") ||
             reference.contains("torque_zeros") || reference.contains("sudden_load") ||
             reference.contains("workspace")));
      for (const Units& u : kSystems) {
        // under the sanitizers the two extremes only (every system in the Release build): the
        // sanitizers look for memory errors, which do not depend on the units
        if (buckle::test::kSanitizedBuild && u.length != 1e-4 && u.length != 1e4) continue;
        INFO("unit system " << u.name << " (lengths x " << u.length << ", stiffness x " << u.stiffness << ")");
        const json scaled = rewrite(shipped, u);
        const json got = runInUnits(scaled, dir, file.stem().string() + "_" + std::to_string(&u - kSystems));
        compare(got, reference, shipped, u);
      }
    }
  }
  fs::remove_all(dir);
}

TEST_CASE("the rewrite scales what it should", "[scene][units]") {
  const json scene = json::parse(R"({"chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": 0.5}, "y": {"held": 0.25}, "phi": {"load": 0.1}},
    "path": {"parameter": "Fx", "from": 0.0, "to": -2.5, "direction": {"Me": 0.2, "y": 0.5}},
    "analyses": {"continuation": true, "equilibria": {"at": -1.0}}, "solver": {"initial_step": 0.02}})");
  const Units u{"test", 10.0, 3.0};
  const json s = rewrite(scene, u);
  CHECK(s["chain"]["b"] == Approx(10.0));
  CHECK(s["chain"]["k"] == Approx(3.0));
  CHECK(s["chain"]["L0"] == Approx(22.5));
  CHECK(s["end"]["x"]["load"] == Approx(0.5 * 30.0));
  CHECK(s["end"]["y"]["held"] == Approx(2.5));
  CHECK(s["end"]["phi"]["load"] == Approx(0.1 * 300.0));
  CHECK(s["path"]["to"] == Approx(-75.0));
  CHECK(s["path"]["direction"]["Me"] == Approx(0.2 * 300.0 / 30.0));  // torque per force
  CHECK(s["path"]["direction"]["y"] == Approx(0.5 * 10.0 / 30.0));    // length per force
  CHECK(s["solver"]["initial_step"] == Approx(0.02));                  // dimensionless: as shipped
  CHECK(s["analyses"]["equilibria"]["at"] == Approx(-30.0));           // a value of the path's Fx
}

// ---- unit labels (scene/units.h) ----------------------------------------------------------------

using buckle::scene::Dimension;
using buckle::scene::UnitSystem;

namespace {

UnitSystem named(const std::string& length, const std::string& force) {
  UnitSystem u;
  u.kind = UnitSystem::Kind::Named;
  u.length = length;
  u.force = force;
  return u;
}

std::string slurpFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The value of every `set xlabel/ylabel/y2label/cblabel '…'` or "…" in a gnuplot script.
std::vector<std::string> axisLabels(const std::string& script) {
  std::vector<std::string> out;
  std::istringstream in(script);
  for (std::string line; std::getline(in, line);) {
    for (const char* cmd : {"set xlabel ", "set ylabel ", "set y2label ", "set cblabel "})
      if (line.rfind(cmd, 0) == 0) {
        const std::string rest = line.substr(std::string(cmd).size());
        const char q = rest.empty() ? '\'' : rest[0];
        const size_t end = rest.find(q, 1);
        out.push_back(rest.substr(1, end == std::string::npos ? std::string::npos : end - 1));
      }
  }
  return out;
}

}  // namespace

TEST_CASE("unit names compose into every derived unit", "[scene][units][labels]") {
  const UnitSystem si = named("m", "N");
  CHECK(si.unit(Dimension::Length) == "m");
  CHECK(si.unit(Dimension::Force) == "N");
  CHECK(si.unit(Dimension::Moment) == "N·m");
  CHECK(si.unit(Dimension::Stiffness) == "N/m");
  CHECK(si.unit(Dimension::Compliance) == "m/N");
  CHECK(si.unit(Dimension::RotationalStiffness) == "N·m/rad");
  CHECK(si.suffix(Dimension::Force) == " (N)");
  CHECK(si.suffix(Dimension::Angle) == " (rad)");
  CHECK(si.suffix(Dimension::None).empty());
  // a compound name is grouped, so N/(mm) and (kg m/s^2)/mm read right
  CHECK(named("mm", "kg m/s^2").unit(Dimension::Stiffness) == "(kg m/s^2)/mm");

  UnitSystem nondim;
  nondim.kind = UnitSystem::Kind::Nondimensional;
  CHECK(nondim.suffix(Dimension::Force) == " (units of k b)");
  CHECK(nondim.suffix(Dimension::Moment) == " (units of k b^2)");
  CHECK(nondim.suffix(Dimension::Stiffness) == " (units of k)");

  const UnitSystem consistent;  // no `units`: nothing claims k b
  for (Dimension d : {Dimension::Length, Dimension::Force, Dimension::Moment, Dimension::Stiffness}) {
    INFO(consistent.suffix(d));
    CHECK(consistent.suffix(d).find("scene's units") != std::string::npos);
    CHECK(consistent.suffix(d).find("k b") == std::string::npos);
  }
}

TEST_CASE("bad units are refused at /units with what is accepted", "[scene][units][labels]") {
  const std::string chain = R"("chain": {"segments": 3, "a": 0.01, "b": 0.02, "k": 2000, "L0": 0.045},
      "end": {"x": {"load": 0}, "y": {"held": 0}, "phi": "free"}, "path": {"parameter": "Fx", "from": 0, "to": -1},
      "analyses": {"continuation": true})";
  struct Bad {
    const char* units;
    const char* path;
  };
  for (const Bad& b : {Bad{R"({"length": "m", "force": "N'\nsystem 'x"})", "/units/force"},
                       Bad{R"({"length": "m<b>", "force": "N"})", "/units/length"},
                       Bad{R"({"length": "mmmmmmmmmmmmmmmmm", "force": "N"})", "/units/length"},
                       Bad{R"({"length": "", "force": "N"})", "/units/length"},
                       Bad{R"({"length": "m"})", "/units/force"},
                       Bad{R"({"length": "m", "force": "N", "time": "s"})", "/units/time"},
                       Bad{R"("SI")", "/units"},
                       Bad{R"("nondimensional")", "/units"}}) {
    INFO(b.units);
    try {
      buckle::scene::parseScene(std::string("{\"units\": ") + b.units + ", " + chain + "}", "scene.json");
      FAIL("accepted");
    } catch (const buckle::scene::SceneError& e) {
      CHECK(e.path() == b.path);
      CHECK(!e.message().empty());
    }
  }
  // nondimensional is accepted exactly when b = k = 1
  const std::string unit = R"({"units": "nondimensional", "chain": {"segments": 3, "a": 0.5, "b": 1, "k": 1,
      "L0": 2.25}, "end": {"x": {"load": 0}, "y": {"held": 0}, "phi": "free"},
      "path": {"parameter": "Fx", "from": 0, "to": -1}, "analyses": {"continuation": true}})";
  CHECK(buckle::scene::parseScene(unit, "scene.json").units.kind == UnitSystem::Kind::Nondimensional);
}

TEST_CASE("the SI chain says N, m and N/m in every plot, column doc and the report", "[scene][units][labels]") {
  const fs::path dir = unitsDir() / "si_labels";
  fs::remove_all(dir);
  const json scene = readJson(sceneDir() / "si_chain.json");
  runInUnits(scene, dir, "si");
  const json summary = readJson(dir / "si" / "summary.json");
  CHECK(summary["units"]["force"] == "N");
  CHECK(summary["units"]["stiffness"] == "N/m");

  // every axis label of every gnuplot script names a unit of the scene (or rad), never k b
  size_t labelled = 0;
  std::set<std::string> seen;
  for (const auto& e : fs::directory_iterator(dir / "si" / "plots")) {
    if (e.path().extension() != ".gp") continue;
    const std::string script = slurpFile(e.path());
    INFO(e.path().filename().string());
    CHECK(script.find("units of") == std::string::npos);
    for (const std::string& label : axisLabels(script)) {
      INFO(label);
      const bool hasUnit = label.find("(N)") != std::string::npos || label.find("(m)") != std::string::npos ||
                           label.find("(N/m)") != std::string::npos || label.find("(N·m)") != std::string::npos ||
                           label.find("(rad)") != std::string::npos;
      CHECK(hasUnit);
      seen.insert(label);
      ++labelled;
    }
  }
  CHECK(labelled >= 8);  // x and y of five plots less the shapes panels' unlabelled axes
  CHECK(seen.count("F_x (N)") == 1);
  CHECK(seen.count("stiffness (N/m)") == 1);
  CHECK(seen.count("{/Symbol d}_x = x_0 - x (m)") == 1);
  CHECK(seen.count("M(q) = -dE/dq (N·m)") == 1);

  // the report: the units table the page draws its axes with, and the labels of the drawn columns
  const std::string html = slurpFile(dir / "si" / "report.html");
  CHECK(html.find("units of") == std::string::npos);
  CHECK(html.find(R"x("force":" (N)")x") != std::string::npos);
  CHECK(html.find(R"x("length":" (m)")x") != std::string::npos);
  CHECK(html.find(R"x("Fx":"Fx (N)")x") != std::string::npos);
  CHECK(html.find(R"x("q5":"q5 (rad)")x") != std::string::npos);
}

TEST_CASE("the design map in units of 1e-4 (lengths) and 1e-8 (stiffness)", "[scene][units]") {
  // b = 1e-4 and k = 1e-8: forces of 1e-12, torques of 1e-16, far from every threshold of 1
  const json shipped = readJson(sceneDir() / "design_map.json");
  const fs::path dir = unitsDir();
  const json reference = runInUnits(rewrite(shipped, Units{"shipped", 1.0, 1.0}), dir, "design_map_reference");
  REQUIRE(reference.contains("critical_curves"));
  const Units tiny{"1e-4, 1e-8", 1e-4, 1e-8};
  const json got = runInUnits(rewrite(shipped, tiny), dir, "design_map_tiny");
  compare(got, reference, shipped, tiny);
}
