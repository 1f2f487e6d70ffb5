// Bad input: every class of malformed or inconsistent scene is rejected with exit code 2, a
// message naming the file and the JSON path of the bad value, and no output directory (not
// even a half-written temporary one) left behind. Also: exit code 1 with partial output when a
// computation cannot finish, and plain data when gnuplot is missing.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>
#include <string>

#include "scene/case_runner.h"
#include "scene/command.h"
#include "scene/scene.h"
#include "small_scene.h"
#include "scene_run.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

using buckle::test::replaceOnce;

const std::string kGood = buckle::test::smallScene(0);

fs::path errorsDir() { return buckle::test::scratchDirectory("scene_errors"); }

using Outcome = buckle::test::SceneOutcome;

Outcome runText(const std::string& name, const std::string& text) {
  return buckle::test::runSceneText("scene_errors", name, text);
}

/// Nothing but the scene file in its directory: no output, no staging directory.
void requireNothingWritten(const Outcome& o) {
  CHECK(!fs::exists(o.out));
  int entries = 0;
  for (const auto& e : fs::directory_iterator(o.file.parent_path())) {
    (void)e;
    ++entries;
  }
  CHECK(entries == 1);
}

void requireBadInput(const std::string& name, const std::string& text, const std::string& path,
                     const std::string& expected) {
  const Outcome o = runText(name, text);
  INFO(o.err);
  CHECK(o.rc == 2);
  CHECK(o.err.find(o.file.string()) != std::string::npos);  // the file
  CHECK(o.err.find(": " + path + ": ") != std::string::npos);  // the JSON path of the bad value
  CHECK(o.err.find(expected) != std::string::npos);          // what was expected
  requireNothingWritten(o);
}

}  // namespace

TEST_CASE("a good scene runs (baseline for the bad-input cases)", "[scene][errors]") {
  const Outcome o = runText("good", kGood);
  INFO(o.err);
  CHECK(o.rc == 0);
  CHECK(fs::exists(o.out / "branches.csv"));
  CHECK(fs::exists(o.out / "summary.json"));
}

TEST_CASE("bad JSON", "[scene][errors]") {
  const std::string text = replaceOnce(kGood, "\"segments\": 3,", "\"segments\": 3");
  // the path is that of the last value read before the syntax error
  requireBadInput("bad_json", text, "/chain/segments", "invalid JSON at line 3");
  requireBadInput("bad_json_truncated", "{\"chain\": {\"segments\": 3,", "/chain/segments", "unexpected end of input");
}

TEST_CASE("unknown key", "[scene][errors]") {
  requireBadInput("unknown_key", replaceOnce(kGood, "\"a\": 0.5", "\"a\": 0.5, \"stifness\": 2"), "/chain/stifness",
                  "unknown key \"stifness\"");
  requireBadInput("unknown_top_key", replaceOnce(kGood, "\"plots\": []", "\"plots\": [], \"extra\": 1"), "/extra",
                  "unknown key");
}

TEST_CASE("wrong type", "[scene][errors]") {
  requireBadInput("wrong_type", replaceOnce(kGood, "\"k\": 1.0", "\"k\": \"stiff\""), "/chain/k",
                  "expected a number");
  requireBadInput("wrong_type_depth", replaceOnce(kGood, "\"branch_switching\": 0", "\"branch_switching\": 1.5"),
                  "/analyses/continuation/branch_switching", "expected an integer");
  requireBadInput("wrong_type_contact",
                  replaceOnce(kGood, "\"branch_switching\": 0", "\"branch_switching\": 0, \"contact\": \"yes\""),
                  "/analyses/continuation/contact", "expected true or false");
  requireBadInput("wrong_type_end", replaceOnce(kGood, "\"phi\": \"free\"", "\"phi\": 3"), "/end/phi",
                  "expected \"free\"");
}

