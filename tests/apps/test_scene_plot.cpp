// The gnuplot plots of a run (apps/scene/plot.cpp), checked on the scripts and data files they
// leave in <out>/plots: one key entry and one colour per case, stability explained in the key,
// special points in their case's colour, labels apart from each other, stiffness minima marked
// at the traced stiffness, shapes requested where nothing stable was traced reported, and the
// sudden-load energies (their sum constant to the integrator's own balance error). Also the load
// history's stable pieces in branches.csv, each point an equilibrium (recomputed with the
// mechanics model) and stable.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <unistd.h>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "scene/command.h"
#include "temp_dir.h"
#include "read_output.h"
#include "build_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace buckle::mechanics;

namespace {

using buckle::test::readJson;
using buckle::test::readText;

fs::path scenePath(const std::string& name) { return fs::path(BUCKLE_SOURCE_DIR) / "data" / "scenes" / name; }

fs::path plotDir(const std::string& name) { return buckle::test::absentPath("scene_plot", name); }

struct Run {
  int rc;
  std::string log, err;
};

Run runPlotScene(const fs::path& scene, const fs::path& out) {
  std::ostringstream log, err;
  buckle::scene::RunCommandOptions opt;
  opt.scene = scene.string();
  opt.out = out.string();
  const int rc = buckle::scene::runSceneCommand(opt, log, err);
  return {rc, log.str(), err.str()};
}

/// The blocks of a BlockFile data file (gnuplot `index`), each a list of rows of numbers; "#"
/// comment lines of a block kept apart.
struct Block {
  std::vector<std::string> comments;
  std::vector<std::vector<double>> rows;
};

std::vector<Block> readBlocks(const fs::path& p) {
  std::vector<Block> blocks;
  std::istringstream in(readText(p));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# block ", 0) == 0) {
      blocks.emplace_back();
      continue;
    }
    if (blocks.empty() || line.empty()) continue;
    if (line[0] == '#') {
      blocks.back().comments.push_back(line);
      continue;
    }
    std::istringstream ls(line);
    std::vector<double> row;
    std::string tok;
    while (ls >> tok) {
      if (tok[0] == '"') break;  // a label: the numbers before it are kept
      row.push_back(tok == "NaN" ? std::nan("") : std::stod(tok));
    }
    if (!row.empty() && std::isfinite(row[0])) blocks.back().rows.push_back(row);
  }
  return blocks;
}

/// The `plot` clauses of a gnuplot body, one string each.
std::vector<std::string> plotClauses(const std::string& body) {
  const size_t at = body.find("plot \\\n");
  REQUIRE(at != std::string::npos);
  std::vector<std::string> out;
  std::istringstream in(body.substr(at + 7));
  std::string line;
  while (std::getline(in, line)) {
    const size_t b = line.find_first_not_of(' ');
    if (b == std::string::npos) break;
    std::string c = line.substr(b);
    const bool more = c.size() >= 3 && c.compare(c.size() - 3, 3, ", \\") == 0;
    if (more) c.resize(c.size() - 3);
    out.push_back(c);
    if (!more) break;
  }
  return out;
}

// Plain string scanning, not <regex>: GCC 12 warns (-Wmaybe-uninitialized) inside <regex>
// at -O1 with the sanitizers, and the builds are warning-free.
// The value of `key 'text'` or `key "text"` (the scripts quote fixed texts one way, any text from
// the scene the other, escape.h; the texts compared here hold no escapes).
std::string field(const std::string& clause, const std::string& key) {
  for (const char quote : {'\'', '"'}) {
    const std::string open = key + " " + quote;
    const size_t at = clause.find(open);
    if (at == std::string::npos) continue;
    const size_t from = at + open.size(), to = clause.find(quote, from);
    return to == std::string::npos ? std::string() : clause.substr(from, to - from);
  }
  return std::string();
}

