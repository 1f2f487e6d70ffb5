// Task-space paths in a scene (issue 29, scene_task.cpp, case_runner_task.cpp): "path": {"task":
// …, "inputs": …, "rule": …}. branches.csv's rows against the straight task path and against the
// plain equilibrium of the chain rebuilt from the row's input columns, the special point's input
// at its bound, the same scene in scaled units, and bad input (exit 2, the JSON path, nothing written).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "buckle/mechanics/control_path.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "rfc4180.h"
#include "scene_run.h"

namespace fs = std::filesystem;
using nlohmann::json;
namespace mech = buckle::mechanics;

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// The paper's chain with lengths ×L, stiffness ×k, the payload ×kL, the target ×L.
std::string taskScene(double L, double k, const std::string& path, const std::string& analyses = R"({"continuation": {}})",
                      const std::string& end = "") {
  return R"({
  "chain": {"segments": 3, "a": )" + num(0.5 * L) + R"(, "b": )" + num(L) + R"(, "k": )" + num(k) + R"(, "L0": )" +
         num(2.25 * L) + R"(},
  "end": )" + (end.empty() ? R"({"x": {"load": )" + num(-0.3 * k * L) + R"(}, "y": {"load": )" + num(-0.3 * k * L) +
                                 R"(}, "phi": "free"})"
                           : end) + R"(,
  "path": )" + path + R"(,
  "analyses": )" + analyses + R"(,
  "plots": []
})";
}

std::string chosenPath(double L, const std::string& bound = "") {
  return R"({"task": {"coordinates": ["x", "y"], "to": [)" + num(0.2 * L) + ", " + num(-4.2 * L) +
         R"(]}, "inputs": [{"input": "dL0", "segment": 1}, {"input": "dL0", "segment": 2)" + bound + R"(}], "rule": "chosen"})";
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    FAIL("no column " << name);
    return -1;
  }
};

Table readBranches(const fs::path& out) {
  std::ifstream in(out / "branches.csv");
  std::stringstream ss;
  ss << in.rdbuf();
  const auto records = buckle::test::readCsv(ss.str());
  Table t;
  t.header = records.front();
  for (size_t r = 1; r < records.size(); ++r) {
    std::vector<double> row;
    for (const std::string& f : records[r]) row.push_back(f.empty() ? std::nan("") : std::stod(f));
    t.rows.push_back(row);
  }
  return t;
}

}  // namespace

