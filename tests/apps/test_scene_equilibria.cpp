// The equilibria analysis of a scene (docs/scenes.md): the list in special_points.json and
// equilibria.csv equal the library's allEquilibria at the case's end condition moved to `at`;
// bad options rejected with exit code 2, the JSON path named and nothing written.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "buckle/mechanics/all_equilibria.h"
#include "scene_run.h"
#include "read_output.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string equilibriaScene(const std::string& equilibria, bool withPath = true) {
  return std::string(R"({"units": "nondimensional",
    "chain": {"segments": 4, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},)") +
         (withPath ? R"("path": {"parameter": "Fx", "from": -1.2, "to": 0.0},)" : "") +
         R"("analyses": {"equilibria": )" + equilibria + "}}";
}

using buckle::test::readJson;

int csvRows(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  int rows = -1;  // the header
  while (std::getline(in, line)) ++rows;
  return rows;
}

// The library's list for the scene's four-segment clamped-pinned chain at Fx (the scene's options:
// 24 random starts, seed 3; the case's unloaded shape as a start, as the case runner adds it).
buckle::mechanics::AllEquilibria libraryEquilibria(double Fx) {
  using namespace buckle::mechanics;
  AllEquilibriaOptions options;
  options.randomStarts = 24;
  options.seed = 3;
  options.starts.push_back(Eigen::VectorXd::Zero(4));
  return allEquilibria(Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                       EndCondition::clampedPinned(Fx), options);
}

}  // namespace

TEST_CASE("scene equilibria: the list at `at` is the library's, in special_points.json and the CSV",
          "[scene][equilibria]") {
  const buckle::test::SceneOutcome o =
      buckle::test::runSceneText("scene_equilibria", "at", equilibriaScene(R"({"starts": 24, "seed": 3, "at": -0.9})"));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const json sp = readJson(o.out / "special_points.json");
  REQUIRE(sp["equilibria"].size() == 1);
  const json& c = sp["equilibria"][0];
  CHECK(c["at"].get<double>() == -0.9);
  CHECK(c["held"] == json::array({"y"}));

  using namespace buckle::mechanics;
  const AllEquilibria lib = libraryEquilibria(-0.9);
  REQUIRE(c["count"].get<size_t>() == lib.equilibria.size());
  CHECK(c["starts"].get<int>() == lib.starts);
  CHECK(c["method"] == lib.method);
  for (size_t k = 0; k < lib.equilibria.size(); ++k) {
    const json& e = c["equilibria"][k];
    const FoundEquilibrium& f = lib.equilibria[k];
    CHECK(e["potential"].get<double>() == Approx(f.potential).epsilon(1e-12).margin(1e-14));
    CHECK(e["index"].get<int>() == f.index);
    CHECK(e["stable"].get<bool>() == f.stable);
    CHECK(e["loads"]["Fx"].get<double>() == -0.9);  // the given load, at `at`
    CHECK(e["reactions"]["Fy"].get<double>() == Approx(f.reactions[0]).margin(1e-12));
    for (int i = 0; i < 4; ++i) CHECK(e["q"][size_t(i)].get<double>() == Approx(f.q[i]).margin(1e-12));
  }
  CHECK(csvRows(o.out / "equilibria.csv") == int(lib.equilibria.size()));
}

TEST_CASE("scene equilibria: a list `at`, one complete set per value, each the library's at that load",
          "[scene][equilibria]") {
  const std::vector<double> at{-0.2, -0.9, -1.1};
  const buckle::test::SceneOutcome o = buckle::test::runSceneText(
      "scene_equilibria", "at_list", equilibriaScene(R"({"starts": 24, "seed": 3, "at": [-0.2, -0.9, -1.1]})"));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const json sp = readJson(o.out / "special_points.json");
  REQUIRE(sp["equilibria"].size() == at.size());

  using namespace buckle::mechanics;
  std::vector<int> straightIndex;  // the straight chain's index in each set (-1: not found)
  size_t rows = 0;
  for (size_t s = 0; s < at.size(); ++s) {
    INFO("Fx = " << at[s]);
    const json& c = sp["equilibria"][s];
    CHECK(c["at"].get<double>() == at[s]);
    const AllEquilibria lib = libraryEquilibria(at[s]);
    REQUIRE(c["count"].get<size_t>() == lib.equilibria.size());
    rows += lib.equilibria.size();
    straightIndex.push_back(-1);
    for (const FoundEquilibrium& f : lib.equilibria)
      if (f.q.cwiseAbs().maxCoeff() < 1e-9) straightIndex.back() = f.index;
    for (size_t k = 0; k < lib.equilibria.size(); ++k) {
      const json& e = c["equilibria"][k];
      CHECK(e["loads"]["Fx"].get<double>() == at[s]);
      CHECK(e["index"].get<int>() == lib.equilibria[k].index);
      for (int i = 0; i < 4; ++i)
        CHECK(e["q"][size_t(i)].get<double>() == Approx(lib.equilibria[k].q[i]).margin(1e-12));
    }
  }
  // the straight chain is in every set: stable below the first critical load, unstable past it
  CHECK(straightIndex.front() == 0);
  CHECK(straightIndex.back() >= 1);
  // equilibria.csv: one row per equilibrium, the set's value in `at`, ranks from 1 in each set
  std::ifstream in(o.out / "equilibria.csv");
  std::string line;
  std::getline(in, line);
  CHECK(line.rfind("case,at,rank,", 0) == 0);
  std::vector<int> perSet(at.size(), 0);
  size_t read = 0;
  while (std::getline(in, line)) {
    ++read;
    std::istringstream cells(line);
    std::string cell, value, rank;
    std::getline(cells, cell, ',');
    std::getline(cells, value, ',');
    std::getline(cells, rank, ',');
    size_t s = 0;
    while (s < at.size() && std::stod(value) != at[s]) ++s;
    REQUIRE(s < at.size());
    CHECK(std::stoi(rank) == ++perSet[s]);
  }
  CHECK(read == rows);
}

