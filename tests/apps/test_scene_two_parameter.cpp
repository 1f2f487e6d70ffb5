// The two_parameter analysis through a scene: critical_curves.csv against eq 17, the
// codimension-two points in special_points.json, the critical_curves plot, and bad input named
// by its JSON path.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "scene/command.h"
#include "scene/output.h"
#include "scene_run.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string twoParameterScene(const std::string& twoParameter, const std::string& chain = R"("a": 0.5, "L0": 2.25)") {
  return R"({
  "description": "two-parameter test chain",
  "chain": {"segments": 3, "b": 1.0, "k": 1.0, )" +
         chain + R"(},
  "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
  "path": {"parameter": "Fx", "from": 0.0, "to": -1.0},
  "analyses": {"two_parameter": )" +
         twoParameter + R"(},
  "plots": ["critical_curves"]
})";
}

using Outcome = buckle::test::SceneOutcome;

Outcome runTwoParameter(const std::string& name, const std::string& text) {
  return buckle::test::runSceneText("scene_two_parameter", name, text);
}

void requireBadTwoParameter(const std::string& name, const std::string& text, const std::string& path,
                     const std::string& expected) {
  const Outcome o = runTwoParameter(name, text);
  INFO(o.err);
  CHECK(o.rc == 2);
  CHECK(o.err.find(": " + path + ": ") != std::string::npos);
  CHECK(o.err.find(expected) != std::string::npos);
  CHECK(!fs::exists(o.out));
}

}  // namespace

TEST_CASE("two_parameter: the BP curve in L0 is eq 17, K0 at b L0 = 2(b^2 - a^2)", "[scene][two_parameter]") {
  const Outcome o = runTwoParameter("good", twoParameterScene(R"({"parameter": "L0", "from": 1.0, "to": 3.0})"));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  std::ifstream csv(o.out / "critical_curves.csv");
  std::string line;
  std::getline(csv, line);
  CHECK(line == "case,curve,type,parameter,mu,lambda,kappa,koiter_a,koiter_b,post_buckling");
  int rows = 0;
  while (std::getline(csv, line)) {
    std::stringstream ss(line);
    std::string f[10];
    for (auto& x : f) std::getline(ss, x, ',');
    CHECK(f[2] == "BP");
    CHECK(f[3] == "L0");
    const double L0 = std::stod(f[4]), Fx = std::stod(f[5]), kappa = L0 - 2.0 * (1.0 - 0.25);
    CHECK(std::abs(Fx - (std::sqrt(21.0) - 14.0) / 10.0 * kappa) <= 1e-11);
    CHECK(std::abs(std::stod(f[6]) - kappa) <= 1e-12);
    // supercritical throughout (the paper's chain, b < 0 and the eigenvalue falls with |Fx|)
    CHECK(f[9] == "supercritical");
    CHECK(std::stod(f[8]) < 0.0);
    ++rows;
  }
  CHECK(rows > 20);
  std::ifstream in(o.out / "special_points.json");
  const json sp = json::parse(in);
  REQUIRE(sp["critical_curves"].size() == 1);
  const json& curve = sp["critical_curves"][0];
  CHECK(curve["type"] == "BP");
  REQUIRE(curve["codim2"].size() == 1);
  CHECK(curve["codim2"][0]["label"] == "K0");
  CHECK(std::abs(curve["codim2"][0]["mu"].get<double>() - 1.5) <= 1e-12);
  CHECK(curve["codim2"][0]["converged"] == true);
  if (!buckle::scene::findGnuplot().empty()) CHECK(fs::exists(o.out / "plots" / "critical_curves.png"));
}

TEST_CASE("two_parameter: a chain off the trivial branch is reported, not crashed on", "[scene][two_parameter]") {
  // unequal preloads bend the unloaded chain: no straight branch to follow (run incomplete, exit 1)
  const Outcome o = runTwoParameter("bent", twoParameterScene(R"({"parameter": "L0", "from": 1.0, "to": 3.0})",
                                      R"("a": 0.5, "L1_0": 2.3, "L2_0": 2.2)"));
  INFO(o.err);
  CHECK(o.rc == 1);
  std::ifstream in(o.out / "summary.json");
  const json summary = json::parse(in);
  CHECK(summary["complete"] == false);
  CHECK(summary.dump().find("not an equilibrium along the load path") != std::string::npos);
}

TEST_CASE("two_parameter: bad input names the key", "[scene][two_parameter]") {
  requireBadTwoParameter("missing_parameter", twoParameterScene(R"({"from": 1.0, "to": 3.0})"), "/analyses/two_parameter/parameter",
                  "missing (required)");
  requireBadTwoParameter("unknown_parameter", twoParameterScene(R"({"parameter": "c", "from": 1.0, "to": 3.0})"),
                  "/analyses/two_parameter/parameter", "not one of a, b, k, L0, dL0");
  requireBadTwoParameter("segment_of_end", twoParameterScene(R"({"parameter": "y", "segment": 1, "from": -1, "to": 1})"),
                  "/analyses/two_parameter/segment", "no segment");
  requireBadTwoParameter("segment_range", twoParameterScene(R"({"parameter": "a", "segment": 4, "from": 0.1, "to": 0.9})"),
                  "/analyses/two_parameter/segment", "expected a segment");
  requireBadTwoParameter("range_without_value", twoParameterScene(R"({"parameter": "L0", "from": 2.5, "to": 3.0})"),
                  "/analyses/two_parameter/from", "expected a range containing L0 = 2.25");
  requireBadTwoParameter("empty_range", twoParameterScene(R"({"parameter": "L0", "from": 3.0, "to": 1.0})"), "/analyses/two_parameter/to",
                  "expected to > from");
  requireBadTwoParameter("no_curve", twoParameterScene(R"({"parameter": "L0", "from": 1.0, "to": 3.0, "modes": 0})"),
                  "/analyses/two_parameter/modes", "no curve asked");
  requireBadTwoParameter("unknown_key", twoParameterScene(R"({"parameter": "L0", "from": 1.0, "to": 3.0, "mode": 1})"),
                  "/analyses/two_parameter/mode", "unknown key");
  requireBadTwoParameter("not_object", twoParameterScene("true"), "/analyses/two_parameter", "expected an object");
}