int indexOf(const std::string& clause) {
  const std::string open = " index ";
  const size_t at = clause.find(open);
  if (at == std::string::npos) return -1;
  const size_t from = at + open.size(), to = clause.find(' ', from);
  if (to == std::string::npos || to == from) return -1;
  const std::string digits = clause.substr(from, to - from);
  if (digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(digits);
}

double setting(const std::string& body, const std::string& name) {
  const std::string open = "set " + name + " at screen ";
  const size_t at = body.find(open);
  REQUIRE(at != std::string::npos);
  return std::stod(body.substr(at + open.size()));
}

std::pair<double, double> range(const std::string& body, const std::string& axis) {
  const std::string open = "set " + axis + "range [";
  const size_t at = body.find(open);
  REQUIRE(at != std::string::npos);
  const size_t colon = body.find(':', at), close = body.find(']', at);
  REQUIRE((colon != std::string::npos && close != std::string::npos && colon < close));
  return {std::stod(body.substr(at + open.size(), colon - at - open.size())),
          std::stod(body.substr(colon + 1, close - colon - 1))};
}

/// `x y label_x label_y "text" leader_x leader_y`: the numbers and the text, or false.
bool labelLine(const std::string& line, double (&v)[6], std::string& text) {
  const size_t q0 = line.find('"'), q1 = q0 == std::string::npos ? q0 : line.find('"', q0 + 1);
  if (q1 == std::string::npos) return false;
  // tokens read with std::stod, which takes gnuplot's "NaN" (a label without a leader)
  std::istringstream head(line.substr(0, q0)), tail(line.substr(q1 + 1));
  std::string token;
  int k = 0;
  for (std::istringstream* part : {&head, &tail})
    while (*part >> token) {
      if (k == 6) return false;
      try {
        v[k++] = std::stod(token);
      } catch (const std::exception&) {
        return false;
      }
    }
  if (k != 6) return false;
  text = line.substr(q0 + 1, q1 - q0 - 1);
  return true;
}

/// The bifurcation and stiffness plots of an output (those with a NAME_labels.dat).
std::vector<std::string> labelledPlots(const fs::path& out) {
  std::vector<std::string> stems;
  for (const auto& e : fs::directory_iterator(out / "plots")) {
    const std::string file = e.path().filename().string();
    if (file.size() >= 11 && file.compare(file.size() - 11, 11, "_labels.dat") == 0)
      stems.push_back(file.substr(0, file.size() - 11));
  }
  std::sort(stems.begin(), stems.end());
  return stems;
}

/// The pixel frame of a bifurcation/stiffness plot: its fixed margins and ranges (NAME_body.gp)
/// on the 1000×700 terminal (NAME.gp).
struct PixelFrame {
  double l, r, b, t, x0, x1, y0, y1;
  bool logY = false;  ///< `set logscale y`: the stiffness over decades (y0, y1 then their logarithms)
  static constexpr double W = 1000, H = 700;
  explicit PixelFrame(const fs::path& plots, const std::string& stem) {
    const std::string body = readText(plots / (stem + "_body.gp"));
    l = setting(body, "lmargin"), r = setting(body, "rmargin"), b = setting(body, "bmargin"), t = setting(body, "tmargin");
    std::tie(x0, x1) = range(body, "x");
    std::tie(y0, y1) = range(body, "y");
    logY = body.find("set logscale y") != std::string::npos;
    if (logY) y0 = std::log10(y0), y1 = std::log10(y1);
    CHECK(readText(plots / (stem + ".gp")).find("size 1000,700") != std::string::npos);
  }
  std::pair<double, double> px(double x, double y) const {
    const double v = logY ? std::log10(y) : y;
    return {W * (l + (r - l) * (x - x0) / (x1 - x0)), H * (b + (t - b) * (v - y0) / (y1 - y0))};
  }
};

struct Label {
  double x, y;       ///< the point labelled (data)
  std::string text;
};

/// The labels of plot STEM (NAME_labels.dat: x y label_x label_y "text" leader_x leader_y),
/// checked to lie inside the plot area apart from one another and from every labelled marker,
/// each leader ending on its label.
std::vector<Label> labelsApart(const fs::path& plots, const std::string& stem) {
  const PixelFrame f(plots, stem);
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> boxes, markers;
  std::vector<Label> labels;
  std::ifstream in(plots / (stem + "_labels.dat"));
  std::string line;
  while (std::getline(in, line)) {
    double v[6];
    std::string text;
    if (!labelLine(line, v, text)) continue;
    labels.push_back({v[0], v[1], text});
    const auto [ax, ay] = f.px(v[0], v[1]);
    const auto [cx, cy] = f.px(v[2], v[3]);
    // 9 pt DejaVu Sans in pngcairo: about 7.2 px per character ("BP mode 12": 72 px), 11 px high
    const double w = 7.2 * double(text.size()), h = 11.0;
    boxes.push_back({cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2});
    markers.push_back({ax - 5, ay - 5, ax + 5, ay + 5});
    const Box& bx = boxes.back();
    CHECK(bx.x0 >= f.W * f.l - 1e-6);
    CHECK(bx.x1 <= f.W * f.r + 1e-6);
    CHECK(bx.y0 >= f.H * f.b - 1e-6);
    CHECK(bx.y1 <= f.H * f.t + 1e-6);
    // a leader, when drawn, runs from the point to the label
    if (!std::isnan(v[4])) {
      const auto [ex, ey] = f.px(v[4], v[5]);
      // the leader ends on the placement box, which reserves 7.3 px a character and 4 px of margin
      const double half = (7.3 * double(text.size()) + 4.0) / 2;
      CHECK(ex >= cx - half - 1);
      CHECK(ex <= cx + half + 1);
      CHECK(ey >= bx.y0 - 3);
      CHECK(ey <= bx.y1 + 3);
    }
  }
  auto overlap = [](const Box& p, const Box& q) { return p.x0 < q.x1 && q.x0 < p.x1 && p.y0 < q.y1 && q.y0 < p.y1; };
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = 0; j < boxes.size(); ++j) {
      if (i != j) CHECK(!overlap(boxes[i], boxes[j]));
      CHECK(!overlap(boxes[i], markers[j]));
    }
  return labels;
}

/// Rows of branches.csv by column name.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  size_t col(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    return size_t(it - header.begin());
  }
};

Csv readBranchesCsv(const fs::path& p) {
  Csv csv;
  std::istringstream in(readText(p));
  std::string line, tok;
  std::getline(in, line);
  std::istringstream hs(line);
  while (std::getline(hs, tok, ',')) csv.header.push_back(tok);
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<double> row;
    while (std::getline(ls, tok, ',')) row.push_back(tok.empty() || tok == "nan" ? std::nan("") : std::stod(tok));
    csv.rows.push_back(row);
  }
  return csv;
}

