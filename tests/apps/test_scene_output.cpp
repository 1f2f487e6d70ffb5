// The staging directory of an output (scene/output.h): it follows the umask like every file
// the program creates, replaces the target only on commit, and is gone on every other path.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>
#include <sys/stat.h>
#include <unistd.h>

#include "output_helpers.h"
#include "temp_dir.h"
#include "buckle/mechanics/shape_name.h"
#include "scene/command.h"
#include "scene/output.h"

namespace fs = std::filesystem;
using buckle::scene::StagingDirectory;
using buckle::test::mode;
using buckle::test::stagingLeftovers;

namespace {

fs::path outputDir(const std::string& name) { return buckle::test::freshDirectory("output", name); }

/// Sets the umask for the test's lifetime.
struct Umask {
  mode_t previous;
  explicit Umask(mode_t m) : previous(::umask(m)) {}
  ~Umask() { ::umask(previous); }
  Umask(const Umask&) = delete;
  Umask& operator=(const Umask&) = delete;
};

}  // namespace

TEST_CASE("the staging directory and its files follow the umask", "[scene][output]") {
  for (const mode_t mask : {mode_t(022), mode_t(077), mode_t(002), mode_t(027)}) {
    INFO("umask 0" << std::oct << mask);
    const fs::path dir = outputDir("umask");
    const Umask umask(mask);
    {
      StagingDirectory staging((dir / "out").string());
      CHECK(mode(staging.path()) == (0777u & ~unsigned(mask)));
      std::ofstream(fs::path(staging.path()) / "summary.json") << "{}";
      fs::create_directories(fs::path(staging.path()) / "plots");
      staging.commit();
    }
    CHECK(mode(dir / "out") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "plots") == (0777u & ~unsigned(mask)));
    CHECK(mode(dir / "out" / "summary.json") == (0666u & ~unsigned(mask)));
    CHECK(stagingLeftovers(dir) == 0);
  }
}

TEST_CASE("a staging directory that is not committed leaves nothing behind", "[scene][output]") {
  const fs::path dir = outputDir("abandoned");
  std::ofstream(dir / "keep.txt") << "keep";
  SECTION("destroyed normally") {
    StagingDirectory staging((dir / "out").string());
    std::ofstream(fs::path(staging.path()) / "branches.csv") << "partial";
    CHECK(stagingLeftovers(dir) == 1);
  }
  SECTION("an exception while writing") {
    try {
      StagingDirectory staging((dir / "out").string());
      fs::create_directories(fs::path(staging.path()) / "plots");
      throw std::runtime_error("disk full");
    } catch (const std::runtime_error&) {
    }
  }
  CHECK(!fs::exists(dir / "out"));
  CHECK(stagingLeftovers(dir) == 0);
  CHECK(fs::exists(dir / "keep.txt"));
}

TEST_CASE("commit replaces a previous output as a whole and only then", "[scene][output]") {
  const fs::path dir = outputDir("replace");
  fs::create_directories(dir / "out" / "plots");
  std::ofstream(dir / "out" / "summary.json") << "old";
  std::ofstream(dir / "out" / "plots" / "old.png") << "old";
  {
    StagingDirectory staging((dir / "out/").string());
    std::ofstream(fs::path(staging.path()) / "summary.json") << "new";
    CHECK(fs::exists(dir / "out" / "plots" / "old.png"));  // untouched until commit
    staging.commit();
  }
  std::ifstream in(dir / "out" / "summary.json");
  std::string text;
  in >> text;
  CHECK(text == "new");
  CHECK(!fs::exists(dir / "out" / "plots"));
  CHECK(stagingLeftovers(dir) == 0);
}

TEST_CASE("the staging directory's parents are created as needed", "[scene][output]") {
  const fs::path dir = outputDir("parents");
  {
    StagingDirectory staging((dir / "a" / "b" / "out").string());
    CHECK(fs::path(staging.path()).parent_path() == dir / "a" / "b");
    CHECK(fs::path(staging.path()).filename().string().rfind(".out.tmp-", 0) == 0);
    staging.commit();
  }
  CHECK(fs::is_directory(dir / "a" / "b" / "out"));
  CHECK(stagingLeftovers(dir / "a" / "b") == 0);
}