TEST_CASE("negative stiffness", "[scene][errors]") {
  requireBadInput("negative_k", replaceOnce(kGood, "\"k\": 1.0", "\"k\": -1.0"), "/chain/k", "expected a number > 0");
  requireBadInput("negative_k1",
                  replaceOnce(kGood, "\"segments\": 3,", "\"segments\": [{}, {\"k1\": -2}, {}],"),
                  "/chain/segments/1/k1", "expected a number > 0");
}

TEST_CASE("n = 0", "[scene][errors]") {
  requireBadInput("n0", replaceOnce(kGood, "\"segments\": 3", "\"segments\": 0"), "/chain/segments",
                  "expected an integer in [1,");
  requireBadInput("n0_list", replaceOnce(kGood, "\"segments\": 3", "\"segments\": []"), "/chain/segments",
                  "non-empty list");
}

TEST_CASE("a range that does not contain the start", "[scene][errors]") {
  requireBadInput("range", replaceOnce(kGood, "\"from\": 0.0", "\"from\": -0.5"), "/path/from",
                  "contains the start value Fx = 0");
}

TEST_CASE("NaN", "[scene][errors]") {
  requireBadInput("nan", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": NaN"), "/chain/L0", "expected a finite number");
  requireBadInput("inf", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": 1e999"), "/chain/L0", "expected a finite number");
}

TEST_CASE("duplicate keys are rejected with their JSON path", "[scene][errors]") {
  requireBadInput("dup_k", replaceOnce(kGood, "\"k\": 1.0", "\"k\": 1.0, \"k\": -5"), "/chain/k", "duplicate key \"k\"");
  requireBadInput("dup_chain", replaceOnce(kGood, "\"plots\": []", "\"plots\": [], \"chain\": {\"segments\": 4}"), "/chain",
                  "duplicate key \"chain\"");
}

TEST_CASE("one segment cap for counts, lists and all cases together", "[scene][errors]") {
  const std::string cap = std::to_string(buckle::scene::kMaxSegments);
  requireBadInput("cap_count", replaceOnce(kGood, "\"segments\": 3", "\"segments\": " + std::to_string(buckle::scene::kMaxSegments + 1)),
                  "/chain/segments", "an integer in [1, " + cap + "]");
  std::string list = "[{}";
  for (int i = 0; i < buckle::scene::kMaxSegments; ++i) list += ",{}";
  requireBadInput("cap_list", replaceOnce(kGood, "\"segments\": 3", "\"segments\": " + list + "]"), "/chain/segments",
                  "expected at most " + cap + " segments, got a list of " + std::to_string(buckle::scene::kMaxSegments + 1));
  const int half = buckle::scene::kMaxSegments / 2 + 1;
  const std::string cases = "\"plots\": [], \"cases\": [{\"chain\": {\"segments\": " + std::to_string(half) +
                            "}}, {\"chain\": {\"segments\": " + std::to_string(half) + "}}]";
  requireBadInput("cap_cases", replaceOnce(kGood, "\"plots\": []", cases), "/cases/1", "in all cases together");
}

