// `buckle regress` as a program: drift beyond tolerance fails (exit 1), a malformed baseline is
// bad input naming file and JSON path (exit 2), --update writes baselines that pass and that
// are the same bytes every time.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "temp_dir.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::exitCode;
using buckle::test::slurp;

namespace {

const std::string kScenes = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes";

fs::path regressDir(const std::string& name) { return buckle::test::freshDirectory("cli_regress", name); }

// A small selection: a scene with branch switching and a benchmark problem (fast).
std::string update(const fs::path& dir, const std::string& extra = "") {
  return "regress --update --baselines '" + dir.string() + "' --scenes '" + kScenes +
         "' --only default --only auto_A_U --repetitions 1 " + extra;
}

std::string regress(const fs::path& dir, const std::string& extra = "") {
  return "regress --baselines '" + dir.string() + "' --scenes '" + kScenes + "' --time-tolerance 0 --repetitions 1 " + extra;
}

/// The file without its reference timing line (the one thing two fresh runs may differ in).
std::string withoutTiming(const fs::path& p) {
  std::istringstream in(slurp(p));
  std::string out;
  for (std::string line; std::getline(in, line);)
    if (line.find("\"reference_seconds\"") == std::string::npos) out += line + "\n";
  return out;
}

}  // namespace

TEST_CASE("buckle regress --update writes baselines that then pass", "[cli][regress]") {
  const fs::path dir = regressDir("fresh");
  const fs::path log = dir.parent_path() / "fresh.txt";
  REQUIRE(exitCode(update(dir), log) == 0);
  INFO(slurp(log));
  CHECK(fs::exists(dir / "default.json"));
  CHECK(fs::exists(dir / "auto_A_U.json"));
  CHECK(!fs::exists(dir / "fig2.json"));  // --only
  const fs::path json = dir.parent_path() / "rows.json";
  const int rc = exitCode(regress(dir, "--json '" + json.string() + "'"), log);
  INFO(slurp(log));
  CHECK(rc == 0);
  const std::string table = slurp(log);
  CHECK(table.find("b0 BP#0 lambda") != std::string::npos);
  CHECK(table.find("FAIL") == std::string::npos);
  const nlohmann::json rows = nlohmann::json::parse(slurp(json));
  CHECK(rows["exit"] == 0);
  CHECK(rows["failed"] == 0);
  CHECK(rows["rows"].size() > 20);
}

TEST_CASE("buckle regress --update is deterministic", "[cli][regress]") {
  const fs::path a = regressDir("a"), b = regressDir("b");
  const fs::path log = a.parent_path() / "det.txt";
  REQUIRE(exitCode(update(a), log) == 0);
  REQUIRE(exitCode(update(b), log) == 0);
  for (const char* f : {"default.json", "auto_A_U.json"}) {
    INFO(f);
    CHECK(withoutTiming(a / f) == withoutTiming(b / f));
    // updating values only (reference timing kept) changes not a byte
    const std::string before = slurp(a / f);
    REQUIRE(exitCode(update(a, "--keep-timing"), log) == 0);
    CHECK(slurp(a / f) == before);
  }
  // nothing but the baselines is left behind (the writes go through temporary files)
  int files = 0;
  for (const auto& e : fs::directory_iterator(a)) files += e.is_regular_file();
  CHECK(files == 2);
}

