// Control paths in a scene (issue 29, scene_control.cpp): "path": {"parameter": "dL0", …} traces
// the chain under the /end payload as its control inputs change. The scene's folds against the
// library's own control path, its start against the payload applied by a load path, the same
// scene in scaled units, and bad input (exit 2, the JSON path and the accepted range).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "scene_run.h"
#include "read_output.h"

namespace fs = std::filesystem;
using nlohmann::json;
namespace mech = buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The actuation scene's chain with lengths ×L, stiffness ×k and the payload ×kL.
std::string actuationScene(double L, double k, const std::string& path, const std::string& analyses) {
  const auto num = [](double v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
  };
  return R"({
  "chain": {"segments": 3, "a": )" + num(0.5 * L) + R"(, "b": )" + num(L) + R"(, "k": )" + num(k) + R"(, "L0": )" +
         num(2.25 * L) + R"(},
  "end": {"x": {"load": )" + num(-0.3 * k * L) + R"(}, "y": {"load": )" + num(-0.3 * k * L) + R"(}, "phi": "free"},
  "path": )" + path + R"(,
  "analyses": )" + analyses + R"(,
  "plots": []
})";
}

const std::string kPath = R"({"parameter": "dL0", "from": -3.0, "to": 3.0})";
const std::string kContinuation = R"({"continuation": {}})";

using buckle::test::readJson;

std::vector<double> foldParameters(const fs::path& out) {
  std::vector<double> lp;
  const json all = readJson(out / "special_points.json");  // kept alive through the loop
  for (const json& p : all["special_points"])
    if (p["type"] == "LP") lp.push_back(p["parameter"]);
  return lp;
}

}  // namespace

TEST_CASE("control path scene: the start under the payload and the folds of the library's dL0 path", "[scene]") {
  const buckle::test::SceneOutcome o =
      buckle::test::runSceneText("control_path", "run", actuationScene(1.0, 1.0, kPath, kContinuation));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  // the start: the straight chain loaded along λ·payload, λ: 0 → 1
  const mech::Chain chain = mech::Chain::uniform(3, mech::SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
  mech::EquilibriumProblem ramp(chain, mech::EndCondition::freeEnd(), payload);
  cont::TracerOptions to;
  to.lambdaMin = -1.0;
  to.lambdaMax = 1.0;
  to.detection.stability = true;
  const cont::Branch loading =
      cont::trace(ramp, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), to);
  REQUIRE(loading.stopReason == cont::StopReason::LambdaRange);
  const json c = readJson(o.out / "summary.json")["cases"][0];
  CHECK(double(c["start_parameter"]) == 0.0);  // dL0 of the scene's chain
  REQUIRE(c.contains("start_q"));
  for (int i = 0; i < 3; ++i) CHECK(double(c["start_q"][i]) == Approx(loading.points.back().u[i]).margin(1e-8));
  CHECK(!c.contains("start_note"));  // the loading does not snap

  // the folds: the library's own dL0 path from that start, both ways
  mech::EquilibriumProblem actuated(chain, mech::EndCondition::freeEnd(payload), Eigen::Vector3d::Zero(), {},
                                    mech::ControlDirection::named(3, mech::ControlInput::dL0));
  to.lambdaMin = -3.0;
  to.lambdaMax = 3.0;
  std::vector<double> expected;
  for (const cont::InitialDirection& d : {cont::InitialDirection::decreasingLambda()}) {
    const cont::Branch b = cont::trace(actuated, loading.points.back().u, 0.0, d, to);
    for (const cont::SpecialPoint* sp : b.specialPointsOfType(cont::SpecialPointType::Fold)) expected.push_back(sp->lambda);
  }
  REQUIRE(expected.size() == 2);  // snap-through under actuation at dL0 ≈ −2.45, the way back at ≈ 0.995
  const std::vector<double> lp = foldParameters(o.out);
  REQUIRE(lp.size() == 2);
  for (double e : expected) {
    bool found = false;
    for (double v : lp) found = found || std::abs(v - e) <= 1e-9;
    CHECK(found);
  }
}

TEST_CASE("control path scene in scaled units (lengths x 1e4, stiffness x 1e-8): folds scale as lengths", "[scene]") {
  const std::string path = R"({"parameter": "dL0", "from": -30000, "to": 30000})";
  const buckle::test::SceneOutcome ref =
      buckle::test::runSceneText("control_path", "ref", actuationScene(1.0, 1.0, kPath, kContinuation));
  const buckle::test::SceneOutcome scaled =
      buckle::test::runSceneText("control_path", "scaled", actuationScene(1e4, 1e-8, path, kContinuation));
  INFO(ref.err << scaled.err);
  REQUIRE(ref.rc == 0);
  REQUIRE(scaled.rc == 0);
  const std::vector<double> a = foldParameters(ref.out), b = foldParameters(scaled.out);
  REQUIRE(a.size() == 2);
  REQUIRE(b.size() == a.size());
  for (size_t i = 0; i < a.size(); ++i) CHECK(b[i] == Approx(1e4 * a[i]).epsilon(1e-9));
}

TEST_CASE("control path scene: a payload that snaps the chain while it is applied is said so", "[scene]") {
  // κ < 0 (L0 = 1.2): the straight unloaded start is unstable, the payload's loading jumps at once
  const std::string text = R"({
  "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 1.2},
  "end": {"x": {"load": 0.0}, "y": {"load": 0.0}, "phi": {"load": 0.05}},
  "path": {"parameter": "L0", "from": 1.0, "to": 1.4},
  "analyses": {"continuation": {}},
  "plots": []
})";
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("control_path", "snap", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const json c = readJson(o.out / "summary.json")["cases"][0];
  CHECK(double(c["start_parameter"]) == Approx(1.2).epsilon(1e-15));
  REQUIRE(c.contains("start_note"));
  CHECK(std::string(c["start_note"]).find("snapped") != std::string::npos);
}