TEST_CASE("extreme numbers are rejected at the user's key, never with internal names", "[scene][errors]") {
  struct Bad {
    std::string from, to, path, expected;
  };
  const std::string chain = "\"a\": 0.5, \"b\": 1.0, \"k\": 1.0, \"L0\": 2.25";
  for (const Bad& b : {
           // a/b so large that atan(a1/b1) + atan(a2/b2) rounds to π: no joint range
           Bad{chain, "\"a\": 1e308, \"b\": 1.0", "/chain/a", "no range of motion"},
           Bad{chain, "\"a\": 0.5, \"b\": 1e-320", "/chain/b", "no range of motion"},
           Bad{"\"segments\": 3,", "\"segments\": [{}, {\"a\": 1e20}, {}],", "/chain/segments/1/a", "no range of motion"},
           // spring model past the double range (products of four lengths, k L0²)
           Bad{chain, "\"b\": 1e300", "/chain/b", "out of the range the spring model can compute"},
           Bad{chain, "\"b\": 1e-200, \"a\": 5e-201, \"L0\": 2.25e-200", "/chain/b", "out of the range the spring model"},
           Bad{chain, "\"L0\": 1e308", "/chain/L0", "out of the range the spring model"},
           Bad{chain, "\"a\": 0.5, \"a1\": 1e300", "/chain/a1", "out of the range the spring model"},
           Bad{chain, "\"k1\": 1e300, \"L1_0\": 1e200", "/chain/k1", "out of the range the spring model"},
           // user joint limits that leave nothing
           Bad{chain, "\"q_min\": 1e308", "/chain/q_min", "expected joint limits q_min < q_max"},
           Bad{chain, "\"q_max\": -1e-320, \"q_min\": 0", "/chain/q_min", "expected joint limits q_min < q_max"},
           Bad{chain, "\"q_max\": -3", "/chain/q_max", "overlap the geometric range"},
           // masses of the sudden load's rods: overflowing or subnormal
           Bad{"\"continuation\": {\"branch_switching\": 0}",
               "\"continuation\": true, \"sudden_load\": {\"value\": -0.5, \"mass_per_length\": 1e308}",
               "/analyses/sudden_load/mass_per_length", "out of the range the inertial model"},
           Bad{"\"continuation\": {\"branch_switching\": 0}",
               "\"continuation\": true, \"sudden_load\": {\"value\": -0.5, \"mass_per_length\": 1e-320}",
               "/analyses/sudden_load/mass_per_length", "out of the range the inertial model"},
           // huge integers are no integers in range
           Bad{"\"segments\": 3", "\"segments\": 123456789012345678901234567890", "/chain/segments", "an integer in [1,"},
           Bad{"\"segments\": 3", "\"segments\": 18446744073709551615", "/chain/segments", "an integer in [1,"},
           Bad{"\"branch_switching\": 0", "\"branch_switching\": -9223372036854775808",
               "/analyses/continuation/branch_switching", "an integer in [0, 4]"},
           Bad{"\"k\": 1.0", "\"k\": -0.0", "/chain/k", "expected a number > 0"},
           Bad{"\"k\": 1.0", "\"k\": -1e-320", "/chain/k", "expected a number > 0"},
       }) {
    const std::string name = "extreme_" + std::to_string(std::hash<std::string>{}(b.to) % 100000);
    requireBadInput(name, replaceOnce(kGood, b.from, b.to), b.path, b.expected);
    const Outcome o = runText(name, replaceOnce(kGood, b.from, b.to));
    for (const char* internal : {"qMinUser", "qMaxUser", "invalid segment", "SuddenLoadOptions", "inertia link"})
      CHECK(o.err.find(internal) == std::string::npos);
  }
}

TEST_CASE("extreme numbers the model can compute are accepted", "[scene][errors]") {
  // tiny or zero half-heights, subnormal free lengths, -0 where 0 is allowed, huge stiffness
  for (const char* chain : {"\"a\": 1e-320", "\"a\": -0.0", "\"L0\": 1e-320", "\"k\": 1e300", "\"b\": 1e20"}) {
    const Outcome o = runText("accepted", replaceOnce(kGood, "\"a\": 0.5, \"b\": 1.0, \"k\": 1.0, \"L0\": 2.25", chain));
    INFO(chain << ": " << o.err);
    CHECK(o.rc != 2);
  }
}

TEST_CASE("a directory as the scene file says so", "[scene][errors]") {
  const fs::path dir = errorsDir() / "scene_dir";
  fs::create_directories(dir);
  buckle::scene::RunCommandOptions opt;
  opt.scene = dir.string();
  opt.out = (errorsDir() / "dir_out").string();
  std::ostringstream log, err;
  CHECK(buckle::scene::runSceneCommand(opt, log, err) == 2);
  CHECK(err.str().find(dir.string() + ": (document): is a directory") != std::string::npos);
  CHECK(!fs::exists(opt.out));
}

