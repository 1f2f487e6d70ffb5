// The sudden-load scene (issue 5): the dynamic rest state and the quasi-static answer are both
// equilibria under the applied load (checked here with the mechanics model directly), the
// energy balance of the damped inertial response holds, and "differs" matches the distance.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "buckle/mechanics/chain.h"
#include "mechanics/curled_chain.h"
#include "mechanics/wall_statics.h"
#include "scene/command.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace buckle::mechanics;

namespace {

/// Runs the shipped scene `name` into a scratch directory `out` and returns its special_points.json.
json runShipped(const std::string& name, const fs::path& out) {
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / (name + ".json")).string();
  opt.out = out.string();
  const int status = buckle::scene::runSceneCommand(opt, log, err);
  INFO(err.str());
  REQUIRE(status == 0);
  std::ifstream in(out / "special_points.json");
  return json::parse(in);
}

}  // namespace

TEST_CASE("sudden-load scene: dynamic and quasi-static answers are equilibria, energy balance", "[scene]") {
  const fs::path out = buckle::test::absentPath("sudden", "out");
  const json doc = runShipped("sudden_load", out);
  REQUIRE(doc["sudden_load"].size() == 1);
  const json& r = doc["sudden_load"][0];
  CHECK(r["success"] == true);
  CHECK(r["stable"] == true);
  CHECK(r["model"] == "inertial");
  CHECK(double(r["energy_balance_error"]) < 1e-7);
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
  const Wrench F(0.0, 0.1, 0.0);
  for (const json* shape : {&r["rest"]["q"], &r["quasi_static"]["q"]}) {
    Eigen::VectorXd q(3), g(3);
    for (int i = 0; i < 3; ++i) q[i] = (*shape)[size_t(i)];
    totalPotentialGradient(chain, q, F, g);
    CHECK(g.cwiseAbs().maxCoeff() < 1e-9);
  }
  const json& qs = r["quasi_static"];
  CHECK(bool(qs["differs"]) == (double(qs["max_difference"]) > 1e-6));
  // whichever is reported lower in Π is lower
  if (qs["lower"] == "dynamic") CHECK(double(qs["potential_dynamic"]) < double(qs["potential_static"]));
  if (qs["lower"] == "static") CHECK(double(qs["potential_static"]) < double(qs["potential_dynamic"]));
  // the trajectory is written
  CHECK(fs::file_size(out / "sudden_load.csv") > 1000);
  fs::remove_all(out);
}

TEST_CASE("sudden load on the wall: the chain strikes, slides and rests on it with the force of its statics",
          "[scene][wall]") {
  const fs::path out = buckle::test::absentPath("sudden_wall", "out");
  const json doc = runShipped("wall_sudden_load", out);
  REQUIRE(doc["sudden_load"].size() == 1);
  const json& r = doc["sudden_load"][0];
  INFO(r["message"]);
  CHECK(r["success"] == true);
  CHECK(r["stable"] == true);
  CHECK(double(r["energy_balance_error"]) < 1e-7);
  // at rest on the wall: one vertex, pushing with the force of the test's own statics
  const json& wall = r["rest"]["wall"];
  REQUIRE(wall.size() == 1);
  CHECK(wall[0]["vertex"] == "5d-");
  const Chain chain = testing::curledChain(false);
  Eigen::VectorXd q(5);
  for (int i = 0; i < 5; ++i) q[i] = r["rest"]["q"][size_t(i)];
  const buckle::test::Statics s = buckle::test::wallStatics(chain, q, Eigen::Vector2d(0.0, 0.13), WallVertex{4, 4});
  CHECK(s.imbalance <= 1e-10);
  CHECK(s.mu > 0.0);
  CHECK(double(wall[0]["wall_force"]) == Approx(s.mu).epsilon(1e-8));
  CHECK(std::abs(buckle::test::vertexAt(chain, q, WallVertex{4, 4}).x()) <= 1e-12 * chain.linkLengths().sum());
  // the events: in time order, every release of a vertex held before, every impact losing energy,
  // the last event of the resting vertex a contact
  const json& events = r["contact_events"];
  REQUIRE(events.size() >= 1);
  std::map<std::string, bool> held;
  double t = 0.0;
  for (const json& e : events) {
    CHECK(double(e["t"]) >= t);
    t = e["t"];
    REQUIRE(e.contains("vertex"));
    const std::string v = e["vertex"];
    if (e["event"] == "contact") {
      CHECK_FALSE(held[v]);
      CHECK(double(e["kinetic_lost"]) >= 0.0);
      held[v] = true;
    } else {
      CHECK(held[v]);
      held[v] = false;
    }
  }
  CHECK(double(events[0]["kinetic_lost"]) > 0.0);
  CHECK(held["5d-"]);
  fs::remove_all(out);
}
