// The self-contact scene (issue 31): the hook's end is held on its own straight part from SH and
// released on the way back at the same moment (SR); branches.csv names the held contact and its
// force, positive on the held stretch and nowhere else.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "build_paths.h"
#include "rfc4180.h"
#include "scene/command.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using nlohmann::json;

TEST_CASE("self-contact scene: held from SH, released at the same moment on the way back", "[scene]") {
  const fs::path out = buckle::test::absentPath("self_contact", "out");
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / "self_contact_hook.json").string();
  opt.out = out.string();
  const int status = buckle::scene::runSceneCommand(opt, log, err);
  INFO(err.str());
  REQUIRE(status == 0);
  std::ifstream in(out / "special_points.json");
  const json doc = json::parse(in);
  std::vector<double> held, released;
  for (const json& p : doc["special_points"]) {
    if (p["type"] == "SH") held.push_back(p["parameter"].get<double>());
    if (p["type"] == "SR") released.push_back(p["parameter"].get<double>());
    if (p["type"] == "SH" || p["type"] == "SR") {
      CHECK(p["self_contact"]["vertex"] == "8d-");
      CHECK(p["self_contact"]["edge"] == "3p[j,+]");
    }
  }
  // the continuation's SH, the history's SH on the way up and its SR on the way down: one moment
  REQUIRE(held.size() == 2);
  REQUIRE(released.size() == 1);
  CHECK(held[1] == Approx(held[0]).epsilon(1e-10));
  CHECK(released[0] == Approx(held[0]).epsilon(1e-10));
  // branches.csv: the contact and a pushing force beyond SH (on the way up), none before it
  std::ifstream csv(out / "branches.csv");
  std::stringstream text;
  text << csv.rdbuf();
  const auto rows = buckle::test::readCsv(text.str());
  REQUIRE(rows.size() > 2);
  const auto column = [&](const std::string& name) {
    for (size_t c = 0; c < rows[0].size(); ++c)
      if (rows[0][c] == name) return c;
    FAIL("no column " << name);
    return size_t(0);
  };
  const size_t branch = column("branch"), me = column("Me"), self = column("self"), force = column("self_force");
  int heldRows = 0;
  for (size_t r = 1; r < rows.size(); ++r) {
    if (rows[r][branch] != "0") continue;  // the continuation's branch
    const double M = std::stod(rows[r][me]);
    INFO("Me = " << M);
    if (M < held[0] * (1 - 1e-9)) {
      CHECK(rows[r][self].empty());
      CHECK(std::stod(rows[r][force]) == 0.0);
    } else if (M > held[0] * (1 + 1e-6)) {
      CHECK(rows[r][self] == "8d- on 3p[j,+]");
      CHECK(std::stod(rows[r][force]) > 0.0);
      ++heldRows;
    }
  }
  CHECK(heldRows >= 3);
  fs::remove_all(out);
}
