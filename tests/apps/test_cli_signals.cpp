// SIGINT, SIGTERM and SIGHUP, each while `buckle run` computes and while it writes: the run
// ends with 128 + the signal, its output directory is complete (summary.json says "interrupted"
// and which plots were not drawn) and no temporary directory is left.
//
// Both phases are reached deterministically. Computing: the program prints its "scene ..." line
// once its handlers are installed, and the 100-segment tree takes far longer than the test
// needs to react. Writing: gnuplot is replaced (BUCKLE_GNUPLOT) by a script that records its pid
// in a marker file and sleeps, so the signal arrives while the first plot is being drawn.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "temp_dir.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::slurp;

namespace {

using Clock = std::chrono::steady_clock;

fs::path signalsDir() { return buckle::test::scratchDirectory("cli_signals"); }

/// A stand-in for gnuplot: writes its pid to $BUCKLE_TEST_MARKER, then sleeps (the signal's window).
fs::path fakeGnuplot(const fs::path& dir) {
  const fs::path script = dir / "fake_gnuplot.sh";
  std::ofstream(script) << "#!/bin/sh\necho $$ > \"$BUCKLE_TEST_MARKER.tmp\"\nmv \"$BUCKLE_TEST_MARKER.tmp\" "
                           "\"$BUCKLE_TEST_MARKER\"\nexec sleep 120\n";
  fs::permissions(script, fs::perms::owner_all);
  return script;
}

/// The default scene: 100 segments for a long computation, 3 for a short one; three plots.
fs::path sceneFile(const fs::path& dir, int segments) {
  std::ifstream in(std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json");
  nlohmann::json scene = nlohmann::json::parse(in);
  scene["chain"]["segments"] = segments;
  scene["analyses"].erase("critical_forces");
  scene["solver"]["time_limit"] = 600;
  scene["plots"] = nlohmann::json::array();
  for (const char* name : {"first", "second", "third"})
    scene["plots"].push_back({{"type", "bifurcation"}, {"name", name}, {"x", "Fx"}, {"y", "q2"}});
  const fs::path file = dir / "scene.json";
  std::ofstream(file) << scene.dump(2);
  return file;
}

/// Waits until `done()` (true) or `seconds` pass (false).
template <typename Done>
bool waitFor(Done done, double seconds) {
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < until) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

struct Stopped {
  int status = -1;          ///< raw wait status
  double afterSignal = 0;   ///< seconds from the signal to the end
  std::string log;
};

/// Starts buckle on `scene`, waits for `ready`, sends `sig`, waits for the end.
template <typename Ready>
Stopped runAndSignal(const fs::path& dir, const fs::path& scene, int sig, Ready ready) {
  const fs::path logFile = dir / "log.txt";
  const std::string buckle = buckle::test::kBuckle, sceneArg = scene.string(), out = (dir / "out").string();
  const std::string gnuplot = fakeGnuplot(dir).string(), marker = (dir / "gnuplot.pid").string();
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::setenv("BUCKLE_GNUPLOT", gnuplot.c_str(), 1);
    ::setenv("BUCKLE_TEST_MARKER", marker.c_str(), 1);
    const int fd = ::open(logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execl(buckle.c_str(), buckle.c_str(), "run", sceneArg.c_str(), "--out", out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  Stopped s;
  const bool reached = waitFor([&] { return ready(slurp(logFile)); }, 120.0);
  const auto t0 = Clock::now();
  ::kill(pid, sig);
  ::waitpid(pid, &s.status, 0);
  s.afterSignal = std::chrono::duration<double>(Clock::now() - t0).count();
  s.log = slurp(logFile);
  INFO(s.log);
  REQUIRE(reached);
  return s;
}

void requireConsistentOutput(const fs::path& dir, const std::string& signalName) {
  const fs::path out = dir / "out";
  REQUIRE(fs::exists(out / "summary.json"));
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["complete"] == false);
  CHECK(summary["interrupted"] == true);
  CHECK(summary["interruption"].get<std::string>().find(signalName) != std::string::npos);
  std::ifstream sp(out / "special_points.json");
  CHECK_NOTHROW(nlohmann::json::parse(sp));
  CHECK(fs::exists(out / "branches.csv"));
  CHECK(fs::exists(out / "report.html"));
  // the plots not drawn are named, none is half drawn
  const nlohmann::json notDrawn = summary["plots"].value("not_drawn", nlohmann::json::array());
  CHECK(notDrawn.size() == 3 - summary["plots"]["files"].size() / 2);
  for (const auto& name : notDrawn) {
    CHECK_FALSE(fs::exists(out / "plots" / (name.get<std::string>() + ".png")));
    CHECK_FALSE(fs::exists(out / "plots" / (name.get<std::string>() + ".svg")));
  }
  for (const auto& e : fs::directory_iterator(dir)) {
    INFO(e.path());
    CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
  }
}

}  // namespace

TEST_CASE("each stop signal while computing: 128 + signal, partial results, no plots drawn", "[cli][signals]") {
  for (const auto& [sig, name] : {std::pair<int, std::string>{SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"}}) {
    DYNAMIC_SECTION(name) {
      const fs::path dir = signalsDir() / ("computing_" + name);
      fs::remove_all(dir);
      fs::create_directories(dir);
      const Stopped s = runAndSignal(dir, sceneFile(dir, 100), sig,
                                     [](const std::string& log) { return log.find("case(s)") != std::string::npos; });
      INFO(s.log);
      REQUIRE(WIFEXITED(s.status));
      CHECK(WEXITSTATUS(s.status) == 128 + sig);
      CHECK(s.afterSignal < 30.0);  // a step, then the writers (generous for the sanitizers)
      CHECK_FALSE(fs::exists(dir / "gnuplot.pid"));  // stopped: no plot drawn after the signal
      requireConsistentOutput(dir, name);
    }
  }
}

TEST_CASE("each stop signal while the plots are drawn: 128 + signal, gnuplot ended, output complete", "[cli][signals]") {
  for (const auto& [sig, name] : {std::pair<int, std::string>{SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"}}) {
    DYNAMIC_SECTION(name) {
      const fs::path dir = signalsDir() / ("writing_" + name);
      fs::remove_all(dir);
      fs::create_directories(dir);
      const fs::path marker = dir / "gnuplot.pid";
      const Stopped s = runAndSignal(dir, sceneFile(dir, 3), sig, [&](const std::string&) { return fs::exists(marker); });
      INFO(s.log);
      REQUIRE(WIFEXITED(s.status));
      CHECK(WEXITSTATUS(s.status) == 128 + sig);
      CHECK(s.afterSignal < 10.0);  // not the fake gnuplot's 120 s
      const pid_t gnuplot = std::stoi(slurp(marker));
      CHECK((::kill(gnuplot, 0) == -1 && errno == ESRCH));  // the drawing was ended, not left running
      requireConsistentOutput(dir, name);
    }
  }
}

TEST_CASE("the time limit bounds the plotting: a plot that would take minutes is ended at the limit", "[cli][time]") {
  const fs::path dir = signalsDir() / "plot_time_limit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path scene = sceneFile(dir, 3);
  const std::string cmd = "BUCKLE_GNUPLOT='" + fakeGnuplot(dir).string() + "' BUCKLE_TEST_MARKER='" +
                          (dir / "gnuplot.pid").string() + "' '" + buckle::test::kBuckle + "' run '" + scene.string() +
                          "' --time-limit 3 --out '" + (dir / "out").string() + "' > '" + (dir / "log.txt").string() +
                          "' 2>&1";
  const auto t0 = Clock::now();
  const int status = std::system(cmd.c_str());
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  INFO(slurp(dir / "log.txt"));
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);  // stopped by the time limit
  CHECK(wall < 4.5);                // 3 s, not the fake gnuplot's 120 s
  REQUIRE(fs::exists(dir / "gnuplot.pid"));  // the first plot was being drawn
  std::ifstream in(dir / "out" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["complete"] == false);
  CHECK(summary["interruption"].get<std::string>().find("time limit of 3 s") != std::string::npos);
  CHECK(summary["plots"]["not_drawn"].size() == 3);
}
