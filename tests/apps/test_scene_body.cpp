// /gravity, /point_loads and the gravity path (scene_body.cpp, docs/scenes.md "Weight and point
// loads"): a heavy cantilever traced in g against an independent Newton solve of the library's
// GravityPotential, its frequencies against the vibration analysis with that potential's Hessian,
// a point load with a rate against the same load at the end, and bad input refused with exit 2
// naming the JSON path, nothing written.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/gravity.h"
#include "buckle/mechanics/vibration.h"
#include "../mechanics/heavy_newton.h"
#include "branches_table.h"
#include "scene_run.h"

namespace fs = std::filesystem;
using namespace buckle::mechanics;

namespace {

using Table = buckle::test::BranchesTable;
using buckle::test::readBranches;

// Four segments (a, b, k, L0) = (0.5, 1, 1, 2.25), free end; `extra` goes into the top level.
std::string bodyScene(const std::string& extra, const std::string& path, const std::string& analyses) {
  return R"({"chain": {"segments": 4, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
  "end": {"x": {"load": 0.0}, "y": {"load": 0.0}, "phi": "free"}, )" +
         extra + R"(, "path": )" + path + R"(, "analyses": )" + analyses + R"(, "plots": []})";
}

const std::string kGravity = R"("gravity": {"value": 0.0, "direction": [0, -1], "mass_per_length": 0.01})";
const std::string kGravityPath = R"({"parameter": "gravity", "from": 0.0, "to": 3.0})";

void requireBadBody(const std::string& name, const std::string& text, const std::string& path,
                     const std::string& expected) {
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", name, text);
  INFO(o.err);
  CHECK(o.rc == 2);
  CHECK(o.err.find(": " + path + ": ") != std::string::npos);
  CHECK(o.err.find(expected) != std::string::npos);
  CHECK(!fs::exists(o.out));
}

// Newton on E + V (GravityPotential) with g raised in 30 equal steps
Vector independentSag(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& g) {
  Vector q = Vector::Zero(chain.size());
  for (int step = 1; step <= 30; ++step) q = testing::heavyNewton(chain, inertia, g * (step / 30.0), q, 30);
  return q;
}

// ‖∂E/∂q + ∂V/∂q‖∞ at q: the torques of the springs and of the links' weight (uniform rods of
// ρ = 0.01) under g, V from GravityPotential (absolute positions, eq G2), independent of the
// library's body loads. Zero at an equilibrium of the free chain with no end load.
Vector weightImbalanceVector(const Chain& chain, const Eigen::Vector2d& g, const Vector& q) {
  Vector dE(chain.size()), dV(chain.size());
  energyGradient(chain, q, dE);
  GravityPotential(chain, InertiaData::uniformRods(chain, 0.01), g).gradient(q, dV);
  return dE + dV;
}
double weightImbalance(const Chain& chain, const Eigen::Vector2d& g, const Vector& q) {
  return weightImbalanceVector(chain, g, q).lpNorm<Eigen::Infinity>();
}

}  // namespace

