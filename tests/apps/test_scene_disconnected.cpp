// The branches through the equilibria the continuation's tree does not reach (equilibria
// "branches", docs/scenes.md), read back from the files `buckle run` writes for the scene
// data/scenes/disconnected_branch.json: the disconnected branch in branches.csv crosses the
// analysis value at the equilibria equilibria.csv assigns to it, the tree's branch never comes
// near the stable one it misses, the plots draw and key it; bad options exit 2 naming the path.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "rfc4180.h"
#include "scene_run.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rows of a CSV file as maps column -> text.
std::vector<std::map<std::string, std::string>> rows(const fs::path& file) {
  const auto cells = buckle::test::readCsv(readText(file));
  std::vector<std::map<std::string, std::string>> out;
  for (size_t r = 1; r < cells.size(); ++r) {
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < cells[0].size() && c < cells[r].size(); ++c) row[cells[0][c]] = cells[r][c];
    out.push_back(row);
  }
  return out;
}

double num(const std::map<std::string, std::string>& row, const std::string& key) { return std::stod(row.at(key)); }

}  // namespace

TEST_CASE("scene disconnected branches: the branch through the missed equilibria, in every output",
          "[scene][equilibria][disconnected]") {
  const std::string text = readText(fs::path(BUCKLE_SOURCE_DIR) / "data/scenes/disconnected_branch.json");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_disconnected", "scene", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const double at = json::parse(text)["analyses"]["equilibria"]["at"].get<double>();

  // summary.json: the tree's branch, then the disconnected ones with their seed
  const json summary = json::parse(readText(o.out / "summary.json"));
  const json& branches = summary["cases"][0]["branches"];
  std::map<int, int> seedOf;  // disconnected branch id -> rank of its seed
  for (const json& b : branches)
    if (b.contains("from_equilibrium")) seedOf[b["id"].get<int>()] = b["from_equilibrium"].get<int>();
  REQUIRE(seedOf.size() == 2);
  CHECK(seedOf.count(0) == 0);

  const auto eq = rows(o.out / "equilibria.csv");
  const auto points = rows(o.out / "branches.csv");
  REQUIRE(eq.size() == 3);
  int stableOff = 0;
  for (size_t k = 0; k < eq.size(); ++k) {
    INFO("equilibrium " << k + 1);
    REQUIRE(!eq[k].at("branch").empty());
    const int branch = std::stoi(eq[k].at("branch"));
    const bool disconnected = seedOf.count(branch) > 0;
    if (disconnected && eq[k].at("stable") == "1") ++stableOff;
    if (disconnected) CHECK(seedOf.at(branch) == 2);  // the stable one missed: rank 2 (ascending Π)
    // the branch named crosses Fx = at where the equilibrium is: the chord through at, linearly
    // interpolated, within a tenth of the chord's own length in q
    double best = INFINITY;
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const auto &a = points[i], &b = points[i + 1];
      if (std::stoi(a.at("branch")) != branch || std::stoi(b.at("branch")) != branch) continue;
      const double la = num(a, "parameter") - at, lb = num(b, "parameter") - at;
      if (la * lb > 0.0 || la == lb) continue;
      const double w = la / (la - lb);
      double d = 0.0, chord = 0.0;
      for (const char* q : {"q1", "q2", "q3"}) {
        d = std::max(d, std::abs(num(a, q) + w * (num(b, q) - num(a, q)) - num(eq[k], q)));
        chord = std::max(chord, std::abs(num(b, q) - num(a, q)));
      }
      if (d <= 0.1 * chord + 1e-12) best = std::min(best, d);
    }
    CHECK(std::isfinite(best));
    // the tree's branch (0) never comes near a disconnected equilibrium at any parameter value
    if (disconnected) {
      double nearest = INFINITY;
      for (const auto& p : points)
        if (p.at("branch") == "0")
          nearest = std::min(nearest, std::abs(num(p, "q1") - num(eq[k], "q1")) + std::abs(num(p, "parameter") - at));
      CHECK(nearest > 0.5);
    }
  }
  CHECK(stableOff == 1);

  // its fold is a special point of the disconnected branch, between the analysis value and 0
  const json sp = json::parse(readText(o.out / "special_points.json"));
  int folds = 0;
  for (const json& s : sp["special_points"])
    if (s["type"] == "LP") {
      ++folds;
      CHECK(seedOf.count(s["branch"].get<int>()) == 1);
      CHECK(s["parameter"].get<double>() > at);
      CHECK(s["parameter"].get<double>() < 0.0);
    }
  CHECK(folds == 1);
  for (const json& e : sp["equilibria"][0]["equilibria"]) CHECK(e["branch"].is_number_integer());

  // plots: the disconnected branch keyed in its own colour; one shape panel per equilibrium,
  // the stable ones marked
  const std::string bif = readText(o.out / "plots" / "bifurcation_body.gp");
  CHECK(bif.find("disconnected branch") != std::string::npos);
  const std::string shapes = readText(o.out / "plots" / "equilibrium_shapes_body.gp");
  size_t titles = 0, stable = 0;
  for (size_t p = shapes.find("set title"); p != std::string::npos; p = shapes.find("set title", p + 1)) ++titles;
  for (size_t p = shapes.find("STABLE"); p != std::string::npos; p = shapes.find("STABLE", p + 1)) ++stable;
  CHECK(titles == 3);
  CHECK(stable == 2);
}

