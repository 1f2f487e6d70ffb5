// The --out policy (scene/output_target.h): what may be replaced by an output directory, with
// and without --force, and that a refusal leaves every file as it was. The current directory is
// a fresh directory holding a scene file, as when a user runs `buckle run s.json --out ...`.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include "output_helpers.h"
#include "temp_dir.h"
#include "scene/output_target.h"

namespace fs = std::filesystem;
using buckle::scene::checkOutputTarget;
using buckle::scene::isBuckleOutput;
using buckle::scene::OutputTargetError;
using buckle::test::snapshot;

namespace {

/// A fresh directory made the current one for the test's lifetime.
struct InFreshDirectory {
  fs::path previous = fs::current_path();
  fs::path root;
  explicit InFreshDirectory(const std::string& name) {
    root = buckle::test::freshDirectory("output_target", name);
    fs::create_directories(root / "work");
    fs::current_path(root / "work");
    std::ofstream("s.json") << "{\"chain\": {\"segments\": 3}}";
  }
  ~InFreshDirectory() { fs::current_path(previous); }
  InFreshDirectory(const InFreshDirectory&) = delete;
  InFreshDirectory& operator=(const InFreshDirectory&) = delete;
};

/// The refusal message of `target` (fails the test when it is accepted).
std::string refusal(const std::string& target, bool force) {
  try {
    checkOutputTarget(target, {"s.json"}, force);
  } catch (const OutputTargetError& e) {
    return e.what();
  }
  FAIL("--out " << target << (force ? " --force" : "") << " was accepted");
  return "";
}

void writeBuckleOutput(const fs::path& dir) {
  fs::create_directories(dir / "plots");
  std::ofstream(dir / "summary.json") << "{\"generator\": \"buckle run\", \"schema\": 1}";
  std::ofstream(dir / "branches.csv") << "case,branch\n";
  std::ofstream(dir / "plots" / "bifurcation.png") << "png";
  std::ofstream(dir / "plots" / "bifurcation.gp") << "plot";
}

}  // namespace

TEST_CASE("the current directory and its ancestors are never an output however written", "[scene][output]") {
  InFreshDirectory here("cwd");
  fs::create_directories("sub");
  fs::create_symlink(fs::current_path(), "here_link");
  fs::create_symlink(here.root, "parent_link");
  const auto before = snapshot(here.root);
  const std::string cwd = fs::current_path().string();
  for (const std::string& t : {std::string("."), std::string("./"), std::string("sub/.."), std::string("../work"),
                               std::string("../work/."), cwd, cwd + "/", cwd + "/.", std::string("here_link"),
                               std::string("here_link/")}) {
    for (bool force : {false, true}) {
      INFO("--out " << t << " force " << force);
      CHECK_THAT(refusal(t, force), Catch::Contains("is the current directory"));
    }
  }
  for (const std::string& t : {std::string(".."), std::string("../"), std::string("sub/../.."), std::string("parent_link"),
                               here.root.parent_path().string()}) {
    for (bool force : {false, true}) {
      INFO("--out " << t << " force " << force);
      CHECK_THAT(refusal(t, force), Catch::Contains("contains the current directory"));
    }
  }
  for (bool force : {false, true}) {
    CHECK_THAT(refusal("/", force), Catch::Contains("is the root directory"));
    CHECK_THAT(refusal("//", force), Catch::Contains("is the root directory"));
    CHECK_THAT(refusal("/..", force), Catch::Contains("is the root directory"));
  }
  CHECK_THAT(refusal("", false), Catch::Contains("--out is empty"));
  CHECK(snapshot(here.root) == before);
}

TEST_CASE("the scene file and a directory holding it are never an output", "[scene][output]") {
  InFreshDirectory here("scene");
  fs::create_symlink("s.json", "scene_link");
  fs::create_hard_link("s.json", "scene_hard");
  fs::create_directories("elsewhere");
  std::ofstream("elsewhere/t.json") << "{}";
  const auto before = snapshot(here.root);
  for (bool force : {false, true}) {
    for (const char* t : {"s.json", "./s.json", "sub/../s.json", "scene_link", "scene_hard"}) {
      INFO("--out " << t << " force " << force);
      CHECK_THAT(refusal(t, force), Catch::Contains("is the scene file s.json"));
    }
    try {
      checkOutputTarget("elsewhere", {"elsewhere/t.json"}, force);
      FAIL("a directory holding the scene was accepted");
    } catch (const OutputTargetError& e) {
      CHECK_THAT(e.what(), Catch::Contains("contains the scene file elsewhere/t.json"));
    }
  }
  CHECK(snapshot(here.root) == before);
}

TEST_CASE("an existing file or foreign directory is replaced only with --force", "[scene][output]") {
  InFreshDirectory here("foreign");
  std::ofstream("notes.txt") << "my notes";
  fs::create_directories("mine/deeper");
  std::ofstream("mine/data.csv") << "1,2,3";
  std::ofstream("mine/deeper/more.txt") << "more";
  const auto before = snapshot(here.root);

  CHECK_THAT(refusal("notes.txt", false), Catch::Contains("is an existing file") && Catch::Contains("--force"));
  CHECK_THAT(refusal("mine", false), Catch::Contains("is an existing directory that is not a buckle output") &&
                                         Catch::Contains("--force"));
  CHECK_THAT(refusal("mine/", false), Catch::Contains("not a buckle output"));
  CHECK(snapshot(here.root) == before);

  const fs::path cwd = fs::current_path();
  CHECK(checkOutputTarget("notes.txt", {"s.json"}, true) == (cwd / "notes.txt").string());
  CHECK(checkOutputTarget("mine/", {"s.json"}, true) == (cwd / "mine").string());
  CHECK(snapshot(here.root) == before);  // the check itself writes nothing
}

