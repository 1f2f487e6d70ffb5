// The registry of analyses (apps/scene/analyses.h): the scene parser accepts exactly its keys, the
// docs' table lists exactly them, and a run's computed list and stages follow the registry's order.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "scene/analyses.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "small_scene.h"
#include "scene_run.h"
#include "build_paths.h"

namespace {

using buckle::test::replaceOnce;

using buckle::scene::Analysis;
using buckle::scene::analyses;

std::set<std::string> registryKeys() {
  std::set<std::string> keys;
  for (const Analysis& a : analyses())
    if (a.key) keys.insert(a.key);
  return keys;
}

}  // namespace

TEST_CASE("analyses: docs/scenes.md's analyses table lists exactly the registry's keys", "[scene][analyses]") {
  std::ifstream in(std::string(BUCKLE_SOURCE_DIR) + "/docs/scenes.md");
  REQUIRE(in);
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const size_t from = doc.find("## `analyses`"), to = doc.find("\n## ", from + 1);
  REQUIRE(from != std::string::npos);
  std::set<std::string> documented;
  const std::string table = doc.substr(from, to - from);
  const std::regex row(R"(\n\| `([a-z_]+)` \|)");
  for (std::sregex_iterator it(table.begin(), table.end(), row), end; it != end; ++it) documented.insert((*it)[1]);
  CHECK(documented == registryKeys());
}

TEST_CASE("analyses: every registered key is accepted, any other key is refused naming the accepted ones",
          "[scene][analyses]") {
  const std::string base = buckle::test::smallScene(0);
  for (const std::string& key : registryKeys()) {
    // an unknown key inside a registered block is refused at that block's path: the key reached its parser
    const std::string text =
        replaceOnce(base, R"("analyses": {"continuation": {"branch_switching": 0}})", R"("analyses": {")" + key + R"(": {"bogus": 1}})");
    INFO(key);
    try {
      buckle::scene::parseScene(text, "registry.json");
      FAIL("accepted an unknown option of " << key);
    } catch (const buckle::scene::SceneError& e) {
      CHECK(std::string(e.what()).find("/analyses/" + key) != std::string::npos);
    }
  }
  const std::string bad = replaceOnce(base, R"("analyses": {)", R"("analyses": {"frobnicate": true, )");
  try {
    buckle::scene::parseScene(bad, "registry.json");
    FAIL("accepted /analyses/frobnicate");
  } catch (const buckle::scene::SceneError& e) {
    const std::string what = e.what();
    CHECK(what.find("frobnicate") != std::string::npos);
    for (const std::string& key : registryKeys()) CHECK(what.find(key) != std::string::npos);
  }
}

TEST_CASE("analyses: a run's computed list and stage timings follow the registry's order", "[scene][analyses]") {
  // continuation, critical forces, torque-angle curves and stiffness: stages torque_angle,
  // critical_forces, continuation in the registry's order; stiffness computed within the continuation
  std::string text = replaceOnce(buckle::test::smallScene(0), R"("analyses": {)",
                                 R"("analyses": {"stiffness": true, "critical_forces": true, "torque_angle": true, )");
  const buckle::scene::Scene scene = buckle::scene::parseScene(text, "registry.json");
  const buckle::scene::RunResult run = buckle::scene::runScene(scene);
  std::vector<std::string> stages, expectedStages, expectedComputed;
  for (const auto& [stage, seconds] : run.timings) stages.push_back(stage);
  for (const Analysis& a : analyses())
    if (a.asked(scene.analyses)) {
      expectedComputed.push_back(a.computed(scene));
      if (a.stage) expectedStages.push_back(a.stage);
    }
  CHECK(stages == expectedStages);
  CHECK(stages == std::vector<std::string>{"torque_angle", "critical_forces", "continuation"});
  CHECK(run.computed == expectedComputed);
  CHECK(run.computed.size() == 4);
  // the stages that ran left their results: critical loads, the torque curve, branches with K_F
  REQUIRE(run.cases.size() == 1);
  CHECK(run.cases[0].haveCritical);
  CHECK(run.cases[0].haveTorque);
  REQUIRE(!run.cases[0].points.empty());
  CHECK(run.cases[0].points.front().haveStiffness);
}
