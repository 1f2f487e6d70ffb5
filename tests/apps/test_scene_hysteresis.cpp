// The hysteresis scene (issue 5): an unstable straight start that jumps, then snaps at the folds
// of the joints' torque–angle curve under a cycled end torque, each jump a record of its own;
// and a load history held at the base wall.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>

#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/wall_contact.h"
#include "scene/command.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "scene_run.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Every joint carries M(q) + Me = 0 (eq 9 with only Me), M(q) = 2k[(b² − a²) sin q − b L0 sin(q/2)]
// (eq 10): the stable branch ends where dM/dq = 0, c = cos(q/2) solving
// 2(b² − a²)c² − (b L0/2)c − (b² − a²) = 0, at |Me| = |M(q)|.
double foldTorque(double a, double b, double k, double L0) {
  const double A = 2 * (b * b - a * a), B = -0.5 * b * L0, C = -(b * b - a * a);
  const double c = (-B + std::sqrt(B * B - 4 * A * C)) / (2 * A);
  const double q = 2 * std::acos(c);
  return std::abs(2 * k * ((b * b - a * a) * std::sin(q) - b * L0 * std::sin(q / 2)));
}

}  // namespace

TEST_CASE("hysteresis scene: unstable start jumps, then two snaps at the closed-form folds", "[scene]") {
  const fs::path out = buckle::test::absentPath("hysteresis", "out");
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / "hysteresis.json").string();
  opt.out = out.string();
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);
  std::ifstream in(out / "special_points.json");
  const json sp = json::parse(in);
  const double Mfold = foldTorque(0.5, 1.0, 1.0, 1.2);
  int start = 0, up = 0, down = 0;
  for (const json& p : sp["special_points"]) {
    if (p["type"] != "JUMP") continue;
    CHECK(p["field"] == "jumping");
    const json& j = p["jump_to"];
    CHECK(j["success"] == true);
    CHECK(double(j["energy_released"]) > 0.0);
    const double at = p["parameter"];
    if (std::abs(at) < 1e-12) {
      ++start;
      continue;
    }
    // released just past the fold (overshoot 1e-6 of the load)
    CHECK(std::abs(at) == Approx(Mfold).epsilon(1e-5));
    // it snaps to the mirrored shape: the end rotation changes sign
    CHECK(double(p["position"]["phi"]) * double(j["position"]["phi"]) < 0.0);
    (at > 0 ? up : down)++;
  }
  CHECK(start == 1);
  CHECK(up == 1);
  CHECK(down == 1);
  fs::remove_all(out);
}

TEST_CASE("load history with the wall: its pieces are held on the base wall between contact and release, as the "
          "continuation's branch",
          "[scene][wall]") {
  // contact_release's curled chain (data/scenes/contact_release.json), Fy up to 0.13 and back: the
  // history's pieces hold segment 5's distal corner on the wall from WC (Fy = 0.110) to the
  // waypoint and back down to WR at the same load; without "wall" they pass through it (BC).
  const std::string text = R"({
    "chain": {"segments": [{"q0": 0.2, "q_min": 0.1}, {"q0": 1.3}, {"q0": 1.3}, {"q0": 1.3}, {"q0": 1.3}],
              "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": "free", "y": {"load": 0.0}, "phi": "free"},
    "path": {"parameter": "Fy", "from": 0.0, "to": 1.0},
    "analyses": {"continuation": {"wall": true}, "load_history": {"waypoints": [0.0, 0.13, 0.0]}},
    "solver": {"step": {"initial_step": 0.01, "max_step": 0.02}}, "plots": []
  })";
  const buckle::test::SceneOutcome r = buckle::test::runSceneText("scene_hysteresis", "wall", text);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  namespace mech = buckle::mechanics;
  const buckle::scene::RunResult run = buckle::scene::runScene(buckle::scene::loadScene(r.file.string()));
  REQUIRE(run.cases.size() == 1);
  const buckle::scene::CaseResult& c = run.cases.front();
  std::set<int> history;
  for (const buckle::scene::BranchRecord& b : c.branches)
    if (b.origin.rfind("load history", 0) == 0) history.insert(b.id);
  REQUIRE(history.size() == 2);
  const double L = c.chain.linkLengths().sum();
  const mech::WallVertex v{4, 4};
  int onWall = 0;
  for (const mech::PointReport& p : c.points) {
    if (!history.count(p.branch)) continue;
    INFO("branch " << p.branch << ", Fy = " << p.parameter);
    CHECK(mech::nearestWallVertex(c.chain, p.q).distance >= -1e-12 * L);
    if (p.locked.wallCount() == 0) continue;
    ++onWall;
    REQUIRE(p.locked.wallCount() == 1);
    CHECK(p.locked.wall()[0] == v);
    REQUIRE(p.wallForces.size() == 1);
    CHECK(p.wallForces[0] >= -1e-12);
    CHECK(p.stable);
  }
  CHECK(onWall >= 4);
  // the wall events on the history's pieces, at the continuation's WC; no pass through the wall
  double contact = 0.0;
  int wc = 0, wr = 0;
  for (const buckle::scene::SpecialPointResult& s : c.specials) {
    if (!history.count(s.branch)) {
      if (s.type == mech::EventType::WallContact) contact = s.lambda;
      continue;
    }
    CHECK(s.type != mech::EventType::BaseContact);
    wc += s.type == mech::EventType::WallContact;
    wr += s.type == mech::EventType::WallRelease;
  }
  CHECK(wc == 1);
  CHECK(wr == 1);
  for (const buckle::scene::SpecialPointResult& s : c.specials)
    if (history.count(s.branch) && (s.type == mech::EventType::WallContact || s.type == mech::EventType::WallRelease))
      CHECK(s.lambda == Approx(contact).epsilon(1e-10));
  std::filesystem::remove_all(r.file.parent_path());
}