// A two-case variant of the paper's clamped–pinned column (default.json): stable and unstable
// branches, branch points and folds in both cases.
const char* kTwoCases = R"({
  "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
  "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
  "path": {"parameter": "Fx", "from": 0.0, "to": -2.5},
  "cases": [{"label": "L0 = 2.25"}, {"label": "L0 = 2.4", "chain": {"L0": 2.4}}],
  "analyses": {"continuation": {"branch_switching": 1, "contact": false}, "jump": true},
  "plots": [{"type": "bifurcation", "name": "two", "x": "Fx", "y": "q2"},
            {"type": "shapes", "name": "shapes", "at": [-0.5, -2.4], "cases": [0]}]
})";

/// Runs data/scenes/SCENE.json into a fresh directory NAME, which it returns; the run must succeed.
fs::path runShipped(const std::string& scene, const std::string& name) {
  const fs::path out = plotDir(name);
  const Run r = runPlotScene(scenePath(scene + ".json"), out);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  return out;
}

/// Writes kTwoCases as DIR.json and runs it into DIR/out.
Run runTwoCases(const fs::path& dir) {
  const fs::path scene = dir.string() + ".json";
  std::ofstream(scene) << kTwoCases;
  return runPlotScene(scene, dir / "out");
}

}  // namespace

TEST_CASE("multi-case bifurcation plot: one colour and key entry per case, stability in the key", "[scene][plot]") {
  const fs::path dir = plotDir("two_cases"), out = dir / "out";
  const Run r = runTwoCases(dir);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  const std::string body = readText(out / "plots" / "two_body.gp");
  const std::vector<std::string> clauses = plotClauses(body);
  const std::vector<Block> curves = readBlocks(out / "plots" / "two.dat");
  // curves: one colour per case (its stable and unstable parts alike), distinct between cases,
  // the stable part carrying the case label as its only key entry
  std::map<std::string, std::set<std::string>> coloursOfLabel;
  std::map<std::string, int> titled;
  std::vector<std::string> caseColour;
  int stableKey = 0, unstableKey = 0;
  for (const std::string& c : clauses) {
    if (c.rfind("keyentry with lines", 0) == 0) {
      if (c.find(" dt 1 ") != std::string::npos && field(c, "title") == "stable") ++stableKey;
      if (c.find(" dt 2 ") != std::string::npos && field(c, "title") == "unstable") ++unstableKey;
      continue;
    }
    if (c.rfind("\"two.dat\"", 0) != 0) continue;
    const std::string colour = field(c, "rgb"), title = field(c, "title");
    if (!title.empty()) {
      ++titled[title];
      CHECK(c.find(" dt 1 ") != std::string::npos);  // the key shows the stable (solid) line
      caseColour.push_back(colour);
    }
  }
  CHECK(titled == std::map<std::string, int>{{"L0 = 2.25", 1}, {"L0 = 2.4", 1}});
  REQUIRE(caseColour.size() == 2);
  CHECK(caseColour[0] != caseColour[1]);
  CHECK(stableKey == 1);
  CHECK(unstableKey == 1);
  // every curve clause of case k (blocks in case order: stable, unstable) uses the case colour
  int curveClauses = 0, unstableDrawn = 0;
  for (const std::string& c : clauses) {
    if (c.rfind("\"two.dat\"", 0) != 0) continue;
    const int block = indexOf(c);
    REQUIRE(block >= 0);
    const size_t k = size_t(block) / 2;  // two blocks (stable, unstable) per case
    REQUIRE(k < 2);
    CHECK(field(c, "rgb") == caseColour[k]);
    CHECK(c.find(block % 2 == 0 ? " dt 1 " : " dt 2 ") != std::string::npos);
    if (block % 2 == 1 && !curves[size_t(block)].rows.empty()) ++unstableDrawn;
    ++curveClauses;
  }
  CHECK(curveClauses == 4);
  CHECK(unstableDrawn == 2);  // both cases have unstable branches, drawn dashed
  // special points: filled markers in the colour of their case, one key entry per type
  const std::vector<Block> special = readBlocks(out / "plots" / "two_special.dat");
  std::set<std::string> typesKeyed;
  int colouredMarkers = 0;
  for (const std::string& c : clauses) {
    if (c.rfind("keyentry with points", 0) == 0) typesKeyed.insert(field(c, "title"));
    if (c.rfind("\"two_special.dat\"", 0) != 0 || c.find("lw 1 lc rgb 'black'") != std::string::npos) continue;
    const Block& b = special.at(size_t(indexOf(c)));
    REQUIRE(!b.comments.empty());
    const size_t k = b.comments[0].find("# case 1") == 0 ? 1 : 0;
    CHECK(b.comments[0].find("# case " + std::to_string(k)) == 0);
    CHECK(field(c, "rgb") == caseColour[k]);
    ++colouredMarkers;
  }
  CHECK(colouredMarkers >= 4);  // BP and LP (and BD) in both cases
  CHECK(typesKeyed.count("BP branch point") == 1);
  CHECK(typesKeyed.count("LP fold") == 1);
  fs::remove_all(dir.parent_path());
}