TEST_CASE("scene equilibria: bad options name the JSON path, exit 2, nothing written", "[scene][equilibria]") {
  struct Bad {
    std::string name, value, path;
    bool withPath;
  };
  for (const Bad& b : std::vector<Bad>{{"starts", R"({"starts": -1})", "/analyses/equilibria/starts", true},
                                       {"seed", R"({"seed": 1.5})", "/analyses/equilibria/seed", true},
                                       {"key", R"({"stars": 3})", "/analyses/equilibria/stars", true},
                                       {"type", R"("yes")", "/analyses/equilibria", true},
                                       {"at_range", R"({"at": -2.0})", "/analyses/equilibria/at", true},
                                       {"at_empty", R"({"at": []})", "/analyses/equilibria/at", true},
                                       {"at_list_range", R"({"at": [-0.5, -2.0]})", "/analyses/equilibria/at/1", true},
                                       {"at_list_type", R"({"at": [-0.5, "x"]})", "/analyses/equilibria/at/1", true},
                                       {"at_path", R"({"at": -0.5})", "/path", false}}) {
    INFO(b.name);
    const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_equilibria", b.name, equilibriaScene(b.value, b.withPath));
    CHECK(o.rc == 2);
    CHECK(o.err.find(b.path) != std::string::npos);
    CHECK(!fs::exists(o.out));
  }
  // no path needed without `at`: the end condition as given
  const buckle::test::SceneOutcome ok = buckle::test::runSceneText("scene_equilibria", "no_path", equilibriaScene("true", false));
  INFO(ok.err);
  CHECK(ok.rc == 0);
}

TEST_CASE("scene equilibria on a control path: the chain with its free lengths at `at`", "[scene][equilibria]") {
  // dL0 of every segment as the path, the payload held: the equilibria at dL0 = 0.6 are those of
  // the chain built with L1_0 = 2.25 + 0.3, L2_0 = 2.25 − 0.3 under the same loads (a plain scene).
  const std::string ends = R"("end": {"x": {"load": -0.3}, "y": {"load": -0.3}, "phi": "free"},)";
  const std::string options = R"({"starts": 24, "seed": 3, "at": 0.6})";
  const buckle::test::SceneOutcome controlled = buckle::test::runSceneText(
      "scene_equilibria", "control",
      std::string(R"({"chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},)") + ends +
          R"("path": {"parameter": "dL0", "from": -1.0, "to": 1.0}, "analyses": {"equilibria": )" + options + "}}");
  INFO(controlled.err);
  REQUIRE(controlled.rc == 0);
  const buckle::test::SceneOutcome built = buckle::test::runSceneText(
      "scene_equilibria", "built",
      std::string(R"({"chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L1_0": 2.55, "L2_0": 1.95},)") + ends +
          R"("analyses": {"equilibria": {"starts": 24, "seed": 3}}})");
  INFO(built.err);
  REQUIRE(built.rc == 0);
  const json a = readJson(controlled.out / "special_points.json")["equilibria"][0];
  const json b = readJson(built.out / "special_points.json")["equilibria"][0];
  REQUIRE(a["count"].get<int>() == b["count"].get<int>());
  REQUIRE(a["count"].get<int>() >= 1);
  for (size_t k = 0; k < a["equilibria"].size(); ++k) {
    const json &e = a["equilibria"][k], &f = b["equilibria"][k];
    CHECK(e["potential"].get<double>() == Approx(f["potential"].get<double>()).epsilon(1e-10).margin(1e-12));
    CHECK(e["index"] == f["index"]);
    for (int i = 0; i < 3; ++i)
      CHECK(e["q"][size_t(i)].get<double>() == Approx(f["q"][size_t(i)].get<double>()).margin(1e-10));
  }
}