TEST_CASE("scene disconnected branches at a list of values: a later set on an earlier set's branch seeds nothing",
          "[scene][equilibria][disconnected]") {
  json doc = json::parse(readText(fs::path(BUCKLE_SOURCE_DIR) / "data/scenes/disconnected_branch.json"));
  doc["analyses"]["equilibria"]["at"] = json::array({-1.0, -1.3});
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_disconnected", "at_list", doc.dump());
  INFO(o.err);
  REQUIRE(o.rc == 0);
  // the same two disconnected branches as from -1 alone, both seeded by the set at -1
  const json summary = json::parse(readText(o.out / "summary.json"));
  std::map<int, double> seedAt;
  for (const json& b : summary["cases"][0]["branches"])
    if (b.contains("from_equilibrium")) seedAt[b["id"].get<int>()] = b["from_equilibrium_at"].get<double>();
  REQUIRE(seedAt.size() == 2);
  for (const auto& [id, value] : seedAt) CHECK(value == -1.0);
  // every equilibrium at -1.3 lies on a branch already traced, which crosses Fx = -1.3 there
  const json sp = json::parse(readText(o.out / "special_points.json"));
  REQUIRE(sp["equilibria"].size() == 2);
  const json& later = sp["equilibria"][1];
  CHECK(later["at"].get<double>() == -1.3);
  REQUIRE(later["count"].get<int>() == 3);
  const auto points = rows(o.out / "branches.csv");
  for (const json& e : later["equilibria"]) {
    REQUIRE(e["branch"].is_number_integer());
    const int branch = e["branch"].get<int>();
    CHECK((branch == 0 || seedAt.count(branch) == 1));
    double best = INFINITY;
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const auto &a = points[i], &b = points[i + 1];
      if (std::stoi(a.at("branch")) != branch || std::stoi(b.at("branch")) != branch) continue;
      const double la = num(a, "parameter") + 1.3, lb = num(b, "parameter") + 1.3;
      if (la * lb > 0.0 || la == lb) continue;
      const double w = la / (la - lb);
      double d = 0.0;
      for (int q = 0; q < 3; ++q) {
        const std::string name = "q" + std::to_string(q + 1);
        d = std::max(d, std::abs(num(a, name) + w * (num(b, name) - num(a, name)) - e["q"][size_t(q)].get<double>()));
      }
      best = std::min(best, d);
    }
    CHECK(best < 0.05);
  }
}

TEST_CASE("scene disconnected branches: bad options name the JSON path, exit 2, nothing written",
          "[scene][equilibria][disconnected]") {
  const std::string chain = R"("chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},)";
  struct Bad {
    std::string name, text, path;
  };
  for (const Bad& b : std::vector<Bad>{
           {"not_bool", "{" + chain + R"("end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
             "path": {"parameter": "Fx", "from": 0.0, "to": -1.0},
             "analyses": {"continuation": true, "equilibria": {"branches": "yes"}}})",
            "/analyses/equilibria/branches"},
           {"no_continuation", "{" + chain + R"("end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
             "path": {"parameter": "Fx", "from": 0.0, "to": -1.0},
             "analyses": {"equilibria": {"branches": true}}})",
            "/analyses/equilibria/branches"},
           {"through_reaction", "{" + chain + R"("end": {"x": {"held": "start"}, "y": {"held": 0.0}, "phi": "free"},
             "path": {"parameter": "x", "from": 6.0, "to": 5.0, "load_limit": 2.0},
             "analyses": {"continuation": true, "equilibria": {"branches": true}}})",
            "/analyses/equilibria/branches"}}) {
    INFO(b.name);
    const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_disconnected", b.name, b.text);
    CHECK(o.rc == 2);
    CHECK(o.err.find(b.path) != std::string::npos);
    CHECK(!fs::exists(o.out));
  }
}