TEST_CASE("special-point labels do not overlap one another, a marker or the plot border", "[scene][plot]") {
  for (const char* sceneName : {"default", "hysteresis", "fig9_fig10"}) {
    const std::string name = sceneName;
    DYNAMIC_SECTION(name) {
      const fs::path out = runShipped(name, name);
      int plots = 0;
      for (const std::string& stem : labelledPlots(out)) {
        INFO(stem);
        ++plots;
        CHECK(labelsApart(out / "plots", stem).size() > 0);
      }
      CHECK(plots >= 2);
      if (name == "hysteresis") {
        // the fold's branch point and the jump released there share one label
        const std::string labels = readText(out / "plots" / "hysteresis_q1_labels.dat");
        CHECK(labels.find(", JUMP\"") != std::string::npos);
      }
      if (name == "fig9_fig10") {
        // Kxx falls by decades into the quasi-buckling minimum and stays positive: a log axis,
        // whose pixel positions the labels above were checked in
        const Csv csv = readBranchesCsv(out / "branches.csv");
        double lo = INFINITY, hi = 0.0;
        for (const auto& row : csv.rows)
          if (row[csv.col("case")] <= 2.0 && std::isfinite(row[csv.col("Kxx")]))
            lo = std::min(lo, row[csv.col("Kxx")]), hi = std::max(hi, row[csv.col("Kxx")]);
        REQUIRE(lo > 0.0);
        CHECK(PixelFrame(out / "plots", "fig10a_Kxx").logY == (hi > 100.0 * lo));
      }
      fs::remove_all(out);
    }
  }
}

TEST_CASE("stiffness plots mark KMIN at its located stiffness and joint limits at the traced one", "[scene][plot]") {
  const fs::path out = runShipped("fig9_fig10", "fig9_fig10_kmin");
  const Csv csv = readBranchesCsv(out / "branches.csv");
  const json sp = readJson(out / "special_points.json");
  const std::vector<Block> special = readBlocks(out / "plots" / "fig10a_Kxx_special.dat");
  std::map<std::string, int> marked;
  std::set<int> limitCases;  // cases with a joint-limit marker (BD, or CT where the joint locks)
  for (const Block& b : special) {
    if (b.comments.empty()) continue;
    const std::string& c = b.comments[0];
    const int k = std::stoi(c.substr(7));
    const std::string type = c.substr(c.rfind(": ") + 2);
    for (const std::vector<double>& row : b.rows) {
      ++marked[type];
      if (type == "BD" || type == "CT") limitCases.insert(k);
      // the special point of that type in special_points.json at this Fx
      bool found = false;
      for (const json& p : sp["special_points"]) {
        if (p["case"] != k || p["type"] != type || std::abs(double(p["loads"]["Fx"]) - row[0]) > 1e-9) continue;
        found = true;
        if (type != "KMIN" && type != "BD" && type != "CT") continue;
        // at a traced point: the marker's Kxx is that point's Kxx in branches.csv
        bool atPoint = false;
        for (const auto& rowCsv : csv.rows) {
          if (int(rowCsv[csv.col("case")]) != k || int(rowCsv[csv.col("branch")]) != int(p["branch"])) continue;
          if (std::abs(rowCsv[csv.col("Fx")] - row[0]) > 1e-9 * (1 + std::abs(row[0]))) continue;
          bool sameQ = true;
          for (int i = 0; i < 3; ++i)
            sameQ = sameQ && std::abs(rowCsv[csv.col("q" + std::to_string(i + 1))] - double(p["q"][size_t(i)])) < 1e-9;
          if (!sameQ) continue;
          atPoint = true;
          CHECK(row[1] == Approx(rowCsv[csv.col("Kxx")]).epsilon(1e-9));
        }
        if (type == "KMIN") {
          // located between traced points, at its own K_xx: below the traced points nearest in Fx
          CHECK(!atPoint);
          double below = -1e300, above = 1e300, kBelow = 0.0, kAbove = 0.0;
          for (const auto& rowCsv : csv.rows) {
            if (int(rowCsv[csv.col("case")]) != k || int(rowCsv[csv.col("branch")]) != int(p["branch"])) continue;
            const double fx = rowCsv[csv.col("Fx")];
            if (fx <= row[0] && fx > below) below = fx, kBelow = rowCsv[csv.col("Kxx")];
            if (fx >= row[0] && fx < above) above = fx, kAbove = rowCsv[csv.col("Kxx")];
          }
          CHECK(row[1] > 0.0);
          CHECK(row[1] <= kBelow);
          CHECK(row[1] <= kAbove);
        }
      }
      CHECK(found);
    }
  }
  // fig9_fig10: a deep Kxx minimum for a/b = 0.75 and 0.9, the joint limit in all three cases
  // (where the joint locks and the branch goes on under contact: CT)
  CHECK(marked["KMIN"] == 2);
  CHECK(limitCases.size() == 3);
  fs::remove_all(out);
}

TEST_CASE("a shape requested where no stable point was traced is reported, not moved", "[scene][plot]") {
  const fs::path dir = plotDir("shape_outside"), out = dir / "out";
  const Run r = runTwoCases(dir);
  REQUIRE(r.rc == 0);  // a plot note, not a failed computation
  const json summary = readJson(out / "summary.json");
  CHECK(summary["complete"] == true);
  REQUIRE(summary.contains("notes"));
  REQUIRE(summary["notes"].size() == 1);  // Fx = -0.5 is on the stable straight branch
  const std::string note = summary["notes"][0];
  CHECK(note.find("/plots/1/at/1") != std::string::npos);
  CHECK(note.find("Fx = -2.4") != std::string::npos);
  CHECK(note.find("outside the traced stable range") != std::string::npos);
  CHECK(r.err.find("note: " + note) != std::string::npos);
  // the panel at -2.4 has no chain in it; the one at -0.5 has the three joints
  CHECK(readBlocks(out / "plots" / "shapes_0_1_jnt.dat")[0].rows.empty());
  CHECK(readBlocks(out / "plots" / "shapes_0_0_jnt.dat")[0].rows.size() == 3);
  const std::string body = readText(out / "plots" / "shapes_body.gp");
  CHECK(body.find("Fx = -2.4: not drawn") != std::string::npos);
  fs::remove_all(dir.parent_path());
}

