// The streamed rows of branches.csv (scene/branch_stream.h): the same files as the points held in
// memory give, and an interrupted run's rows all belong to branches summary.json lists.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "output_helpers.h"
#include "rfc4180.h"
#include "scene/branch_stream.h"
#include "scene/command.h"
#include "scene/output.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "temp_dir.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using namespace buckle::scene;

namespace {

/// The default scene with `segments` segments (two cases when `twoCases`: a second with longer springs),
/// its bifurcation plots kept, its jumps and critical forces left out.
fs::path defaultScene(const fs::path& dir, int segments, bool twoCases) {
  std::ifstream in(std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json");
  nlohmann::json scene = nlohmann::json::parse(in);
  scene["chain"]["segments"] = segments;
  scene["analyses"].erase("critical_forces");
  scene["analyses"].erase("jump");
  if (twoCases) scene["cases"] = {{{"label", "soft"}}, {{"label", "longer"}, {"chain", {{"L0", 2.5}}}}};
  fs::create_directories(dir);
  const fs::path file = dir / ("default_" + std::to_string(segments) + ".json");
  std::ofstream(file) << scene.dump(2);
  return file;
}

/// Runs the scene in memory or streamed, and writes its outputs into `out`.
RunResult runAndWrite(const Scene& scene, const fs::path& out, const fs::path& spool) {
  RunControl control;
  if (!spool.empty()) {
    fs::create_directories(spool);
    control.streamTo = spool.string();
  }
  RunResult run = runScene(scene, control);
  fs::remove_all(out);
  fs::create_directories(out);
  writeOutputs(scene, run, out.string());
  return run;
}

}  // namespace

TEST_CASE("streamed branches.csv, joint_angles.npy and plot data equal the in-memory ones", "[scene][stream]") {
  const fs::path dir = buckle::test::scratchDirectory("branch_stream") / "equal";
  fs::remove_all(dir);
  // 3 segments: the joint angles in branches.csv; 14: in joint_angles.npy; two cases: the rows
  // case by case
  for (const auto& [segments, twoCases] : {std::pair<int, bool>{3, false}, {14, false}, {3, true}}) {
    CAPTURE(segments, twoCases);
    const Scene scene = loadScene(defaultScene(dir, segments, twoCases).string());
    const RunResult held = runAndWrite(scene, dir / "held", {});
    const RunResult streamed = runAndWrite(scene, dir / "streamed", dir / "spool");
    REQUIRE(streamed.stream);
    REQUIRE_FALSE(held.stream);
    size_t points = 0;
    for (size_t c = 0; c < held.cases.size(); ++c) {
      points += held.cases[c].points.size();
      CHECK(streamed.cases[c].recordedPoints == held.cases[c].points.size());
      CHECK(held.cases[c].recordedPoints == held.cases[c].points.size());
    }
    CHECK(streamed.stream->rows() == points);
    CHECK(held.cases.front().branches.size() > 3);  // a tree: the continuation's branches reordered by id
    const auto a = buckle::test::snapshot(dir / "held"), b = buckle::test::snapshot(dir / "streamed");
    for (const auto& [file, bytes] : a) {
      // the page and summary hold the run's time; images are gnuplot's
      if (file == "summary.json" || file == "report.html" || file.find(".png") != std::string::npos ||
          file.find(".svg") != std::string::npos)
        continue;
      CAPTURE(file);
      REQUIRE(b.count(file) == 1);
      CHECK(b.at(file) == bytes);
    }
    CHECK(a.count("branches.csv") == 1);
    CHECK(a.count("joint_angles.npy") == (segments > kBranchesCsvJointColumns ? 1u : 0u));
    // nothing of the spool is left in its directory
    CHECK(fs::is_empty(dir / "spool"));
  }
}

TEST_CASE("rows beyond the stream's memory bound go through a spool file: the same bytes, nothing left", "[scene][stream]") {
  const fs::path dir = buckle::test::scratchDirectory("branch_stream") / "spilled";
  fs::remove_all(dir);
  // 14 segments: branches.csv and joint_angles.npy, both spilled after their first 1000 bytes
  const Scene scene = loadScene(defaultScene(dir, 14, false).string());
  const RunResult held = runAndWrite(scene, dir / "held", {});
  fs::create_directories(dir / "spool");
  BranchStream memory(scene, (dir / "spool").string()), spilled(scene, (dir / "spool").string(), 1000);
  const CaseResult& cr = held.cases.front();
  size_t pieces = 0;
  for (size_t first = 0; first < cr.points.size();) {
    size_t last = first;
    while (last < cr.points.size() && cr.points[last].branch == cr.points[first].branch) ++last;
    const std::vector<buckle::mechanics::PointReport> piece(cr.points.begin() + long(first), cr.points.begin() + long(last));
    memory.add(0, cr, piece);
    spilled.add(0, cr, piece);
    ++pieces;
    first = last;
  }
  REQUIRE(pieces > 3);
  CHECK(fs::is_empty(dir / "spool"));  // the spool files are unlinked as soon as they are open
  for (const auto& [stream, name] : {std::pair<const BranchStream*, const char*>{&memory, "memory"}, {&spilled, "spilled"}}) {
    fs::create_directories(dir / name);
    stream->write((dir / name).string());
    const auto a = buckle::test::snapshot(dir / "held"), b = buckle::test::snapshot(dir / name);
    for (const char* file : {"branches.csv", "joint_angles.npy"}) {
      CAPTURE(name, file);
      REQUIRE(a.count(file) == 1);
      REQUIRE(b.count(file) == 1);
      CHECK(b.at(file) == a.at(file));
    }
  }
  // the test spills: the rows are far more than the bound
  CHECK(buckle::test::snapshot(dir / "held").at("branches.csv").size() > 10 * 1000);
}

TEST_CASE("an interrupted streamed run's rows belong to the branches summary.json lists", "[scene][stream]") {
  const fs::path dir = buckle::test::scratchDirectory("branch_stream") / "interrupted";
  fs::remove_all(dir);
  RunCommandOptions opt;
  opt.scene = defaultScene(dir, 60, false).string();
  opt.out = (dir / "out").string();
  opt.quiet = true;
  opt.timeLimit = 1.5;  // the 60-segment tree takes several seconds
  std::ostringstream log, err;
  const int rc = runSceneCommand(opt, log, err);
  CHECK(rc == kIncomplete);
  std::ifstream in(dir / "out" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  REQUIRE(summary["interrupted"] == true);
  std::map<int, int> listed;  // branch id -> points
  for (const nlohmann::json& b : summary["cases"][0]["branches"]) listed[b["id"].get<int>()] = b["points"].get<int>();
  std::ifstream csv(dir / "out" / "branches.csv");
  std::stringstream text;
  text << csv.rdbuf();
  const auto rows = buckle::test::readCsv(text.str());
  REQUIRE(rows.size() >= 2);
  REQUIRE(rows[0][1] == "branch");
  std::map<int, int> counted;
  int previous = -1;
  for (size_t r = 1; r < rows.size(); ++r) {
    const int branch = std::stoi(rows[r][1]);
    CHECK(branch >= previous);  // by branch id, as in memory
    previous = branch;
    ++counted[branch];
  }
  for (const auto& [branch, count] : counted) {
    CAPTURE(branch);
    REQUIRE(listed.count(branch) == 1);
    CHECK(listed.at(branch) == count);
  }
  for (const auto& [branch, points] : listed) CHECK((points == 0 || counted.count(branch) == 1));
  // the spool files were unlinked when made: beside the output only it
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.path().filename() != "default_60.json";
  CHECK(entries == 1);
}
