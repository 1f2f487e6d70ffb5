// The self-contact scene (issue 31): the hook's end is held on its own straight part from SH and
// released on the way back at the same moment (SR); branches.csv names the held contact and its
// force, positive on the held stretch and nowhere else.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
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

namespace {

// Runs the shipped scene `name` (changed by `edit` when given, then written beside `out`) into a
// fresh directory: its special_points.json (empty on failure, the error as a failed check) and the
// directory.
json runShipped(const std::string& name, fs::path& out, const std::function<void(json&)>& edit = {}) {
  out = buckle::test::absentPath(name, "out");
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / (name + ".json")).string();
  if (edit) {
    std::ifstream shipped(opt.scene);
    json scene = json::parse(shipped);
    edit(scene);
    opt.scene = out.string() + ".json";
    std::ofstream(opt.scene) << scene.dump();
  }
  opt.out = out.string();
  const int status = buckle::scene::runSceneCommand(opt, log, err);
  INFO(err.str());
  CHECK(status == 0);
  if (status != 0) return json();
  std::ifstream in(out / "special_points.json");
  return json::parse(in);
}

}  // namespace

TEST_CASE("self-contact scene: held from SH, released at the same moment on the way back", "[scene]") {
  fs::path out;
  const json doc = runShipped("self_contact_hook", out);
  REQUIRE(doc.is_object());
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

TEST_CASE("self-contact scene: a sudden moment strikes the hook's end on its own link and it rests held there",
          "[scene]") {
  fs::path out;
  const json doc = runShipped("self_contact_sudden", out);
  REQUIRE(doc.is_object());
  REQUIRE(doc["sudden_load"].size() == 1);
  const json& s = doc["sudden_load"][0];
  INFO(s["message"]);
  CHECK(s["success"] == true);
  CHECK(s["model"] == "inertial");
  // the strike: a contact event of the end's corner on segment 3, with a kinetic-energy loss
  bool struck = false;
  for (const json& e : s["contact_events"])
    if (e["event"] == "contact" && e.value("vertex", "") == "8d-" && e.value("edge", "") == "3p[j,+]")
      struck = e["kinetic_lost"].get<double>() > 0.0;
  CHECK(struck);
  // at rest held on itself, pushing, and the quasi-static answer (the held continuation) the same
  REQUIRE(s["rest"]["self"].size() == 1);
  CHECK(s["rest"]["self"][0]["vertex"] == "8d-");
  CHECK(s["rest"]["self"][0]["edge"] == "3p[j,+]");
  CHECK(s["rest"]["self"][0]["contact_force"].get<double>() > 0.0);
  CHECK(s["quasi_static"]["differs"] == false);
  CHECK(s["quasi_static"]["max_difference"].get<double>() < 1e-8);
  fs::remove_all(out);
}

TEST_CASE("self-contact scene: natural frequencies beyond SH are those of the chain held on itself", "[scene]") {
  // the hook with masses: the held contact stiffens the second mode at once (the first, nearly
  // along the contact's edge, hardly changes); without the contact's row the frequencies would go
  // on smoothly through SH
  fs::path out;
  const json doc = runShipped("self_contact_hook", out, [](json& scene) {
    scene["analyses"] = {{"continuation", {{"branch_switching", 0}, {"self", true}}},
                         {"frequencies", {{"count", 2}, {"mass_per_length", 1.0}}}};
    scene["plots"] = json::array();
  });
  REQUIRE(doc.is_object());
  std::ifstream csv(out / "branches.csv");
  std::stringstream text;
  text << csv.rdbuf();
  const auto rows = buckle::test::readCsv(text.str());
  REQUIRE(rows.size() > 2);
  size_t self = 0, omega2 = 0;
  for (size_t c = 0; c < rows[0].size(); ++c) {
    if (rows[0][c] == "self") self = c;
    if (rows[0][c] == "omega2") omega2 = c;
  }
  REQUIRE(omega2 > 0);
  double lastFree = 0.0, firstHeld = 0.0;
  for (size_t r = 1; r < rows.size(); ++r) {
    const double w = std::stod(rows[r][omega2]);
    REQUIRE(std::isfinite(w));
    CHECK(w > 0.0);
    if (rows[r][self].empty()) lastFree = w;
    else if (firstHeld == 0.0) firstHeld = w;
  }
  CHECK(firstHeld > 1.2 * lastFree);
  fs::remove_all(out);
  fs::remove(out.string() + ".json");
}
