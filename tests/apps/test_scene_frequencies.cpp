// `frequencies` (docs/scenes.md): the omega columns of branches.csv against the closed form of one
// segment, the mass scaling law, the same chain in m and in mm, their sign against the stability
// column, the shipped scene data/scenes/vibration.json at its branch point, a vertex held on the
// base wall, the labels' units and the refusals (a named-unit scene without a mass unit, no traced
// branches, bad keys).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/control_path.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/vibration.h"
#include "branches_table.h"
#include "scene/columns.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "scene_run.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using namespace buckle::mechanics;

namespace {

using Table = buckle::test::BranchesTable;
using buckle::test::readBranches;

// A chain of `segments` (a, b, k, L0) = (0.5, 1, 1, 2.25)·(L, L, K, L), the end held in y (or
// free) and pushed along x to −1.2·K·L, frequencies of rods of mass per length rho.
std::string frequencyScene(int segments, double L, double K, double rho, bool heldY, const std::string& units = "",
                  int count = 3) {
  std::ostringstream s;
  s.precision(17);
  s << "{" << (units.empty() ? "" : "\"units\": " + units + ",") << "\"chain\": {\"segments\": " << segments
    << ", \"a\": " << 0.5 * L << ", \"b\": " << L << ", \"k\": " << K << ", \"L0\": " << 2.25 * L << "},"
    << "\"end\": {\"x\": {\"load\": 0.0}, \"y\": " << (heldY ? "{\"held\": 0.0}" : "{\"load\": 0.0}")
    << ", \"phi\": \"free\"}, \"path\": {\"parameter\": \"Fx\", \"from\": 0.0, \"to\": " << -1.2 * K * L << "},"
    << "\"analyses\": {\"continuation\": true, \"frequencies\": {\"count\": " << count << ", \"mass_per_length\": " << rho
    << "}}, \"plots\": []}";
  return s.str();
}

Table runTable(const std::string& name, const std::string& text) {
  const buckle::test::SceneOutcome r = buckle::test::runSceneText("scene_frequencies", name, text);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  return readBranches(r.out);
}

double relativeError(double x, double reference) { return std::abs(x - reference) / std::abs(reference); }

}  // namespace