TEST_CASE("task path scene: rows on the straight path, each an equilibrium of the chain at its inputs", "[scene]") {
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("task_path", "run", taskScene(1.0, 1.0, chosenPath(1.0)));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const Table t = readBranches(o.out);
  const int x = t.column("x"), y = t.column("y"), s = t.column("parameter"), d1 = t.column("dL0[1]"),
            d2 = t.column("dL0[2]"), q1 = t.column("q1");
  REQUIRE(t.rows.size() > 10);
  const double x0 = t.rows[0][size_t(x)], y0 = t.rows[0][size_t(y)];
  const double lx = 0.2 - x0, ly = -4.2 - y0, length = std::hypot(lx, ly);
  const mech::Chain chain = mech::Chain::uniform(3, mech::SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  for (const std::vector<double>& row : t.rows) {
    // on the segment from the start to (0.2, -4.2), at arclength s (CSV: 12 significant digits)
    const double sv = row[size_t(s)];
    CHECK(std::abs(row[size_t(x)] - (x0 + sv * lx / length)) <= 1e-10 * length);
    CHECK(std::abs(row[size_t(y)] - (y0 + sv * ly / length)) <= 1e-10 * length);
    // the chain rebuilt from the row's inputs: dL0 of segments 1, 2 moved, the mean kept
    mech::ControlDirection d;
    d.rates = Eigen::MatrixX2d::Zero(3, 2);
    d.rates.row(0) << 0.5 * row[size_t(d1)], -0.5 * row[size_t(d1)];
    d.rates.row(1) << 0.5 * row[size_t(d2)], -0.5 * row[size_t(d2)];
    mech::EquilibriumProblem plain(mech::chainWithControls(chain, d, 1.0), mech::EndCondition::freeEnd({-0.3, -0.3, 0.0}),
                                   Eigen::Vector3d::Zero());
    Eigen::VectorXd q(3), F(3);
    q << row[size_t(q1)], row[size_t(q1) + 1], row[size_t(q1) + 2];
    REQUIRE(buckle::continuation::BoundProblem(plain).residual(q, 0.0, F));
    CHECK(F.cwiseAbs().maxCoeff() <= 1e-10);  // k b² = 1; the CSV's 12 digits
  }
  std::ifstream in(o.out / "special_points.json");
  const json sp = json::parse(in)["special_points"];
  const json summary = json::parse(std::ifstream(o.out / "summary.json"));
  // the path either reaches its end or stops at a special point that says why
  const json& branch = summary["cases"][0]["branches"][0];
  if (branch["stop"] == "completed") {
    CHECK(sp.empty());
    CHECK(t.rows.back()[size_t(s)] == Approx(length).epsilon(1e-10));
  } else {
    REQUIRE(sp.size() == 1);
    CHECK(sp[0]["note"] == branch["stop_message"]);
  }
}

TEST_CASE("task path scene: an input bound ends the path with the input on it", "[scene]") {
  const buckle::test::SceneOutcome o =
      buckle::test::runSceneText("task_path", "bound", taskScene(1.0, 1.0, chosenPath(1.0, R"(, "max": 1.0)")));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const json sp = json::parse(std::ifstream(o.out / "special_points.json"))["special_points"];
  REQUIRE(sp.size() == 1);
  CHECK(sp[0]["type"] == "IB");
  CHECK(sp[0]["note"] == "input dL0[2] upper bound");
  CHECK(double(sp[0]["inputs"]["dL0[2]"]) == Approx(1.0).epsilon(1e-12));
  const Table t = readBranches(o.out);
  for (const std::vector<double>& row : t.rows) CHECK(row[size_t(t.column("dL0[2]"))] <= 1.0 + 1e-12);
}

TEST_CASE("task path scene: the same path in scaled units (lengths x1e-4, stiffness x1e8)", "[scene]") {
  const double L = 1e-4, k = 1e8;
  const std::string min = R"({"task": {"coordinates": ["x", "y"], "to": [)";
  const auto path = [&](double l) {
    return min + num(-1.0 * l) + ", " + num(-3.0 * l) +
           R"(]}, "inputs": ["dL0", {"input": "dL0", "segment": 2, "weight": 3}, {"input": "L0", "segment": 3}], "rule": "min_change"})";
  };
  const buckle::test::SceneOutcome a = buckle::test::runSceneText("task_path", "unit", taskScene(1.0, 1.0, path(1.0)));
  const buckle::test::SceneOutcome b = buckle::test::runSceneText("task_path", "scaled", taskScene(L, k, path(L)));
  INFO(a.err << b.err);
  REQUIRE(a.rc == 0);
  REQUIRE(b.rc == 0);
  const Table ta = readBranches(a.out), tb = readBranches(b.out);
  REQUIRE(ta.rows.size() == tb.rows.size());
  const int s = ta.column("parameter"), q1 = ta.column("q1"), d = ta.column("dL0[2]"), m = ta.column("min_eig");
  for (size_t i = 0; i < ta.rows.size(); ++i) {
    CHECK(tb.rows[i][size_t(s)] / L == Approx(ta.rows[i][size_t(s)]).epsilon(1e-8).margin(1e-10));
    CHECK(tb.rows[i][size_t(q1)] == Approx(ta.rows[i][size_t(q1)]).epsilon(1e-8).margin(1e-10));
    CHECK(tb.rows[i][size_t(d)] / L == Approx(ta.rows[i][size_t(d)]).epsilon(1e-8).margin(1e-10));
    CHECK(tb.rows[i][size_t(m)] / (k * L * L) == Approx(ta.rows[i][size_t(m)]).epsilon(1e-8).margin(1e-10));
  }
}

TEST_CASE("task path scene: bad input names the JSON path, exit 2, nothing written", "[scene]") {
  struct Case {
    const char* name;
    std::string path, analyses, end;
    const char* pointer;
    const char* expected;
  };
  const std::string ok = chosenPath(1.0);
  const std::string cont = R"({"continuation": {}})";
  const std::vector<Case> cases = {
      {"held", ok, cont, R"({"x": {"load": -0.3}, "y": {"held": -3}})", "/end/y", "must be a load, not held"},
      {"count", R"({"task": {"coordinates": ["x", "y"], "to": [-1, -3]}, "inputs": ["dL0"]})", cont, "", "/path/inputs",
       "as many inputs as task coordinates (2), got 1"},
      {"too_few", R"({"task": {"coordinates": ["x", "y", "phi"], "to": [-1, -3, 0]}, "inputs": ["dL0", "L0"], "rule": "min_change"})",
       cont, "", "/path/inputs", "at least as many inputs"},
      {"coordinate", R"({"task": {"coordinates": ["y", "x"], "to": [-1, -3]}, "inputs": ["dL0", "L0"]})", cont, "",
       "/path/task/coordinates/1", "each once and in that order"},
      {"point", R"({"task": {"coordinates": ["x", "y"], "to": [-1]}, "inputs": ["dL0", "L0"]})", cont, "",
       "/path/task/to", "an array of 2 number(s): x, y"},
      {"both", R"({"task": {"coordinates": ["x"], "to": [-1], "waypoints": [[1]]}, "inputs": ["dL0"]})", cont, "",
       "/path/task/to", "exactly one of"},
      {"reach", R"({"task": {"coordinates": ["x", "y"], "waypoints": [[0, -3], [9, 0]]}, "inputs": ["dL0", "L0"]})", cont,
       "", "/path/task/waypoints/1", "a position the end can reach"},
      {"reach_from", R"({"task": {"coordinates": ["x", "y"], "from": [0, -9], "waypoints": [[0, -3]]}, "inputs": ["dL0", "L0"]})",
       cont, "", "/path/task/from", "a position the end can reach"},
      {"input", R"({"task": {"coordinates": ["x"], "to": [-1]}, "inputs": ["dL1"]})", cont, "", "/path/inputs/0",
       "one of L1_0, L2_0, L0, dL0"},
      {"twice", R"({"task": {"coordinates": ["x", "y"], "to": [-1, -3]}, "inputs": ["dL0", "dL0"]})", cont, "",
       "/path/inputs/1", "listed twice"},
      {"weight", R"({"task": {"coordinates": ["x"], "to": [-1]}, "inputs": [{"input": "dL0", "weight": 2}]})", cont, "",
       "/path/inputs/0/weight", "only applies to the rules \"min_change\" and \"most_stable\""},
      {"bounds", R"({"task": {"coordinates": ["x"], "to": [-1]}, "inputs": [{"input": "L0", "min": 2.5}]})", cont, "",
       "/path/inputs/0/min", "contain the input's start value L0 = 2.25"},
      {"segment", R"({"task": {"coordinates": ["x"], "to": [-1]}, "inputs": [{"input": "L0", "segment": 4}]})", cont, "",
       "/path/inputs/0/segment", "an integer in [1, 3]"},
      {"rule", R"({"task": {"coordinates": ["x"], "to": [-1]}, "inputs": ["L0"], "rule": "stiffest"})", cont, "",
       "/path/rule", "one of chosen, min_change"},
      {"analysis", ok, R"({"continuation": {}, "frequencies": {"mass_per_length": 1}})", "", "/analyses/frequencies",
       "not computed along a task path"},
      {"no_continuation", ok, R"({"torque_angle": true})", "", "/analyses/continuation", "add \"continuation\": true"},
  };
  for (const Case& cs : cases) {
    INFO(cs.name);
    const buckle::test::SceneOutcome o =
        buckle::test::runSceneText("task_path", cs.name, taskScene(1.0, 1.0, cs.path, cs.analyses, cs.end));
    INFO(o.err);
    CHECK(o.rc == 2);
    CHECK(o.err.find(": " + std::string(cs.pointer) + ": ") != std::string::npos);
    CHECK(o.err.find(cs.expected) != std::string::npos);
    CHECK(!fs::exists(o.out));
  }
}
