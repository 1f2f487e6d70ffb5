// report.html (scene/report.h): joint positions against the chain's own kinematics, and the
// embedded data against the run they describe (every point and special point, nothing that
// would end the <script> element early); the page is accepted as part of a buckle output.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "scene/output.h"
#include "scene/output_target.h"
#include "scene/report.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace fs = std::filesystem;
namespace mech = buckle::mechanics;
using namespace buckle::scene;
using nlohmann::json;

namespace {

/// The text embedded in the page's <script type="application/json" id="buckle-data">.
std::string embeddedText(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"buckle-data\">";
  const size_t begin = page.find(open);
  REQUIRE(begin != std::string::npos);
  CHECK(page.find(open, begin + 1) == std::string::npos);
  const size_t from = begin + open.size();
  const size_t end = page.find("</script>", from);
  REQUIRE(end != std::string::npos);
  return page.substr(from, end - from);
}

/// The document embedded in the page.
json embedded(const std::string& page) { return json::parse(embeddedText(page)); }

Scene smallScene(const std::string& description) {
  json s = {{"description", description},
            {"chain", {{"segments", 3}, {"a", 0.5}, {"b", 1.0}, {"k", 1.0}, {"L0", 2.25}}},
            {"end", {{"x", {{"load", 0.0}}}, {"y", {{"held", 0.0}}}, {"phi", "free"}}},
            {"path", {{"parameter", "Fx"}, {"from", 0.0}, {"to", -1.0}}},
            {"analyses", {{"continuation", {{"branch_switching", 1}}}, {"critical_forces", true}}},
            {"solver", {{"max_step", 0.05}}},
            {"plots", json::array({{{"type", "bifurcation"}, {"x", "Fx"}, {"y", "q2"}},
                                   {{"type", "shapes"}, {"at", {-0.5}}}})}};
  return parseScene(s.dump(), "small.json");
}

/// A case of `n` paper segments added to `run` for a page built from synthetic results.
CaseResult& syntheticCase(RunResult& run, int n) {
  CaseResult& cr =
      run.cases.emplace_back(mech::Chain::uniform(n, mech::SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)));
  cr.label = "main";
  cr.q0 = Eigen::VectorXd::Zero(n);
  return cr;
}

}  // namespace

TEST_CASE("the report embeds every traced point and special point of the run", "[scene][report]") {
  const Scene scene = smallScene("a </script><b> in the description must not end the data");
  const RunResult run = runScene(scene);
  REQUIRE(run.cases.size() == 1);
  const CaseResult& cr = run.cases[0];
  REQUIRE(!cr.points.empty());
  REQUIRE(!cr.specials.empty());
  const json specials = specialPointsJson(scene, run);
  const json summary = summaryJson(scene, run, PlotReport{});
  const std::string page = reportHtml(scene, run, specials, summary);
  const json data = embedded(page);
  CHECK(data["description"] == scene.description);
  const json& c = data["cases"][0];
  CHECK(c["columns"]["parameter"].size() == cr.points.size());
  CHECK(c["columns"]["q2"].size() == cr.points.size());
  CHECK(c["shapes"].size() == cr.points.size());
  REQUIRE(c["specials"].size() == cr.specials.size());
  for (size_t i = 0; i < cr.specials.size(); ++i) {
    const SpecialPointResult& s = cr.specials[i];
    const json& e = c["specials"][i];
    CHECK(e["type"] == mech::label(s.type));
    CHECK(e["branch"] == s.branch);
    // 10 significant digits in the table
    CHECK(std::abs(e["parameter"].get<double>() - s.parameter) <= 1e-9 * std::max(1.0, std::abs(s.parameter)));
    const Eigen::Matrix2Xd p = mech::jointPositions(cr.chain, s.q);
    const json& joints = e["joints"];
    REQUIRE(joints.size() == size_t(2 * p.cols()));
    const double L = cr.chain.length();
    for (Eigen::Index j = 0; j < p.cols(); ++j) {  // 4 significant digits
      CHECK(std::abs(joints[size_t(2 * j)].get<double>() - p(0, j)) <= 1e-3 * L);
      CHECK(std::abs(joints[size_t(2 * j + 1)].get<double>() - p(1, j)) <= 1e-3 * L);
    }
  }
  // stability per point as traced
  for (size_t i = 0; i < cr.points.size(); ++i) CHECK(c["stable"][i] == (cr.points[i].stable ? 1 : 0));
  CHECK(data["main"]["x"] == "Fx");
  CHECK(data["main"]["y"][0] == "q2");
  REQUIRE(data["plots"].size() == 2);
  CHECK(data["plots"][1]["type"] == "shapes");
  CHECK(data["critical"].size() == specials["critical_loads"].size());
}