TEST_CASE("sudden-load plot: energies with a constant sum, rest shape beside the quasi-static one", "[scene][plot]") {
  const fs::path out = runShipped("sudden_load", "sudden");
  const json sp = readJson(out / "special_points.json");
  const json& s = sp["sudden_load"][0];
  const double balance = s["energy_balance_error"];
  const std::vector<Block> energy = readBlocks(out / "plots" / "sudden_load_0_energy.dat");
  // the energy file has no block header: one table t Π T W_d sum
  std::ifstream in(out / "plots" / "sudden_load_0_energy.dat");
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::vector<double> row(5);
    for (double& v : row) ls >> v;
    rows.push_back(row);
  }
  REQUIRE(rows.size() > 100);
  CHECK(rows[0][0] == 0.0);
  CHECK(rows[0][2] == 0.0);
  CHECK(rows[0][3] == 0.0);
  const double total0 = rows[0][1];
  double drift = 0.0, peakKinetic = 0.0, dissipated = 0.0;
  for (const auto& row : rows) {
    CHECK(row[4] == Approx(row[1] + row[2] + row[3]).epsilon(1e-15).margin(1e-15));
    drift = std::max(drift, std::abs(row[1] + row[2] + row[3] - total0));
    peakKinetic = std::max(peakKinetic, row[2]);
    dissipated = std::max(dissipated, row[3]);
  }
  // Π + T + W_d is constant to the balance error the integrator reports, which is tiny against
  // the energy that changes form
  CHECK(drift <= balance * (1 + 1e-9) + 4e-16 * std::abs(total0));
  CHECK(peakKinetic == Approx(double(s["peak_kinetic"])).epsilon(1e-9));
  CHECK(balance < 1e-6 * peakKinetic);
  CHECK(dissipated > 0.0);
  // the drawn chains: the last joint plus the last link along φ is the end position reported
  // for each answer
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
  for (const auto& [file, pos] : {std::pair<std::string, json>{"sudden_load_0_rest_jnt.dat", s["rest"]["position"]},
                                  {"sudden_load_0_static_jnt.dat", s["quasi_static"]["position"]}}) {
    const std::vector<Block> joints = readBlocks(out / "plots" / file);
    REQUIRE(joints[0].rows.size() == 3);
    const std::vector<double>& last = joints[0].rows.back();
    const double phi = pos["phi"], L = chain.linkLengths()[3];
    CHECK(last[0] + L * std::cos(phi) == Approx(double(pos["x"])).margin(1e-8));
    CHECK(last[1] + L * std::sin(phi) == Approx(double(pos["y"])).margin(1e-8));
  }
  // the two answers differ in this scene, and the plot says so
  const std::string body = readText(out / "plots" / "sudden_load_body.gp");
  CHECK(body.find("quasi-static: ") != std::string::npos);
  CHECK(body.find(bool(s["quasi_static"]["differs"]) ? "(differs" : "(same") != std::string::npos);
  const json summary = readJson(out / "summary.json");
  if (!summary["plots"]["gnuplot"].get<std::string>().empty() &&
      summary["plots"]["gnuplot"].get<std::string>().rfind("not found", 0) != 0)
    CHECK(fs::exists(out / "plots" / "sudden_load.png"));
  fs::remove_all(out);
}

TEST_CASE("load history: its stable pieces are the branches of branches.csv, in equilibrium and stable",
          "[scene][plot]") {
  const fs::path out = runShipped("hysteresis", "hysteresis_branches");
  REQUIRE(fs::exists(out / "branches.csv"));
  const Csv csv = readBranchesCsv(out / "branches.csv");
  const json summary = readJson(out / "summary.json");
  const json& branches = summary["cases"][0]["branches"];
  REQUIRE(branches.size() >= 4);  // up to the fold, back down to the other fold, up again
  std::map<int, int> pointsOf;
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
  const double scale = 1.0 * 1.0 * 1.0;  // k b²: the torques' unit
  double worstGradient = 0.0, worstEigen = std::numeric_limits<double>::infinity(), stiffest = 0.0;
  for (const auto& row : csv.rows) {
    ++pointsOf[int(row[csv.col("branch")])];
    Eigen::VectorXd q(3), g(3);
    for (int i = 0; i < 3; ++i) q[i] = row[csv.col("q" + std::to_string(i + 1))];
    const Wrench F(row[csv.col("Fx")], row[csv.col("Fy")], row[csv.col("Me")]);
    CHECK(F[0] == 0.0);
    CHECK(F[1] == 0.0);
    CHECK(F[2] == Approx(row[csv.col("parameter")]).margin(1e-15));
    totalPotentialGradient(chain, q, F, g);
    worstGradient = std::max(worstGradient, g.cwiseAbs().maxCoeff());
    // stable: the Hessian of Π (free end: all of it) has no negative eigenvalue; at the pieces'
    // last points (the folds) the smallest is zero to the location accuracy
    Eigen::MatrixXd H(3, 3);
    totalPotentialHessian(chain, q, F, H);
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues()[0];
    worstEigen = std::min(worstEigen, smallest);
    stiffest = std::max(stiffest, H.norm());
    CHECK(row[csv.col("stable")] == 1.0);
    // min_eig is the point's own (free end: H's smallest), at the folds too
    CHECK(row[csv.col("min_eig")] == Approx(smallest).margin(1e-9 * scale));
  }
  CHECK(worstGradient < 1e-8 * scale);
  CHECK(worstEigen > -1e-9 * stiffest);
  for (const json& b : branches) {
    CHECK(b["origin"].get<std::string>().rfind("load history", 0) == 0);
    CHECK(pointsOf[int(b["id"])] == int(b["points"]));
    CHECK(pointsOf[int(b["id"])] >= 2);
  }
  CHECK(pointsOf.size() == branches.size());
  // each jump lands where the next piece starts; the history ends at the last waypoint
  const json sp = readJson(out / "special_points.json");
  int jumps = 0;
  for (const json& p : sp["special_points"]) {
    if (p["type"] != "JUMP") continue;
    ++jumps;
    bool startsPiece = false;
    for (const auto& row : csv.rows) {
      if (row[csv.col("point")] != 0.0) continue;
      double d = 0.0;
      for (int i = 0; i < 3; ++i)
        d = std::max(d, std::abs(row[csv.col("q" + std::to_string(i + 1))] - double(p["jump_to"]["q"][size_t(i)])));
      startsPiece = startsPiece || d < 1e-9;
    }
    CHECK(startsPiece);
  }
  CHECK(jumps == 3);
  CHECK(csv.rows.back()[csv.col("parameter")] == Approx(0.3).margin(1e-12));
  fs::remove_all(out);
}

