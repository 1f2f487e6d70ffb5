// Runs every scene in data/scenes/ through `buckle run` (the library entry point) and checks
// the outputs: files present, run complete, and the special points against the model's closed
// forms where they exist — eq 17 for the straight clamped–pinned three-segment chain
// (Fx_U,Z = λ·κ/b, λ_U = (√21 − 14)/10, λ_Z = −(√21 + 14)/10, κ = k(b L0 − 2(b² − a²))) and the
// torque zeros of a symmetric segment (eq 10: cos(q/2) = b L0 / (2(b² − a²))).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>
#include <vector>

#include "scene/command.h"
#include "scene/output.h"
#include "scene/output_target.h"
#include "temp_dir.h"
#include "read_output.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

fs::path sceneDir() { return fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes"; }

fs::path allDir(const std::string& name) { return buckle::test::absentPath("scene_all", name); }

using buckle::test::readJson;

struct Closed {
  double FxU, FxZ;
};

Closed eq17(double a, double b, double k, double L0) {
  const double kappa = k * (b * L0 - 2.0 * (b * b - a * a));
  return {(std::sqrt(21.0) - 14.0) / 10.0 * kappa / b, -(std::sqrt(21.0) + 14.0) / 10.0 * kappa / b};
}

}  // namespace

TEST_CASE("every scene in data/scenes runs and matches the closed forms", "[scene][slow]") {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(sceneDir()))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  REQUIRE(scenes.size() >= 8);
  const bool gnuplot = !buckle::scene::findGnuplot().empty();
  int closedFormChecks = 0;

  for (const fs::path& scene : scenes) {
    DYNAMIC_SECTION(scene.filename().string()) {
      const fs::path out = allDir(scene.stem().string());
      std::ostringstream log, err;
      buckle::scene::RunCommandOptions opt;
      opt.scene = scene.string();
      opt.out = out.string();
      const int rc = buckle::scene::runSceneCommand(opt, log, err);
      INFO(err.str());
      REQUIRE(rc == 0);
      REQUIRE(fs::exists(out / "summary.json"));
      REQUIRE(fs::exists(out / "special_points.json"));
      std::string why;  // every file the writers make is known to the --out policy (output_target.h)
      const bool recognised = buckle::scene::isBuckleOutput(out.string(), &why);
      INFO(why);
      CHECK(recognised);
      const json summary = readJson(out / "summary.json");
      const json sp = readJson(out / "special_points.json");
      CHECK(summary["complete"] == true);
      const json src = readJson(scene);
      if (src["analyses"].contains("continuation")) {
        REQUIRE(fs::exists(out / "branches.csv"));
        std::ifstream csv(out / "branches.csv");
        std::string header;
        std::getline(csv, header);
        CHECK(header.rfind("case,branch,point,parameter,Fx,Fy,", 0) == 0);
        // stiffness columns exactly when asked
        const bool stiffness = src["analyses"].value("stiffness", false);
        CHECK((header.find("Kxx") != std::string::npos) == stiffness);
      }
      if (gnuplot) {
        for (const auto& f : summary["plots"]["files"]) CHECK(fs::exists(out / f.get<std::string>()));
        // every scene draws something, except the sudden-load scene (its trajectory is data only)
        // and a scene of every equilibrium alone (a table)
        const bool dataOnly = src["analyses"].contains("sudden_load") ||
                              (src["analyses"].contains("equilibria") && src["analyses"].size() == 1);
        if (!dataOnly) CHECK(!summary["plots"]["files"].empty());
        CHECK(!summary["plots"].contains("failures"));
      }

      // eq 17 against every branch point found by continuation, and the linear buckling loads
      for (size_t c = 0; c < summary["cases"].size(); ++c) {
        const json& cs = summary["cases"][c];
        if (!cs.contains("critical_forces") || !cs["critical_forces"].contains("closed_form_eq17")) continue;
        const json& seg = cs["segment_parameters"][0];
        const Closed exact = eq17(seg["a1"], seg["b1"], seg["k1"], seg["L1_0"]);
        CHECK(cs["critical_forces"]["closed_form_eq17"]["Fx_U"].get<double>() == Approx(exact.FxU).epsilon(1e-12));
        int bps = 0;
        for (const json& p : sp["special_points"]) {
          if (p["case"] != c || p["type"] != "BP") continue;
          double qmax = 0.0;
          for (const json& qi : p["q"]) qmax = std::max(qmax, std::abs(qi.get<double>()));
          if (qmax > 1e-9) continue;  // a secondary bifurcation, off the straight branch
          const double Fx = p["loads"]["Fx"];
          const double expected = p["shape"] == "U" ? exact.FxU : exact.FxZ;
          INFO("case " << c << " BP " << p["shape"] << " Fx = " << Fx << ", eq 17: " << expected);
          CHECK(std::abs(Fx - expected) < 1e-8);
          CHECK(p["field"] == "buckling");
          ++bps;
          ++closedFormChecks;
        }
        if (src["analyses"].contains("continuation")) CHECK(bps >= 2);
        for (const json& m : sp["critical_loads"]) {
          if (m["case"] != c) continue;
          const double expected = m["shape"] == "U" ? exact.FxU : exact.FxZ;
          CHECK(std::abs(m["load_factor"].get<double>() - expected) < 1e-10);
          ++closedFormChecks;
        }
      }
      // torque zeros of a symmetric segment with equal preloads (eq 10)
      if (sp.contains("torque_zeros")) {
        for (size_t c = 0; c < summary["cases"].size(); ++c) {
          const json& seg = summary["cases"][c]["segment_parameters"][0];
          const double a = seg["a1"], b = seg["b1"], L0 = seg["L1_0"];
          const double ratio = b * L0 / (2.0 * (b * b - a * a));
          std::vector<double> expected{0.0};
          if (ratio < 1.0) {
            const double q = 2.0 * std::acos(ratio);
            if (q < seg["q_max"].get<double>()) expected = {-q, 0.0, q};
          }
          std::vector<double> found;
          for (const json& z : sp["torque_zeros"])
            if (z["case"] == c) found.push_back(z["q"]);
          std::sort(found.begin(), found.end());
          REQUIRE(found.size() == expected.size());
          for (size_t i = 0; i < found.size(); ++i) {
            CHECK(found[i] == Approx(expected[i]).margin(1e-10));
            ++closedFormChecks;
          }
        }
      }
      // energy equilibria are stationary: the end torque vanishes there
      if (sp.contains("energy_equilibria")) {
        CHECK(!sp["energy_equilibria"].empty());
        for (const json& e : sp["energy_equilibria"]) CHECK(std::abs(e["loads"]["Me"].get<double>()) < 1e-8);
      }
      // every equilibrium at one state: each listed one polished to the chain's rounding, and every
      // stationary point of the energy curves (end held, eq 6–8) among them, stability alike
      if (sp.contains("equilibria")) {
        REQUIRE(!sp["equilibria"].empty());
        for (const json& c : sp["equilibria"]) {
          CHECK(c["count"].get<size_t>() == c["equilibria"].size());
          CHECK(c["interrupted"] == false);
          for (const json& e : c["equilibria"]) CHECK(e["accuracy"].get<double>() <= 1e-10);
          if (!sp.contains("energy_equilibria")) continue;
          int onCurves = 0;
          for (const json& l : sp["energy_equilibria"]) {
            if (l["case"] != c["case"]) continue;
            ++onCurves;
            bool listed = false;
            for (const json& e : c["equilibria"]) {
              double d = 0.0;
              for (size_t i = 0; i < 3; ++i)
                d = std::max(d, std::abs(e["q"][i].get<double>() - l["q"][i].get<double>()));
              if (d <= 1e-12 && e["stable"] == l["stable"]) listed = true;
            }
            CHECK(listed);
          }
          CHECK(onCurves == int(c["count"].get<size_t>()));
        }
      }
      // the non-straight start q0 = (θ, −2θ, θ), cos θ = 7/8, with the end held at its unloaded
      // position (5.5, 0): q0 itself is a stable equilibrium of the energy curve, at zero load
      if (scene.stem() == "fig7") {
        const double theta = std::acos(7.0 / 8.0);
        bool found = false;
        for (const json& e : sp["energy_equilibria"]) {
          if (e["case"] != 0 || std::abs(e["q1"].get<double>() - theta) > 1e-8) continue;
          found = true;
          CHECK(e["stable"] == true);
          CHECK(e["q"][1].get<double>() == Approx(-2.0 * theta).margin(1e-8));
          CHECK(std::abs(e["loads"]["Fx"].get<double>()) < 1e-8);
          CHECK(std::abs(e["loads"]["Fy"].get<double>()) < 1e-8);
        }
        CHECK(found);
      }
      // every special point is named by the one classifier (mechanics/classification.h, the
      // table in docs/mechanics.md): type, field and stability agree
      const bool jumpsAsked = src["analyses"].contains("jump");
      for (const json& p : sp["special_points"]) {
        const std::string type = p["type"], field = p["field"];
        const std::string before = p["stability_before"], after = p["stability_after"];
        INFO(scene.stem().string() << ": " << type << " at " << p["parameter"] << " (" << field << ", " << before
                                   << " -> " << after << ")");
        // located on a stretch held on the base wall: the wall pushes there (it releases where a
        // force returns to zero), and at WR the leaving vertex is among them with its force zero
        if (p.contains("wall"))
          for (const json& w : p["wall"]) CHECK(w["wall_force"].get<double>() >= -1e-9);
        if (type == "WR") {
          REQUIRE(p.contains("wall"));
          bool leaving = false;
          for (const json& w : p["wall"]) leaving = leaving || w["vertex"] == p["wall_contact"]["vertex"];
          CHECK(leaving);
        }
        if (field == "task path") {
          // where a task path ends (case_runner_task.cpp): why, in words, and the inputs there
          CHECK((type == "LP" || type == "BP" || type == "LS" || type == "BD" || type == "IB"));
          CHECK(!p.value("note", "").empty());
          CHECK(p.contains("inputs"));
          if (type == "LS") {  // the path ends where the equilibrium at fixed inputs stops being stable
            CHECK(before == "stable");
            CHECK(after == "unstable");
          }
          CHECK(!p.contains("jump_to"));
        } else if (type == "BP") {
          CHECK(field == "buckling");
        } else if (type == "LP") {
          const bool stableSide = before == "stable" || after == "stable";
          CHECK(field == (stableSide ? "jumping" : "none"));
          // a jump is simulated exactly where the chain must jump (under load control: the jump
          // of a chain whose held coordinate turns back is not simulated)
          const bool held = p.value("note", "").find("displacement control") != std::string::npos;
          if (jumpsAsked && !held) CHECK(p.contains("jump_to") == stableSide);
          if (p.contains("jump_to")) CHECK(stableSide);
        } else if (type == "LPF" || type == "BD") {
          CHECK(field == "quasi-buckling");
          CHECK(!p.contains("jump_to"));
        } else if (type == "KMIN") {
          CHECK(field == "quasi-buckling");
          CHECK(before == "stable");
          CHECK(after == "stable");
          REQUIRE(p.contains("stiffness"));  // K_F at the located minimum itself
          CHECK(p["stiffness"]["Kxx"].get<double>() > 0.0);
        } else if (type == "JUMP") {
          CHECK(field == "jumping");
        } else if (type == "CT" || type == "RL") {
          // contact at a joint (mechanics/contact.h): the free and the locked equilibria meet
          // there, so the contact torque is zero to the location's accuracy
          CHECK(field == "none");
          CHECK(!p.contains("jump_to"));
          REQUIRE(p.contains("contact"));
          CHECK(std::abs(p["contact"]["contact_torque"].get<double>()) <= 1e-9);
        } else if (type == "WC" || type == "WR") {
          // a vertex reaches or leaves the wall (mechanics/contact.h): the free and the held
          // equilibria meet there, so the wall force is zero to the location's accuracy and the
          // vertex lies on x = 0
          CHECK(field == "none");
          CHECK(!p.contains("jump_to"));
          REQUIRE(p.contains("wall_contact"));
          CHECK(!p["wall_contact"]["vertex"].get<std::string>().empty());
          CHECK(std::abs(p["wall_contact"]["contact_force"].get<double>()) <= 1e-9);
          REQUIRE(p.contains("contact_point"));
          CHECK(std::abs(p["contact_point"][0].get<double>()) <= 1e-9 * std::max(1.0, std::abs(p["position"]["x"].get<double>())));
        } else if (type == "SH" || type == "SR") {
          // a vertex is held on or leaves another link's edge (mechanics/self_contact.h): the free
          // and the held equilibria meet there, so the contact force is zero to the location's
          // accuracy, between links two or more apart
          CHECK(field == "none");
          CHECK(!p.contains("jump_to"));
          REQUIRE(p.contains("self_contact"));
          CHECK(!p["self_contact"]["vertex"].get<std::string>().empty());
          CHECK(!p["self_contact"]["edge"].get<std::string>().empty());
          CHECK(std::abs(p["self_contact"]["contact_force"].get<double>()) <= 1e-9);
          REQUIRE(p.contains("contact_point"));
        } else if (type == "BC" || type == "SC") {
          // base / self contact (mechanics/contact_geometry.h): detected, no phenomenon, the
          // touching point on the wall x = 0 for BC
          CHECK(field == "none");
          CHECK(!p.contains("jump_to"));
          REQUIRE(p.contains("contact_point"));
          if (type == "BC" && p["accuracy"]["refined"].get<bool>())
            CHECK(std::abs(p["contact_point"][0].get<double>()) <= 1e-9 * std::max(1.0, std::abs(p["position"]["x"].get<double>())));
        } else {
          FAIL("unknown special point type " << type);
        }
      }
      // jumps (from folds, or the load history's JUMP records) land somewhere else, releasing energy
      for (const json& p : sp["special_points"]) {
        if (!p.contains("jump_to")) continue;
        CHECK((p["type"] == "LP" || p["type"] == "JUMP"));
        CHECK(p["jump_to"]["success"] == true);
        CHECK(p["jump_to"]["energy_released"].get<double>() > 0.0);
        CHECK(p["jump_to"]["distance"].get<double>() > 1e-3);
      }
      fs::remove_all(out);
    }
  }
  (void)closedFormChecks;
}

