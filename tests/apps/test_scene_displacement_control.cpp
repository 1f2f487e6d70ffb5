// Displacement control from a straight start (PathSpec::throughReaction): the scene of the docs
// runs without a load limit, its outputs agree with each other (branches.csv rows, summary.json
// counts, every special point on a drawn curve), the derived limit is the library's critical
// reaction times the margin, and a load limit below the first critical reaction is said, not
// passed off as a complete run.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "branches_table.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/reaction_path.h"
#include "scene_run.h"
#include "read_output.h"

using nlohmann::json;
namespace mech = buckle::mechanics;

namespace {

using buckle::test::readJson;

std::string sceneText(const std::string& pathExtra, const std::string& continuation) {
  return R"({"units": {"length": "m", "force": "N"},
    "chain": {"segments": 5, "a": 0.01, "b": 0.02, "k": 2000.0, "L0": 0.045},
    "end": {"x": {"held": "start"}, "y": {"held": 0.0}, "phi": "free"},
    "path": {"parameter": "x", "from": 0.2, "to": 0.15)" +
         pathExtra + R"(},
    "analyses": {"continuation": )" +
         continuation + R"(, "stiffness": true}})";
}

// The first critical reaction of the scene's chain, from the library directly.
double firstCriticalReaction() {
  const mech::Chain chain = mech::Chain::uniform(5, mech::SegmentParameters::symmetric(0.01, 0.02, 2000.0, 0.045));
  mech::LinearBucklingOptions opt;
  opt.direction = Eigen::Vector3d(1, 0, 0);
  const mech::LinearBucklingResult lb =
      mech::linearBuckling(chain, Eigen::VectorXd::Zero(5), mech::EndCondition::clampedPinned(0.0), opt);
  REQUIRE(!lb.modes.empty());
  return lb.modes.front().lambda;
}

}  // namespace

TEST_CASE("displacement control without a load limit: derived, and every output agrees", "[scene][reaction]") {
  const auto run = buckle::test::runSceneText("displacement_control", "derived", sceneText("", "true"));
  INFO(run.err);
  REQUIRE(run.rc == 0);
  const json summary = readJson(run.out / "summary.json");
  const json& c = summary["cases"][0];
  const double Fc = firstCriticalReaction();
  CHECK(c["load_limit_derived"].get<bool>());
  CHECK(c["first_critical_reaction"].get<double>() == Approx(Fc).epsilon(1e-12));
  CHECK(c["load_limit"].get<double>() == Approx(mech::kReactionLimitMargin * std::abs(Fc)).epsilon(1e-12));

  // rows per branch in branches.csv = the summary's points per branch
  const buckle::test::BranchesTable rows = buckle::test::readBranches(run.out);
  std::map<int, std::vector<const std::map<std::string, double>*>> byBranch;
  for (const auto& r : rows) byBranch[int(r.at("branch"))].push_back(&r);
  REQUIRE(c["branches"].size() >= 3);  // the straight branch and the first buckled one, both sides
  bool reachedEnd = false;
  for (const json& b : c["branches"]) {
    const int id = b["id"].get<int>();
    CHECK(int(byBranch[id].size()) == b["points"].get<int>());
    for (const auto* r : byBranch[id]) {
      CHECK(r->at("x") >= 0.15 - 1e-12);
      CHECK(r->at("x") <= 0.2 + 1e-12);
    }
    if (b["parent"].get<int>() >= 0 && b["stop"] == "parameter range end") {
      // the buckled branch ends where x leaves the range: on the range end itself
      CHECK(std::abs(byBranch[id].back()->at("x") - 0.15) <= 1e-9 * 0.05);
      reachedEnd = true;
    }
  }
  CHECK(reachedEnd);

  // every special point on a drawn curve: between two consecutive rows of its branch in x and Fx
  const json specials = readJson(run.out / "special_points.json");
  int onCurve = 0, total = 0;
  for (const json& s : specials["special_points"]) {
    ++total;
    const auto& pts = byBranch[s["branch"].get<int>()];
    const double x = s["position"]["x"].get<double>(), F = s["loads"]["Fx"].get<double>();
    const double tx = 1e-9 * 0.05, tF = 1e-9 * std::abs(Fc);
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      const double x0 = pts[i]->at("x"), x1 = pts[i + 1]->at("x"), F0 = pts[i]->at("Fx"), F1 = pts[i + 1]->at("Fx");
      if (x >= std::min(x0, x1) - tx && x <= std::max(x0, x1) + tx && F >= std::min(F0, F1) - tF &&
          F <= std::max(F0, F1) + tF) {
        ++onCurve;
        break;
      }
    }
  }
  CHECK(total >= 1);
  CHECK(onCurve == total);
}

TEST_CASE("a load limit below the first critical reaction is said, not passed as complete", "[scene][reaction]") {
  const double Fc = firstCriticalReaction();
  const double low = 0.9 * std::abs(Fc);
  const auto run = buckle::test::runSceneText("displacement_control", "low",
                                              sceneText(", \"load_limit\": " + std::to_string(low), "true"));
  CHECK(run.rc == 1);
  const json summary = readJson(run.out / "summary.json");
  CHECK_FALSE(summary["complete"].get<bool>());
  REQUIRE(summary.contains("problems"));
  const std::string problem = summary["problems"][0].get<std::string>();
  INFO(problem);
  CHECK(problem.find("never moved along x") != std::string::npos);
  CHECK(problem.find("/path/load_limit") != std::string::npos);
  std::ostringstream fc;
  fc.precision(10);
  fc << std::abs(Fc);
  CHECK(problem.find(fc.str()) != std::string::npos);  // the critical reaction the limit falls short of
  CHECK(problem.find(" (N)") != std::string::npos);    // in the scene's force unit
  CHECK_FALSE(summary["cases"][0]["load_limit_derived"].get<bool>());
}

TEST_CASE("displacement control with branch switching turned off says how to move the end", "[scene][reaction]") {
  const auto run = buckle::test::runSceneText("displacement_control", "noswitch",
                                              sceneText("", R"({"branch_switching": 0})"));
  CHECK(run.rc == 1);
  const json summary = readJson(run.out / "summary.json");
  REQUIRE(summary.contains("problems"));
  CHECK(summary["problems"][0].get<std::string>().find("branch_switching") != std::string::npos);
}