namespace {

/// Segments of the long chain whose plots are checked (default.json otherwise).
constexpr int kLongChain = 50;

/// data/scenes/default.json with `segments` segments and every bifurcation plot's `labels` set
/// (empty: left to its default), the shapes at `at` (empty: as shipped), the path ending at Fx =
/// `to` (NaN: as shipped), run into a fresh directory NAME.
fs::path runDefault(int segments, const std::string& labels, const std::string& name,
                    const std::vector<double>& at = {}, double to = std::nan("")) {
  json scene = readJson(scenePath("default.json"));
  scene["chain"]["segments"] = segments;
  if (!std::isnan(to)) scene["path"]["to"] = to;
  for (json& p : scene["plots"]) {
    if (!labels.empty() && p["type"] == "bifurcation") p["labels"] = labels;
    if (!at.empty() && p["type"] == "shapes") p["at"] = at;
  }
  const fs::path dir = plotDir(name);
  fs::create_directories(dir);
  std::ofstream(dir / "scene.json") << scene.dump(1);
  const Run r = runPlotScene(dir / "scene.json", dir / "out");
  INFO(r.err);
  REQUIRE(r.rc == 0);
  return dir / "out";
}

/// A branch point at (Fx, q2), the shape of the branch leaving it ("U", "mode 12").
struct BranchPoint {
  double fx, q2;
  std::string shape;
};

/// Special points of special_points.json per type, and the branch points of the primary branches
/// (no parent).
struct Specials {
  std::map<std::string, size_t> count;
  std::vector<BranchPoint> primaryBranchPoints;
  size_t total = 0;
};

Specials specials(const fs::path& out) {
  Specials s;
  std::set<int> primary;
  // the documents kept in variables: a range-for over a member of a temporary would dangle
  const json summary = readJson(out / "summary.json"), points = readJson(out / "special_points.json");
  for (const json& b : summary["cases"][0]["branches"])
    if (int(b["parent"]) < 0) primary.insert(int(b["id"]));
  REQUIRE(!primary.empty());
  for (const json& p : points["special_points"]) {
    ++s.count[p["type"]];
    ++s.total;
    if (p["type"] == "BP" && primary.count(int(p["branch"])))
      s.primaryBranchPoints.push_back({double(p["loads"]["Fx"]), double(p["q"][1]), p["shape"]});
  }
  return s;
}

/// What the summary of plot STEM (y = q2 against x = Fx) shows, checked against the run's
/// special points: every branch point of the primary branch labelled at its place, at most
/// `extra` other labels, one key entry per type giving its count, the unlabelled markers of one
/// block no closer than 4 px (a thinned block drawn only where its omitted points lie within
/// 4 px of a drawn one). Returns the number of labels.
size_t checkSummary(const fs::path& out, const std::string& stem, size_t extra) {
  const fs::path plots = out / "plots";
  const Specials sp = specials(out);
  const std::string body = readText(plots / (stem + "_body.gp"));
  CHECK(body.find("set key title \"labelled: ") != std::string::npos);
  const std::vector<Label> labels = labelsApart(plots, stem);
  const PixelFrame f(plots, stem);
  // every branch point of the primary branch is named by a label at its point, within the 12 px
  // under which a summary merges neighbours: "BP U", or by its mode in "BP 3, 4", "BP 24-27"
  for (const BranchPoint& bp : sp.primaryBranchPoints) {
    const auto [bx, by] = f.px(bp.fx, bp.q2);
    bool labelled = false;
    for (const Label& l : labels) {
      const auto [lx, ly] = f.px(l.x, l.y);
      if (std::hypot(lx - bx, ly - by) > 12.0 || l.text.rfind("BP ", 0) != 0) continue;
      if (bp.shape.rfind("mode ", 0) != 0) {
        labelled = labelled || l.text.find("BP " + bp.shape) != std::string::npos;
        continue;
      }
      const int mode = std::stoi(bp.shape.substr(5));
      // "BP a, b-c, d, LP": numbers and ranges up to the first other text
      std::istringstream in(l.text.substr(3));
      std::string item;
      while (std::getline(in, item, ',')) {
        if (item[0] == ' ') item.erase(0, 1);
        if (item.empty() || !std::isdigit(static_cast<unsigned char>(item[0]))) break;
        const size_t dash = item.find('-');
        const int lo = std::stoi(item), hi = dash == std::string::npos ? lo : std::stoi(item.substr(dash + 1));
        labelled = labelled || (lo <= mode && mode <= hi);
      }
    }
    INFO("branch point at Fx = " << bp.fx << ", " << bp.shape);
    CHECK(labelled);
  }
  CHECK(labels.size() <= sp.primaryBranchPoints.size() + extra);
  // the key: every type once, with the count of special_points.json
  std::map<std::string, size_t> keyed;
  for (const std::string& c : plotClauses(body)) {
    if (c.rfind("keyentry with points", 0) != 0) continue;
    const std::string title = field(c, "title");
    const size_t open = title.rfind(" ("), close = title.rfind(')');
    REQUIRE(open != std::string::npos);
    REQUIRE(close == title.size() - 1);
    keyed[title.substr(0, title.find(' '))] += std::stoul(title.substr(open + 2, close - open - 2));
  }
  CHECK(keyed == sp.count);
  // unlabelled markers: blocks "TYPE unlabelled, D of N drawn"; drawn ones at least 4 px apart
  size_t drawnSmall = 0, omitted = 0, labelledMarkers = 0;
  for (const Block& b : readBlocks(plots / (stem + "_special.dat"))) {
    REQUIRE(!b.comments.empty());
    const size_t at = b.comments[0].find(" unlabelled, ");
    if (at == std::string::npos) {
      labelledMarkers += b.rows.size();
      continue;
    }
    const size_t shown = std::stoul(b.comments[0].substr(at + 13)),
                 of = std::stoul(b.comments[0].substr(b.comments[0].find(" of ", at) + 4));
    CHECK(b.rows.size() == shown);
    CHECK(shown <= of);
    drawnSmall += shown;
    omitted += of - shown;
    for (size_t i = 0; i < b.rows.size(); ++i)
      for (size_t j = 0; j < i; ++j) {
        const auto [xi, yi] = f.px(b.rows[i][0], b.rows[i][1]);
        const auto [xj, yj] = f.px(b.rows[j][0], b.rows[j][1]);
        CHECK(std::hypot(xi - xj, yi - yj) >= 4.0 - 1e-6);
      }
  }
  // every special point is a marker: labelled, drawn small, or within 4 px of one drawn small
  INFO("unlabelled markers drawn " << drawnSmall << ", within 4 px of one drawn " << omitted);
  CHECK(labelledMarkers + drawnSmall + omitted == sp.total);
  CHECK(labelledMarkers >= labels.size());
  return labels.size();
}

}  // namespace

