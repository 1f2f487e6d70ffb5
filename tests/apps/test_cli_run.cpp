// `buckle run` as a program: exit codes, the output files, --help.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "temp_dir.h"

#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::exitCode;
using buckle::test::slurp;

namespace {

fs::path runDir() { return buckle::test::scratchDirectory("cli_run"); }

}  // namespace

TEST_CASE("buckle run default.json writes the bifurcation diagram and exits 0", "[cli][run]") {
  const fs::path out = runDir() / "default";
  fs::remove_all(out);
  const std::string scene = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json";
  const int rc = exitCode("run '" + scene + "' --out '" + out.string() + "'", runDir() / "log.txt");
  INFO(slurp(runDir() / "log.txt"));
  REQUIRE(rc == 0);
  CHECK(fs::exists(out / "branches.csv"));
  CHECK(fs::exists(out / "special_points.json"));
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["complete"] == true);
  CHECK(summary["cases"][0]["branches"].size() >= 5);  // straight branch + U± and Z±
  const auto eq17 = summary["cases"][0]["critical_forces"]["abs_error_vs_eq17"];
  CHECK(eq17["continuation_BP_U"].get<double>() < 1e-8);
  CHECK(eq17["continuation_BP_Z"].get<double>() < 1e-8);
  // the last line's computation time is summary.json's total, as report.html shows it ("%.3g" s)
  const std::string log = slurp(runDir() / "log.txt");
  const size_t at = log.find("; computed in ");
  REQUIRE(at != std::string::npos);
  const size_t from = at + std::string("; computed in ").size();
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", summary["timings_seconds"]["total"].get<double>());
  CHECK(log.substr(from, log.find(" s (", from) - from) == text);
  std::ifstream page(out / "report.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  CHECK(html.find("\"time_text\":\"" + std::string(text) + "\"") != std::string::npos);
}

TEST_CASE("buckle run on a bad scene exits 2 and writes nothing", "[cli][run]") {
  const fs::path dir = runDir() / "bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.json") << R"({"chain": {"segments": 3, "k": -1}, "path": {"parameter": "Fx", "from": 0, "to": -1},
    "end": {"y": {"held": 0}}, "analyses": {"continuation": true}})";
  const int rc = exitCode("run '" + (dir / "scene.json").string() + "' --out '" + (dir / "out").string() + "'",
                          runDir() / "bad.txt");
  const std::string msg = slurp(runDir() / "bad.txt");
  INFO(msg);
  CHECK(rc == 2);
  CHECK(msg.find((dir / "scene.json").string() + ": /chain/k: expected a number > 0") != std::string::npos);
  CHECK(!fs::exists(dir / "out"));
}

TEST_CASE("buckle run --help and a missing scene argument", "[cli][run]") {
  CHECK(exitCode("run --help", runDir() / "help.txt") == 0);
  CHECK(slurp(runDir() / "help.txt").find("Exit status") != std::string::npos);
  CHECK(exitCode("run", runDir() / "noarg.txt") == 2);
}

TEST_CASE("buckle run --out \"\" and an unknown subcommand exit 2 naming the mistake", "[cli][run]") {
  const std::string scene = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json";
  CHECK(exitCode("run '" + scene + "' --out ''", runDir() / "empty_out.txt") == 2);
  CHECK(slurp(runDir() / "empty_out.txt").find("--out is empty") != std::string::npos);
  CHECK(exitCode("frobnicate", runDir() / "frobnicate.txt") == 2);
  CHECK(slurp(runDir() / "frobnicate.txt").find("unknown subcommand \"frobnicate\" (one of: ") != std::string::npos);
}