TEST_CASE("frequencies: one free segment at rest oscillates at sqrt(K_q / (rho l^3 / 3))", "[scene]") {
  const Table t = runTable("one", frequencyScene(1, 1.0, 1.0, 2.0, false, "", 2));
  const Chain chain = Chain::uniform(1, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  Vector kq(1);
  jointStiffness(chain, Vector::Zero(1), kq);
  const double l = chain.linkLengths()[1];
  REQUIRE(t.front().at("parameter") == 0.0);
  CHECK(relativeError(t.front().at("omega1"), std::sqrt(kq[0] / (2.0 * l * l * l / 3.0))) <= 1e-11);
  CHECK(std::isnan(t.front().at("omega2")));  // one segment has one mode
}

TEST_CASE("frequencies: masses x4 halve every omega, the chain in mm gives omega times sqrt(1e-3 s)", "[scene]") {
  const Table si = runTable("si", frequencyScene(4, 0.02, 2000.0, 0.5, true, R"({"length": "m", "force": "N", "mass": "kg"})"));
  const Table heavy = runTable("heavy", frequencyScene(4, 0.02, 2000.0, 2.0, true, R"({"length": "m", "force": "N", "mass": "kg"})"));
  // mm: lengths ×1e3, k in N/mm ×1e-3, ρ in kg/mm ×1e-3; time unit √(kg·mm/N) = √1e-3 s
  const Table mm = runTable("mm", frequencyScene(4, 20.0, 2.0, 5e-4, true, R"({"length": "mm", "force": "N", "mass": "kg"})"));
  REQUIRE(si.size() == heavy.size());
  REQUIRE(si.size() == mm.size());
  int unstable = 0;
  for (size_t i = 0; i < si.size(); ++i)
    for (const char* c : {"omega1", "omega2", "omega3"}) {
      INFO("row " << i << ", " << c);
      CHECK(relativeError(heavy[i].at(c), 0.5 * si[i].at(c)) <= 1e-10);
      CHECK(relativeError(mm[i].at(c), std::sqrt(1e-3) * si[i].at(c)) <= 1e-8);
      if (std::string(c) == "omega1") {
        // Sylvester: ω₁² has the sign of the stability operator's smallest eigenvalue
        if (std::abs(si[i].at("min_eig")) > 1e-6 * 2000.0 * 0.02 * 0.02)
          CHECK((si[i].at("omega1") < 0) == (si[i].at("min_eig") < 0));
        unstable += si[i].at("omega1") < 0;
      }
    }
  CHECK(unstable > 0);  // the path goes past the first branch point
}

TEST_CASE("frequencies: the shipped scene's omega1 vanishes at its branch point, the axis says rad/s", "[scene]") {
  const fs::path file = fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / "vibration.json";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  const buckle::test::SceneOutcome r = buckle::test::runSceneText("scene_frequencies", "shipped", text.str());
  REQUIRE(r.rc == 0);
  const Table t = readBranches(r.out);
  // on the straight branch (branch 0) ω₁ is real before the branch point and imaginary after it,
  // ω₁² linear in Fx through it
  double lastStable = 0, firstUnstable = 0;
  double wStable = 0, wUnstable = 0;
  for (const auto& row : t) {
    if (row.at("branch") != 0) continue;
    if (row.at("omega1") > 0) {
      lastStable = row.at("Fx");
      wStable = row.at("omega1");
    } else if (firstUnstable == 0) {
      firstUnstable = row.at("Fx");
      wUnstable = row.at("omega1");
    }
  }
  REQUIRE(firstUnstable < lastStable);
  // the zero of the straight line through (Fx, ±ω₁²) of the two neighbours
  const double a = wStable * wStable, b = -wUnstable * wUnstable;
  const double zero = lastStable + (firstUnstable - lastStable) * a / (a - b);
  std::ifstream sp(r.out / "special_points.json");
  const auto doc = nlohmann::json::parse(sp);
  double bp = 0;
  for (const auto& p : doc["special_points"])
    if (p["type"] == "BP" && p["branch"] == 0) bp = p["parameter"];
  REQUIRE(bp < 0);
  CHECK(std::abs(zero - bp) <= 2e-3 * std::abs(bp));
  std::ifstream gp(r.out / "plots" / "frequencies_body.gp");
  std::stringstream script;
  script << gp.rdbuf();
  CHECK(script.str().find("{/Symbol w}_{1} (rad/s)") != std::string::npos);
}

TEST_CASE("frequencies: labels name the frequency unit each unit system implies", "[scene]") {
  using buckle::scene::UnitSystem;
  UnitSystem si;
  si.kind = UnitSystem::Kind::Named;
  si.length = "m";
  si.force = "N";
  si.mass = "kg";
  CHECK(buckle::scene::columnLabel("omega2", si, buckle::scene::LabelStyle::Plain) == "ω2 (rad/s)");
  si.length = "mm";
  CHECK(buckle::scene::columnLabel("omega12", si, buckle::scene::LabelStyle::Plain) == "ω12 (rad/(kg·mm/N)^1/2)");
  UnitSystem nondimensional;
  nondimensional.kind = UnitSystem::Kind::Nondimensional;
  CHECK(buckle::scene::columnLabel("omega1", nondimensional, buckle::scene::LabelStyle::Plain) ==
        "ω1 (units of √(k/m), m the mass unit)");
  CHECK(buckle::scene::columnLabel("omega1", UnitSystem(), buckle::scene::LabelStyle::Plain) ==
        "ω1 (rad/time, in the scene's units)");
  CHECK(buckle::scene::columnDimension("omega3") == buckle::scene::Dimension::AngularFrequency);
  CHECK(buckle::scene::frequencyIndex("omega0") == -1);
  CHECK(buckle::scene::frequencyIndex("omegax") == -1);
  CHECK(buckle::scene::frequencyIndex("omega") == -1);
}

TEST_CASE("frequencies: refused with the key, the path and the accepted range", "[scene]") {
  struct Bad {
    std::string text, path, words;
  };
  const std::string base = frequencyScene(3, 1.0, 1.0, 1.0, true);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string s = base;
    const size_t at = s.find(from);
    REQUIRE(at != std::string::npos);
    return s.replace(at, from.size(), to);
  };
  const std::vector<Bad> bad = {
      {frequencyScene(3, 0.02, 2000.0, 0.5, true, R"({"length": "m", "force": "N"})"), "/units/mass", "rad/s"},
      {with("\"continuation\": true, ", ""), "/analyses", "continuation or load_history"},
      {with("\"count\": 3", "\"count\": 0"), "/analyses/frequencies/count", ""},
      {with("\"count\": 3", "\"count\": 51"), "/analyses/frequencies/count", ""},
      {with(", \"mass_per_length\": 1", ""), "/analyses/frequencies/mass_per_length", "missing"},
      {with("\"mass_per_length\": 1", "\"mass_per_length\": -1"), "/analyses/frequencies/mass_per_length", ""},
      {with("\"mass_per_length\": 1", "\"mass_per_length\": 1e-320"), "/analyses/frequencies/mass_per_length",
       "ordinary"},
      {with("\"count\": 3", "\"count\": 3, \"modes\": true"), "/analyses/frequencies", "modes"},
  };
  for (const Bad& b : bad) {
    INFO(b.text);
    try {
      buckle::scene::parseScene(b.text, "s.json");
      FAIL("accepted");
    } catch (const buckle::scene::SceneError& e) {
      CHECK(std::string(e.path()).find(b.path) == 0);
      CHECK(std::string(e.what()).find(b.words) != std::string::npos);
    }
  }
}