TEST_CASE("new paths and empty directories and previous buckle outputs are accepted", "[scene][output]") {
  InFreshDirectory here("accepted");
  const fs::path cwd = fs::current_path();
  CHECK(checkOutputTarget("out/new", {"s.json"}, false) == (cwd / "out" / "new").string());
  CHECK(!fs::exists("out"));  // nothing created by the check
  fs::create_directories("empty");
  CHECK(checkOutputTarget("empty", {"s.json"}, false) == (cwd / "empty").string());

  writeBuckleOutput("previous");
  std::string why;
  CHECK(isBuckleOutput("previous", &why));
  CHECK(checkOutputTarget("./previous/.", {"s.json"}, false) == (cwd / "previous").string());
  // a symbolic link to an output: the directory it names is the one replaced
  fs::create_symlink(cwd / "previous", "latest");
  CHECK(checkOutputTarget("latest", {"s.json"}, false) == (cwd / "previous").string());

  SECTION("a user file inside a previous output makes it foreign") {
    std::ofstream("previous/notes.txt") << "mine";
    CHECK(!isBuckleOutput("previous", &why));
    CHECK_THAT(why, Catch::Contains("notes.txt, which buckle does not write"));
    CHECK_THAT(refusal("previous", false), Catch::Contains("notes.txt, which buckle does not write"));
  }
  SECTION("so does a subdirectory of plots/") {
    fs::create_directories("previous/plots/mine");
    CHECK(!isBuckleOutput("previous", &why));
    CHECK_THAT(why, Catch::Contains("plots/mine"));
  }
  SECTION("a user's image in plots/ is foreign when the summary lists what the run wrote there") {
    std::ofstream("previous/summary.json")
        << R"({"generator": "buckle run", "schema": 1, "plots": {"written": ["plots/bifurcation.gp", "plots/bifurcation.png"]}})";
    CHECK(isBuckleOutput("previous"));
    std::ofstream("previous/plots/mynote.png") << "mine";
    CHECK(!isBuckleOutput("previous", &why));
    CHECK_THAT(why, Catch::Contains("plots/mynote.png, which buckle did not write"));
    CHECK_THAT(refusal("previous", false), Catch::Contains("--force"));
  }
  SECTION("a summary.json without buckle's marker is not enough") {
    std::ofstream("previous/summary.json") << "{\"generator\": \"someone else\"}";
    CHECK(!isBuckleOutput("previous", &why));
    CHECK_THAT(why, Catch::Contains("\"generator\" marker"));
    std::ofstream("previous/summary.json") << "not json";
    CHECK(!isBuckleOutput("previous"));
  }
  SECTION("an output written before the marker existed is recognised by its summary's keys") {
    std::ofstream("previous/summary.json") << R"({"scene": "s.json", "complete": true, "computed": [], "solver": {},
                                                 "cases": [], "timings_seconds": {}})";
    CHECK(isBuckleOutput("previous"));
    CHECK(buckle::scene::outputGenerator("previous") == "buckle run");
    std::ofstream("previous/summary.json") << R"({"scene": "s.json", "complete": true})";
    CHECK(!isBuckleOutput("previous"));
  }
  SECTION("an atlas output is recognised too") {
    std::ofstream("previous/summary.json") << "{\"generator\": \"buckle atlas\", \"schema\": 1}";
    CHECK(isBuckleOutput("previous"));
  }
}

TEST_CASE("an unwritable place is refused before anything is computed", "[scene][output]") {
  InFreshDirectory here("unwritable");
  std::ofstream("notes.txt") << "my notes";
  fs::create_symlink("nowhere", "dangling");
  const auto before = snapshot(here.root);
  for (bool force : {false, true}) {
    CHECK_THAT(refusal("notes.txt/out", force), Catch::Contains("notes.txt is not a directory"));
    CHECK_THAT(refusal("notes.txt/a/b", force), Catch::Contains("notes.txt is not a directory"));
    CHECK_THAT(refusal("dangling", force), Catch::Contains("symbolic link that leads nowhere"));
    // /proc takes no new directories, whoever asks (permission bits do not stop root)
    CHECK_THAT(refusal("/proc/buckle_out", force), Catch::Contains("cannot write in /proc"));
  }
  CHECK(snapshot(here.root) == before);

  fs::create_directories("locked");
  fs::permissions("locked", fs::perms::owner_read | fs::perms::owner_exec);
  if (::geteuid() == 0) {
    WARN("running as root: permission bits do not stop writes, the read-only directory case is skipped");
  } else {
    CHECK_THAT(refusal("locked/out", false), Catch::Contains("cannot write in") && Catch::Contains("locked"));
    CHECK(fs::is_empty("locked"));
  }
  fs::permissions("locked", fs::perms::owner_all);
}
