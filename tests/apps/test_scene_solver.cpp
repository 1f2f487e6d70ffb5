// The scene's `solver` object as the tracer sees it: `location_tolerance` (relative) reaches the
// locator, a looser one is honoured and a tighter one achieved, and bad values are refused with
// the key, the JSON path and the accepted range (exit 2, nothing written).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "scene_run.h"
#include "small_scene.h"
#include "read_output.h"

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

std::string withSolver(const std::string& solver) {
  std::string s = buckle::test::smallScene(0);
  const std::string plots = "\"plots\": []";
  return s.replace(s.find(plots), plots.size(), "\"plots\": [], \"solver\": " + solver);
}

using buckle::test::readJson;

/// The first branch point of the run: its parameter and reported accuracy |Δλ|.
struct Located {
  double lambda, accuracy;
};
Located firstBranchPoint(const fs::path& out) {
  const json sp = readJson(out / "special_points.json");
  for (const json& p : sp["special_points"])
    if (p["type"] == "BP") return {p["parameter"].get<double>(), p["accuracy"]["parameter"].get<double>()};
  FAIL("no branch point");
  return {0.0, 0.0};
}

}  // namespace

TEST_CASE("solver.location_tolerance: a looser one is honoured, a tighter one achieved", "[scene][solver]") {
  Located at[3];
  const double tolerances[3] = {1e-4, 1e-12, 1e-15};
  for (int k = 0; k < 3; ++k) {
    char text[64];
    std::snprintf(text, sizeof text, "{\"location_tolerance\": %g}", tolerances[k]);
    const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_solver", "tol" + std::to_string(k), withSolver(text));
    INFO(o.err);
    REQUIRE(o.rc == 0);
    CHECK(readJson(o.out / "summary.json")["solver"]["location"]["tolerance"].get<double>() == tolerances[k]);
    at[k] = firstBranchPoint(o.out);
    // |Δλ| ≤ tol·max(λ₀, |λ|), λ₀ = 1 in the chain's force unit k̄/b̄ = 1 here
    const double scale = std::max(1.0, std::abs(at[k].lambda));
    CHECK(at[k].accuracy <= tolerances[k] * scale);
  }
  // the same point, to within the looser tolerance
  CHECK(std::abs(at[0].lambda - at[2].lambda) <= 1e-4 * std::max(1.0, std::abs(at[2].lambda)));
  CHECK(std::abs(at[1].lambda - at[2].lambda) <= 1e-12 * std::max(1.0, std::abs(at[2].lambda)));
}

TEST_CASE("solver.location_tolerance: bad values name the key, the path and the range", "[scene][solver]") {
  for (const std::string bad : {"0", "-1e-12", "0.5", "1e-20", "\"tight\"", "true"}) {
    const buckle::test::SceneOutcome o =
        buckle::test::runSceneText("scene_solver", "bad", withSolver("{\"location_tolerance\": " + bad + "}"));
    INFO(bad << ": " << o.err);
    CHECK(o.rc == 2);
    CHECK(o.err.find(o.file.string()) != std::string::npos);
    CHECK(o.err.find("/solver/location_tolerance") != std::string::npos);
    CHECK(!fs::exists(o.out));
    if (bad[0] != '"' && bad != "true") CHECK(o.err.find("[1e-15, 1e-2]") != std::string::npos);
  }
}

TEST_CASE("solver.max_points: a branch that uses them up is said with the keys that move the budget",
          "[scene][solver]") {
  // The small scene with one generation of switching and 20 points a branch: the straight branch
  // (Fx to −1 in steps of at most 0.05, past the U point at −0.706) and the U child both run
  // out; each problem says which key to change, the child's also how to end switched branches
  // there as asked.
  std::string text = buckle::test::smallScene(1);
  const std::string plots = "\"plots\": []";
  text.replace(text.find(plots), plots.size(), "\"plots\": [], \"solver\": {\"max_points\": 20, \"step\": {\"max_step\": 0.05}}");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_solver", "max_points", text);
  INFO(o.err);
  CHECK(o.rc == 1);
  const json summary = readJson(o.out / "summary.json");
  CHECK_FALSE(summary["complete"].get<bool>());
  bool straight = false, child = false;
  for (const json& p : summary["problems"]) {
    const std::string s = p.get<std::string>();
    INFO(s);
    if (s.find("maximum number of points") == std::string::npos) continue;
    CHECK(s.find("raise /solver/max_points to follow it further") != std::string::npos);
    const bool switched = s.find("(BP ") != std::string::npos;
    CHECK((s.find("/analyses/continuation/child_points") != std::string::npos) == switched);
    (switched ? child : straight) = true;
  }
  CHECK(straight);
  CHECK(child);
}