TEST_CASE("frequencies along a control path are those of the chain at the point's free lengths", "[scene]") {
  // dL0 of every segment under a payload (the shipped actuation scene's chain): every traced point
  // against the library's vibration analysis of the chain whose free lengths are the point's own
  // (the scene's start has dL0 = 0, the direction's origin), with the free end.
  const std::string text = R"({
    "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": -0.3}, "y": {"load": -0.3}, "phi": "free"},
    "path": {"parameter": "dL0", "from": -1.0, "to": 1.0},
    "analyses": {"continuation": {}, "frequencies": {"count": 3, "mass_per_length": 0.5}},
    "solver": {"max_step": 0.05}, "plots": []
  })";
  const Table t = runTable("control", text);
  const Chain base = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const ControlDirection control = ControlDirection::named(3, ControlInput::dL0);
  int checked = 0;
  double spread = 0.0;  // how far the free lengths moved the lowest frequency over the path
  for (const auto& row : t) {
    const Chain at = chainWithControls(base, control, row.at("parameter"));
    VibrationAnalysis vib(at, InertiaData::uniformRods(base, 0.5));
    const Vector q = (Vector(3) << row.at("q1"), row.at("q2"), row.at("q3")).finished();
    const VibrationModes m = vib.modes(q, Wrench(row.at("Fx"), row.at("Fy"), row.at("Me")), {}, {}, 3, false);
    for (int i = 0; i < 3; ++i) {
      const double expected = signedFrequency(m.omegaSquared[i]);
      CHECK(row.at("omega" + std::to_string(i + 1)) == Approx(expected).epsilon(1e-9).margin(1e-9));
    }
    spread = std::max(spread, std::abs(row.at("omega1") - t.front().at("omega1")));
    ++checked;
  }
  CHECK(checked >= 10);
  CHECK(spread > 1e-2 * std::abs(t.front().at("omega1")));  // the free lengths matter here
}

TEST_CASE("frequencies on a wall stretch are those of the chain held there, their sign the stability's", "[scene]") {
  // contact_release's chain (data/scenes/contact_release.json): segment 5's corner is held on the
  // base wall between WC (Fy = 0.110) and WR (0.150); every point there against the library's
  // vibration analysis with that vertex held by its wall force, and against the chain without it.
  const std::string text = R"({
    "chain": {"segments": [{"q0": 0.2, "q_min": 0.1}, {"q0": 1.3}, {"q0": 1.3}, {"q0": 1.3}, {"q0": 1.3}],
              "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": "free", "y": {"load": 0.0}, "phi": "free"},
    "path": {"parameter": "Fy", "from": 0.0, "to": 0.3},
    "analyses": {"continuation": {"wall": true}, "frequencies": {"count": 3, "mass_per_length": 0.5}},
    "solver": {"step": {"initial_step": 0.005, "max_step": 0.005}}, "plots": []
  })";
  const buckle::test::SceneOutcome r = buckle::test::runSceneText("scene_frequencies", "wall", text);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  const buckle::scene::RunResult run = buckle::scene::runScene(buckle::scene::loadScene(r.file.string()));
  REQUIRE(run.cases.size() == 1);
  const buckle::scene::CaseResult& c = run.cases.front();
  VibrationAnalysis vib(c.chain, InertiaData::uniformRods(c.chain, 0.5));
  int onWall = 0;
  for (const PointReport& p : c.points) {
    if (p.locked.wallCount() == 0) continue;
    ++onWall;
    INFO("Fy = " << p.parameter);
    REQUIRE(p.omega.size() == 3);
    REQUIRE(p.omega.allFinite());
    const VibrationModes held = vib.modes(p.q, p.F, {}, p.locked, p.wallForces, 3, false);
    std::vector<int> locked;
    for (const LockedJoint& j : p.locked.joints()) locked.push_back(j.joint);
    const VibrationModes unheld = vib.modes(p.q, p.F, {}, locked, 3, false);
    for (int i = 0; i < 3; ++i) CHECK(p.omega[i] == Approx(signedFrequency(held.omegaSquared[i])).epsilon(1e-9));
    CHECK(std::abs(held.omegaSquared[0] - unheld.omegaSquared[0]) > 1e-3 * std::abs(unheld.omegaSquared[0]));
    // Sylvester: the pencil's inertia is the constrained stability operator's
    CHECK((p.omega[0] > 0.0) == (p.negative == 0));
  }
  CHECK(onWall >= 5);
  // the located points of the stretch (WR at Fy = 0.150) with the wall forces they report
  int located = 0;
  for (const buckle::scene::SpecialPointResult& s : c.specials) {
    if (s.wallForces.size() == 0) continue;
    ++located;
    INFO("special point at Fy = " << s.parameter);
    REQUIRE(s.omega.size() == 3);
    CHECK(s.omega.allFinite());
  }
  CHECK(located >= 1);
}
