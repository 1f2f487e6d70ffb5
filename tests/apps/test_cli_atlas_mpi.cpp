// `buckle-mpi atlas` under mpirun (apps/buckle/atlas_mpi.cpp): with 2 and 3 ranks (an even and
// an uneven split of the cells) atlas.csv is the threaded `buckle atlas` run's byte for byte,
// order included; a time limit keeps what was computed; bad input is reported once and stops
// every rank; `buckle` itself, which links no MPI, refuses more than one rank and names
// buckle-mpi. Built only when CMake found MPI and mpiexec (BUCKLE_MPIEXEC).
#include <catch2/catch.hpp>

#ifdef BUCKLE_MPIEXEC

#include "cli_helpers.h"
#include "mpi_run.h"
#include "temp_dir.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using buckle::test::count;
using buckle::test::exitCode;
using buckle::test::kBuckleMpi;
using buckle::test::mpiExitCode;
using buckle::test::slurp;

namespace {

fs::path mpiDir(const std::string& name) { return buckle::test::freshDirectory("cli_atlas_mpi", name); }

// 7 x 4 = 28 cells: a/b up to 20 gives failed cells with their error message besides
// supercritical, subcritical and unstable starts, so every field of a cell travels.
const std::string kGrid = "atlas --x a --x-range 0.1 20 7 --y L0 --y-range 0.1 3 4 --quiet";

}  // namespace

TEST_CASE("atlas.csv under mpirun -np 2 and -np 3 is the threaded run's, byte for byte", "[cli][atlas][mpi]") {
  const fs::path dir = mpiDir("same");
  const int threaded = exitCode(kGrid + " -j 2 --out '" + (dir / "threads").string() + "'", dir / "threads.log");
  const std::string reference = slurp(dir / "threads" / "atlas.csv");
  REQUIRE(count(reference, "\n") == 29);
  REQUIRE(count(reference, ",failed,") > 0);
  REQUIRE(count(reference, ",supercritical,") > 0);
  CHECK(threaded == 1);  // the failed cells
  for (int ranks : {2, 3}) {
    const std::string name = "np" + std::to_string(ranks);
    INFO(slurp(dir / (name + ".log")));
    CHECK(mpiExitCode(ranks, kGrid + " -j 1 --out '" + (dir / name).string() + "'", dir / (name + ".log")) == threaded);
    CHECK(slurp(dir / name / "atlas.csv") == reference);
    const nlohmann::json summary = nlohmann::json::parse(slurp(dir / name / "summary.json"));
    CHECK(summary["mpi_ranks"] == ranks);
    CHECK(summary["failed_cells"] == count(reference, ",failed,"));
    // the message of the failed cells is printed once, by rank 0
    CHECK(count(slurp(dir / (name + ".log")), "could not be computed") == 1);
  }
}

TEST_CASE("a time limit under mpirun keeps every cell's parameters and marks the rest not computed",
          "[cli][atlas][mpi]") {
  // A limit already passed when the cells start: no rank computes any, rank 0 still writes them.
  const fs::path dir = mpiDir("time_limit");
  const fs::path log = dir / "log.txt";
  CHECK(mpiExitCode(2, kGrid + " -j 1 --time-limit 1e-9 --out '" + (dir / "atlas").string() + "'", log) == 1);
  INFO(slurp(log));
  std::ifstream csv(dir / "atlas" / "atlas.csv");
  std::string line;
  std::getline(csv, line);
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    CHECK(line.find(",nan,,not computed,0,\"stopped early: time limit of 1e-09 s reached\"") != std::string::npos);
  }
  CHECK(rows == 28);
  const nlohmann::json summary = nlohmann::json::parse(slurp(dir / "atlas" / "summary.json"));
  CHECK(summary["not_computed_cells"] == 28);
  CHECK(count(slurp(log), "28 cell(s) not computed") == 1);
}

TEST_CASE("bad input under mpirun: one message, exit 2, nothing written, no rank left waiting", "[cli][atlas][mpi]") {
  const fs::path dir = mpiDir("bad");
  const fs::path log = dir / "log.txt";
  CHECK(mpiExitCode(2, "atlas --x a --x-range 0.1 1 0 --out '" + (dir / "a").string() + "'", log) == 2);
  CHECK(count(slurp(log), "--x-range takes FROM TO COUNT") == 1);
  CHECK(!fs::exists(dir / "a"));
  std::ofstream(dir / "notes.txt") << "mine";
  CHECK(mpiExitCode(3, kGrid + " --out '" + (dir / "notes.txt").string() + "'", log) == 2);
  CHECK(count(slurp(log), "is an existing file") == 1);
  CHECK(slurp(dir / "notes.txt") == "mine");
}

TEST_CASE("buckle links no MPI: under mpirun with 2 ranks it names buckle-mpi and writes nothing",
          "[cli][atlas][mpi]") {
  const fs::path dir = mpiDir("plain");
  const fs::path log = dir / "log.txt";
  CHECK(mpiExitCode(2, kGrid + " --out '" + (dir / "a").string() + "'", log, buckle::test::kBuckle) == 2);
  INFO(slurp(log));
  CHECK(count(slurp(log), "buckle-mpi atlas") >= 1);  // each rank says so (mpirun may stop the second first)
  CHECK(!fs::exists(dir / "a"));
  // one rank under mpirun is a plain run on threads: the same cells as without mpirun
  CHECK(mpiExitCode(1, kGrid + " -j 1 --out '" + (dir / "one").string() + "'", dir / "one.log", buckle::test::kBuckle) ==
        1);
  CHECK(exitCode(kGrid + " -j 1 --out '" + (dir / "threads").string() + "'", dir / "threads.log") == 1);
  CHECK(slurp(dir / "one" / "atlas.csv") == slurp(dir / "threads" / "atlas.csv"));
  const nlohmann::json summary = nlohmann::json::parse(slurp(dir / "one" / "summary.json"));
  CHECK(summary["mpi_ranks"] == 1);
}

TEST_CASE("buckle-mpi has the atlas and run alone", "[cli][atlas][mpi]") {
  const fs::path dir = mpiDir("help");
  const std::string cmd = "'" + kBuckleMpi + "' --help > '" + (dir / "help.txt").string() + "' 2>&1";
  CHECK(std::system(cmd.c_str()) == 0);
  const std::string help = slurp(dir / "help.txt");
  CHECK(count(help, "  atlas ") == 1);
  CHECK(count(help, "  run ") == 1);
  CHECK(count(help, "  regress ") == 0);
  CHECK(count(help, "  critical ") == 0);
}

#endif  // BUCKLE_MPIEXEC