TEST_CASE("buckle regress reports a value shifted beyond its tolerance as FAIL, exit 1", "[cli][regress]") {
  const fs::path dir = regressDir("perturbed");
  const fs::path log = dir.parent_path() / "perturbed.txt";
  REQUIRE(exitCode(update(dir), log) == 0);
  nlohmann::ordered_json doc = nlohmann::ordered_json::parse(slurp(dir / "default.json"));
  auto& sp = doc["cases"][0]["special_points"][0];
  const double tol = sp["tolerance"]["absolute"].get<double>() + sp["tolerance"]["relative"].get<double>() *
                                                                    std::abs(sp["lambda"].get<double>());
  sp["lambda"] = sp["lambda"].get<double>() + 10 * tol;
  std::ofstream(dir / "default.json") << doc.dump(2);
  const int rc = exitCode(regress(dir), log);
  const std::string table = slurp(log);
  INFO(table);
  CHECK(rc == 1);
  // exactly the shifted value fails
  std::istringstream in(table);
  int failed = 0;
  for (std::string line; std::getline(in, line);)
    if (line.size() >= 4 && line.compare(line.size() - 4, 4, "FAIL") == 0) {
      ++failed;
      CHECK(line.find("b0 BP#0 lambda") != std::string::npos);
    }
  CHECK(failed == 1);

  // a shape that changed fails too
  doc = nlohmann::ordered_json::parse(slurp(dir / "auto_A_U.json"));
  doc["cases"][0]["special_points"][0]["shape"] = "Z";
  std::ofstream(dir / "auto_A_U.json") << doc.dump(2);
  CHECK(exitCode(regress(dir, "--only auto_A_U"), log) == 1);
  CHECK(slurp(log).find("shape") != std::string::npos);

  // so does a branch point's post-buckling classification (recorded with every BP that has one)
  REQUIRE(exitCode(update(dir), log) == 0);
  doc = nlohmann::ordered_json::parse(slurp(dir / "default.json"));
  auto& bp = doc["cases"][0]["special_points"][0];
  REQUIRE(bp["type"] == "BP");
  REQUIRE(bp.contains("post_buckling"));
  bp["post_buckling"] = bp["post_buckling"] == "subcritical" ? "supercritical" : "subcritical";
  std::ofstream(dir / "default.json") << doc.dump(2);
  CHECK(exitCode(regress(dir, "--only default"), log) == 1);
  CHECK(slurp(log).find("b0 BP#0 post_buckling") != std::string::npos);
}

TEST_CASE("buckle regress on a malformed baseline exits 2 naming the file and the JSON path", "[cli][regress]") {
  const fs::path dir = regressDir("malformed");
  const fs::path log = dir.parent_path() / "malformed.txt";
  REQUIRE(exitCode(update(dir, "") , log) == 0);
  nlohmann::ordered_json doc = nlohmann::ordered_json::parse(slurp(dir / "default.json"));
  doc["cases"][0]["special_points"][1]["tolerance"]["absolute"] = "tiny";
  std::ofstream(dir / "default.json") << doc.dump(2);
  CHECK(exitCode(regress(dir), log) == 2);
  std::string msg = slurp(log);
  INFO(msg);
  CHECK(msg.find((dir / "default.json").string() + ": /cases/0/special_points/1/tolerance/absolute: expected a number") !=
        std::string::npos);
  // --update refuses to overwrite it
  CHECK(exitCode(update(dir), log) == 2);

  std::ofstream(dir / "default.json") << "{\"format\": \"buckle-regression/1\", \"name\": NaN}";
  CHECK(exitCode(regress(dir), log) == 2);
  msg = slurp(log);
  CHECK(msg.find((dir / "default.json").string() + ": /name: expected a finite number") != std::string::npos);

  fs::remove(dir / "default.json");
  doc = nlohmann::ordered_json::parse(slurp(dir / "auto_A_U.json"));
  doc["source"]["problem"] = "A_X";
  std::ofstream(dir / "auto_A_U.json") << doc.dump(2);
  CHECK(exitCode(regress(dir), log) == 2);
  CHECK(slurp(log).find("/source/problem: unknown benchmark problem \"A_X\"") != std::string::npos);

  CHECK(exitCode(regress(dir, "--only nosuch"), log) == 2);
  CHECK(exitCode(regress(dir.parent_path() / "does_not_exist"), log) == 2);
}