TEST_CASE("n = 3: labels auto labels every special point, as labels all does", "[scene][plot]") {
  const fs::path autoOut = runDefault(3, "", "auto3"), allOut = runDefault(3, "all", "all3");
  for (const std::string& stem : {std::string("bifurcation_q2"), std::string("force_deflection")}) {
    INFO(stem);
    // the same labels, placed the same, and the same script as with every label asked for
    CHECK(readText(autoOut / "plots" / (stem + "_labels.dat")) == readText(allOut / "plots" / (stem + "_labels.dat")));
    CHECK(readText(autoOut / "plots" / (stem + "_body.gp")) == readText(allOut / "plots" / (stem + "_body.gp")));
    CHECK(readText(autoOut / "plots" / (stem + "_body.gp")).find("set key title") == std::string::npos);
  }
  // every special point (Fx, q2) has a label naming its type within 3 px (the distance under which
  // one case's labels merge, "BP, JUMP")
  const std::vector<Label> labels = labelsApart(autoOut / "plots", "bifurcation_q2");
  const PixelFrame f(autoOut / "plots", "bifurcation_q2");
  size_t points = 0;
  const json specialPoints = readJson(autoOut / "special_points.json");
  for (const json& p : specialPoints["special_points"]) {
    const std::string type = p["type"];
    const auto [px, py] = f.px(double(p["loads"]["Fx"]), double(p["q"][1]));
    bool labelled = false;
    for (const Label& l : labels) {
      const auto [lx, ly] = f.px(l.x, l.y);
      const std::string text = ", " + l.text + ",";
      labelled = labelled || (std::hypot(lx - px, ly - py) <= 3.0 &&
                              (text.find(", " + type + ",") != std::string::npos ||
                               text.find(", " + type + " ") != std::string::npos));
    }
    INFO(type << " at Fx = " << p["loads"]["Fx"]);
    CHECK(labelled);
    ++points;
  }
  CHECK(points >= 6);  // U and Z, the folds, the contacts
  fs::remove_all(autoOut.parent_path());
  fs::remove_all(allOut.parent_path());
}

TEST_CASE("n = 3 with labels summary: the primary branch's branch points labelled, counts in the key",
          "[scene][plot]") {
  const fs::path out = runDefault(3, "summary", "summary3");
  const size_t labels = checkSummary(out, "bifurcation_q2", 24);
  // U and Z on the straight branch, the fold with its jump, the first fold of the U branch
  CHECK(labels >= 3);
  fs::remove_all(out.parent_path());
}

