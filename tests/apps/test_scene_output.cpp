// The staging directory of an output (scene/output.h): it follows the umask like every file
// the program creates, replaces the target only on commit, and is gone on every other path.
#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include "output_helpers.h"
#include "temp_dir.h"
#include "scene/output.h"

namespace fs = std::filesystem;
using buckle::scene::StagingDirectory;
using buckle::test::mode;
using buckle::test::stagingLeftovers;

namespace {

fs::path freshDir(const std::string& name) { return buckle::test::freshDirectory("output", name); }

/// Sets the umask for the test's lifetime.
struct Umask {
  mode_t previous;
  explicit Umask(mode_t m) : previous(::umask(m)) {}
  ~Umask() { ::umask(previous); }
  Umask(const Umask&) = delete;
  Umask& operator=(const Umask&) = delete;
};

}  // namespace

TEST_CASE("the staging directory and its files follow the umask", "[scene][output]") {
  for (const mode_t mask : {mode_t(022), mode_t(077), mode_t(002), mode_t(027)}) {
    INFO("umask 0" << std::oct << mask);
    const fs::path dir = freshDir("umask");
    const Umask umask(mask);
    {
      StagingDirectory staging((dir / "out").string());
      CHECK(mode(staging.path()) == (0777u & ~unsigned(mask)));
      std::ofstream(fs::path(staging.path()) / "summary.json") << "{}";
      fs::create_directories(fs::path(staging.path()) / "plots");
      staging.commit();
    }
    CHECK(mode(dir / "out") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "plots") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "summary.json") == (0666u & ~unsigned(mask)));
    CHECK(stagingLeftovers(dir) == 0);
  }
}

TEST_CASE("a staging directory that is not committed leaves nothing behind", "[scene][output]") {
  const fs::path dir = freshDir("abandoned");
  std::ofstream(dir / "keep.txt") << "keep";
  SECTION("destroyed normally") {
    StagingDirectory staging((dir / "out").string());
    std::ofstream(fs::path(staging.path()) / "branches.csv") << "partial";
    CHECK(stagingLeftovers(dir) == 1);
  }
  SECTION("an exception while writing") {
    try {
      StagingDirectory staging((dir / "out").string());
      fs::create_directories(fs::path(staging.path()) / "plots");
      throw std::runtime_error("disk full");
    } catch (const std::runtime_error&) {
    }
  }
  CHECK(!fs::exists(dir / "out"));
  CHECK(stagingLeftovers(dir) == 0);
  CHECK(fs::exists(dir / "keep.txt"));
}

TEST_CASE("commit replaces a previous output as a whole and only then", "[scene][output]") {
  const fs::path dir = freshDir("replace");
  fs::create_directories(dir / "out" / "plots");
  std::ofstream(dir / "out" / "summary.json") << "old";
  std::ofstream(dir / "out" / "plots" / "old.png") << "old";
  {
    StagingDirectory staging((dir / "out/").string());
    std::ofstream(fs::path(staging.path()) / "summary.json") << "new";
    CHECK(fs::exists(dir / "out" / "plots" / "old.png"));  // untouched until commit
    staging.commit();
  }
  std::ifstream in(dir / "out" / "summary.json");
  std::string text;
  in >> text;
  CHECK(text == "new");
  CHECK(!fs::exists(dir / "out" / "plots"));
  CHECK(stagingLeftovers(dir) == 0);
}

TEST_CASE("the staging directory's parents are created as needed", "[scene][output]") {
  const fs::path dir = freshDir("parents");
  {
    StagingDirectory staging((dir / "a" / "b" / "out").string());
    CHECK(fs::path(staging.path()).parent_path() == dir / "a" / "b");
    CHECK(fs::path(staging.path()).filename().string().rfind(".out.tmp-", 0) == 0);
    staging.commit();
  }
  CHECK(fs::is_directory(dir / "a" / "b" / "out"));
  CHECK(stagingLeftovers(dir / "a" / "b") == 0);
}

namespace {
volatile std::sig_atomic_t gDelivered = 0;
extern "C" void recordSignal(int sig) { gDelivered = sig; }
}  // namespace

TEST_CASE("a signal while the output is staged is delivered once the staging directory is gone", "[scene][output]") {
  const fs::path dir = freshDir("signal");
  struct sigaction record {}, previous {};
  record.sa_handler = recordSignal;
  sigemptyset(&record.sa_mask);
  REQUIRE(sigaction(SIGTERM, &record, &previous) == 0);
  gDelivered = 0;
  {
    StagingDirectory staging((dir / "out").string());
    std::raise(SIGTERM);  // e.g. the second Ctrl-C, whose default action ends the program
    sigset_t pending;
    sigpending(&pending);
    CHECK(gDelivered == 0);
    CHECK(sigismember(&pending, SIGTERM) == 1);
    CHECK(stagingLeftovers(dir) == 1);
  }
  CHECK(gDelivered == SIGTERM);  // delivered after the removal
  CHECK(stagingLeftovers(dir) == 0);
  sigaction(SIGTERM, &previous, nullptr);
}