TEST_CASE("inconsistent scenes", "[scene][errors]") {
  requireBadInput("load_on_held", replaceOnce(kGood, "\"parameter\": \"Fx\"", "\"parameter\": \"Fy\""),
                  "/path/parameter", "is held");
  requireBadInput("jump_without_branches",
                  replaceOnce(kGood, "\"continuation\": {\"branch_switching\": 0}", "\"jump\": true, \"critical_forces\": true"),
                  "/analyses/jump", "needs /analyses/continuation");
  requireBadInput("jump_bad_key", replaceOnce(kGood, "\"continuation\": {", "\"jump\": {\"eps\": 1}, \"continuation\": {"),
                  "/analyses/jump/eps", "unknown key");
  requireBadInput("stiffness_without_branches",
                  replaceOnce(kGood, "\"continuation\": {\"branch_switching\": 0}", "\"stiffness\": true, \"critical_forces\": true"),
                  "/analyses/stiffness", "needs /analyses/continuation");
  requireBadInput("plot_column", replaceOnce(kGood, "\"plots\": []", "\"plots\": [{\"type\": \"bifurcation\", \"y\": \"q7\"}]"),
                  "/plots/0/y", "a column of branches.csv");
  requireBadInput("plot_labels",
                  replaceOnce(kGood, "\"plots\": []", "\"plots\": [{\"type\": \"bifurcation\", \"labels\": \"some\"}]"),
                  "/plots/0/labels", "one of auto, all, summary");
  requireBadInput("shapes_labels",
                  replaceOnce(kGood, "\"plots\": []",
                              "\"plots\": [{\"type\": \"shapes\", \"at\": [0], \"labels\": \"all\"}]"),
                  "/plots/0/labels", "only bifurcation and stiffness plots label special points");
  requireBadInput("case_override",
                  replaceOnce(kGood, "\"plots\": []", "\"plots\": [], \"cases\": [{\"label\": \"A\"}, {\"chain\": {\"a\": -1}}]"),
                  "/cases/1/chain/a", "expected a number >= 0");
}

TEST_CASE("missing file", "[scene][errors]") {
  buckle::scene::RunCommandOptions opt;
  opt.scene = (errorsDir() / "does_not_exist.json").string();
  opt.out = (errorsDir() / "missing_out").string();
  std::ostringstream log, err;
  CHECK(buckle::scene::runSceneCommand(opt, log, err) == 2);
  CHECK(err.str().find("cannot open") != std::string::npos);
  CHECK(!fs::exists(opt.out));
}

TEST_CASE("a computation that cannot finish writes what it has and exits 1", "[scene][errors]") {
  // a time limit no run can meet: the first branch is abandoned
  const Outcome o = runText("time_limit", replaceOnce(kGood, "\"plots\": []", "\"plots\": [], \"solver\": {\"time_limit\": 1e-9}"));
  CHECK(o.rc == 1);
  CHECK(o.err.find("time limit") != std::string::npos);
  REQUIRE(fs::exists(o.out / "summary.json"));
  std::ifstream in(o.out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["complete"] == false);
  CHECK(!summary["problems"].empty());
}

TEST_CASE("without gnuplot the data is still written and the summary says so", "[scene][errors]") {
  ::setenv("BUCKLE_GNUPLOT", "", 1);
  const Outcome o = runText("no_gnuplot", replaceOnce(kGood, "\"plots\": []", "\"plots\": [\"bifurcation\"]"));
  ::unsetenv("BUCKLE_GNUPLOT");
  CHECK(o.rc == 0);
  CHECK(fs::exists(o.out / "branches.csv"));
  CHECK(fs::exists(o.out / "plots" / "bifurcation.gp"));
  CHECK(fs::exists(o.out / "plots" / "bifurcation.dat"));
  CHECK(!fs::exists(o.out / "plots" / "bifurcation.png"));
  std::ifstream in(o.out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["plots"]["gnuplot"].get<std::string>().find("not found") == 0);
}