TEST_CASE("the default scene is the paper's chain with both buckled branches", "[scene]") {
  const fs::path out = allDir("default_check");
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (sceneDir() / "default.json").string();
  opt.out = out.string();
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);
  const json sp = readJson(out / "special_points.json");
  const Closed exact = eq17(0.5, 1.0, 1.0, 2.25);
  bool u = false, z = false;
  for (const json& p : sp["special_points"]) {
    if (p["type"] != "BP") continue;
    const double Fx = p["loads"]["Fx"];
    if (std::abs(Fx - exact.FxU) < 1e-8) {
      u = true;
      CHECK(p["shape"] == "U");
      CHECK(p["stability_before"] == "stable");
    }
    if (std::abs(Fx - exact.FxZ) < 1e-8) z = true;
  }
  CHECK(u);
  CHECK(z);
  // the U branch is supercritical: stable just past Fx_U, with |Fx| rising
  std::ifstream csv(out / "branches.csv");
  std::string line;
  std::getline(csv, line);
  int stableBuckled = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    const double Fx = std::stod(f[4]), q2 = std::stod(f[13]);
    const int stable = std::stoi(f[15]);
    if (f[1] != "0" && std::abs(q2) > 0.05 && Fx < exact.FxU && Fx > exact.FxU - 0.3 && stable == 1) ++stableBuckled;
  }
  CHECK(stableBuckled >= 4);
  fs::remove_all(out);
}
