// `buckle show DIR` as a program: on a real run's output it prints every special point of
// special_points.json and every branch of summary.json; on anything else it exits 2.
#include <catch2/catch.hpp>

#include "cli_helpers.h"
#include "temp_dir.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>
#include "build_paths.h"

namespace fs = std::filesystem;
using buckle::test::exitCode;
using buckle::test::slurp;
using nlohmann::json;

namespace {

fs::path showDir() { return buckle::test::scratchDirectory("cli_show"); }

std::string g(double v, const char* format) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// Split on runs of spaces.
std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// Runs data/scenes/NAME.json into a fresh directory, then `buckle show` on it: its output.
std::string runAndShow(const std::string& name, fs::path& out) {
  out = showDir() / name;
  fs::remove_all(out);
  const std::string scene = std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/" + name + ".json";
  REQUIRE(exitCode("run '" + scene + "' --quiet --out '" + out.string() + "'", showDir() / (name + "_run.txt")) == 0);
  REQUIRE(exitCode("show '" + out.string() + "'", showDir() / (name + "_show.txt")) == 0);
  return slurp(showDir() / (name + "_show.txt"));
}

}  // namespace

TEST_CASE("buckle show prints every special point and branch of a run", "[cli][show]") {
  fs::path out;
  const std::string shown = runAndShow("default", out);
  INFO(shown);
  const json sp = json::parse(slurp(out / "special_points.json"));
  const json summary = json::parse(slurp(out / "summary.json"));
  const std::vector<std::string> text = lines(shown);
  const auto start = std::find_if(text.begin(), text.end(), [](const std::string& l) { return l.rfind("special points (", 0) == 0; });
  REQUIRE(start != text.end());
  CHECK(*start == "special points (" + std::to_string(sp["special_points"].size()) + ", special_points.json):");
  REQUIRE(sp["special_points"].size() >= 4);  // U and Z branch points, the folds/limits beyond them
  // every BP carries Koiter's coefficients: the paper's chain buckles supercritically (symmetric,
  // b·τ < 0), and an end moment couples to both modes (docs/outputs.md)
  int bps = 0;
  for (const json& p : sp["special_points"]) {
    if (p["type"] != "BP") continue;
    ++bps;
    CHECK(p.at("koiter_a").get<double>() == 0.0);
    CHECK(p.at("koiter_b").get<double>() < 0.0);
    CHECK(p.at("post_buckling") == "supercritical");
    // the three end coordinates, then the preload asymmetry dL0 of all segments and of the most
    // sensitive one (docs/outputs.md)
    REQUIRE(p.at("imperfection_sensitivity").size() == 5);
    CHECK(p["imperfection_sensitivity"][3]["imperfection"] == "dL0");
    CHECK(p["imperfection_sensitivity"][3]["segment"] == "all");
    CHECK(p["imperfection_sensitivity"][4]["imperfection"] == "dL0");
    CHECK(p["imperfection_sensitivity"][4]["segment"].is_number_integer());
    CHECK(p["imperfection_sensitivity"][2]["imperfection"] == "Me");
    CHECK(p["imperfection_sensitivity"][2]["coupling"].get<double>() != 0.0);
    CHECK(p["imperfection_sensitivity"][2]["exponent"].get<double>() == 0.0);  // no limit point
  }
  CHECK(bps == 2);
  // one row per point, in order, after the header: case, type, field, branch, parameter, Fx, Fy, Me, shape
  for (size_t i = 0; i < sp["special_points"].size(); ++i) {
    const json& p = sp["special_points"][i];
    REQUIRE(start + 2 + long(i) < text.end());
    const std::string& row = *(start + 2 + long(i));
    const std::vector<std::string> w = words(row);
    INFO("row " << i << ": " << row);
    REQUIRE(w.size() >= 12);
    CHECK(w[0] == std::to_string(p["case"].get<int>()));
    CHECK(w[1] == p["type"].get<std::string>());
    CHECK(w[2] == p["field"].get<std::string>());
    CHECK(w[3] == std::to_string(p["branch"].get<int>()));
    CHECK(w[4] == g(p["parameter"].get<double>(), "%.10g"));
    CHECK(w[5] == g(p["loads"]["Fx"].get<double>(), "%.6g"));
    CHECK(w[8] == (p["shape"].get<std::string>().empty() ? "-" : p["shape"].get<std::string>()));
    // then the stability labels (which hold spaces) and the achieved accuracy
    const std::string stability =
        " " + p["stability_before"].get<std::string>() + " -> " + p["stability_after"].get<std::string>() + " ";
    const size_t at = row.find(stability);
    CHECK(at != std::string::npos);
    for (const char* key : {"parameter", "residual"}) {
      const json& a = p["accuracy"][key];
      CHECK(row.find(" " + (a.is_number() ? g(a.get<double>(), "%.1e") : std::string("nan")) + " ", at) !=
            std::string::npos);
    }
  }
  const json& branches = summary["cases"][0]["branches"];
  REQUIRE(branches.size() >= 5);
  CHECK(shown.find("branches (" + std::to_string(branches.size()) + ", summary.json") != std::string::npos);
  for (const json& b : branches) {
    INFO(b.dump());
    CHECK(shown.find(b["origin"].get<std::string>()) != std::string::npos);
  }
  CHECK(shown.find("critical loads (") != std::string::npos);
  CHECK(shown.find("complete: yes") != std::string::npos);
}