TEST_CASE("an existing output directory is replaced as a whole", "[scene][errors]") {
  const Outcome first = runText("replace", kGood);
  REQUIRE(first.rc == 0);
  std::ofstream(first.out / "stale.txt") << "old";
  buckle::scene::RunCommandOptions opt;
  opt.scene = first.file.string();
  opt.out = first.out.string();
  opt.force = true;  // stale.txt is not buckle's: replaced only with --force (test_scene_output_target.cpp)
  std::ostringstream log, err;
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);
  CHECK(!fs::exists(first.out / "stale.txt"));
  CHECK(fs::exists(first.out / "summary.json"));
  int entries = 0;
  for (const auto& e : fs::directory_iterator(first.file.parent_path())) {
    (void)e;
    ++entries;
  }
  CHECK(entries == 2);  // scene.json and out
}

TEST_CASE("the stiffness measure of KMIN is one of Kxx, Kyy, Kmin", "[scene][errors]") {
  const std::string base = R"({"chain": {"segments": 3}, "path": {"parameter": "Fx", "from": 0, "to": -1},
    "analyses": {"continuation": true, "stiffness": )";
  const buckle::scene::Scene ok = buckle::scene::parseScene(base + R"({"measure": "Kmin"}}})", "s.json");
  CHECK(ok.analyses.stiffness);
  CHECK(ok.analyses.stiffnessMeasure == buckle::mechanics::StiffnessMeasure::MinEigenvalue);
  CHECK(buckle::scene::parseScene(base + "true}}", "s.json").analyses.stiffnessMeasure ==
        buckle::mechanics::StiffnessMeasure::Kxx);
  CHECK_THROWS_WITH(buckle::scene::parseScene(base + R"({"measure": "Kzz"}}})", "s.json"),
                    Catch::Contains("/analyses/stiffness/measure") && Catch::Contains("Kxx, Kyy, Kmin"));
  CHECK_THROWS_WITH(buckle::scene::parseScene(base + R"({"kind": "Kxx"}}})", "s.json"),
                    Catch::Contains("/analyses/stiffness"));
}

// ---- the bad inputs of issue 27: each answered before computing, naming key, path and range ----

TEST_CASE("joint limits that exclude the straight start", "[scene][errors]") {
  requireBadInput("q_min_straight", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": 2.25, \"q_min\": 0.1"), "/chain/q_min",
                  "expected q_min < 0: the chain starts straight (q = 0)");
  requireBadInput("q_max_straight", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": 2.25, \"q_max\": -0.1"), "/chain/q_max",
                  "expected q_max > 0");
}

TEST_CASE("a held end out of reach and loads beyond the chain's scale", "[scene][errors]") {
  // three segments of length 2 b: the end reaches at most 6 b from the base
  requireBadInput("y_held_100", replaceOnce(kGood, "\"held\": 0.0", "\"held\": 100"), "/end/y/held",
                  "expected a position the end can reach: |y| <= 6");
  requireBadInput("y_held_1e300", replaceOnce(kGood, "\"held\": 0.0", "\"held\": 1e300"), "/end/y/held",
                  "expected a position the end can reach");
  requireBadInput("Fy_1e308", replaceOnce(kGood, "\"y\": {\"held\": 0.0}", "\"y\": {\"load\": 1e308}"), "/end/y/load",
                  "expected a load |Fy| <= 1e+12");
  requireBadInput("path_to_1e300", replaceOnce(kGood, "\"to\": -1.0", "\"to\": -1e300"), "/path/to",
                  "expected a load |Fx| <= 1e+12");
}

