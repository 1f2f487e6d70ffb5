// The column dictionary (scene/columns.h): the stiffness quantities an engineer reads off
// branches.csv — compliance, the stiffness along one direction with the other free, the principal
// stiffnesses and the softest direction — against their definitions on 2×2 matrices and against
// the closed form of the straight chain's lateral stiffness.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "scene/columns.h"
#include "scene/command.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::scene::stiffnessColumnValue;

namespace {

using buckle::scene::kNaN;
const double kInf = std::numeric_limits<double>::infinity();

std::map<std::string, double> columns(const Eigen::Matrix2d& K, const Eigen::Matrix2d& C) {
  std::map<std::string, double> out;
  for (const std::string& c : buckle::scene::stiffnessColumns()) out[c] = stiffnessColumnValue(c, K, C);
  return out;
}

/// The rows of a CSV file with a header, as column → value (no quoted fields in branches.csv).
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
  std::ifstream in(file);
  REQUIRE(in.good());
  auto split = [](const std::string& line) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    return f;
  };
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size() && i < f.size(); ++i) row[header[i]] = f[i];
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("stiffness columns obey their definitions on regular K_F", "[scene][columns]") {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    // symmetric, definite or not, over twelve orders of magnitude (units of any size)
    const double scale = std::pow(10.0, 6.0 * u(random));
    Eigen::Matrix2d K;
    K << u(random), u(random), 0.0, u(random);
    K(1, 0) = K(0, 1);
    K *= scale;
    const Eigen::Matrix2d C = K.inverse();
    INFO("trial " << trial << " K = " << K);
    for (const Eigen::Matrix2d& givenC : {C, Eigen::Matrix2d(Eigen::Matrix2d::Constant(kNaN))}) {
      auto v = columns(K, givenC);  // a KMIN point carries K_F only: C_F from K_F⁻¹
      CHECK(v["Kxx"] == K(0, 0));
      CHECK(v["Cxy"] == Approx(C(0, 1)).epsilon(1e-10));
      CHECK(v["Kx_yfree"] * v["Cxx"] == Approx(1.0).epsilon(1e-12));
      CHECK(v["Ky_xfree"] * v["Cyy"] == Approx(1.0).epsilon(1e-12));
      // principal stiffnesses: the invariants of K_F, K1 ≤ K2, and K_F d1 = K1 d1 along θ1
      CHECK(v["K1"] <= v["K2"]);
      CHECK(v["K1"] + v["K2"] == Approx(K.trace()).margin(1e-10 * K.norm()));
      CHECK(v["K1"] * v["K2"] == Approx(K.determinant()).margin(1e-10 * K.squaredNorm()));
      const Eigen::Vector2d d(std::cos(v["theta1"]), std::sin(v["theta1"]));
      CHECK((K * d - v["K1"] * d).norm() <= 1e-9 * K.norm());
      CHECK(std::abs(v["theta1"]) <= M_PI / 2 + 1e-15);
    }
  }
}

TEST_CASE("a rigid direction has infinite stiffness, the other stays finite", "[scene][columns]") {
  // the straight chain: the end cannot move along x (C_xx = 0, K_F undefined)
  Eigen::Matrix2d C;
  C << 0.0, 0.0, 0.0, 0.25;
  auto v = columns(Eigen::Matrix2d::Constant(kNaN), C);
  CHECK(std::isnan(v["Kxx"]));
  CHECK(v["Cyy"] == 0.25);
  CHECK(v["Kx_yfree"] == kInf);
  CHECK(v["Ky_xfree"] == 4.0);
  CHECK(v["K1"] == 4.0);
  CHECK(v["K2"] == kInf);
  CHECK(std::abs(std::abs(v["theta1"]) - M_PI / 2) < 1e-15);  // the soft direction is y
  // what rounding leaves of the zero eigenvalue, of either sign, is still a rigid direction
  for (double residue : {1e-18, -1e-18}) {
    C(0, 0) = residue;
    v = columns(Eigen::Matrix2d::Constant(kNaN), C);
    CHECK(v["Kx_yfree"] == kInf);
    CHECK(v["K1"] == Approx(4.0).epsilon(1e-15));
    CHECK(v["K2"] == kInf);
  }
}

TEST_CASE("the straight SI chain's lateral stiffness with x free is the closed form", "[scene][columns]") {
  // At F = 0 the stability operator of the straight chain is κ I (eq 4) and the end Jacobian's
  // y row holds the distances from the joints to the end, b (2n − 2j + 1) (joint j at
  // x = b + 2b (j − 1), the end at 2 b n): C_yy = Σ_j b² (2n − 2j + 1)² / κ = b² n (2n − 1)(2n + 1) / (3 κ),
  // C_xx = 0 (the end cannot move along the straight chain to first order). branches.csv holds 12
  // significant digits.
  const fs::path dir = buckle::test::scratchDirectory("scene_columns") / "si";
  fs::remove_all(dir.parent_path());
  fs::create_directories(dir.parent_path());
  buckle::scene::RunCommandOptions opt;
  opt.scene = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/si_chain.json";
  opt.out = dir.string();
  opt.quiet = true;
  std::ostringstream log, err;
  INFO(err.str());
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);
  const auto rows = readCsv(dir / "branches.csv");
  REQUIRE(!rows.empty());
  const auto& start = rows.front();
  REQUIRE(std::stod(start.at("parameter")) == 0.0);
  const int n = 10;
  const double a = 0.01, b = 0.02, k = 2000.0, L0 = 0.045;
  const double kappa = k * (b * L0 - 2.0 * (b * b - a * a));
  const double Cyy = b * b * n * (2.0 * n - 1.0) * (2.0 * n + 1.0) / (3.0 * kappa);
  CHECK(std::stod(start.at("Cyy")) == Approx(Cyy).epsilon(1e-11));
  CHECK(std::stod(start.at("Ky_xfree")) == Approx(1.0 / Cyy).epsilon(1e-11));
  CHECK(std::abs(std::stod(start.at("Cxx"))) <= 1e-11 * Cyy);
  CHECK(start.at("Kx_yfree") == "inf");
  CHECK(std::stod(start.at("K1")) == Approx(1.0 / Cyy).epsilon(1e-11));
  // the end's rotation under Me with the forces unchanged: n joints in series, each κ (eq 4)
  CHECK(std::stod(start.at("Kphi")) == Approx(kappa / n).epsilon(1e-11));
  // K_F and C_F are inverses wherever both are finite
  size_t both = 0;
  for (const auto& r : rows) {
    Eigen::Matrix2d K, C;
    K << std::stod(r.at("Kxx")), std::stod(r.at("Kxy")), std::stod(r.at("Kxy")), std::stod(r.at("Kyy"));
    C << std::stod(r.at("Cxx")), std::stod(r.at("Cxy")), std::stod(r.at("Cxy")), std::stod(r.at("Cyy"));
    if (!K.allFinite() || !C.allFinite()) continue;
    ++both;
    CHECK((K * C - Eigen::Matrix2d::Identity()).norm() <= 1e-10 * K.norm() * C.norm());
  }
  CHECK(both > rows.size() / 2);
}