TEST_CASE("buckle show prints the equilibria of the energy curves", "[cli][show]") {
  fs::path out;
  const std::string shown = runAndShow("fig4", out);
  INFO(shown);
  const json eq = json::parse(slurp(out / "special_points.json"))["energy_equilibria"];
  REQUIRE(eq.size() >= 4);
  CHECK(shown.find("equilibria on the energy curves (" + std::to_string(eq.size()) + ",") != std::string::npos);
  CHECK(shown.find("special points: none") != std::string::npos);
  CHECK(shown.find("branches: none") != std::string::npos);
  const std::vector<std::string> text = lines(shown);
  for (const json& e : eq) {
    // its row: case, ik_branch, q1, E, d2E/dq1^2, stability
    const std::string stability = e["stable"].get<bool>() ? "stable" : "unstable";
    const bool found = std::any_of(text.begin(), text.end(), [&](const std::string& l) {
      const std::vector<std::string> w = words(l);
      return w.size() >= 6 && w[0] == std::to_string(e["case"].get<int>()) &&
             w[1] == std::to_string(e["ik_branch"].get<int>()) && w[2] == g(e["q1"].get<double>(), "%.10g") &&
             w[3] == g(e["energy"].get<double>(), "%.10g") && w[5] == stability;
    });
    INFO(e.dump());
    CHECK(found);
  }
}

TEST_CASE("buckle show prints the branch through each equilibrium when the branches were traced", "[cli][show]") {
  fs::path out;
  const std::string shown = runAndShow("disconnected_branch", out);
  INFO(shown);
  const json eq = json::parse(slurp(out / "special_points.json"))["equilibria"][0]["equilibria"];
  REQUIRE(eq.size() == 3);
  const std::vector<std::string> text = lines(shown);
  const auto header = std::find_if(text.begin(), text.end(), [](const std::string& l) {
    const std::vector<std::string> w = words(l);
    return !w.empty() && w[0] == "case" && w.back() == "branch";
  });
  REQUIRE(header != text.end());
  // rows in the order of the list: the last word is the equilibrium's branch
  for (size_t k = 0; k < eq.size(); ++k) {
    const std::vector<std::string> w = words(*(header + 1 + long(k)));
    REQUIRE(w.size() >= 7);
    CHECK(w.back() == std::to_string(eq[k]["branch"].get<int>()));
  }
}

TEST_CASE("buckle show on something that is not a run's output exits 2", "[cli][show]") {
  const fs::path dir = showDir() / "not_output";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "notes.txt") << "x";
  const fs::path log = showDir() / "not_output.txt";
  CHECK(exitCode("show '" + dir.string() + "'", log) == 2);
  CHECK(slurp(log).find("buckle show: " + dir.string() + " is not a buckle output") != std::string::npos);
  CHECK(exitCode("show '" + (dir / "notes.txt").string() + "'", log) == 2);
  CHECK(slurp(log).find("is not a directory") != std::string::npos);
  CHECK(exitCode("show '" + (dir / "missing").string() + "'", log) == 2);
  CHECK(slurp(log).find("does not exist") != std::string::npos);
  std::ofstream(dir / "summary.json") << R"({"generator": "buckle atlas", "schema": 1})";
  CHECK(exitCode("show '" + dir.string() + "'", log) == 2);
  CHECK(slurp(log).find("is a `buckle atlas` output") != std::string::npos);
  std::ofstream(dir / "summary.json") << R"({"generator": "buckle run", "schema": 1})";  // special_points.json missing
  CHECK(exitCode("show '" + dir.string() + "'", log) == 2);
  CHECK(slurp(log).find("special_points.json: cannot be read") != std::string::npos);
  CHECK(exitCode("show", log) == 2);
}

TEST_CASE("buckle show prints a scene's text on one line, without terminal control characters", "[cli][show]") {
  const fs::path dir = showDir() / "hostile";
  fs::remove_all(dir);
  fs::create_directories(dir);
  json scene = json::parse(slurp(std::string(BUCKLE_SOURCE_DIR) + "/data/scenes/default.json"));
  scene["description"] = "first line\nsecond \x1b[2J\x1b]0;title\x07 line";
  scene["cases"] = {{{"label", "label\r\nwith \x1b[31mred"}}, {{"label", "plain"}}};  // labels shown with two cases
  scene["plots"] = json::array();
  std::ofstream(dir / "scene.json") << scene.dump();
  REQUIRE(exitCode("run '" + (dir / "scene.json").string() + "' --quiet --out '" + (dir / "out").string() + "'",
                   dir / "run.txt") == 0);
  REQUIRE(exitCode("show '" + (dir / "out").string() + "'", dir / "show.txt") == 0);
  const std::string shown = slurp(dir / "show.txt");
  INFO(shown);
  CHECK(shown.find('\x1b') == std::string::npos);
  CHECK(shown.find('\x07') == std::string::npos);
  CHECK(shown.find('\r') == std::string::npos);
  CHECK(shown.find("first line second ") != std::string::npos);  // the description on one line
  CHECK(shown.find("label with ") != std::string::npos);
}
