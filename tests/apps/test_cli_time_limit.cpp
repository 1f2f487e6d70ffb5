// `buckle run` under a time limit and under SIGINT / SIGTERM: it stops within a step (of the
// continuation or of a branch report's per-point work), writes what it computed (summary.json "complete": false, "interrupted": true, and why), exits 1
// (time limit) or 128 + the signal, and leaves no temporary directory behind.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "temp_dir.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>
#include <vector>
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::exitCode;
using buckle::test::slurp;
using Catch::Matchers::Contains;

namespace {

fs::path timeLimitDir() { return buckle::test::scratchDirectory("cli_time"); }

/// The default scene (branch switching, jumps) with 100 segments: far more than a few seconds of
/// work (its 50-segment version takes about 5 s in Release).
fs::path longScene(const fs::path& dir, double timeLimit) {
  std::ifstream in(std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json");
  nlohmann::json scene = nlohmann::json::parse(in);
  scene["chain"]["segments"] = 100;
  // the time limit is about the continuation tree: no dense linear buckling of 100 segments
  // first (under the sanitizers it alone takes half a minute)
  scene["analyses"].erase("critical_forces");
  scene["solver"]["time_limit"] = timeLimit;
  const fs::path file = dir / ("long_" + std::to_string(int(timeLimit)) + ".json");
  std::ofstream(file) << scene.dump(2);
  return file;
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json summaryOf(const fs::path& out) {
  std::ifstream in(out / "summary.json");
  return nlohmann::json::parse(in);
}

/// Partial results are results: the files are complete JSON / CSV with the points computed.
void requirePartialResults(const fs::path& out) {
  REQUIRE(fs::exists(out / "summary.json"));
  const nlohmann::json summary = summaryOf(out);
  CHECK(summary["complete"] == false);
  CHECK(summary["interrupted"] == true);
  std::ifstream sp(out / "special_points.json");
  CHECK_NOTHROW(nlohmann::json::parse(sp));
  const std::string csv = slurp(out / "branches.csv");
  CHECK(std::count(csv.begin(), csv.end(), '\n') >= 2);  // the header and the points traced (few under ASan)
}

/// No staging directory (.NAME.tmp-XXXXXX) left beside the output.
void requireNoTemporaries(const fs::path& parent) {
  for (const auto& e : fs::directory_iterator(parent)) {
    INFO(e.path());
    CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  }
}

/// `buckle run` on the long scene (scene time limit `timeLimit`) in a fresh work/`name`, with
/// `extra` arguments: exit code, wall time and the captured output; the output in work/name/out.
struct LongRun {
  fs::path dir, out;
  int rc = -1;
  double wall = 0.0;
  std::string log;
};
LongRun runLong(const std::string& name, double timeLimit, const std::string& extra = "") {
  LongRun r;
  r.dir = timeLimitDir() / name;
  fs::remove_all(r.dir);
  fs::create_directories(r.dir);
  const fs::path scene = longScene(r.dir, timeLimit);
  r.out = r.dir / "out";
  const auto t0 = std::chrono::steady_clock::now();
  r.rc = exitCode("run '" + scene.string() + "' --out '" + r.out.string() + "' " + extra, r.dir / "log.txt");
  r.wall = secondsSince(t0);
  r.log = slurp(r.dir / "log.txt");
  return r;
}

}  // namespace

TEST_CASE("a 100-segment default scene with time_limit 5 returns within 6 s with partial results", "[cli][time]") {
  const LongRun run = runLong("limit", 5.0);
  INFO(run.log);
  CHECK(run.rc == 1);
  // it used its time: the computation stops before the limit by the time it expects writing to
  // take, at least 1 s and at most half the limit (CaseRunner::keepTimeForWriting), which grows
  // with the points computed, so a fast machine stops earlier
  CHECK(run.wall > 2.5);
#if defined(__SANITIZE_ADDRESS__)
  CHECK(run.wall < 15.0);  // the writers and plots are slower under the sanitizers
#else
  CHECK(run.wall < 6.0);
#endif
  requirePartialResults(run.out);
  const nlohmann::json summary = summaryOf(run.out);
  CHECK_THAT(summary["interruption"].get<std::string>(), Contains("time limit of 5 s reached"));
  CHECK_THAT(run.log, Contains("stopped early"));
  // progress went to stderr as plain lines (not a terminal), at least the first one after ~1 s
  CHECK_THAT(run.log, Contains("buckle: ["));
  CHECK(run.log.find('\r') == std::string::npos);
  requireNoTemporaries(run.dir);
}

TEST_CASE("the time limit stops the branch reports' loaded stiffness too, and the summary says what was left out",
          "[cli][time]") {
  // The shipped hook with 5000 segments and the stiffness at every point (tens of ms a point: its
  // report alone takes longer than the limit, whether the limit comes while the branch is traced
  // or while it is reported): the report stops computing K there, the points keep their rows with
  // K nan, the branch says what was left out, and the run ends within the limit, incomplete.
  const fs::path dir = timeLimitDir() / "report";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ifstream in(std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/self_contact_hook.json");
  nlohmann::json scene = nlohmann::json::parse(in);
  const int n = 5000, straight = n / 5;
  std::vector<double> q0(size_t(n), 0.0);
  for (int i = straight; i < n; ++i) q0[size_t(i)] = 4.5 / (n - straight);
  scene["chain"]["segments"] = n;
  scene["chain"]["q0"] = q0;
  scene["path"]["to"] = 1.5 / n;
  scene["analyses"] = {{"continuation", {{"branch_switching", 0}, {"self", true}}}, {"stiffness", true}};
  scene["plots"] = nlohmann::json::array();
  const fs::path file = dir / "hook.json", out = dir / "out";
  std::ofstream(file) << scene.dump();
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = exitCode("run '" + file.string() + "' --out '" + out.string() + "' --time-limit 1 --quiet", dir / "log.txt");
  const double wall = secondsSince(t0);
  INFO(slurp(dir / "log.txt"));
  CHECK(rc == 1);
#if defined(__SANITIZE_ADDRESS__)
  CHECK(wall < 15.0);
#else
  CHECK(wall < 2.0);  // 2.0 s without the reports' interrupt
#endif
  requirePartialResults(out);
  bool named = false;
  const nlohmann::json summary = summaryOf(out);
  INFO(summary["cases"][0]["branches"].dump());
  for (const auto& b : summary["cases"][0]["branches"])
    named |= b.contains("skipped") && b["skipped"].get<std::string>().find("the loaded stiffness at") != std::string::npos;
  CHECK(named);
  CHECK_THAT(slurp(out / "branches.csv"), Contains(",nan,"));
  requireNoTemporaries(dir);
}

TEST_CASE("the command line's time limit overrides the scene's, quiet silences the progress", "[cli][time]") {
  const LongRun run = runLong("override", 600.0, "--time-limit 1.5 --quiet");
  INFO(run.log);
  CHECK(run.rc == 1);
  CHECK(run.wall < 10.0);
  requirePartialResults(run.out);
  CHECK(summaryOf(run.out)["solver"]["time_limit"] == 1.5);
  CHECK(run.log.find("buckle: [") == std::string::npos);
  CHECK(exitCode("run '" + (run.dir / "long_600.json").string() + "' --time-limit -1", run.dir / "bad.txt") == 2);
  // NaN is no limit at all: refused, not taken as "not given"
  CHECK(exitCode("run '" + (run.dir / "long_600.json").string() + "' --time-limit nan", run.dir / "nan.txt") == 2);
  CHECK(slurp(run.dir / "nan.txt").find("--time-limit") != std::string::npos);
}

TEST_CASE("SIGINT and SIGTERM stop a long run with partial results and no temporary directory", "[cli][time]") {
  for (const auto& [name, expected] : {std::pair<std::string, int>{"INT", 130}, {"TERM", 143}}) {
    DYNAMIC_SECTION("SIG" << name) {
      const fs::path dir = timeLimitDir() / ("signal_" + name);
      fs::remove_all(dir);
      fs::create_directories(dir);
      const fs::path scene = longScene(dir, 600.0);
      const fs::path out = dir / "out";
      // timeout(1) sends the signal after 2 s and, with --preserve-status, exits as buckle did
      const std::string cmd = "timeout --preserve-status -s " + name + " 2 '" + buckle::test::kBuckle + "' run '" +
                              scene.string() + "' --out '" + out.string() + "' > '" + (dir / "log.txt").string() +
                              "' 2>&1";
      const auto t0 = std::chrono::steady_clock::now();
      const int status = std::system(cmd.c_str());
      const double wall = secondsSince(t0);
      const std::string log = slurp(dir / "log.txt");
      INFO(log);
      REQUIRE(WIFEXITED(status));
      CHECK(WEXITSTATUS(status) == expected);
      CHECK(wall < 12.0);  // 2 s, then a step and the writers (generous for the sanitizers)
      requirePartialResults(out);
      CHECK_THAT(summaryOf(out)["interruption"].get<std::string>(), Contains("signal"));
      requireNoTemporaries(dir);
    }
  }
}