TEST_CASE("the page's data are written as nlohmann::json dumps them, values rounded as printf's %g", "[scene][report]") {
  // The page writes its per-point arrays as text; the independent formulation is the library's
  // own writer: the document parsed and dumped again gives the same bytes (dump's number format,
  // member order, escaping), and every value is the point's own, rounded as snprintf + strtod do.
  const Scene scene = smallScene("text \"quoted\", a tab\t, an é and a </ that must be escaped");
  const RunResult run = runScene(scene);
  const CaseResult& cr = run.cases[0];
  const std::string page = reportHtml(scene, run, specialPointsJson(scene, run), summaryJson(scene, run, PlotReport{}));
  std::string text = embeddedText(page);
  // every "<" is written \u003c inside the page's <script> (escape.h); dump writes it plainly
  CHECK(text.find('<') == std::string::npos);
  for (size_t at = text.find("\\u003c"); at != std::string::npos; at = text.find("\\u003c", at + 1)) text.replace(at, 6, "<");
  const json data = json::parse(text);
  CHECK(data.dump(-1, ' ', false, json::error_handler_t::replace) == text);
  const auto printed = [](double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return std::strtod(buf, nullptr);
  };
  const json& c = data["cases"][0];
  REQUIRE(c["branch"].size() == cr.points.size());
  for (size_t i = 0; i < cr.points.size(); ++i) {
    const mech::PointReport& p = cr.points[i];
    CHECK(c["branch"][i] == p.branch);
    CHECK(c["point"][i] == p.index);
    CHECK(c["columns"]["parameter"][i].get<double>() == printed(p.parameter, 6));
    CHECK(c["columns"]["Fx"][i].get<double>() == printed(p.F[0], 6));
    CHECK(c["columns"]["q2"][i].get<double>() == printed(p.q[1], 6));
    const Eigen::Matrix2Xd xy = mech::jointPositions(cr.chain, p.q);
    REQUIRE(c["shapes"][i].size() == size_t(2 * xy.cols()));
    for (Eigen::Index j = 0; j < xy.cols(); ++j) {
      CHECK(c["shapes"][i][size_t(2 * j)].get<double>() == printed(xy(0, j), 4));
      CHECK(c["shapes"][i][size_t(2 * j + 1)].get<double>() == printed(xy(1, j), 4));
    }
  }
}

TEST_CASE("report.html is written with the outputs and keeps the directory a buckle output", "[scene][report]") {
  const Scene scene = smallScene("report written by writeOutputs");
  const RunResult run = runScene(scene);
  const fs::path dir = fs::temp_directory_path() / ("buckle_test_report_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  writeOutputs(scene, run, dir.string());
  REQUIRE(fs::is_regular_file(dir / "report.html"));
  std::ifstream in(dir / "report.html", std::ios::binary);
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(embedded(page)["scene"] == "small.json");
  std::string why;
  CHECK(isBuckleOutput(dir.string(), &why));
  INFO(why);
  fs::remove_all(dir);
}

TEST_CASE("the page's rounded numbers are the doubles nearest to printf's %.*g (snprintf + strtod)", "[scene][report]") {
  // The independent formulation: glibc's snprintf and strtod, which the page used before;
  // every magnitude from subnormal to huge, both signs, ties of the decimal rounding.
  std::mt19937_64 random(20261202);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::uniform_int_distribution<int> exponent(-320, 300);
  std::vector<double> values{0.0, -0.0, 1.0, 0.5, 1.25, 2.5e-7, 123456.5, 1234565.0, 9.9999995, 999999.5, -3.0e-5,
                             5e-324, 1.7976931348623157e308, 0.1, 1.0 / 3.0};
  for (int k = 0; k < 20000; ++k) {
    const double v = (k % 2 ? -1.0 : 1.0) * mantissa(random) * std::pow(10.0, exponent(random));
    values.push_back(v);
  }
  for (int digits : {3, 4, 6, 10})
    for (double v : values) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.*g", digits, v);
      const double expected = std::strtod(buf, nullptr);
      const json got = roundedForPage(v, digits);
      REQUIRE(got.is_number_float());
      const double g = got.get<double>();
      INFO(buf << " digits " << digits);
      REQUIRE(std::memcmp(&g, &expected, sizeof g) == 0);  // the same bits: the same page bytes
    }
  CHECK(roundedForPage(std::nan(""), 6).is_null());
  CHECK(roundedForPage(-std::numeric_limits<double>::infinity(), 6).is_null());
}