TEST_CASE("scene gravity path: a heavy cantilever's angles and frequencies equal the library's independent ones",
          "[scene][body_loads]") {
  const std::string text = bodyScene(kGravity, kGravityPath, R"({"continuation": true, "frequencies": {"count": 2, "mass_per_length": 0.01}})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "cantilever", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const Table t = readBranches(o.out);
  const std::map<std::string, double>& last = t.back();
  CHECK(last.at("parameter") == Approx(3.0).epsilon(1e-12));
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const InertiaData rods = InertiaData::uniformRods(chain, 0.01);
  const Vector q = independentSag(chain, rods, Eigen::Vector2d(0.0, -3.0));
  Vector traced(4);
  for (int i = 0; i < 4; ++i) traced[i] = last.at("q" + std::to_string(i + 1));
  CHECK((traced - q).lpNorm<Eigen::Infinity>() <= 1e-9 * q.lpNorm<Eigen::Infinity>());
  CHECK(q.lpNorm<Eigen::Infinity>() > 1e-3);  // it sags
  // ω from the vibration analysis with the weight's Hessian (GravityPotential's generator)
  Vector gamma(4);
  GravityPotential(chain, rods, Eigen::Vector2d(0.0, -3.0)).hessianGenerator(q, gamma);
  VibrationAnalysis va(chain, rods);
  const VibrationModes m = va.modes(q, Wrench::Zero(), {}, {}, 2, false, gamma);
  const VibrationModes weightless = va.modes(q, Wrench::Zero(), {}, {}, 2, false);
  for (int k = 0; k < 2; ++k) {
    const double omega = last.at("omega" + std::to_string(k + 1));
    CHECK(omega == Approx(signedFrequency(m.omegaSquared[k])).epsilon(1e-8));
    CHECK(std::abs(omega - signedFrequency(weightless.omegaSquared[k])) > 1e-4 * omega);
  }
}

TEST_CASE("scene load history under the weight: the column buckles under its own weight and the history follows "
          "equilibria of that weight", "[scene][body_loads]") {
  // The chain standing on its clamp (gravity along −x): past the critical g the straight column
  // loses its stability at a branch point and the history goes on along the stable branch born
  // there; every point it keeps is an equilibrium of E + V at its g (independent Newton,
  // GravityPotential with absolute positions).
  const std::string text =
      bodyScene(R"("gravity": {"value": 0.0, "direction": [-1, 0], "mass_per_length": 0.01})",
            R"({"parameter": "gravity", "from": 0.0, "to": 10.0})", R"({"load_history": {"waypoints": [0.0, 10.0]}})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "heavy_history", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const Table t = readBranches(o.out);
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  int bent = 0;
  for (const auto& row : t) {
    Vector q(4);
    for (int i = 0; i < 4; ++i) q[i] = row.at("q" + std::to_string(i + 1));
    // the branch point where the piece on the buckled branch starts is critical (its smallest
    // eigenvalue zero to rounding, Newton ill-conditioned there): every other point is stable
    if (std::abs(row.at("min_eig")) <= 1e-12) continue;
    CHECK(row.at("stable") == 1.0);
    // the springs' and the weight's torques balance, to the CSV's 12 digits against κ = 0.75
    CHECK(weightImbalance(chain, Eigen::Vector2d(-row.at("parameter"), 0.0), q) <= 1e-10);
    if (q.lpNorm<Eigen::Infinity>() > 1e-2) ++bent;
  }
  CHECK(bent > 0);  // past the critical weight the history is on the buckled branch
}

TEST_CASE("scene sudden weight: the cantilever released under its full weight at once comes to rest at the static "
          "sag", "[scene][body_loads]") {
  // g jumps from 0 to 3 (the gravity path's sudden load): the gradient flow with the weight ends at
  // the one stable equilibrium, the sag of the independent Newton solve on E + V.
  const std::string text = bodyScene(kGravity, kGravityPath, R"({"sudden_load": {"value": 3.0}})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "sudden_weight", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  std::ifstream in(o.out / "special_points.json");
  const nlohmann::json sp = nlohmann::json::parse(in);
  REQUIRE(sp["sudden_load"].size() == 1);
  const nlohmann::json& e = sp["sudden_load"][0];
  CHECK(e["success"].get<bool>());
  CHECK(e["stable"].get<bool>());
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Vector q = independentSag(chain, InertiaData::uniformRods(chain, 0.01), Eigen::Vector2d(0.0, -3.0));
  REQUIRE(q.lpNorm<Eigen::Infinity>() > 1e-3);  // it sags: the weight was in the dynamics
  Vector rest(4);
  for (int i = 0; i < 4; ++i) rest[i] = e["rest"]["q"][size_t(i)].get<double>();
  CHECK((rest - q).lpNorm<Eigen::Infinity>() <= 1e-9 * q.lpNorm<Eigen::Infinity>());
  CHECK_FALSE(e["quasi_static"]["differs"].get<bool>());
}

TEST_CASE("scene control path under the weight: the free lengths move, every point balances the springs at its "
          "free lengths against the weight", "[scene][body_loads]") {
  // The horizontal heavy cantilever with L0 of every segment the path parameter (both springs):
  // its start is the sag under the weight (applied with the payload), and each traced point is an
  // equilibrium of E(q; L0 = λ) + V (GravityPotential, independent of the library's body loads).
  const std::string text = bodyScene(R"("gravity": {"value": 3.0, "direction": [0, -1], "mass_per_length": 0.01})",
                                 R"({"parameter": "L0", "from": 2.0, "to": 2.5})", R"({"continuation": true})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "control_weight", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const Table t = readBranches(o.out);
  REQUIRE(t.size() > 5);
  double sag = 0.0;
  for (const auto& row : t) {
    const double L0 = row.at("parameter");
    const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, L0));
    Vector q(4);
    for (int i = 0; i < 4; ++i) q[i] = row.at("q" + std::to_string(i + 1));
    CHECK(weightImbalance(chain, Eigen::Vector2d(0.0, -3.0), q) <= 1e-10);
    sag = std::max(sag, q.lpNorm<Eigen::Infinity>());
  }
  CHECK(sag > 1e-3);  // the weight bends it
}

TEST_CASE("scene task path under the weight: the end is lifted by dL0, every point balances the springs at its "
          "inputs against the weight and the payload", "[scene][body_loads][task_path]") {
  // The heavy cantilever with a payload, its end driven up to y = 0 by the differential input of
  // every segment: each traced point an equilibrium of E(q; dL0) + V − F·pose (GravityPotential,
  // independent of the library's body loads), the end on the path.
  const std::string text = R"({"chain": {"segments": 4, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": 0.0}, "y": {"load": -0.1}, "phi": {"load": 0.0}},
    "gravity": {"value": 3.0, "direction": [0, -1], "mass_per_length": 0.01},
    "path": {"task": {"coordinates": ["y"], "to": [0.0]}, "inputs": ["dL0"]},
    "analyses": {"continuation": true}, "plots": []})";
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "task_weight", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const Table t = readBranches(o.out);
  REQUIRE(t.size() > 5);
  const Eigen::Vector3d payload(0.0, -0.1, 0.0);
  CHECK(t.front().at("y") < -3.0);  // the start sags under the weight and the payload
  CHECK(std::abs(t.back().at("y")) <= 1e-9);
  for (const auto& row : t) {
    const double dL0 = row.at("dL0");  // L1_0 − L2_0 of every segment, the common mode kept
    SegmentParameters segment = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
    segment.L1_0 += 0.5 * dL0;
    segment.L2_0 -= 0.5 * dL0;
    const Chain chain = Chain::uniform(4, segment);
    Vector q(4);
    for (int i = 0; i < 4; ++i) q[i] = row.at("q" + std::to_string(i + 1));
    ChainData data(chain);
    forwardKinematics(chain, q, data);
    Matrix J(3, 4);
    endJacobian(data, J);
    const Vector endLoad = J.transpose() * payload;
    CHECK((weightImbalanceVector(chain, Eigen::Vector2d(0.0, -3.0), q) - endLoad).lpNorm<Eigen::Infinity>() <= 1e-10);
  }
}