TEST_CASE("a time-limited baseline: stopped on time, what it computed agrees, the rest is not reached",
          "[cli][regress]") {
  const fs::path dir = regressDir("limited");
  const fs::path log = dir.parent_path() / "limited.txt";
  // the shipped baseline: long_chain_jumps (its continuation takes 0.35 s in Release here) stopped after 0.05 s
  fs::copy_file(std::string(BUCKLE_SOURCE_DIR) + "/data/regression/long_chain_jumps_time_limited.json",
                dir / "limited.json");
  const std::string only = "--only long_chain_jumps_time_limited";
  const int rc = exitCode(regress(dir, only), log);
  const std::string text = slurp(log);
  INFO(text);
  CHECK(rc == 0);
  CHECK(text.find("stopped by the time limit  yes                yes") != std::string::npos);
  CHECK(text.find("stopped on time") != std::string::npos);

  // A limit the run never reaches is a failure: the baseline is about stopping.
  nlohmann::json b = nlohmann::json::parse(slurp(dir / "limited.json"));
  b["source"]["time_limit"] = 600.0;
  std::ofstream(dir / "limited.json") << b.dump(2);
  CHECK(exitCode(regress(dir, only), log) == 1);
  CHECK(slurp(log).find("stopped by the time limit  yes                no") != std::string::npos);

  // A value computed before the stop that disagrees with the complete run's fails as usual: the
  // first critical load, which linear buckling gives before the tree starts (a slow build, e.g.
  // under ASan, may reach no branch point of the tree in 0.05 s).
  b["source"]["time_limit"] = 0.05;
  nlohmann::json* crit = nullptr;
  for (nlohmann::json& sp : b["cases"][0]["special_points"])
    if (sp["type"] == "CRIT") {
      crit = &sp;
      break;
    }
  REQUIRE(crit != nullptr);
  (*crit)["lambda"] = (*crit)["lambda"].get<double>() * (1.0 + 1e-6);
  std::ofstream(dir / "limited.json") << b.dump(2);
  CHECK(exitCode(regress(dir, only), log) == 1);
  CHECK(slurp(log).find("CRIT#0 lambda") != std::string::npos);

  // time_limit belongs to scenes only, and must be positive
  b["source"] = {{"problem", "A_U"}, {"time_limit", 1.0}};
  std::ofstream(dir / "limited.json") << b.dump(2);
  CHECK(exitCode(regress(dir, only), log) == 2);
  CHECK(slurp(log).find("/source/time_limit: a time limit applies to scenes only") != std::string::npos);
}

TEST_CASE("buckle regress --update finds a gallery one folder down and records its cusp points", "[cli][regress]") {
  const fs::path dir = regressDir("gallery");
  const fs::path log = dir.parent_path() / "gallery.txt";
  REQUIRE(exitCode("regress --update --baselines '" + dir.string() + "' --scenes '" + kScenes +
                       "' --only hard_folds_near_cusp --repetitions 1",
                   log) == 0);
  INFO(slurp(log));
  REQUIRE(fs::exists(dir / "hard_folds_near_cusp.json"));
  const nlohmann::json doc = nlohmann::json::parse(slurp(dir / "hard_folds_near_cusp.json"));
  CHECK(doc["source"]["scene"] == "hard/folds_near_cusp.json");
  // the two folds at mirror loads, and the cusp of their fold curves at Fx = 0.3 = -kappa
  int folds = 0, cusps = 0;
  double foldSum = 0.0;
  for (const auto& sp : doc["cases"][0]["special_points"]) {
    if (sp["type"] == "LP") ++folds, foldSum += sp["lambda"].get<double>();
    if (sp["type"] == "CP") {
      ++cusps;
      CHECK(std::abs(sp["lambda"].get<double>() - 0.3) <= 1e-12);
    }
  }
  CHECK(folds == 2);
  CHECK(std::abs(foldSum) <= 1e-15);
  CHECK(cusps == 2);
  CHECK(exitCode(regress(dir, "--only hard_folds_near_cusp"), log) == 0);
}