TEST_CASE("the page of a large run stays a few megabytes and says what it left to the files", "[scene][report]") {
  // A synthetic run far beyond the page's budgets: 60 000 points of a 400-segment chain in 12
  // branches and 2000 special points with their shapes. The page keeps every k-th point of each
  // branch and its last, the first special points' shapes, and says so; nothing else changes.
  const Scene scene = smallScene("large");
  RunResult run;
  const int n = 400;
  CaseResult& cr = syntheticCase(run, n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-0.01, 0.01);
  const int branches = 12, perBranch = 5000;
  for (int b = 0; b < branches; ++b) {
    BranchRecord br;
    br.id = b;
    br.points = perBranch;
    cr.branches.push_back(br);
    for (int i = 0; i < perBranch; ++i) {
      mech::PointReport p;
      p.branch = b;
      p.index = i;
      p.parameter = -1e-3 * i;
      p.q = Eigen::VectorXd::NullaryExpr(n, [&]() { return angle(rng); });
      p.stable = (i / 100) % 2 == 0;
      cr.points.push_back(std::move(p));
    }
  }
  for (int s = 0; s < 2000; ++s) {
    SpecialPointResult sp;
    sp.type = mech::EventType::BranchPoint;
    sp.branch = s % branches;
    sp.q = Eigen::VectorXd::Constant(n, 1e-3 * s);
    cr.specials.push_back(std::move(sp));
  }
  const std::string page = reportHtml(scene, run, specialPointsJson(scene, run), summaryJson(scene, run, PlotReport{}));
  CHECK(page.size() <= 5u * 1000 * 1000);
  const json data = embedded(page);
  REQUIRE(data.contains("abridged"));
  const std::string note = data["abridged"];
  CHECK(note.find("of the 60000 traced points") != std::string::npos);
  CHECK(note.find("of the 2000 special points") != std::string::npos);
  const json& c = data["cases"][0];
  const size_t shown = c["point"].size();
  CHECK(shown < cr.points.size());
  CHECK(c["branch"].size() == shown);
  CHECK(c["stable"].size() == shown);
  CHECK(c["shapes"].size() == shown);
  CHECK(c["columns"]["q2"].size() == shown);
  // every branch's first and last points are there, each shown point's values are its own
  std::vector<int> first(branches, -1), last(branches, -1);
  for (size_t k = 0; k < shown; ++k) {
    const int b = c["branch"][k], i = c["point"][k];
    if (first[size_t(b)] < 0) first[size_t(b)] = i;
    last[size_t(b)] = i;
    const mech::PointReport& p = cr.points[size_t(b * perBranch + i)];
    CHECK(c["stable"][k] == (p.stable ? 1 : 0));
    CHECK(std::abs(c["columns"]["q2"][k].get<double>() - p.q[1]) <= 1e-5 * std::abs(p.q[1]) + 1e-300);
  }
  for (int b = 0; b < branches; ++b) {
    CHECK(first[size_t(b)] == 0);
    CHECK(last[size_t(b)] == perBranch - 1);
  }
  // the first special points carry their shapes, the later ones none; every one is listed
  REQUIRE(c["specials"].size() == cr.specials.size());
  CHECK(c["specials"][0].contains("joints"));
  CHECK(!c["specials"][1999].contains("joints"));
}

TEST_CASE("the page of a small run is complete and says nothing about a summary", "[scene][report]") {
  const Scene scene = smallScene("small");
  const RunResult run = runScene(scene);
  const json data = embedded(reportHtml(scene, run, specialPointsJson(scene, run), summaryJson(scene, run, PlotReport{})));
  CHECK(!data.contains("abridged"));
  CHECK(data["cases"][0]["point"].size() == run.cases[0].points.size());
  for (const json& s : data["cases"][0]["specials"]) CHECK(s.contains("joints"));
}

TEST_CASE("the page of a tree with thousands of special points lists the most important ones", "[scene][report]") {
  // 6000 special points: the primary branch's branch points (every 20th) come before the others;
  // the page lists 2500 of them in their order, those first.
  const Scene scene = smallScene("specials");
  RunResult run;
  const int n = 3;
  CaseResult& cr = syntheticCase(run, n);
  for (int b = 0; b < 2; ++b) {
    BranchRecord br;
    br.id = b;
    br.parent = b == 0 ? -1 : 0;
    cr.branches.push_back(br);
  }
  const int total = 6000;
  std::vector<bool> important(total, false);
  for (int s = 0; s < total; ++s) {
    SpecialPointResult sp;
    const bool primary = s % 20 == 0;
    sp.type = primary ? mech::EventType::BranchPoint : mech::EventType::Release;
    sp.branch = primary ? 0 : 1;
    sp.parameter = -1e-3 * s;  // identifies it on the page
    sp.q = Eigen::VectorXd::Constant(n, 1e-3);
    important[size_t(s)] = primary;
    cr.specials.push_back(std::move(sp));
  }
  const std::string page = reportHtml(scene, run, specialPointsJson(scene, run), summaryJson(scene, run, PlotReport{}));
  const json data = embedded(page);
  const json& listed = data["cases"][0]["specials"];
  REQUIRE(listed.size() == 2500);
  std::vector<int> shown;
  for (const json& s : listed) shown.push_back(int(std::lround(-1e3 * s["parameter"].get<double>())));
  CHECK(std::is_sorted(shown.begin(), shown.end()));
  int primaries = 0;
  for (int s : shown) primaries += important[size_t(s)];
  CHECK(primaries == total / 20);  // every one of them
  // then the others in their order: the first ones
  CHECK(shown[1] == 1);
  REQUIRE(data.contains("abridged"));
  CHECK(data["abridged"].get<std::string>().find("2500 of the 6000 special points") != std::string::npos);
}
