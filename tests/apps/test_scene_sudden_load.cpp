// The sudden-load scene (issue 5): the dynamic rest state and the quasi-static answer are both
// equilibria under the applied load (checked here with the mechanics model directly), the
// energy balance of the damped inertial response holds, and "differs" matches the distance.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "buckle/mechanics/chain.h"
#include "scene/command.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace buckle::mechanics;

TEST_CASE("sudden-load scene: dynamic and quasi-static answers are equilibria, energy balance", "[scene]") {
  const fs::path out = buckle::test::absentPath("sudden", "out");
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = (fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / "sudden_load.json").string();
  opt.out = out.string();
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);
  std::ifstream in(out / "special_points.json");
  const json doc = json::parse(in);
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
