// What a run says while it works and when it ends: the progress reporter (live line, plain
// lines, off) and the summary of repeated problems.
#include <catch2/catch.hpp>

#include <sstream>
#include <string>
#include <vector>

#include <fstream>
#include <nlohmann/json.hpp>

#include "buckle/mechanics/critical_loading.h"
#include "scene/command.h"
#include "scene/progress.h"
#include "scene_run.h"

using buckle::scene::Progress;
using buckle::scene::summariseProblems;
using Catch::Matchers::Contains;

namespace {
size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}
}  // namespace

TEST_CASE("Progress: plain lines name the stage, case, branch, points and parameter", "[progress]") {
  std::ostringstream out;
  {
    Progress p(out, Progress::Mode::Lines, 0.0, 0.0);  // no delay, no throttling
    p.stage("continuation", "n = 50", 1, 3);
    p.step(3, 341, -0.75, 6);
    p.note("jump from the fold at -1.7");
  }
  const std::string text = out.str();
  INFO(text);
  CHECK(count(text, "\n") == 3);
  CHECK(count(text, "buckle: [") == 3);
  CHECK_THAT(text, Contains("case 2/3 \"n = 50\" continuation"));
  CHECK_THAT(text, Contains("branch 3, 341 points, parameter -0.75, 6 special points"));
  CHECK_THAT(text, Contains("jump from the fold at -1.7"));
  CHECK(text.find('\r') == std::string::npos);  // no terminal control in logs
}

TEST_CASE("Progress: the tree's size ahead and warnings, at once and in every mode but Off", "[progress]") {
  std::ostringstream lines, off;
  {
    Progress p(lines, Progress::Mode::Lines, 0.0, 0.0);
    p.stage("continuation", "", 0, 1);
    p.step(2, 10, -0.5, 1, 183);
    p.step(3, 10, -0.5, 1, 1);
    p.step(4, 10, -0.5, 1, 0);
    Progress late(lines, Progress::Mode::Lines, 1e9, 1e9);  // a warning does not wait for the first report
    late.warn("the path crosses 400 critical loads");
    Progress quiet(off, Progress::Mode::Off);
    quiet.warn("never printed");
  }
  const std::string text = lines.str();
  INFO(text);
  CHECK_THAT(text, Contains("branch 2, 10 points, parameter -0.5, 1 special point; 183 branch points queued\n"));
  CHECK_THAT(text, Contains("branch 3, 10 points, parameter -0.5, 1 special point; 1 branch point queued\n"));
  CHECK_THAT(text, Contains("branch 4, 10 points, parameter -0.5, 1 special point\n"));
  CHECK_THAT(text, Contains("buckle: warning: the path crosses 400 critical loads\n"));
  CHECK(off.str().empty());
}

TEST_CASE("Progress: a short run prints nothing, Off never prints, Live rewrites one line", "[progress]") {
  std::ostringstream quiet, off, live;
  {
    Progress p(quiet, Progress::Mode::Lines, 3600.0, 0.0);  // the run ends before the first report
    p.stage("continuation", "", 0, 1);
    p.step(1, 10, 0.1, 0);
  }
  CHECK(quiet.str().empty());
  {
    Progress p(off, Progress::Mode::Off, 0.0, 0.0);
    p.stage("continuation", "", 0, 1);
    p.step(1, 10, 0.1, 0);
  }
  CHECK(off.str().empty());
  {
    Progress p(live, Progress::Mode::Live, 0.0, 0.0);
    p.stage("continuation", "", 0, 1);
    p.finish();
  }
  const std::string text = live.str();
  CHECK(text.find('\n') == std::string::npos);
  CHECK(count(text, "\r") == 2);          // the line, then its erasure before the summary
  CHECK(count(text, "\033[K") == 2);
  CHECK_THAT(text, Contains("continuation"));
}

TEST_CASE("summariseProblems: the first few as they are, the rest once per shape with a count", "[progress]") {
  std::vector<std::string> problems;
  for (int i = 0; i < 999; ++i)
    problems.push_back("branch " + std::to_string(i + 1) + " (BP " + std::to_string(i) + "): no bifurcating direction");
  problems.push_back("jump from the fold at -1.5 did not land");
  const std::vector<std::string> lines = summariseProblems(problems, 3);
  REQUIRE(lines.size() == 5);
  CHECK(lines[0] == problems[0]);
  CHECK(lines[2] == problems[2]);
  CHECK(lines[3] == "996 more like: " + problems[3]);
  CHECK(lines[4] == problems.back());  // a shape seen once is shown as it is
  CHECK(summariseProblems({}, 3).empty());
  CHECK(summariseProblems({"a", "b"}, 8) == std::vector<std::string>{"a", "b"});
}

