// A scene whose description, case labels and plot titles try to break out of every file they
// are written to (escape.h), run through the real gnuplot: nothing is executed, every plot is
// drawn, and every CSV, JSON and the report's embedded data read back with the text intact.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/escape.h"
#include "scene/output.h"
#include "rfc4180.h"
#include "scene_run.h"
#include "small_scene.h"
#include "read_output.h"

namespace fs = std::filesystem;
namespace escape = buckle::scene::escape;

namespace {

using buckle::test::readText;

const std::string kTitle = "x\"\nsystem \"touch PWNED\"\n#";
const std::string kLabel1 = "a'b\"c\\d`touch PWNED`$(touch PWNED)\r\n# system 'touch PWNED'";
// an embedded NUL: the length from the array, not from strlen (nor a count that reads past its end)
const char kLabel2Text[] = "</script><script>alert(1)</script>\0nul, \"comma\"\x1b[31m";
const std::string kLabel2(kLabel2Text, sizeof kLabel2Text - 1);

}  // namespace

TEST_CASE("hostile text in a scene is written, never executed, and reads back from every file", "[scene][escape]") {
  nlohmann::json scene = nlohmann::json::parse(buckle::test::smallScene(1));
  std::string description;
  while (description.size() < (1u << 20)) description += kTitle + " `touch PWNED` $(touch PWNED) ";
  scene["description"] = description;
  scene["cases"] = {{{"label", kLabel1}}, {{"label", kLabel2}, {"chain", {{"L0", 2.3}}}}};
  scene["analyses"]["critical_forces"] = true;
  scene["plots"] = {{{"type", "bifurcation"}, {"name", "inj"}, {"title", kTitle}, {"x", "Fx"}, {"y", "q2"}},
                    {{"type", "shapes"}, {"name", "shp"}, {"title", kLabel1}, {"at", {-0.5}}}};
  const buckle::test::SceneOutcome o = buckle::test::runSceneText("hostile", "run", scene.dump(-1));
  INFO(o.err);
  REQUIRE(o.rc == 0);
  const fs::path dir = o.file.parent_path();

  // nothing ran: no PWNED anywhere gnuplot or a shell could have been
  for (const auto& e : fs::recursive_directory_iterator(dir)) CHECK(e.path().filename() != "PWNED");
  CHECK_FALSE(fs::exists(fs::current_path() / "PWNED"));

  std::ifstream summaryIn(o.out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summaryIn);
  CHECK(summary["description"] == description);
  CHECK(summary["cases"][0]["label"] == kLabel1);
  CHECK(summary["cases"][1]["label"] == kLabel2);
  if (!buckle::scene::findGnuplot().empty()) {
    CHECK(summary["plots"]["files"].size() == 4);  // both plots drawn, PNG and SVG
    CHECK_FALSE(summary["plots"].contains("failures"));
    // the title reached gnuplot as text: its line is in the SVG (XML-escaped by gnuplot)
    const std::string svg = readText(o.out / "plots" / "inj.svg");
    CHECK((svg.find("system &quot;touch PWNED&quot;") != std::string::npos ||
           svg.find("system \"touch PWNED\"") != std::string::npos));
  } else {
    WARN("gnuplot not found: the scripts are not run");
  }

  std::ifstream specialIn(o.out / "special_points.json");
  const nlohmann::json specials = nlohmann::json::parse(specialIn);
  REQUIRE_FALSE(specials["critical_loads"].empty());
  CHECK(specials["critical_loads"].back()["case_label"] == kLabel2);

  // every CSV: a rectangular table
  for (const auto& e : fs::directory_iterator(o.out)) {
    if (e.path().extension() != ".csv") continue;
    INFO(e.path());
    const auto rows = buckle::test::readCsv(readText(e.path()));
    REQUIRE(rows.size() > 1);
    for (const auto& row : rows) CHECK(row.size() == rows[0].size());
  }

  // gnuplot data files: the label stays inside its comment line
  for (const auto& e : fs::directory_iterator(o.out / "plots")) {
    if (e.path().extension() != ".dat") continue;
    const std::string text = readText(e.path());
    CHECK(text.find("\n# system") == std::string::npos);  // the label's second line stays in its comment
    CHECK(text.find('\r') == std::string::npos);
    CHECK(text.find('\0') == std::string::npos);
  }

  // report.html: one data element, whose text is the JSON with the labels intact
  const std::string html = readText(o.out / "report.html");
  const std::string open = "<script type=\"application/json\" id=\"buckle-data\">";
  const size_t begin = html.find(open), end = html.find("</script>", begin);
  REQUIRE(begin != std::string::npos);
  REQUIRE(end != std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
  CHECK(data["description"] == description);
  CHECK(data["cases"][1]["label"] == kLabel2);
  CHECK(html.find("<script>alert") == std::string::npos);
}
