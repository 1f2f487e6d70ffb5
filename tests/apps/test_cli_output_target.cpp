// `buckle run --out` as a program (policy: scene/output_target.h): a refused target exits 2
// before computing and every file stays byte-identical; --force replaces what it may; no
// staging directory survives, whatever the exit; the output follows the umask.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "output_helpers.h"
#include "small_scene.h"
#include "temp_dir.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using buckle::test::mode;
using buckle::test::slurp;
using buckle::test::snapshot;
using buckle::test::stagingLeftovers;

namespace {

const std::string kScene = buckle::test::smallScene(1);

/// A fresh directory holding s.json (the scene), notes.txt and a user folder mine/.
fs::path userDir(const std::string& name) {
  const fs::path d = buckle::test::freshDirectory("cli_out", name);
  fs::create_directories(d / "mine" / "deeper");
  std::ofstream(d / "s.json") << kScene;
  std::ofstream(d / "notes.txt") << "my notes\n";
  std::ofstream(d / "mine" / "data.csv") << "1,2,3\n";
  std::ofstream(d / "mine" / "deeper" / "more.txt") << "more\n";
  return d;
}

/// `buckle ARGS` started in `dir` (so that "." is that directory); exit status, output in `log`.
int runIn(const fs::path& dir, const std::string& args, const fs::path& log) {
  const std::string cmd =
      "cd '" + dir.string() + "' && '" + buckle::test::kBuckle + "' " + args + " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("buckle run --out . (however written) exits 2 and keeps every file", "[cli][run][output]") {
  const fs::path dir = userDir("cwd");
  fs::create_directories(dir / "sub");
  const auto before = snapshot(dir);
  const fs::path log = dir.parent_path() / "cwd.log";
  for (const std::string& out : std::vector<std::string>{".", "./", "sub/..", "../cwd", "../cwd/.", dir.string() + "/",
                                                         dir.string() + "/."}) {
    for (const char* force : {"", " --force"}) {
      INFO("--out " << out << force);
      CHECK(runIn(dir, "run s.json --out '" + out + "'" + force, log) == 2);
      const std::string msg = slurp(log);
      INFO(msg);
      CHECK(msg.find("buckle run: --out \"" + out + "\" is the current directory") != std::string::npos);
      CHECK(msg.find("scene s.json") == std::string::npos);  // refused before the run started
    }
  }
  CHECK(runIn(dir, "run s.json --out .. --force", log) == 2);
  CHECK(slurp(log).find("contains the current directory") != std::string::npos);
  CHECK(runIn(dir, "run s.json --out / --force", log) == 2);
  CHECK(slurp(log).find("is the root directory") != std::string::npos);
  CHECK(snapshot(dir) == before);
}

TEST_CASE("buckle run --out SCENE exits 2 and leaves the scene intact", "[cli][run][output]") {
  const fs::path dir = userDir("scene");
  const auto before = snapshot(dir);
  const fs::path log = dir.parent_path() / "scene.log";
  for (const char* force : {"", " --force"}) {
    CHECK(runIn(dir, std::string("run s.json --out s.json") + force, log) == 2);
    CHECK(slurp(log).find("buckle run: --out \"s.json\" is the scene file s.json") != std::string::npos);
  }
  CHECK(snapshot(dir) == before);
}

TEST_CASE("buckle run --out over a user's file or folder exits 2 unless --force", "[cli][run][output]") {
  const fs::path dir = userDir("foreign");
  const auto before = snapshot(dir);
  const fs::path log = dir.parent_path() / "foreign.log";
  CHECK(runIn(dir, "run s.json --out notes.txt", log) == 2);
  CHECK(slurp(log).find("--out \"notes.txt\" is an existing file") != std::string::npos);
  CHECK(runIn(dir, "run s.json --out mine", log) == 2);
  const std::string msg = slurp(log);
  INFO(msg);
  CHECK(msg.find("--out \"mine\" is an existing directory that is not a buckle output") != std::string::npos);
  CHECK(msg.find("add --force") != std::string::npos);
  CHECK(snapshot(dir) == before);

  // --force: the user asked for it; the folder is replaced by the output as a whole
  CHECK(runIn(dir, "run s.json --out mine --force", log) == 0);
  CHECK(fs::exists(dir / "mine" / "summary.json"));
  CHECK(!fs::exists(dir / "mine" / "data.csv"));
  CHECK(runIn(dir, "run s.json --out notes.txt --force", log) == 0);
  CHECK(fs::is_directory(dir / "notes.txt"));
  CHECK(slurp(dir / "s.json") == kScene);
  CHECK(stagingLeftovers(dir) == 0);
}

TEST_CASE("buckle run over its previous output replaces it but a user file in it needs --force", "[cli][run][output]") {
  const fs::path dir = userDir("previous");
  const fs::path log = dir.parent_path() / "previous.log";
  REQUIRE(runIn(dir, "run s.json --out out/s", log) == 0);
  const nlohmann::json summary = nlohmann::json::parse(slurp(dir / "out" / "s" / "summary.json"));
  CHECK(summary["generator"] == "buckle run");
  CHECK(summary["schema"] == 1);
  const std::string branches = slurp(dir / "out" / "s" / "branches.csv");
  std::ofstream(dir / "out" / "s" / "branches.csv") << "overwritten";
  INFO(slurp(log));
  CHECK(runIn(dir, "run s.json --out out/s", log) == 0);  // recognised by its marker
  CHECK(slurp(dir / "out" / "s" / "branches.csv") == branches);

  std::ofstream(dir / "out" / "s" / "my_fit.txt") << "mine";
  CHECK(runIn(dir, "run s.json --out out/s", log) == 2);
  CHECK(slurp(log).find("my_fit.txt, which buckle does not write") != std::string::npos);
  CHECK(slurp(dir / "out" / "s" / "my_fit.txt") == "mine");
  CHECK(runIn(dir, "run s.json --out out/s --force", log) == 0);
  CHECK(!fs::exists(dir / "out" / "s" / "my_fit.txt"));
  CHECK(stagingLeftovers(dir / "out") == 0);
}

TEST_CASE("buckle run into an unwritable place exits 2 and writes nothing", "[cli][run][output]") {
  const fs::path dir = userDir("unwritable");
  const auto before = snapshot(dir);
  const fs::path log = dir.parent_path() / "unwritable.log";
  CHECK(runIn(dir, "run s.json --out notes.txt/out", log) == 2);
  CHECK(slurp(log).find("notes.txt is not a directory") != std::string::npos);
  CHECK(runIn(dir, "run s.json --out /proc/buckle_test_out", log) == 2);
  CHECK(slurp(log).find("cannot write in /proc") != std::string::npos);
  CHECK(snapshot(dir) == before);
  if (::geteuid() == 0) {
    WARN("running as root: permission bits do not stop writes, the read-only directory case is skipped");
  } else {
    fs::create_directories(dir / "locked");
    fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    CHECK(runIn(dir, "run s.json --out locked/out", log) == 2);
    CHECK(slurp(log).find("cannot write in") != std::string::npos);
    CHECK(fs::is_empty(dir / "locked"));
    fs::permissions(dir / "locked", fs::perms::owner_all);
  }
}

TEST_CASE("no staging directory is left after success or failure", "[cli][run][output]") {
  const fs::path dir = userDir("staging");
  const fs::path log = dir.parent_path() / "staging.log";
  CHECK(runIn(dir, "run s.json --out out", log) == 0);
  CHECK(stagingLeftovers(dir) == 0);
  // a computation that cannot finish (exit 1): partial results, no staging directory
  std::string scene = kScene;
  scene.replace(scene.find("\"plots\": []"), 11, "\"plots\": [], \"solver\": {\"time_limit\": 1e-9}");
  std::ofstream(dir / "slow.json") << scene;
  CHECK(runIn(dir, "run slow.json --out out", log) == 1);
  CHECK(fs::exists(dir / "out" / "summary.json"));
  CHECK(stagingLeftovers(dir) == 0);
  // bad input (exit 2): nothing at all
  std::ofstream(dir / "bad.json") << "{\"chain\": ";
  CHECK(runIn(dir, "run bad.json --out bad_out", log) == 2);
  CHECK(!fs::exists(dir / "bad_out"));
  CHECK(stagingLeftovers(dir) == 0);
}

TEST_CASE("buckle run's output follows the umask", "[cli][run][output]") {
  const fs::path dir = userDir("umask");
  const fs::path log = dir.parent_path() / "umask.log";
  std::string scene = kScene;
  scene.replace(scene.find("\"plots\": []"), 11, "\"plots\": [\"bifurcation\"]");
  std::ofstream(dir / "p.json") << scene;
  for (const mode_t mask : {mode_t(022), mode_t(027)}) {
    INFO("umask 0" << std::oct << mask);
    const mode_t previous = ::umask(mask);  // inherited by the program
    const int rc = runIn(dir, "run p.json --out out", log);
    ::umask(previous);
    REQUIRE(rc == 0);
    CHECK(mode(dir / "out") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "plots") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "summary.json") == (0666u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "branches.csv") == (0666u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "plots" / "bifurcation.gp") == (0666u & ~unsigned(mask)));
  }
}
