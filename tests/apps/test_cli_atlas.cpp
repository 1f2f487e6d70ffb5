// `buckle atlas` as a program: atlas.csv has one column per quantity, summary.json carries the
// output marker, and --out is checked before computing like `buckle run`'s.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "output_helpers.h"
#include "temp_dir.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using buckle::test::exitCode;
using buckle::test::slurp;

namespace {

fs::path atlasDir(const std::string& name) { return buckle::test::freshDirectory("cli_atlas", name); }

// A 2 x 2 atlas: a few hundred milliseconds.
const std::string kSmall = "atlas --x a --x-range 0.4 0.6 2 --y L0 --y-range 2.0 2.5 2 -j 1 --quiet";

}  // namespace

TEST_CASE("atlas.csv names every column once and summary.json says which are the axes", "[cli][atlas]") {
  const fs::path dir = atlasDir("columns");
  REQUIRE(exitCode(kSmall + " --out '" + (dir / "out").string() + "'", dir / "log.txt") == 0);
  std::ifstream csv(dir / "out" / "atlas.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header == "a,L0,n,kappa,straight_stable,first_critical_Fx,first_shape,post_buckling,post_slope,error");
  std::set<std::string> names;
  std::stringstream cols(header);
  for (std::string c; std::getline(cols, c, ',');) CHECK(names.insert(c).second);
  int rows = 0;
  for (std::string line; std::getline(csv, line);) {
    ++rows;
    CHECK(std::count(line.begin(), line.end(), ',') == 9);  // the error field is empty here
  }
  CHECK(rows == 4);
  const nlohmann::json summary = nlohmann::json::parse(slurp(dir / "out" / "summary.json"));
  CHECK(summary["generator"] == "buckle atlas");
  CHECK(summary["schema"] == 1);
  CHECK(summary["x"]["name"] == "a");
  CHECK(summary["y"]["name"] == "L0");
}

TEST_CASE("buckle atlas --out is checked before computing", "[cli][atlas][output]") {
  const fs::path dir = atlasDir("out");
  std::ofstream(dir / "notes.txt") << "my notes";
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine" / "data.csv") << "1,2";
  const fs::path log = dir.parent_path() / "out.log";
  CHECK(exitCode(kSmall + " --out '" + dir.string() + "/notes.txt'", log) == 2);
  CHECK(slurp(log).find("is an existing file") != std::string::npos);
  CHECK(exitCode(kSmall + " --out '" + dir.string() + "/mine'", log) == 2);
  CHECK(slurp(log).find("is an existing directory that is not a buckle output") != std::string::npos);
  CHECK(exitCode(kSmall + " --out . --force", log) == 2);
  CHECK(slurp(log).find("error: --out \".\" is the current directory") != std::string::npos);
  CHECK(exitCode(kSmall + " --out / --force", log) == 2);
  CHECK(exitCode(kSmall + " --out '" + dir.string() + "/notes.txt/atlas'", log) == 2);
  CHECK(slurp(log).find("notes.txt is not a directory") != std::string::npos);
  CHECK(slurp(dir / "notes.txt") == "my notes");
  CHECK(slurp(dir / "mine" / "data.csv") == "1,2");

  // a previous atlas is recognised and replaced; a run output may be replaced by an atlas too
  const std::string out = " --out '" + (dir / "atlas").string() + "'";
  REQUIRE(exitCode(kSmall + out, log) == 0);
  std::ofstream(dir / "atlas" / "atlas.csv") << "overwritten";
  CHECK(exitCode(kSmall + out, log) == 0);
  CHECK(slurp(dir / "atlas" / "atlas.csv").rfind("a,L0,n,", 0) == 0);
  CHECK(exitCode(kSmall + " --out '" + (dir / "mine").string() + "' --force", log) == 0);
  CHECK(!fs::exists(dir / "mine" / "data.csv"));
  CHECK(buckle::test::stagingLeftovers(dir) == 0);
}