TEST_CASE("scene equilibria under the weight: each balances the springs against the weight, the lowest is the sag",
          "[scene][body_loads]") {
  // Every equilibrium of the heavy horizontal cantilever at g = 3, by deflation with the body loads:
  // each found one balances ∂E/∂q + ∂V/∂q = 0 and reports Π = E + V (V from GravityPotential, with
  // absolute positions); the one of lowest Π is stable and is the independent static sag.
  const std::string text = bodyScene(kGravity, kGravityPath, R"({"equilibria": {"at": 3.0, "starts": 16, "smooth_starts": 16}})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "equilibria_weight", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  std::ifstream in(o.out / "equilibria.csv");
  REQUIRE(in.good());
  std::stringstream csv;
  csv << in.rdbuf();
  const auto rows = buckle::test::readCsv(csv.str());
  REQUIRE(rows.size() >= 2);
  std::map<std::string, size_t> col;
  for (size_t c = 0; c < rows[0].size(); ++c) col[rows[0][c]] = c;
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const InertiaData rods = InertiaData::uniformRods(chain, 0.01);
  const GravityPotential V(chain, rods, Eigen::Vector2d(0.0, -3.0));
  for (size_t r = 1; r < rows.size(); ++r) {
    Vector q(4);
    for (int i = 0; i < 4; ++i) q[i] = std::stod(rows[r][col.at("q" + std::to_string(i + 1))]);
    CHECK(weightImbalance(chain, Eigen::Vector2d(0.0, -3.0), q) <= 1e-9);
    const double pi = energy(chain, q) + V.value(q);
    CHECK(std::stod(rows[r][col.at("potential")]) == Approx(pi).epsilon(1e-12).margin(1e-13));
  }
  // rank 1, the lowest Π: stable, the sag
  CHECK(rows[1][col.at("stable")] == "1");
  Vector first(4);
  for (int i = 0; i < 4; ++i) first[i] = std::stod(rows[1][col.at("q" + std::to_string(i + 1))]);
  const Vector sag = independentSag(chain, rods, Eigen::Vector2d(0.0, -3.0));
  CHECK((first - sag).lpNorm<Eigen::Infinity>() <= 1e-9);
}

TEST_CASE("scene energy curves under the weight: E + V along the configuration curve, its stationary points the "
          "equilibria deflation finds",
          "[scene][body_loads]") {
  // the paper's three segments as heavy rods, the end held at (5.5, 0.4): the energy curves' sweep
  // (E + V along the inverse kinematics) and deflated Newton on the full equations are independent
  const std::string text = R"({"chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"held": 5.5}, "y": {"held": 0.4}, "phi": "free"},
    "gravity": {"value": 1.0, "direction": [0.5, -0.866], "mass_per_length": 0.05},
    "analyses": {"energy_curves": {"x": 5.5, "y": 0.4, "points": 801},
                 "equilibria": {"starts": 16, "smooth_starts": 16}}, "plots": []})";
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "energy_curves_weight", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  std::ifstream in(o.out / "special_points.json");
  const nlohmann::json sp = nlohmann::json::parse(in);
  const nlohmann::json& curves = sp["energy_equilibria"];
  const nlohmann::json& found = sp["equilibria"][0]["equilibria"];
  REQUIRE(curves.size() >= 2);
  REQUIRE(found.size() == curves.size());
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Eigen::Vector2d g = Eigen::Vector2d(0.5, -0.866).normalized();
  const GravityPotential V(chain, InertiaData::uniformRods(chain, 0.05), g);
  for (const nlohmann::json& l : curves) {
    CHECK(std::abs(l["loads"]["Me"].get<double>()) < 1e-9);
    Vector q(3);
    for (int i = 0; i < 3; ++i) q[i] = l["q"][size_t(i)].get<double>();
    bool listed = false;
    for (const nlohmann::json& e : found) {
      double d = 0.0;
      for (int i = 0; i < 3; ++i) d = std::max(d, std::abs(e["q"][size_t(i)].get<double>() - q[i]));
      if (d > 1e-12) continue;
      listed = true;
      CHECK(e["stable"] == l["stable"]);
      // Π = E + V with V from the independent potential, both in the list and on the curve
      CHECK(e["potential"].get<double>() == Approx(energy(chain, q) + V.value(q)).epsilon(1e-12).margin(1e-13));
    }
    CHECK(listed);
  }
}

