// The hysteresis scene (issue 5): an unstable straight start that jumps, then snaps at the folds
// of the joints' torque–angle curve under a cycled end torque, each jump a record of its own.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "scene/command.h"
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