TEST_CASE("control path scene: bad input names the key, the path and the accepted range (exit 2)", "[scene][errors]") {
  struct Case {
    const char* name;
    std::string path, analyses;
    const char* pointer;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"unknown", R"({"parameter": "dL1", "from": -1, "to": 1})", kContinuation, "/path/parameter",
       "a control input L1_0, L2_0, L0, dL0"},
      {"segment", R"({"parameter": "dL0", "segment": 4, "from": -1, "to": 1})", kContinuation, "/path/segment",
       "an integer in [1, 3]"},
      {"free_length", R"({"parameter": "dL0", "from": -5, "to": 1})", kContinuation, "/path/from",
       "expected a value in (-4.5, 4.5)"},
      {"start", R"({"parameter": "L1_0", "segment": 2, "from": 2.5, "to": 3})", kContinuation, "/path/from",
       "contains the start value L1_0 of segment 2 = 2.25"},
      {"direction", R"({"parameter": "L0", "from": 2, "to": 3, "direction": {"Fy": 1}})", kContinuation,
       "/path/direction/Fy", "allowed here: dL0"},
      {"direction_own", R"({"parameter": "L0", "from": 2, "to": 3, "direction": {"L0": 1}})", kContinuation,
       "/path/direction/L0", "L0's own rate is 1"},
      {"direction_list", R"({"parameter": "dL0", "from": -1, "to": 1, "direction": {"L0": [1, 2]}})", kContinuation,
       "/path/direction/L0", "a list of 3 rates"},
      {"critical", kPath, R"({"continuation": {}, "critical_forces": true})", "/analyses/critical_forces",
       "is a control input"},
  };
  for (const Case& cs : cases) {
    INFO(cs.name);
    const buckle::test::SceneOutcome o =
        buckle::test::runSceneText("control_path", cs.name, actuationScene(1.0, 1.0, cs.path, cs.analyses));
    INFO(o.err);
    CHECK(o.rc == 2);
    CHECK(o.err.find(": " + std::string(cs.pointer) + ": ") != std::string::npos);
    CHECK(o.err.find(cs.expected) != std::string::npos);
    CHECK(!fs::exists(o.out));
  }
}

TEST_CASE("control path scene: a direction in control space moves both inputs, the parameter at rate 1", "[scene]") {
  // L0 rises by λ − 2.25 while dL0 of segment 1 moves at 0.5 and of segment 3 at −0.5 per unit:
  // the scene's path ends equal those of the library's problem with those rates.
  const std::string path = R"({"parameter": "L0", "from": 1.5, "to": 3.0, "direction": {"dL0": [0.5, 0, -0.5]}})";
  const buckle::test::SceneOutcome o =
      buckle::test::runSceneText("control_path", "direction", actuationScene(1.0, 1.0, path, kContinuation));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const mech::Chain chain = mech::Chain::uniform(3, mech::SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  mech::ControlDirection d = mech::ControlDirection::named(3, mech::ControlInput::L0);
  d.rates.row(0) += 0.5 * Eigen::RowVector2d(0.5, -0.5);
  d.rates.row(2) -= 0.5 * Eigen::RowVector2d(0.5, -0.5);
  d.origin = 2.25;
  const json c = readJson(o.out / "summary.json")["cases"][0];
  CHECK(double(c["start_parameter"]) == 2.25);
  Eigen::VectorXd u(3);
  for (int i = 0; i < 3; ++i) u[i] = c["start_q"][i];
  mech::EquilibriumProblem actuated(chain, mech::EndCondition::freeEnd(Eigen::Vector3d(-0.3, -0.3, 0.0)),
                                    Eigen::Vector3d::Zero(), {}, d);
  cont::TracerOptions to;
  to.lambdaMin = 1.5;
  to.lambdaMax = 3.0;
  // branches.csv rows (12 significant digits): parameter in column 3, q1..q3 in 12..14
  std::vector<std::vector<double>> rows;
  std::ifstream csv(o.out / "branches.csv");
  std::string line;
  std::getline(csv, line);
  while (std::getline(csv, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(cell.empty() ? 0.0 : std::atof(cell.c_str()));
    rows.push_back(row);
  }
  int ends = 0;
  for (const cont::InitialDirection& dir : {cont::InitialDirection::increasingLambda(), cont::InitialDirection::decreasingLambda()}) {
    const cont::Branch b = cont::trace(actuated, u, 2.25, dir, to);
    REQUIRE(b.stopReason == cont::StopReason::LambdaRange);
    const cont::ContinuationPoint& last = b.points.back();
    for (const std::vector<double>& row : rows) {
      if (row.size() < 15 || row[3] != last.lambda) continue;
      ++ends;
      for (int i = 0; i < 3; ++i) CHECK(row[size_t(12 + i)] == Approx(last.u[i]).margin(1e-10));
    }
  }
  CHECK(ends == 2);
  // the free lengths at λ = 3: L0 = 3 everywhere, dL0 = ±0.5·0.75 on segments 1 and 3
  const mech::Chain end = mech::chainWithControls(chain, d, 3.0);
  CHECK(mech::controlInputValue(end, mech::ControlInput::L0) == Approx(3.0).epsilon(1e-15));
  CHECK(mech::controlInputValue(end, mech::ControlInput::dL0, 0) == Approx(0.375).epsilon(1e-15));
  CHECK(mech::controlInputValue(end, mech::ControlInput::dL0, 2) == Approx(-0.375).epsilon(1e-15));
}
