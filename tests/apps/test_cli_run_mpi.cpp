// `buckle-mpi run` under mpirun (apps/buckle/run_command.cpp, scene/shared_work.h): with 2 and 3
// ranks (an even and an uneven split of a workspace map's rows) the output is the single process's
// byte for byte but the timings, in a scene of one case and in one of two cases with other
// analyses that rank 0 alone computes; bad input is reported once; a time limit passed before the
// rows start leaves every rank ending together; `buckle` itself refuses more than one rank.
// Built only when CMake found MPI and mpiexec (BUCKLE_MPIEXEC).
#include <catch2/catch.hpp>

#ifdef BUCKLE_MPIEXEC

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_helpers.h"
#include "mpi_run.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::count;
using buckle::test::exitCode;
using buckle::test::mpiExitCode;
using buckle::test::slurp;

namespace {

fs::path runMpiDir(const std::string& name) { return buckle::test::freshDirectory("cli_run_mpi", name); }

const std::string kWorkspaceScene = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/workspace.json";

// Everything a run writes that does not depend on the clock: the workspace's CSV files, and
// special_points.json and branches.csv when there.
void requireSameOutput(const fs::path& a, const fs::path& b) {
  for (const char* file : {"workspace_map.csv", "workspace_curves.csv", "branches.csv"}) {
    INFO(file);
    REQUIRE(fs::exists(a / file) == fs::exists(b / file));
    if (fs::exists(a / file)) CHECK(slurp(a / file) == slurp(b / file));
  }
  CHECK(nlohmann::json::parse(slurp(a / "special_points.json")) ==
        nlohmann::json::parse(slurp(b / "special_points.json")));
  const nlohmann::json sa = nlohmann::json::parse(slurp(a / "summary.json"));
  const nlohmann::json sb = nlohmann::json::parse(slurp(b / "summary.json"));
  CHECK(sa["complete"] == sb["complete"]);
  CHECK(sa["computed"] == sb["computed"]);
}

// The workspace scene with a second case and a continuation beside the map.
fs::path twoCaseScene(const fs::path& dir) {
  nlohmann::json scene = nlohmann::json::parse(slurp(kWorkspaceScene));
  scene["analyses"]["workspace"]["first"]["count"] = 9;
  scene["analyses"]["workspace"]["second"]["count"] = 13;
  scene["analyses"]["continuation"] = {{"branch_switching", 0}};
  scene["path"] = {{"parameter", "Fx"}, {"from", -0.3}, {"to", -1.0}};
  scene["cases"] = {{{"label", "L0 = 2.25"}}, {{"label", "L0 = 2.3"}, {"chain", {{"L0", 2.3}}}}};
  const fs::path file = dir / "two_cases.json";
  std::ofstream(file) << scene.dump(1);
  return file;
}

}  // namespace

TEST_CASE("buckle-mpi run: a workspace map's rows shared among 2 and 3 ranks, the output of one process",
          "[cli][run][mpi]") {
  const fs::path dir = runMpiDir("same");
  const fs::path two = twoCaseScene(dir);
  for (const fs::path& scene : {fs::path(kWorkspaceScene), two}) {
    const std::string name = scene.stem().string();
    INFO(name);
    const fs::path alone = dir / (name + "_alone");
    const int code = exitCode("run '" + scene.string() + "' --quiet --out '" + alone.string() + "'", dir / "alone.log");
    INFO(slurp(dir / "alone.log"));
    REQUIRE(code == 0);
    for (int ranks : {2, 3}) {
      const fs::path out = dir / (name + "_np" + std::to_string(ranks));
      const fs::path log = dir / (name + "_np" + std::to_string(ranks) + ".log");
      CHECK(mpiExitCode(ranks, "run '" + scene.string() + "' --out '" + out.string() + "'", log) == code);
      INFO(slurp(log));
      requireSameOutput(out, alone);
      CHECK(count(slurp(log), "wrote ") == 1);  // rank 0 alone speaks and writes
    }
  }
}

TEST_CASE("buckle-mpi run: bad input is said once and stops every rank, and a passed time limit ends every rank",
          "[cli][run][mpi]") {
  const fs::path dir = runMpiDir("bad");
  const fs::path log = dir / "log.txt";
  std::ofstream(dir / "bad.json") << R"({"chain": {"segments": 0}})";
  CHECK(mpiExitCode(3, "run '" + (dir / "bad.json").string() + "' --out '" + (dir / "a").string() + "'", log) == 2);
  CHECK(count(slurp(log), "bad scene") == 1);
  CHECK(!fs::exists(dir / "a"));
  std::ofstream(dir / "notes.txt") << "mine";
  CHECK(mpiExitCode(2, "run '" + kWorkspaceScene + "' --out '" + (dir / "notes.txt").string() + "'", log) == 2);
  CHECK(count(slurp(log), "existing file") == 1);
  CHECK(slurp(dir / "notes.txt") == "mine");
  // every rank stops at once; rank 0 still writes the grid, every value "not computed"
  CHECK(mpiExitCode(2, "run '" + kWorkspaceScene + "' --time-limit 1e-9 --out '" + (dir / "t").string() + "'", log) ==
        1);
  INFO(slurp(log));
  const std::string csv = slurp(dir / "t" / "workspace_map.csv");
  CHECK(count(csv, "\n") == 0 + 1);  // the header: nothing was reached before the limit
}

TEST_CASE("buckle run under mpirun with 2 ranks names buckle-mpi and writes nothing", "[cli][run][mpi]") {
  const fs::path dir = runMpiDir("plain");
  const fs::path log = dir / "log.txt";
  CHECK(mpiExitCode(2, "run '" + kWorkspaceScene + "' --out '" + (dir / "a").string() + "'", log,
                    buckle::test::kBuckle) == 2);
  CHECK(count(slurp(log), "buckle-mpi") >= 1);
  CHECK(!fs::exists(dir / "a"));
}

#endif  // BUCKLE_MPIEXEC