TEST_CASE("scene: a path across hundreds of critical loads is warned of at the start, on stderr and in the summary",
          "[progress]") {
  const auto scene = [](int n, const std::string& continuation) {
    return R"({"units": "nondimensional", "chain": {"segments": )" + std::to_string(n) +
           R"(, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
      "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
      "path": {"parameter": "Fx", "from": 0.0, "to": -2.5}, "solver": {"time_limit": 0.3},
      "analyses": {"continuation": )" + continuation + "}}";
  };
  const auto summary = [](const buckle::test::SceneOutcome& o) {
    std::ifstream in(o.out / "summary.json");
    return nlohmann::json::parse(in);
  };
  using namespace buckle::mechanics;
  const int n = 150;
  const int expected = criticalLoadCount(Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                                         Vector::Zero(n),
                                         criticalLoading(EndCondition::clampedPinned(0.0), 0, Eigen::Vector3d::UnitX()),
                                         -2.5);
  REQUIRE(expected > 100);
  const buckle::test::SceneOutcome many =
      buckle::test::runSceneText("scene_progress", "many", scene(n, R"({"branch_switching": 1})"));
  INFO(many.err);
  const nlohmann::json s = summary(many);
  REQUIRE(s.contains("warnings"));
  REQUIRE(s["warnings"].size() == 1);
  const std::string warning = s["warnings"][0].get<std::string>();
  CHECK_THAT(warning, Contains("crosses " + std::to_string(expected) + " critical loads"));
  CHECK_THAT(warning, Contains("/analyses/continuation/branch_points"));
  CHECK_THAT(many.err, Contains("buckle: warning: " + warning.substr(0, 60)));
  // the first few branch points on each branch only, or no switching at all: nothing to warn of
  for (const std::string& quiet : {std::string(R"({"branch_switching": 1, "branch_points": 3})"),
                                   std::string(R"({"branch_switching": 0})")}) {
    const buckle::test::SceneOutcome few = buckle::test::runSceneText("scene_progress", "few", scene(n, quiet));
    INFO(quiet);
    CHECK(!summary(few).contains("warnings"));
    CHECK(few.err.find("warning") == std::string::npos);
  }
}

TEST_CASE("scene: a start shape whose links' bodies overlap is warned of, with the depth in the scene's units",
          "[progress]") {
  // contact_release's curled chain: its last link's triangle lies inside the clamped one
  const auto scene = [](double curl, const std::string& units, double length) {
    std::ostringstream s;
    s.precision(17);
    s << R"({"units": )" << units << R"(, "chain": {"segments": [{"q0": 0.2}, {"q0": )" << curl << R"(}, {"q0": )"
      << curl << R"(}, {"q0": )" << curl << R"(}, {"q0": )" << curl << R"(}], "a": )" << 0.5 * length
      << R"(, "b": )" << length << R"(, "k": 1.0, "L0": )" << 2.25 * length << R"(},
      "end": {"x": {"load": 0.0}, "y": {"load": 0.0}, "phi": "free"},
      "path": {"parameter": "Fy", "from": 0.0, "to": )" << 0.01 * length << R"(},
      "analyses": {"continuation": true}})";
    return s.str();
  };
  const auto warnings = [](const buckle::test::SceneOutcome& o) {
    std::ifstream in(o.out / "summary.json");
    const nlohmann::json s = nlohmann::json::parse(in);
    return s.contains("warnings") ? s["warnings"] : nlohmann::json::array();
  };
  using namespace buckle::mechanics;
  for (double length : {1.0, 0.02}) {
    const std::string units = length == 1.0 ? R"("nondimensional")" : R"({"length": "m", "force": "N"})";
    INFO("units " << units);
    const buckle::test::SceneOutcome curled = buckle::test::runSceneText("scene_progress", "curled", scene(1.3, units, length));
    INFO(curled.err);
    const nlohmann::json w = warnings(curled);
    REQUIRE(w.size() == 1);
    const std::string warning = w[0].get<std::string>();
    CHECK_THAT(warning, Contains("the start shape overlaps itself: the bodies of links 0 and 5"));
    CHECK_THAT(warning, Contains(length == 1.0 ? " (units of b)" : " (m)"));
    // the depth: −d_self of the chain at its q0 (the same chain built here)
    Vector q(5);
    q << 0.2, 1.3, 1.3, 1.3, 1.3;
    const double depth = -selfClearance(Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)), q).distance;
    REQUIRE(depth > 0.0);
    std::ostringstream d;
    d.precision(6);
    d << depth * length;
    CHECK_THAT(warning, Contains("overlap by " + d.str()));
    CHECK_THAT(curled.err, Contains("buckle: warning: " + warning.substr(0, 60)));
    // curled less, the bodies are clear: nothing to warn of
    const buckle::test::SceneOutcome clear = buckle::test::runSceneText("scene_progress", "clear", scene(1.2, units, length));
    CHECK(warnings(clear).empty());
  }
}