TEST_CASE("a long chain's bifurcation diagram is a summary: bounded labels, every type counted", "[scene][plot]") {
  // shapes on the stable part of the first buckled branch (the levels shipped for n = 3 lie beyond
  // the stable range of a 50-segment chain, whose first critical load is -0.0030); the path to
  // Fx = -1.5 (49 branch points, 399 special points: 2.2 s in Release; the whole path to -2.5
  // takes 6 s, and more than the default 120 s time limit under the sanitizers)
  const fs::path out = runDefault(kLongChain, "", "long", {-0.0031, -0.0034}, -1.5);
  const Specials sp = specials(out);
  REQUIRE(sp.total > 60);  // above the automatic summary's threshold
  const size_t labels = checkSummary(out, "bifurcation_q2", 24);
  CHECK(labels < sp.total / 4);
  CHECK(sp.primaryBranchPoints.size() >= 10);
  // many branches: thinner, translucent lines (#AARRGGBB), the stable ones solid
  const std::string body = readText(out / "plots" / "bifurcation_q2_body.gp");
  for (const std::string& c : plotClauses(body)) {
    if (c.rfind("\"bifurcation_q2.dat\"", 0) != 0) continue;
    CHECK(field(c, "rgb").size() == 9);
    CHECK(std::stod(c.substr(c.find(" lw ") + 4)) < 2.0);
  }
  // shapes: the centre line alone (base, joints, end: n + 2 points) to scale, no joint dots
  const std::string shapes = readText(out / "plots" / "shapes_body.gp");
  CHECK(shapes.find("set size ratio -1") != std::string::npos);
  CHECK(shapes.find("_jnt.dat") == std::string::npos);
  CHECK(shapes.find("_spr.dat") == std::string::npos);
  const std::vector<Block> line = readBlocks(out / "plots" / "shapes_0_0_tri.dat");
  REQUIRE(line.size() == 1);
  CHECK(line[0].rows.size() == size_t(kLongChain + 2));
  CHECK(line[0].rows.front()[0] == 0.0);
  CHECK(line[0].rows.front()[1] == 0.0);
  fs::remove_all(out.parent_path());
}

TEST_CASE("a branch point on the straight branch is marked at the value interpolated in the path parameter",
          "[scene][plot]") {
  // C_yy exists only at traced points: the marker of a branch point takes the value between the two
  // traced points around it. On the straight branch every q is 0, so the interpolation is in Fx
  // (by the shape it would put every marker at the branch's first point).
  const fs::path dir = plotDir("straight_marker"), out = dir / "out";
  std::ofstream(dir.string() + ".json") << R"({
    "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
    "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
    "path": {"parameter": "Fx", "from": 0.0, "to": -2.5},
    "analyses": {"continuation": {"branch_switching": 0, "contact": false}, "stiffness": true},
    "plots": [{"type": "stiffness", "name": "cyy", "x": "Fx", "y": ["Cyy"]}]
  })";
  const Run r = runPlotScene(dir.string() + ".json", out);
  INFO(r.err);
  REQUIRE(r.rc == 0);
  const Csv csv = readBranchesCsv(out / "branches.csv");
  int marked = 0;
  for (const Block& b : readBlocks(out / "plots" / "cyy_special.dat")) {
    if (b.comments.empty() || b.comments[0].find(": BP") == std::string::npos) continue;
    for (const std::vector<double>& row : b.rows) {
      double below = -1e300, above = 1e300, cBelow = 0.0, cAbove = 0.0;
      for (const auto& p : csv.rows) {
        if (int(p[csv.col("branch")]) != 0) continue;
        const double fx = p[csv.col("Fx")];
        if (fx <= row[0] && fx > below) below = fx, cBelow = p[csv.col("Cyy")];
        if (fx >= row[0] && fx < above) above = fx, cAbove = p[csv.col("Cyy")];
      }
      REQUIRE(above > below);
      const double expected = cBelow + (row[0] - below) / (above - below) * (cAbove - cBelow);
      CHECK(row[1] == Approx(expected).epsilon(1e-6));  // Fx and C_yy through 10-digit files
      ++marked;
    }
  }
  CHECK(marked == 2);  // the U and Z points of eq 17
}

TEST_CASE("a stiffness plot whose curves change sign over decades has a symmetric-log axis with tics inside it",
          "[scene][plot]") {
  // si_chain's Kxx and Kyy run from +20 N/m through poles to −100 N/m past the branch points
  const fs::path out = runShipped("si_chain", "si_chain_symlog");
  std::ifstream in(out / "plots" / "stiffness_body.gp");
  REQUIRE(in.good());
  std::string line, nonlinear, range, tics;
  while (std::getline(in, line)) {
    if (line.rfind("set nonlinear y via asinh(y/", 0) == 0) nonlinear = line;
    if (line.rfind("set yrange [", 0) == 0) range = line;
    if (line.rfind("set ytics (", 0) == 0) tics = line;
  }
  REQUIRE(!nonlinear.empty());
  REQUIRE(!range.empty());
  const double lo = std::stod(range.substr(12)), hi = std::stod(range.substr(range.find(':') + 1));
  CHECK(lo < 0.0);
  CHECK(hi > 0.0);
  // the range is that of the drawn Kxx, Kyy (framed): every tic value given lies in it
  int count = 0;
  for (size_t at = tics.find("\" "); at != std::string::npos; at = tics.find("\" ", at + 2)) {
    const double t = std::stod(tics.substr(at + 2));
    CHECK(t >= lo);
    CHECK(t <= hi);
    ++count;
  }
  CHECK(count >= 5);  // 0 and decades of both signs
}