namespace {
volatile std::sig_atomic_t gDelivered = 0;
extern "C" void recordSignal(int sig) { gDelivered = sig; }
}  // namespace

TEST_CASE("a signal while the output is staged is delivered once the staging directory is gone", "[scene][output]") {
  const fs::path dir = outputDir("signal");
  struct sigaction record {}, previous {};
  record.sa_handler = recordSignal;
  sigemptyset(&record.sa_mask);
  REQUIRE(sigaction(SIGTERM, &record, &previous) == 0);
  gDelivered = 0;
  {
    StagingDirectory staging((dir / "out").string());
    std::raise(SIGTERM);  // e.g. the second Ctrl-C, whose default action ends the program
    sigset_t pending;
    sigpending(&pending);
    CHECK(gDelivered == 0);
    CHECK(sigismember(&pending, SIGTERM) == 1);
    CHECK(stagingLeftovers(dir) == 1);
  }
  CHECK(gDelivered == SIGTERM);  // delivered after the removal
  CHECK(stagingLeftovers(dir) == 0);
  sigaction(SIGTERM, &previous, nullptr);
}

TEST_CASE("a long chain's joint angles go to joint_angles.npy, rows as in branches.csv", "[scene][output]") {
  // 20 segments, past the first branch points with switching: straight and bent rows
  const fs::path dir = outputDir("npy");
  fs::create_directories(dir);
  std::ofstream(dir / "long.json") << R"({
  "chain": {"segments": 20, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
  "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
  "path": {"parameter": "Fx", "from": 0.0, "to": -0.05},
  "analyses": {"continuation": {"branch_switching": 1}},
  "plots": []
})";
  buckle::scene::RunCommandOptions opt;
  opt.scene = (dir / "long.json").string();
  opt.out = (dir / "out").string();
  std::ostringstream log, err;
  REQUIRE(buckle::scene::runSceneCommand(opt, log, err) == 0);

  std::ifstream csv(dir / "out" / "branches.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header.find(",max_abs_q,sign_changes,") != std::string::npos);
  CHECK(header.find(",q1,") == std::string::npos);
  std::vector<std::pair<double, int>> rows;  // (max_abs_q, sign_changes) of every row
  for (std::string line; std::getline(csv, line);) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    rows.emplace_back(std::stod(f[12]), std::stoi(f[13]));
  }
  REQUIRE(rows.size() > 20);

  // the .npy file: preamble, a header naming the shape, then rows × 20 little-endian doubles
  std::ifstream npy(dir / "out" / "joint_angles.npy", std::ios::binary);
  REQUIRE(npy.good());
  std::string data((std::istreambuf_iterator<char>(npy)), std::istreambuf_iterator<char>());
  REQUIRE(data.size() > 10);
  CHECK(data.substr(0, 8) == std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t headerLength = std::size_t(uint8_t(data[8])) | std::size_t(uint8_t(data[9])) << 8;
  CHECK((10 + headerLength) % 64 == 0);
  const std::string npyHeader = data.substr(10, headerLength);
  CHECK(npyHeader.find("'descr': '<f8'") != std::string::npos);
  CHECK(npyHeader.find("'shape': (" + std::to_string(rows.size()) + ", 20)") != std::string::npos);
  REQUIRE(data.size() == 10 + headerLength + rows.size() * 20 * sizeof(double));
  int bent = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    Eigen::VectorXd q(20);
    std::memcpy(q.data(), data.data() + 10 + headerLength + r * 20 * sizeof(double), 20 * sizeof(double));
    const double qmax = q.cwiseAbs().maxCoeff();
    CHECK(qmax == Approx(rows[r].first).epsilon(1e-11).margin(1e-300));
    CHECK(buckle::mechanics::signChanges(q, 1e-9 * qmax) == rows[r].second);
    if (qmax > 0.0) ++bent;
  }
  CHECK(bent > 0);
  fs::remove_all(dir);
}
