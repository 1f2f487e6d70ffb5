// What a run says while it works and when it ends: the progress reporter (live line, plain
// lines, off) and the summary of repeated problems.
#include <catch2/catch.hpp>

#include <sstream>
#include <string>
#include <vector>

#include "scene/command.h"
#include "scene/progress.h"

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