TEST_CASE("a subnormal stiffness", "[scene][errors]") {
  requireBadInput("k_denormal", replaceOnce(kGood, "\"k\": 1.0", "\"k\": 5e-324"), "/chain/k",
                  "expected a stiffness of at least 2.2e-308");
  requireBadInput("k2_denormal", replaceOnce(kGood, "\"segments\": 3,", "\"segments\": [{}, {\"k2\": 1e-310}, {}],"),
                  "/chain/segments/1/k2", "expected a stiffness of at least 2.2e-308");
}

TEST_CASE("a solver tolerance that accepts non-equilibria", "[scene][errors]") {
  requireBadInput("tolerance_10", replaceOnce(kGood, "\"plots\": []", "\"plots\": [], \"solver\": {\"tolerance\": 10}"),
                  "/solver/tolerance", "expected a number in (0, 1e-3]");
}

TEST_CASE("numbers JSON cannot hold are named as written", "[scene][errors]") {
  requireBadInput("minus_infinity", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": -Infinity"), "/chain/L0",
                  "got -Infinity (not valid JSON)");
  const Outcome o = runText("e309", replaceOnce(kGood, "\"L0\": 2.25", "\"L0\": 1e309"));
  INFO(o.err);
  CHECK(o.rc == 2);
  CHECK(o.err.find("/chain/L0: expected a finite number (at most 1.8e308 in magnitude), got 1e309") != std::string::npos);
  CHECK(o.err.find("json.exception") == std::string::npos);  // no library internals
}

TEST_CASE("an unknown key inside an end coordinate is named", "[scene][errors]") {
  requireBadInput("end_x_extra", replaceOnce(kGood, "\"x\": {\"load\": 0.0}", "\"x\": {\"load\": 0.0, \"lod\": 1}"),
                  "/end/x/lod", "unknown key \"lod\" (allowed here: load, held)");
  requireBadInput("end_x_both", replaceOnce(kGood, "\"x\": {\"load\": 0.0}", "\"x\": {\"load\": 0.0, \"held\": 1}"),
                  "/end/x", "expected one of load, held, got both");
}

TEST_CASE("a two_parameter range far beyond the case's scale", "[scene][errors]") {
  const std::string twoParameter =
      "\"analyses\": {\"two_parameter\": {\"parameter\": \"k\", \"from\": -1e308, \"to\": 1e308, \"modes\": 1}},";
  std::string text = kGood;
  const size_t a = text.find("\"analyses\""), e = text.find("\"plots\"");
  text.replace(a, e - a, twoParameter + "\n  ");
  requireBadInput("two_parameter_1e308", text, "/analyses/two_parameter/from", "expected a range within 1e6 times");
}

TEST_CASE("solver failures are explained in words, the KINSOL flag kept as detail", "[scene][errors]") {
  using buckle::scene::solverFailureInWords;
  const std::string start = "start point did not converge at fixed lambda (KIN_FIRST_SYSFUNC_ERR)";
  const std::string sysfunc = solverFailureInWords(start);
  CHECK(sysfunc.rfind("the spring model could not be evaluated", 0) == 0);
  CHECK(sysfunc.find("; check the joint limits") != std::string::npos);
  CHECK(sysfunc.size() > start.size());
  CHECK(sysfunc.substr(sysfunc.size() - start.size() - 1) == start + ")");  // the flag last, as detail
  const std::string newton = solverFailureInWords("corrector failed (KIN_LINESEARCH_NONCONV)");
  CHECK(newton.rfind("Newton's method made no progress on the equilibrium equations", 0) == 0);
  CHECK(newton.find("lower solver.max_step") != std::string::npos);
  CHECK(solverFailureInWords("corrector failed (KIN_LSETUP_FAIL)").rfind("the linearised equilibrium equations", 0) == 0);
  // messages of the mechanics already in words stay as they are
  CHECK(solverFailureInWords("reached the end of the path range") == "reached the end of the path range");
}
