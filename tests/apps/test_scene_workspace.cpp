// /analyses/workspace's axes along a direction in control space (scene_workspace.cpp, issue 29): an
// axis L1_0 of segment 1 moving L2_0 of segment 1 one for one is the axis L0 of segment 1 — the
// same workspace_map.csv but its input name column — and bad directions name their JSON path.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "read_output.h"
#include "scene_run.h"

namespace fs = std::filesystem;

namespace {

std::string workspaceScene(const std::string& first) {
  return R"({"units": "nondimensional", "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": -0.3}, "y": {"load": -0.3}, "phi": "free"},
    "analyses": {"workspace": {"first": )" +
         first + R"(, "second": {"input": "dL0", "segment": 3, "from": -1.5, "to": 1.5, "count": 9}}},
    "plots": [], "solver": {"step": {"max_step": 0.05}}})";
}

// workspace_map.csv without its input1 column (the axis's name).
std::string withoutInputName(const std::string& csv) {
  std::istringstream in(csv);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) {
    const size_t a = line.find(','), b = line.find(',', a + 1);
    out << line.substr(0, a) << line.substr(b) << "\n";
  }
  return out.str();
}

}  // namespace

TEST_CASE("workspace scene: an axis along a direction equal to a named input gives that input's map",
          "[scene][workspace]") {
  const auto named = buckle::test::runSceneText(
      "workspace_scene", "named", workspaceScene(R"({"input": "L0", "segment": 1, "from": 1.8, "to": 2.7, "count": 7})"));
  INFO(named.err);
  REQUIRE(named.rc == 0);
  const auto along = buckle::test::runSceneText(
      "workspace_scene", "along",
      workspaceScene(
          R"({"input": "L1_0", "segment": 1, "direction": {"L2_0": [1, 0, 0]}, "from": 1.8, "to": 2.7, "count": 7})"));
  INFO(along.err);
  REQUIRE(along.rc == 0);
  const std::string a = buckle::test::readText(named.out / "workspace_map.csv");
  const std::string b = buckle::test::readText(along.out / "workspace_map.csv");
  CHECK(a.find(",L0[1],") != std::string::npos);
  CHECK(b.find(",L1_0[1] + (1 0 0) L2_0,") != std::string::npos);
  CHECK(withoutInputName(a) == withoutInputName(b));
  CHECK(std::count(a.begin(), a.end(), '\n') == 1 + 7 * 9);
}

TEST_CASE("workspace scene: bad directions name their JSON path", "[scene][workspace][errors]") {
  struct Case {
    const char* name;
    const char* first;
    const char* pointer;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"key", R"({"input": "L0", "direction": {"Fy": 1}, "from": 2, "to": 2.5})", "/analyses/workspace/first/direction/Fy",
       "allowed here: dL0"},
      {"own", R"({"input": "L0", "direction": {"L0": 1}, "from": 2, "to": 2.5})", "/analyses/workspace/first/direction/L0",
       "L0's own rate is 1"},
      {"list", R"({"input": "L1_0", "direction": {"L2_0": [1, 2]}, "from": 2, "to": 2.5})",
       "/analyses/workspace/first/direction/L2_0", "a list of 3 rates"},
      {"type", R"({"input": "L1_0", "direction": {"L2_0": "fast"}, "from": 2, "to": 2.5})",
       "/analyses/workspace/first/direction/L2_0", "number"},
      // dL0 of segment 3 moves L1_0 of segment 3, and with it the mean L1_0 of every segment
      {"dependent", R"({"input": "L1_0", "direction": {"L2_0": 1}, "from": 2, "to": 2.5})",
       "/analyses/workspace/second/input", "not independent"},
  };
  for (const Case& cs : cases) {
    INFO(cs.name);
    const auto o = buckle::test::runSceneText("workspace_scene", cs.name, workspaceScene(cs.first));
    INFO(o.err);
    CHECK(o.rc == 2);
    CHECK(o.err.find(": " + std::string(cs.pointer) + ": ") != std::string::npos);
    CHECK(o.err.find(cs.expected) != std::string::npos);
    CHECK(!fs::exists(o.out));
  }
}