TEST_CASE("scene point loads: a force at the last joint growing along an Fx path: the traced end point balances the "
          "joint torques of the end load and that force, summed here from the joint positions", "[scene][body_loads]") {
  // Fy = 0.02 + 0.1·Fx at joint 4 along Fx from 0 to −0.3
  const std::string text = bodyScene(R"("point_loads": [{"joint": 4, "Fy": 0.02, "rate": {"Fy": 0.1}}])",
                                 R"({"parameter": "Fx", "from": 0.0, "to": -0.3})", R"({"continuation": true})");
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("scene_body", "point_load", text);
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const std::map<std::string, double> last = readBranches(o.out).back();  // a copy: the table is a temporary
  REQUIRE(last.at("parameter") == Approx(-0.3).epsilon(1e-12));
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  Vector q(4);
  for (int i = 0; i < 4; ++i) q[i] = last.at("q" + std::to_string(i + 1));
  // residual of the equilibrium: ∂E/∂q − Jᵀ F_end − J_4ᵀ f with J_4 the Jacobian of joint 4's position
  const Eigen::Vector2d f(0.0, 0.02 + 0.1 * -0.3);
  Vector grad(4);
  totalPotentialGradient(chain, q, Wrench(-0.3, 0.0, 0.0), grad);
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector2d arm = P.col(4) - P.col(j + 1);  // joint 4 about joint j+1
    grad[j] -= arm.x() * f.y() - arm.y() * f.x();
  }
  CHECK(grad.lpNorm<Eigen::Infinity>() <= 1e-10);
  CHECK(std::abs(last.at("y")) > 1e-3);
}

TEST_CASE("scene body loads: bad input names the JSON path, exit 2, nothing written", "[scene][body_loads][errors]") {
  const std::string cont = R"({"continuation": true})";
  requireBadBody("no_value", bodyScene(R"("gravity": {"mass_per_length": 0.1})", kGravityPath, cont), "/gravity/value",
                  "missing");
  requireBadBody("negative", bodyScene(R"("gravity": {"value": -1, "mass_per_length": 0.1})", kGravityPath, cont),
                  "/gravity/value", ">= 0");
  requireBadBody("zero_direction",
                  bodyScene(R"("gravity": {"value": 0, "direction": [0, 0], "mass_per_length": 0.1})", kGravityPath, cont),
                  "/gravity/direction", "not zero");
  requireBadBody("no_mass", bodyScene(R"("gravity": {"value": 0})", kGravityPath, cont), "/gravity/mass_per_length",
                  "needs masses");
  requireBadBody("path_without_gravity", bodyScene(R"("description": "x")", kGravityPath, cont), "/path/parameter",
                  "needs /gravity");
  requireBadBody("range", bodyScene(kGravity, R"({"parameter": "gravity", "from": 1.0, "to": 3.0})", cont), "/path/from",
                  "contains the start value gravity = 0");
  requireBadBody("joint", bodyScene(R"("point_loads": [{"joint": 5, "Fy": 1}])", kGravityPath, cont),
                  "/point_loads/0/joint", "");
  requireBadBody("critical_forces", bodyScene(kGravity, kGravityPath, R"({"continuation": true, "critical_forces": true})"),
                  "/analyses/critical_forces", "do not include the weight");
  requireBadBody("mass_model",
                  bodyScene(kGravity, kGravityPath, R"({"continuation": true, "frequencies": {"mass_per_length": 0.5}})"),
                  "/analyses/frequencies/mass_per_length", "one mass model");
  requireBadBody("mass_unit", R"({"units": {"length": "m", "force": "N"},)" + bodyScene(kGravity, kGravityPath, cont).substr(1),
                  "/units/mass", "mass unit");
}
