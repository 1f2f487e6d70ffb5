// gnuplot plots of a run: one data file + one script per plot, rendered to PNG (pngcairo) and
// SVG. Scripts and data stay in <out>/plots so that a figure can be restyled by hand.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <tuple>
#include <unistd.h>
#include <vector>

#include "buckle/mechanics/contact_geometry.h"

#include "scene/child_process.h"
#include "scene/escape.h"
#include "scene/output.h"
#include "scene/plot_range.h"
#include "scene/signals.h"

namespace buckle::scene {

namespace fs = std::filesystem;

namespace {

const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
std::string color(size_t i) { return kColors[i % (sizeof kColors / sizeof kColors[0])]; }

std::string num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

/// Four significant digits, for titles.
std::string short4(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// Five significant digits, for titles.
std::string short5(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.5g", v);
  return buf;
}

/// gnuplot string literal of any text, a scene's included (escape.h).
std::string quote(const std::string& s) { return escape::gnuplotString(s); }

/// Data file with numbered blocks (gnuplot `index`), each made of polylines separated by one
/// blank line.
class BlockFile {
 public:
  int begin() {
    if (blocks_ > 0) os_ << "\n\n";
    // a block that stays empty would merge with the next one and shift every later `index`:
    // each block starts with an undefined point
    os_ << "# block " << blocks_ << "\nNaN NaN\n\n";
    lineOpen_ = false;
    return blocks_++;
  }
  void point(std::initializer_list<double> values) {
    bool first = true;
    for (double v : values) {
      os_ << (first ? "" : " ") << num(v);
      first = false;
    }
    os_ << "\n";
    lineOpen_ = true;
  }
  void text(const std::string& line) { os_ << line << "\n"; }
  void breakLine() {
    if (lineOpen_) os_ << "\n";
    lineOpen_ = false;
  }
  void write(const fs::path& file) const { std::ofstream(file) << os_.str() << "\n"; }
  int blocks() const { return blocks_; }

 private:
  std::ostringstream os_;
  int blocks_ = 0;
  bool lineOpen_ = false;
};

std::vector<size_t> selected(const PlotSpec& spec) {
  std::vector<size_t> out;
  for (int c : spec.cases) out.push_back(static_cast<size_t>(c));
  return out;
}

struct Script {
  std::string name;
  int width = 1000, height = 700;
  std::ostringstream body;
};

std::string parameterColumnLabel(const Scene& scene, const std::string& column) {
  if (column == "parameter") return columnLabel(scene.cases.front().path.parameter, scene.units);
  return columnLabel(column, scene.units);
}

void header(Script& s, const std::string& title) {
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key outside right top box opaque samplen 3 font ',9'\n";
  if (!title.empty()) s.body << "set title " << quote(title) << " noenhanced\n";
}

// ---- label placement ----------------------------------------------------------------------------

// A 2-D plot whose ranges and margins the script fixes, so that the pixel position of every
// data point is known before gnuplot draws it: labels can then be placed apart (below).
struct Frame {
  int width = 1000, height = 700;
  double left = 0.09, right = 0.76, bottom = 0.1, top = 0.91;  ///< plot area, screen fractions
  double xlo = 0, xhi = 1, ylo = 0, yhi = 1;  ///< with logY, ylo and yhi are decimal logarithms
  bool logY = false;
  Eigen::Vector2d pixel(double x, double y) const {
    const double v = logY ? std::log10(y) : y;
    return {width * (left + (right - left) * (x - xlo) / (xhi - xlo)),
            height * (bottom + (top - bottom) * (v - ylo) / (yhi - ylo))};
  }
  Eigen::Vector2d data(const Eigen::Vector2d& px) const {
    const double v = ylo + (px.y() / height - bottom) / (top - bottom) * (yhi - ylo);
    return {xlo + (px.x() / width - left) / (right - left) * (xhi - xlo), logY ? std::pow(10.0, v) : v};
  }
  void script(std::ostream& os) const {
    os << "set lmargin at screen " << num(left) << "\nset rmargin at screen " << num(right) << "\nset bmargin at screen "
       << num(bottom) << "\nset tmargin at screen " << num(top) << "\nset xrange [" << num(xlo) << ":" << num(xhi)
       << "]\n";
    if (logY)
      os << "set logscale y\nset format y '10^{%L}'\nset yrange [" << num(std::pow(10.0, ylo)) << ":"
         << num(std::pow(10.0, yhi)) << "]\n";
    else
      os << "set yrange [" << num(ylo) << ":" << num(yhi) << "]\n";
  }
};

/// Characters of a UTF-8 string (the width of a label in the font's average advance).
size_t glyphs(const std::string& s) {
  return size_t(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// Label metrics of the ',9' font of the plots (DejaVu Sans 9 pt at the terminals' 72 dpi):
// measured advance about 6.1 px per character, line height 11 px; a margin on top.
constexpr double kLabelCharWidth = 6.5, kLabelHeight = 13.0, kMarkerHalf = 7.0;

struct Box {
  double x0, y0, x1, y1;
  bool overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

/// Pixels covered by the plotted curves, with a summed-area table so that the number of curve
/// pixels under a candidate label box is one lookup.
class Occupancy {
 public:
  Occupancy(int w, int h) : w_(w), h_(h), grid_(size_t(w) * size_t(h), 0) {}
  void segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    if (!a.allFinite() || !b.allFinite()) return;
    // in doubles until a pixel is known to be on the canvas (a far-off point must not overflow)
    const int steps = int(std::min(4000.0, std::ceil((b - a).norm()) + 1.0));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (double(k) / steps);
      if (!(p.x() >= 0.0 && p.y() >= 0.0 && p.x() < w_ && p.y() < h_)) continue;
      grid_[size_t(p.y()) * size_t(w_) + size_t(p.x())] = 1;
    }
  }
  /// Marks a rectangle (an unlabelled marker) as covered.
  void fill(const Box& b) {
    const int x0 = int(std::clamp(b.x0, 0.0, double(w_))), x1 = int(std::clamp(b.x1, 0.0, double(w_)));
    const int y0 = int(std::clamp(b.y0, 0.0, double(h_))), y1 = int(std::clamp(b.y1, 0.0, double(h_)));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) grid_[size_t(y) * size_t(w_) + size_t(x)] = 1;
  }
  void finish() {
    sum_.assign(size_t(w_ + 1) * size_t(h_ + 1), 0);
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x)
        at(x + 1, y + 1) = grid_[size_t(y) * size_t(w_) + size_t(x)] + at(x, y + 1) + at(x + 1, y) - at(x, y);
  }
  int count(const Box& b) const {
    const int x0 = int(std::clamp(b.x0, 0.0, double(w_))), x1 = int(std::clamp(b.x1, 0.0, double(w_)));
    const int y0 = int(std::clamp(b.y0, 0.0, double(h_))), y1 = int(std::clamp(b.y1, 0.0, double(h_)));
    return cat(x1, y1) - cat(x0, y1) - cat(x1, y0) + cat(x0, y0);
  }

 private:
  int& at(int x, int y) { return sum_[size_t(y) * size_t(w_ + 1) + size_t(x)]; }
  int cat(int x, int y) const { return sum_[size_t(y) * size_t(w_ + 1) + size_t(x)]; }
  int w_, h_;
  std::vector<unsigned char> grid_;
  std::vector<int> sum_;
};

struct PlacedLabel {
  Eigen::Vector2d anchor;          ///< the marked point (pixels)
  std::string text;
  Eigen::Vector2d centre;          ///< label centre (pixels)
  Box box{0, 0, 0, 0};
  bool leader = false;             ///< drawn away from its point: a leader line joins them
  Eigen::Vector2d leaderEnd;       ///< where the leader meets the label box
  bool shown = true;               ///< false: no free place within reach, only the marker is drawn
  int priority = 0;                ///< placed in increasing priority, then from left to right
};

/// Distances (pixels, beyond the marker) of the rings of candidate label positions.
const std::vector<double> kLabelRings = {2.0, 18.0, 36.0, 58.0, 84.0, 116.0, 156.0};
/// Summary mode: farther rings as well, so that every label of a crowded stretch (the branch
/// points of a long chain's primary branch) finds a place, on a longer leader.
const std::vector<double> kSummaryLabelRings = {2.0,   18.0,  36.0,  58.0,  84.0,  116.0, 156.0,
                                                200.0, 250.0, 310.0, 380.0, 460.0, 560.0};

/// Places every label near its point without overlapping another label, a marker or (where it
/// can) a curve, inside the plot area: candidate positions on rings of growing radius around
/// the point, the cheapest taken, greedily by priority, then from left to right. A label put away from its point
/// gets a leader line. A label that finds no place free of other labels inside the plot area is
/// left out (its marker and the key still show the point): on a diagram with thousands of special
/// points (long chains) overlapping text would hide the curves.
void placeLabels(std::vector<PlacedLabel>& labels, const Frame& f, const Occupancy& curves,
                 const std::vector<double>& rings = kLabelRings) {
  const Box area{f.width * f.left, f.height * f.bottom, f.width * f.right, f.height * f.top};
  std::vector<Box> markers;
  for (const PlacedLabel& l : labels)
    markers.push_back({l.anchor.x() - kMarkerHalf, l.anchor.y() - kMarkerHalf, l.anchor.x() + kMarkerHalf,
                       l.anchor.y() + kMarkerHalf});
  std::vector<size_t> order(labels.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::pair(labels[a].priority, labels[a].anchor.x()) < std::pair(labels[b].priority, labels[b].anchor.x());
  });
  std::vector<Box> placed;
  const double pi = std::acos(-1.0);
  for (size_t i : order) {
    PlacedLabel& l = labels[i];
    const double w = kLabelCharWidth * double(glyphs(l.text)) + 4.0, h = kLabelHeight;
    double bestCost = std::numeric_limits<double>::infinity();
    int rank = 0;
    for (double r : rings) {
      for (int k = 0; k < 16; ++k, ++rank) {
        // preferred directions first: the four diagonals, then the axes, then the rest
        static const int kOrder[16] = {2, 6, 14, 10, 0, 8, 4, 12, 1, 3, 5, 7, 9, 11, 13, 15};
        const double a = kOrder[k] * pi / 8.0;
        const Eigen::Vector2d c = l.anchor + Eigen::Vector2d(std::cos(a) * (kMarkerHalf + r + w / 2),
                                                             std::sin(a) * (kMarkerHalf + r + h / 2));
        const Box b{c.x() - w / 2, c.y() - h / 2, c.x() + w / 2, c.y() + h / 2};
        double cost = r + 0.5 * rank / 16.0;
        if (b.x0 < area.x0 || b.x1 > area.x1 || b.y0 < area.y0 || b.y1 > area.y1) cost += 1e7;
        for (const Box& o : placed)
          if (b.overlaps(o)) cost += 1e6;
        for (const Box& m : markers)
          if (b.overlaps(m)) cost += 1e5;
        cost += 3.0 * curves.count(b);
        if (cost < bestCost) {
          bestCost = cost;
          l.centre = c;
          l.box = b;
          l.leader = r > 2.0;
        }
      }
    }
    if (bestCost >= 1e6) {
      l.shown = false;
      continue;
    }
    placed.push_back(l.box);
    // the leader ends on the box's edge nearest to the point
    l.leaderEnd = {std::clamp(l.anchor.x(), l.box.x0, l.box.x1), std::clamp(l.anchor.y(), l.box.y0, l.box.y1)};
  }
}

// ---- bifurcation / stiffness (columns of branches.csv) ----------------------------------------

/// Column value at a special point; the columns that exist only at traced points (stiffness,
/// smallest eigenvalue) are interpolated along the special point's branch between the two
/// neighbouring points it lies between (exact where it is a traced point: a joint limit), unless
/// the special point carries its own stiffness (KMIN, located between traced points).
double specialValue(const std::string& column, const SpecialRecord& r, const CaseResult& cr) {
  const double v = columnValue(column, r, cr.pose0);
  if (std::isfinite(v) || r.q.size() == 0) return v;
  double best = std::numeric_limits<double>::infinity(), value = v;
  for (size_t i = 0; i + 1 < cr.points.size(); ++i) {
    const PointRecord &a = cr.points[i], &b = cr.points[i + 1];
    if (a.branch != r.branch || b.branch != r.branch || a.q.size() != r.q.size() || b.q.size() != r.q.size()) continue;
    const Eigen::VectorXd d = b.q - a.q;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((r.q - a.q).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (r.q - a.q - t * d).norm();
    // off the chord by more than half the spacing: not between these two points
    if (dist > 0.5 * std::sqrt(len2) && dist > 0.0) continue;
    if (dist < best) {
      best = dist;
      value = (1 - t) * columnValue(column, a, cr.pose0) + t * columnValue(column, b, cr.pose0);
    }
  }
  return value;
}

struct SpecialStyle {
  const char* type;
  int point;       ///< gnuplot point type, filled; point - 1 is the open outline
  const char* key;
  const char* color;  ///< summary mode: the type's colour (markers of all cases)
};
const SpecialStyle kSpecialStyles[] = {{"BP", 7, "BP branch point", "#000000"},
                                       {"LP", 9, "LP fold", "#d62728"},
                                       {"LPF", 9, "LPF reaction fold", "#ff7f0e"},
                                       {"BD", 5, "BD joint limit", "#8c564b"},
                                       {"KMIN", 13, "KMIN Kxx minimum", "#9467bd"},
                                       {"JUMP", 11, "JUMP release", "#ff7f0e"},
                                       {"CT", 15, "CT contact (joint locks)", "#2ca02c"},
                                       {"RL", 3, "RL contact released", "#17becf"},
                                       {"BC", 5, "BC base contact (detected)", "#e377c2"},
                                       {"SC", 5, "SC self contact (detected)", "#7f7f7f"}};

const SpecialStyle& specialStyle(const std::string& type) {
  for (const SpecialStyle& s : kSpecialStyles)
    if (type == s.type) return s;
  static const SpecialStyle other{"", 7, "special point", "#555555"};
  return other;
}

// ---- summary mode (long chains, large trees) -----------------------------------------------------

// A bifurcation diagram of a 50-segment chain carries thousands of special points (2479 in the
// default scene at n = 50: 882 LP, 764 CT, 352 RL, …). Like AUTO's and BifurcationKit's plots of
// large diagrams, the summary labels only the points a reader steers by and draws the others as
// small markers by type, counted in the key.

/// `labels: auto` draws the summary above this many markers (the shipped 3-segment scenes have
/// at most a few dozen, all labelled).
constexpr size_t kSummaryAboveMarkers = 60;
/// Summary labels beyond the branch points of the primary branch (which are all labelled): the
/// jumps, then the first fold of each branch in the order the branches were traced.
constexpr size_t kSummaryExtraLabels = 24;
/// Summary: unlabelled markers of one case and type closer than this many pixels are drawn once.
constexpr double kThinPixels = 4.0;
/// Labels of one case's points closer than this many pixels are merged into one ("BP, JUMP"); a
/// summary merges wider, the branch points of a long chain's primary branch into ranges
/// ("BP 24-27": modes 24 to 27).
constexpr double kMergePixels = 3.0, kSummaryMergePixels = 12.0;

/// One label for the merged points' texts; a summary writes the branch points' modes as ranges
/// ("BP 3, 4", "BP 24-27"), the other texts after them.
std::string mergedLabel(const std::vector<std::string>& parts, bool summary) {
  std::vector<int> modes;
  std::vector<std::string> rest;
  for (const std::string& p : parts) {
    const bool mode = summary && p.size() > 3 && p.rfind("BP ", 0) == 0 &&
                      p.find_first_not_of("0123456789", 3) == std::string::npos;
    if (mode)
      modes.push_back(std::stoi(p.substr(3)));
    else
      rest.push_back(p);
  }
  std::string text;
  std::sort(modes.begin(), modes.end());
  for (size_t i = 0; i < modes.size();) {
    size_t j = i;
    while (j + 1 < modes.size() && modes[j + 1] == modes[j] + 1) ++j;
    text += (i ? ", " : "BP ") + std::to_string(modes[i]);
    if (j == i + 1) text += ", " + std::to_string(modes[j]);
    if (j > i + 1) text += "-" + std::to_string(modes[j]);
    i = j + 1;
  }
  for (const std::string& p : rest) text += (text.empty() ? "" : ", ") + p;
  return text;
}

/// How much a special point matters in a summary, most first.
enum class Importance { PrimaryBranchPoint, Jump, FirstFold, Other };

/// Per special record of a case (same order as `cr.specials`): the branch points of the primary
/// branches (those with no parent: the start), the jumps (a load history's JUMP, a fold with a
/// simulated jump), the first fold (LP, LPF) of each branch in the order the tracer reported
/// them, the rest.
std::vector<Importance> importance(const CaseResult& cr) {
  std::vector<int> primary;
  for (const BranchRecord& b : cr.branches)
    if (b.parent < 0) primary.push_back(b.id);
  std::vector<int> folded;
  std::vector<Importance> out;
  for (const SpecialRecord& r : cr.specials) {
    Importance k = Importance::Other;
    if (r.type == "BP" && std::find(primary.begin(), primary.end(), r.branch) != primary.end())
      k = Importance::PrimaryBranchPoint;
    else if (r.type == "JUMP" || r.jumpSuccess)
      k = Importance::Jump;
    else if ((r.type == "LP" || r.type == "LPF") && std::find(folded.begin(), folded.end(), r.branch) == folded.end()) {
      folded.push_back(r.branch);
      k = Importance::FirstFold;
    }
    out.push_back(k);
  }
  return out;
}

/// Indices of the points kept when points closer than `radius` are drawn once: greedy in the
/// given order over a hash grid of cell `radius` (O(points log points)).
std::vector<size_t> thinned(const std::vector<Eigen::Vector2d>& px, double radius) {
  std::vector<size_t> kept;
  std::map<std::pair<long, long>, std::vector<size_t>> grid;  // cell -> kept points in it
  for (size_t i = 0; i < px.size(); ++i) {
    if (!px[i].allFinite()) continue;
    const long cx = long(std::floor(px[i].x() / radius)), cy = long(std::floor(px[i].y() / radius));
    bool near = false;
    for (long dx = -1; dx <= 1 && !near; ++dx)
      for (long dy = -1; dy <= 1 && !near; ++dy) {
        const auto it = grid.find({cx + dx, cy + dy});
        if (it == grid.end()) continue;
        for (size_t k : it->second) near = near || (px[k] - px[i]).norm() < radius;
      }
    if (near) continue;
    grid[{cx, cy}].push_back(i);
    kept.push_back(i);
  }
  return kept;
}

/// Line width and transparency of the branches (gnuplot's `#AARRGGBB`, AA = 0 opaque) such that
/// hundreds of overlapping branches stay apart: full width up to a dozen branches, then thinner
/// and translucent, unstable parts fainter than stable ones.
struct BranchLook {
  double width = 2.0;
  int alphaStable = 0, alphaUnstable = 0;
};
BranchLook branchLook(size_t branches) {
  BranchLook look;
  if (branches <= 12) return look;
  look.width = std::max(0.8, 2.0 * std::sqrt(12.0 / double(branches)));
  look.alphaStable = int(std::min<size_t>(0x50, 0x10 + branches / 4));
  look.alphaUnstable = std::min(0xA0, look.alphaStable + 0x50);
  return look;
}

std::string withAlpha(const std::string& rgb, int alpha) {
  if (alpha <= 0 || rgb.size() != 7 || rgb[0] != '#') return rgb;
  char buf[8];
  std::snprintf(buf, sizeof buf, "%02X", alpha & 0xFF);
  return "#" + std::string(buf) + rgb.substr(1);
}

void branchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  BlockFile data;
  struct Series {
    int block;
    size_t ordinal, yIdx;  ///< position of the case in the plot's list, column
    bool stable;
    bool any = false;      ///< has a drawable point
  };
  const std::vector<size_t> cases = selected(spec);
  const bool multiCase = cases.size() > 1;
  const size_t ny = spec.y.size();
  auto seriesColor = [&](size_t ordinal, size_t j) { return color(multiCase ? ordinal * ny + j : j); };
  std::vector<Series> series;
  std::vector<std::vector<Eigen::Vector2d>> polylines;  // in data coordinates, for the label placement
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  std::vector<double> ys;  // a stiffness plot's values, framed without the run-up to its poles
  auto extend = [&](double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    xlo = std::min(xlo, x), xhi = std::max(xhi, x), ylo = std::min(ylo, y), yhi = std::max(yhi, y);
    if (spec.type == PlotType::Stiffness) ys.push_back(y);
  };
  for (size_t o = 0; o < cases.size(); ++o) {
    const CaseResult& cr = run.cases[cases[o]];
    for (size_t j = 0; j < ny; ++j) {
      for (bool stable : {true, false}) {
        Series se{data.begin(), o, j, stable};
        // polylines of consecutive points with the wanted stability; a run keeps the first point
        // of the next run so that stable and unstable parts join
        polylines.emplace_back();
        auto add = [&](double x, double y) {
          data.point({x, y});
          polylines.back().emplace_back(x, y);
          extend(x, y);
          se.any = true;
        };
        for (size_t i = 0; i < cr.points.size(); ++i) {
          const PointRecord& p = cr.points[i];
          const bool sameBranchNext = i + 1 < cr.points.size() && cr.points[i + 1].branch == p.branch;
          const double x = columnValue(spec.x, p, cr.pose0), y = columnValue(spec.y[j], p, cr.pose0);
          if (p.stable == stable && std::isfinite(x) && std::isfinite(y)) {
            add(x, y);
            if (sameBranchNext && cr.points[i + 1].stable != stable) {
              const PointRecord& q = cr.points[i + 1];
              add(columnValue(spec.x, q, cr.pose0), columnValue(spec.y[j], q, cr.pose0));
            }
          }
          if (p.stable != stable || !sameBranchNext || !std::isfinite(x) || !std::isfinite(y)) {
            data.breakLine();
            polylines.emplace_back();
          }
        }
        series.push_back(se);
      }
    }
  }
  // special points: one block per case and type; points of one case at the same place share a
  // label ("BP, JUMP")
  struct Mark {
    size_t ordinal;
    std::string type;
    double x, y;
    std::string label;
    Importance rank;
  };
  std::vector<Mark> marks;
  std::map<std::string, size_t> records;  // special points per type over the plot's cases (the key's counts)
  size_t branches = 0;                    // branches drawn, over the plot's cases
  size_t markers = 0;  // one per special point and column
  for (size_t c : cases) markers += run.cases[c].specials.size() * ny;
  const bool summary =
      spec.labels == PlotLabels::Summary || (spec.labels == PlotLabels::Auto && markers > kSummaryAboveMarkers);
  for (size_t o = 0; o < cases.size(); ++o) {
    const CaseResult& cr = run.cases[cases[o]];
    const std::vector<Importance> rank = importance(cr);
    for (size_t i = 0; i < cr.specials.size(); ++i) {
      const SpecialRecord& r = cr.specials[i];
      ++records[r.type];
      for (size_t j = 0; j < ny; ++j) {
        const double x = specialValue(spec.x, r, cr), y = specialValue(spec.y[j], r, cr);
        if (!std::isfinite(x) || !std::isfinite(y)) continue;
        std::string label = r.type;
        // a summary's branch points of long chains: "BP 12" for mode 12 (the key says so)
        if (r.type == "BP" && !r.shape.empty() && r.shape != "other")
          label += " " + (summary && r.shape.rfind("mode ", 0) == 0 ? r.shape.substr(5) : r.shape);
        marks.push_back({o, r.type, x, y, label, rank[i]});
        extend(x, y);
      }
    }
    std::vector<int> ids;
    for (const PointRecord& p : cr.points)
      if (ids.empty() || ids.back() != p.branch) ids.push_back(p.branch);
    std::sort(ids.begin(), ids.end());
    branches += size_t(std::unique(ids.begin(), ids.end()) - ids.begin());
  }
  const BranchLook look = branchLook(branches);
  // the marks labelled: all of them, or in a summary the primary branch's branch points and then,
  // up to a budget, the jumps and first folds (in the order the branches were traced)
  std::vector<bool> labelled(marks.size(), !summary);
  if (summary) {
    std::vector<size_t> order;
    for (size_t i = 0; i < marks.size(); ++i)
      if (marks[i].rank != Importance::Other) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return marks[a].rank < marks[b].rank; });
    size_t extra = 0;
    for (size_t i : order)
      if (marks[i].rank == Importance::PrimaryBranchPoint || extra++ < kSummaryExtraLabels) labelled[i] = true;
  }
  // jumps: arrows from the fold to the landing point
  BlockFile jumps;
  jumps.begin();
  bool anyJump = false;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> arrows;
  for (size_t c : cases) {
    const CaseResult& cr = run.cases[c];
    for (const SpecialRecord& r : cr.specials) {
      if (!r.jumpSuccess || r.jumpQ.size() == 0) continue;
      SpecialRecord to = r;
      to.q = r.jumpQ;
      to.F = r.jumpF;
      to.pose = r.jumpPose;
      for (size_t j = 0; j < ny; ++j) {
        const double x0 = columnValue(spec.x, r, cr.pose0), y0 = columnValue(spec.y[j], r, cr.pose0);
        const double x1 = columnValue(spec.x, to, cr.pose0), y1 = columnValue(spec.y[j], to, cr.pose0);
        if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) continue;
        jumps.point({x0, y0, x1 - x0, y1 - y0});
        arrows.push_back({{x0, y0}, {x1, y1}});
        extend(x0, y0);
        extend(x1, y1);
        anyJump = true;
      }
    }
  }

  // the frame: ranges from the data, margins fixed, the key in the right margin
  Frame f;
  f.width = s.width;
  f.height = s.height;
  std::vector<std::string> typesPresent;  // in the order of kSpecialStyles
  for (const SpecialStyle& st : kSpecialStyles)
    for (const Mark& m : marks)
      if (m.type == st.type) {
        typesPresent.push_back(st.type);
        break;
      }
  for (const Mark& m : marks)
    if (std::find(typesPresent.begin(), typesPresent.end(), m.type) == typesPresent.end()) typesPresent.push_back(m.type);
  // the key's width: gnuplot sizes it with the main font's advance (11 pt: about 8.2 px per
  // character) over the longest title plus the sample
  size_t keyChars = summary ? 22 : 8;  // a summary's key title: lines of up to 22 characters
  // a summary's key gives the count of each type: " (2479)"
  for (const std::string& type : typesPresent)
    keyChars = std::max(keyChars, glyphs(specialStyle(type).key) + (summary ? 3 + std::to_string(records[type]).size() : 0));
  if (multiCase || ny > 1)
    for (size_t o = 0; o < cases.size(); ++o)
      for (size_t j = 0; j < ny; ++j)
        keyChars = std::max(keyChars, glyphs(run.cases[cases[o]].label) + (ny > 1 ? 1 + spec.y[j].size() : 0));
  f.right = std::clamp(1.0 - (8.2 * double(keyChars + 6) + 30.0) / f.width, 0.5, 0.8);
  std::tie(f.xlo, f.xhi) = niceRange(xlo, xhi);
  // stiffness spans decades (the straight chain against a buckled one): a log axis in whole decades
  // when every drawn value is positive and they span more than two
  if (spec.type == PlotType::Stiffness && ylo <= 0.0) std::tie(ylo, yhi) = framedRange(ys);
  f.logY = spec.type == PlotType::Stiffness && ylo > 0.0 && std::isfinite(yhi) && yhi > 100.0 * ylo;
  if (f.logY)
    f.ylo = std::floor(std::log10(ylo)), f.yhi = std::ceil(std::log10(yhi));
  else
    std::tie(f.ylo, f.yhi) = niceRange(ylo, yhi);

  Occupancy occupied(f.width, f.height);
  for (const auto& line : polylines)
    for (size_t i = 0; i + 1 < line.size(); ++i)
      occupied.segment(f.pixel(line[i].x(), line[i].y()), f.pixel(line[i + 1].x(), line[i + 1].y()));
  for (const auto& [a, b] : arrows) occupied.segment(f.pixel(a.x(), a.y()), f.pixel(b.x(), b.y()));
  // a summary's unlabelled markers, per case and type, those closer than kThinPixels drawn once;
  // a label may cover them only where it must (like a curve)
  std::vector<bool> drawn(marks.size(), true);
  if (summary) {
    for (size_t o = 0; o < cases.size(); ++o)
      for (const std::string& type : typesPresent) {
        std::vector<size_t> idx;
        std::vector<Eigen::Vector2d> px;
        for (size_t i = 0; i < marks.size(); ++i)
          if (!labelled[i] && marks[i].ordinal == o && marks[i].type == type) {
            idx.push_back(i);
            px.push_back(f.pixel(marks[i].x, marks[i].y));
            drawn[i] = false;
          }
        for (size_t k : thinned(px, kThinPixels)) {
          drawn[idx[k]] = true;
          occupied.fill({px[k].x() - 2.0, px[k].y() - 2.0, px[k].x() + 2.0, px[k].y() + 2.0});
        }
      }
  }
  occupied.finish();

  // merge the labels of one case's points drawn at the same place
  std::vector<PlacedLabel> labels;
  std::vector<size_t> labelOrdinal;
  std::vector<std::vector<std::string>> parts;
  for (size_t i = 0; i < marks.size(); ++i) {
    if (!labelled[i]) continue;
    const Mark& m = marks[i];
    const Eigen::Vector2d px = f.pixel(m.x, m.y);
    size_t k = 0;
    const double merge = summary ? kSummaryMergePixels : kMergePixels;
    while (k < labels.size() && (labelOrdinal[k] != m.ordinal || (labels[k].anchor - px).norm() > merge)) ++k;
    if (k == labels.size()) {
      labels.emplace_back();
      labels.back().anchor = px;
      labels.back().priority = summary ? int(m.rank) : 0;
      labelOrdinal.push_back(m.ordinal);
      parts.emplace_back();
    }
    labels[k].priority = std::min(labels[k].priority, summary ? int(m.rank) : 0);
    if (std::find(parts[k].begin(), parts[k].end(), m.label) == parts[k].end()) parts[k].push_back(m.label);
  }
  for (size_t k = 0; k < labels.size(); ++k) labels[k].text = mergedLabel(parts[k], summary);
  placeLabels(labels, f, occupied, summary ? kSummaryLabelRings : kLabelRings);

  const std::string stem = spec.name;
  data.write(dir / (stem + ".dat"));
  // special points: blocks per (case, type); labels: one block per case with
  //   x y label_x label_y "text" leader_x leader_y   (leader NaN when the label sits at its point)
  BlockFile sp, lab;
  struct SpecialBlock {
    int block;
    size_t ordinal;
    std::string type;
    bool small;  ///< a summary's unlabelled markers
  };
  std::vector<SpecialBlock> specialBlocks;
  for (size_t o = 0; o < cases.size(); ++o)
    for (const std::string& type : typesPresent)
      for (bool small : {false, true}) {
        size_t count = 0, shown = 0;
        for (size_t i = 0; i < marks.size(); ++i)
          if (marks[i].ordinal == o && marks[i].type == type && labelled[i] != small) ++count, shown += drawn[i];
        if (shown == 0) continue;
        const int block = sp.begin();
        std::string comment =
            "# case " + std::to_string(cases[o]) + " (" + escape::commentText(run.cases[cases[o]].label) + "): " + type;
        if (small)
          comment += " unlabelled, " + std::to_string(shown) + " of " + std::to_string(count) +
                     " drawn (the others within " + num(kThinPixels) + " px of one drawn)";
        sp.text(comment);
        for (size_t i = 0; i < marks.size(); ++i)
          if (marks[i].ordinal == o && marks[i].type == type && labelled[i] != small && drawn[i])
            sp.point({marks[i].x, marks[i].y});
        specialBlocks.push_back({block, o, type, small});
      }
  std::vector<int> labelBlocks(cases.size(), -1);
  for (size_t o = 0; o < cases.size(); ++o) {
    bool any = false;
    for (size_t k = 0; k < labels.size(); ++k) any = any || (labelOrdinal[k] == o && labels[k].shown);
    if (!any) continue;
    labelBlocks[o] = lab.begin();
    lab.text("# case " + std::to_string(cases[o]) + ": x y label_x label_y \"label\" leader_x leader_y");
    for (size_t k = 0; k < labels.size(); ++k) {
      if (labelOrdinal[k] != o || !labels[k].shown) continue;
      const PlacedLabel& l = labels[k];
      const Eigen::Vector2d p = f.data(l.anchor), c = f.data(l.centre), e = f.data(l.leaderEnd);
      const double nan = std::numeric_limits<double>::quiet_NaN();
      std::ostringstream line;
      line << num(p.x()) << " " << num(p.y()) << " " << num(c.x()) << " " << num(c.y()) << " " << escape::datField(l.text) << " "
           << num(l.leader ? e.x() : nan) << " " << num(l.leader ? e.y() : nan);
      lab.text(line.str());
    }
  }
  const bool anySpecial = !marks.empty();
  if (anySpecial) {
    sp.write(dir / (stem + "_special.dat"));
    lab.write(dir / (stem + "_labels.dat"));
  }
  if (anyJump) jumps.write(dir / (stem + "_jumps.dat"));

  header(s, spec.title.empty() ? (spec.type == PlotType::Stiffness ? "Loaded stiffness along the branches"
                                                                   : "Bifurcation diagram: stable solid, unstable dashed")
                               : spec.title);
  s.body << "set key samplen 4\n";
  if (summary)
    s.body << "set key title \"labelled: branch points\\nof the primary branch\\n(BP k: mode k), jumps,\\nfirst "
              "fold per branch;\\nkey: count per type\" left\n";
  s.body << "set xlabel " << quote(parameterColumnLabel(scene, spec.x)) << "\n";
  std::string ylabel;
  for (size_t j = 0; j < ny; ++j) ylabel += (j ? ", " : "") + columnLabel(spec.y[j], scene.units);
  if (ny > 1) {
    bool same = true;
    for (const std::string& y : spec.y) same = same && (y[0] == spec.y[0][0]);
    if (same && spec.y[0][0] == 'K') ylabel = "stiffness" + scene.units.suffix(Dimension::Stiffness);
    if (same && spec.y[0][0] == 'q') ylabel = "joint angles (rad)";
  }
  s.body << "set ylabel " << quote(ylabel) << "\n";
  s.body << "# ranges and margins fixed so that the special-point labels (placed by buckle, "
         << stem << "_labels.dat) do not overlap\n";
  f.script(s.body);
  s.body << "plot \\\n";
  bool first = true;
  auto clause = [&](const std::string& c) {
    s.body << (first ? "  " : ", \\\n  ") << c;
    first = false;
  };
  // one key entry per case (and column): its stable curve; stability itself is explained by
  // the two entries that follow
  const bool perSeriesKey = multiCase || ny > 1;
  bool anyStable = false, anyUnstable = false;
  for (const Series& se : series) {
    (se.stable ? anyStable : anyUnstable) = (se.stable ? anyStable : anyUnstable) || se.any;
    std::string title;
    if (perSeriesKey && se.stable) {
      if (multiCase) title = run.cases[cases[se.ordinal]].label;
      if (ny > 1) title += (title.empty() ? "" : " ") + spec.y[se.yIdx];
    }
    clause(quote(stem + ".dat") + " index " + std::to_string(se.block) + " using 1:2 with lines lw " +
           num(look.width) + " lc rgb " +
           quote(withAlpha(seriesColor(se.ordinal, se.yIdx), se.stable ? look.alphaStable : look.alphaUnstable)) +
           " dt " + (se.stable ? "1" : "2") +
           (title.empty() ? std::string(" notitle") : " title " + quote(title) + " noenhanced"));
  }
  const std::string keyColor = perSeriesKey ? std::string("black") : seriesColor(0, 0);
  if (anyStable || !anyUnstable) clause("keyentry with lines lw 2 dt 1 lc rgb " + quote(keyColor) + " title 'stable'");
  if (anyUnstable) clause("keyentry with lines lw 2 dt 2 lc rgb " + quote(keyColor) + " title 'unstable'");
  if (anyJump)
    clause(quote(stem + "_jumps.dat") +
           " using 1:2:3:4 with vectors head filled size screen 0.015,20 lw 1.5 lc rgb '#ff7f0e' title 'jump'");
  if (anySpecial) {
    // leader lines under the markers
    for (size_t o = 0; o < cases.size(); ++o)
      if (labelBlocks[o] >= 0)
        clause(quote(stem + "_labels.dat") + " index " + std::to_string(labelBlocks[o]) +
               " using 1:2:($6-$1):($7-$2) with vectors nohead lw 0.8 lc rgb '#777777' notitle");
    // a summary's small markers first, under the labelled ones
    for (bool small : {true, false})
      for (const SpecialBlock& b : specialBlocks) {
        if (b.small != small) continue;
        const SpecialStyle& st = specialStyle(b.type);
        const std::string at = quote(stem + "_special.dat") + " index " + std::to_string(b.block) + " using 1:2";
        if (small) {
          clause(at + " with points pt " + std::to_string(st.point) + " ps 0.5 lc rgb " + quote(st.color) + " notitle");
          continue;
        }
        const std::string fill = summary ? st.color : multiCase ? color(b.ordinal * ny) : std::string("black");
        clause(at + " with points pt " + std::to_string(st.point) + " ps 1.4 lc rgb " + quote(fill) + " notitle");
        clause(at + " with points pt " + std::to_string(st.point - 1) + " ps 1.4 lw 1 lc rgb 'black' notitle");
      }
    for (const std::string& type : typesPresent) {
      const SpecialStyle& st = specialStyle(type);
      const std::string title = *st.type ? st.key : type;
      if (summary)
        clause("keyentry with points pt " + std::to_string(st.point) + " ps 1.2 lc rgb " + quote(st.color) + " title " +
               quote(title + " (" + std::to_string(records[type]) + ")") + " noenhanced");
      else
        clause("keyentry with points pt " + std::to_string(st.point) + " ps 1.4 lc rgb 'black' title " + quote(title) +
               " noenhanced");
    }
    for (size_t o = 0; o < cases.size(); ++o)
      if (labelBlocks[o] >= 0)
        clause(quote(stem + "_labels.dat") + " index " + std::to_string(labelBlocks[o]) +
               " using 3:4:5 with labels center font ',9' tc rgb " +
               quote(multiCase ? color(o * ny) : std::string("black")) + " noenhanced notitle");
  }
  s.body << "\n";
}

// ---- torque–angle ------------------------------------------------------------------------------

void torquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  BlockFile data, eq;
  const std::string stem = spec.name;
  std::vector<int> blocks;
  for (size_t c : selected(spec)) {
    blocks.push_back(data.begin());
    const TorqueCurve& t = run.cases[c].torque;
    for (size_t i = 0; i < t.q.size(); ++i) data.point({t.q[i], t.M[i]});
  }
  int stableBlock = eq.begin();
  for (size_t c : selected(spec))
    for (const auto& [q, st] : run.cases[c].torque.equilibria)
      if (st) eq.point({q, 0.0});
  int unstableBlock = eq.begin();
  eq.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
  for (size_t c : selected(spec))
    for (const auto& [q, st] : run.cases[c].torque.equilibria)
      if (!st) eq.point({q, 0.0});
  data.write(dir / (stem + ".dat"));
  eq.write(dir / (stem + "_eq.dat"));
  header(s, spec.title.empty() ? "Torque-angle curves M(q) of one segment" : spec.title);
  s.body << "set xlabel 'q (rad)'\nset ylabel " << quote("M(q) = -dE/dq" + scene.units.suffix(Dimension::Moment))
         << "\nset xzeroaxis lt -1\n";
  s.body << "plot \\\n";
  for (size_t c = 0; c < blocks.size(); ++c) {
    std::string title = run.cases[size_t(spec.cases[c])].label;
    s.body << (c ? ", \\\n  " : "  ") << quote(stem + ".dat") << " index " << blocks[c]
           << " using 1:2 with lines lw 2 lc rgb " << quote(color(c)) << " title " << quote(title) << " noenhanced";
  }
  s.body << ", \\\n  " << quote(stem + "_eq.dat") << " index " << stableBlock
         << " using 1:2 with points pt 7 ps 1.4 lc rgb 'red' title 'stable equilibrium'";
  s.body << ", \\\n  " << quote(stem + "_eq.dat") << " index " << unstableBlock
         << " using 1:2 with points pt 6 ps 1.4 lw 2 lc rgb 'black' title 'unstable equilibrium'\n";
  (void)scene;
}

// ---- energy curves -----------------------------------------------------------------------------

void energyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  const bool torque = scene.analyses.energyCurves.torque;
  const size_t nc = spec.cases.size();
  const int cols = nc <= 1 ? 1 : (nc <= 4 ? 2 : 3);
  const int rows = static_cast<int>((nc + size_t(cols) - 1) / size_t(cols));
  s.width = 700 * cols;
  s.height = 520 * rows;
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key below horizontal font ',9' maxcols 3\n";
  s.body << "set multiplot layout " << rows << "," << cols << " title "
         << quote(spec.title.empty() ? std::string("Energy curves E(q_1) with the end held") : spec.title) << "\n";
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    BlockFile data;
    // blocks: 0 positive feasible, 1 positive beyond joint limits, 2 negative feasible,
    // 3 negative beyond limits, 4 Me positive, 5 Me negative, 6 stable eq, 7 unstable eq
    for (int b : {1, -1}) {
      const auto& samples = b > 0 ? cr.landscape.positive : cr.landscape.negative;
      for (auto want : {mechanics::LandscapeStatus::Feasible, mechanics::LandscapeStatus::JointLimit}) {
        data.begin();
        data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
        data.breakLine();
        for (const auto& smp : samples) {
          if (smp.status == want && std::isfinite(smp.energy))
            data.point({smp.q1, smp.energy});
          else
            data.breakLine();
        }
      }
    }
    for (int b : {1, -1}) {
      data.begin();
      data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
      data.breakLine();
      const auto& samples = b > 0 ? cr.landscape.positive : cr.landscape.negative;
      for (const auto& smp : samples) {
        if (smp.status == mechanics::LandscapeStatus::Feasible && std::isfinite(smp.endTorque) &&
            std::abs(smp.endTorque) < 1e3)
          data.point({smp.q1, smp.endTorque});
        else
          data.breakLine();
      }
    }
    for (bool stable : {true, false}) {
      data.begin();
      data.point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
      for (const auto& e : cr.landscape.equilibria)
        if (e.stable == stable) data.point({e.q1, e.energy});
    }
    const std::string file = stem + "_" + std::to_string(c) + ".dat";
    data.write(dir / file);
    std::ostringstream title;
    title << cr.label << "  (x, y) = (" << num(cr.landscape.x) << ", " << num(cr.landscape.y) << ")";
    s.body << "set title " << quote(title.str()) << " noenhanced font ',10'\n";
    s.body << "set xlabel 'q_1 (rad)'\nset ylabel " << quote("E" + scene.units.suffix(Dimension::Moment)) << "\n";
    if (torque) {
      // Me has poles where J is singular (sin q2 = 0, docs/mechanics.md erratum 7): scale the axis on the bulk
      std::vector<double> mags;
      for (const auto* samples : {&cr.landscape.positive, &cr.landscape.negative})
        for (const auto& smp : *samples)
          if (smp.status == mechanics::LandscapeStatus::Feasible && std::isfinite(smp.endTorque))
            mags.push_back(std::abs(smp.endTorque));
      double range = 1.0;
      if (!mags.empty()) {
        std::sort(mags.begin(), mags.end());
        range = std::max(1e-6, 2.0 * mags[size_t(0.8 * double(mags.size() - 1))]);
      }
      s.body << "set y2label " << quote("M_e" + scene.units.suffix(Dimension::Moment)) << "\nset y2tics\nset ytics nomirror\nset y2zeroaxis lt 0\n"
             << "set y2range [" << num(-range) << ":" << num(range) << "]\n";
    }
    s.body << "plot " << quote(file) << " index 0 using 1:2 with lines lw 2 lc rgb 'blue' title 'q_3 > 0', \\\n"
           << "  '' index 1 using 1:2 with lines lw 1 lc rgb 'black' title 'beyond a joint limit', \\\n"
           << "  '' index 2 using 1:2 with lines lw 2 lc rgb '#2ca02c' title 'q_3 < 0', \\\n"
           << "  '' index 3 using 1:2 with lines lw 1 lc rgb 'black' notitle, \\\n";
    if (torque)
      s.body << "  '' index 4 using 1:2 axes x1y2 with lines lw 1 dt 2 lc rgb 'blue' title 'M_e (q_3 > 0)', \\\n"
             << "  '' index 5 using 1:2 axes x1y2 with lines lw 1 dt 2 lc rgb '#2ca02c' title 'M_e (q_3 < 0)', \\\n";
    s.body << "  '' index 6 using 1:2 with points pt 7 ps 1.5 lc rgb 'red' title 'stable equilibrium', \\\n"
           << "  '' index 7 using 1:2 with points pt 7 ps 1.5 lc rgb 'black' title 'unstable equilibrium'\n";
    if (torque) s.body << "unset y2label\nunset y2tics\nset ytics mirror\n";
  }
  s.body << "unset multiplot\n";
}

// ---- chain shapes ------------------------------------------------------------------------------

/// Below this many pixels per segment a chain is drawn as its centre line (base, joints, end):
/// the triangles, springs and joint-limit arcs of a 50-segment chain across a 500-pixel panel
/// (8 px a segment) would fill it with ink and hide the shape.
constexpr double kDetailedSegmentPixels = 14.0;

/// Whether a chain is drawn in detail in a panel of `panel` pixels (width, height) showing the
/// data box `box` to scale (`set size ratio -1`: the scale is the smaller of the two ratios).
bool detailedChain(const mechanics::Chain& chain, const Eigen::AlignedBox2d& box, const Eigen::Vector2d& panel) {
  const Eigen::Vector2d extent = box.sizes();
  const double scale = std::min(0.8 * panel.x() / extent.x(), 0.7 * panel.y() / extent.y());
  return chain.size() == 0 || scale * chain.length() / double(chain.size()) >= kDetailedSegmentPixels;
}

// Outline of one chain at joint angles q: triangles (closed polygons), springs (zigzags),
// joint-limit arcs; appended to the given block files. `touch`: where the chain has gone through
// the clamp's wall or through itself (contact_geometry.h: the deepest vertex / the crossing).
// Not `detailed` (a long chain, kDetailedSegmentPixels): `triangles` gets the centre line alone
// and springs and limits stay empty; joints within 5 % of a limit are still marked.
void drawChain(const mechanics::Chain& chain, const Eigen::VectorXd& q, BlockFile& triangles, BlockFile& springs,
               BlockFile& limits, BlockFile& joints, BlockFile& nearLimit, BlockFile* touch = nullptr,
               bool detailed = true) {
  if (touch) {
    const mechanics::BaseClearance base = mechanics::baseClearance(chain, q);
    if (base.distance <= 0.0) touch->point({base.point.x(), base.point.y()});
    const mechanics::SelfClearance self = mechanics::selfClearance(chain, q);
    if (self.distance <= 0.0) touch->point({self.point.x(), self.point.y()});
  }
  const int n = chain.size();
  const Eigen::Matrix2Xd P = mechanics::jointPositions(chain, q);
  // joint i within 5 % of its range from a limit
  auto nearLimitAt = [&](int i) {
    const double lo = chain.lowerLimits()[i], hi = chain.upperLimits()[i];
    return std::min(hi - q[i], q[i] - lo) / (hi - lo) < 0.05;
  };
  if (!detailed) {
    for (Eigen::Index j = 0; j < P.cols(); ++j) triangles.point({P(0, j), P(1, j)});
    triangles.breakLine();
    for (int i = 0; i < n; ++i) {
      joints.point({P(0, i + 1), P(1, i + 1)});
      if (nearLimitAt(i)) nearLimit.point({P(0, i + 1), P(1, i + 1)});
    }
    return;
  }
  double theta = 0.0;
  auto dir = [](double t) { return Eigen::Vector2d(std::cos(t), std::sin(t)); };
  auto nrm = [](double t) { return Eigen::Vector2d(-std::sin(t), std::cos(t)); };
  for (int i = 0; i < n; ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    const Eigen::Vector2d joint = P.col(i + 1);
    const double before = theta, after = theta + q[i];
    // proximal triangle: apex at the joint, base b1 behind it, half-height a1
    const Eigen::Vector2d A1 = joint - p.b1 * dir(before) + p.a1 * nrm(before);
    const Eigen::Vector2d B1 = joint - p.b1 * dir(before) - p.a1 * nrm(before);
    const Eigen::Vector2d A2 = joint + p.b2 * dir(after) + p.a2 * nrm(after);
    const Eigen::Vector2d B2 = joint + p.b2 * dir(after) - p.a2 * nrm(after);
    for (const auto& tri : {std::array<Eigen::Vector2d, 3>{joint, A1, B1}, std::array<Eigen::Vector2d, 3>{joint, A2, B2}}) {
      for (const auto& v : tri) triangles.point({v.x(), v.y()});
      triangles.point({tri[0].x(), tri[0].y()});
      triangles.breakLine();
    }
    // springs: zigzag between the +n vertices (spring 1) and the −n vertices (spring 2)
    for (const auto& [P, Q] : {std::pair{A1, A2}, std::pair{B1, B2}}) {
      const Eigen::Vector2d d = Q - P;
      const double len = d.norm();
      const Eigen::Vector2d t = len > 0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1, 0);
      const Eigen::Vector2d m(-t.y(), t.x());
      const int zig = 10;
      springs.point({P.x(), P.y()});
      for (int k = 1; k < zig; ++k) {
        const double f = double(k) / zig;
        const double w = (k % 2 ? 1.0 : -1.0) * 0.08 * std::max(p.b1, p.b2);
        const Eigen::Vector2d v = P + f * d + w * m;
        springs.point({v.x(), v.y()});
      }
      springs.point({Q.x(), Q.y()});
      springs.breakLine();
    }
    // joint-limit arc: admissible directions of the distal link, radius 0.6 b
    const double r = 0.6 * std::min(p.b1, p.b2);
    const double lo = chain.lowerLimits()[i], hi = chain.upperLimits()[i];
    for (int k = 0; k <= 40; ++k) {
      const double a = before + lo + (hi - lo) * k / 40.0;
      limits.point({joint.x() + r * std::cos(a), joint.y() + r * std::sin(a)});
    }
    limits.breakLine();
    for (double a : {before + lo, before + hi}) {
      limits.point({joint.x(), joint.y()});
      limits.point({joint.x() + 1.3 * r * std::cos(a), joint.y() + 1.3 * r * std::sin(a)});
      limits.breakLine();
    }
    joints.point({joint.x(), joint.y()});
    if (nearLimitAt(i)) nearLimit.point({joint.x(), joint.y()});
    theta = after;
  }
}

/// The plot command of one chain drawn by drawChain (files BASE_{lim,tri,spr,jnt,near}.dat),
/// the clamped base a hatched wall; `under`: a plot clause drawn first, beneath the chain. Not
/// `detailed`: the centre line, and only the joints near a limit marked (small red rings).
void chainPanel(std::ostream& os, const std::string& base, double L, const std::string& under = std::string(),
                bool touch = false, bool detailed = true) {
  os << "set object 1 rect from " << num(-0.1 * L) << "," << num(-0.3 * L) << " to 0," << num(0.3 * L)
     << " fc rgb '#bbbbbb' fs pattern 4 border lc rgb '#555555'\n";
  const std::string touchClause =
      touch ? ", \\\n  " + quote(base + "_touch.dat") + " using 1:2 with points pt 3 ps 3 lw 2 lc rgb 'magenta'"
            : std::string();
  os << "plot " << (under.empty() ? std::string() : under + ", \\\n  ");
  if (detailed)
    os << quote(base + "_lim.dat") << " using 1:2 with lines lc rgb '#aaaaaa' lw 1, \\\n"
       << "  " << quote(base + "_tri.dat")
       << " using 1:2 with filledcurves closed fc rgb '#c6dbef' fs solid 1.0 border lc rgb '#08306b', \\\n"
       << "  " << quote(base + "_tri.dat") << " using 1:2 with lines lc rgb '#08306b' lw 1.5, \\\n"
       << "  " << quote(base + "_spr.dat") << " using 1:2 with lines lc rgb '#e6550d' lw 1.5, \\\n"
       << "  " << quote(base + "_jnt.dat") << " using 1:2 with points pt 7 ps 0.9 lc rgb 'black', \\\n"
       << "  " << quote(base + "_near.dat") << " using 1:2 with points pt 6 ps 2.5 lw 2 lc rgb 'red'";
  else
    os << quote(base + "_tri.dat") << " using 1:2 with lines lc rgb '#08306b' lw 2, \\\n"
       << "  " << quote(base + "_near.dat") << " using 1:2 with points pt 6 ps 1 lw 1.5 lc rgb 'red'";
  os << touchClause << "\n";
  os << "unset object 1\n";
}

/// "contact: joint 3U 5L" for a panel title; a long chain's many locked joints are counted.
std::string lockedTitle(const std::string& locked) {
  const size_t joints = size_t(std::count(locked.begin(), locked.end(), ' ')) + 1;
  return joints <= 4 ? ",  contact: joint " + locked : ",  contact: " + std::to_string(joints) + " joints locked";
}

void shapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, size_t plotIndex, const fs::path& dir,
                Script& s, std::vector<std::string>& notes) {
  const std::string stem = spec.name;
  const size_t nc = spec.cases.size(), na = spec.at.size();
  // at most five panels a row: more levels wrap onto further rows of the same case
  const size_t cols = std::min<size_t>(na, 5), rowsPerCase = (na + cols - 1) / cols;
  s.width = std::min<int>(3200, int(520 * cols));
  s.height = std::min<int>(2400, int(330 * nc * rowsPerCase) + 60);

  // per case, the point drawn at each requested level (null: not drawn, `missing` says why)
  std::vector<std::vector<const PointRecord*>> chosenOf;
  std::vector<std::vector<std::string>> missingOf;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    const std::string& parameter = scene.cases[c].path.parameter;
    // the traced stable range, and the sampling of the parameter along the branches
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, spacing = 0.0;
    for (size_t i = 0; i < cr.points.size(); ++i) {
      const PointRecord& p = cr.points[i];
      if (p.stable) lo = std::min(lo, p.parameter), hi = std::max(hi, p.parameter);
      if (i > 0 && cr.points[i - 1].branch == p.branch)
        spacing = std::max(spacing, std::abs(p.parameter - cr.points[i - 1].parameter));
    }
    const double slack = 1e-9 * std::max(std::abs(lo), std::abs(hi));
    std::vector<const PointRecord*>& chosen = chosenOf.emplace_back();
    std::vector<std::string>& missing = missingOf.emplace_back(na);
    for (size_t k = 0; k < na; ++k) {
      const double at = spec.at[k];
      // the stable point nearest to the requested level; among equals, the most deflected
      const PointRecord* best = nullptr;
      double bestD = std::numeric_limits<double>::infinity();
      for (const PointRecord& p : cr.points) {
        if (!p.stable) continue;
        const double d = std::abs(p.parameter - at) - 1e-9 * p.q.cwiseAbs().sum();
        if (d < bestD) {
          bestD = d;
          best = &p;
        }
      }
      // a requested level with no stable point traced there is reported, not moved to the
      // nearest point: outside the traced stable range, or in a gap of it wider than the
      // branches' parameter sampling
      std::ostringstream why;
      if (!best)
        why << "no stable point was traced";
      else if (at < lo - slack || at > hi + slack)
        why << "outside the traced stable range [" << num(lo) << ", " << num(hi) << "]";
      else if (std::abs(best->parameter - at) > spacing + slack)
        why << "no stable point traced there (nearest stable " << parameter << " = " << num(best->parameter) << ")";
      if (!why.str().empty()) {
        missing[k] = why.str();
        best = nullptr;
        std::ostringstream note;
        note << "plot \"" << spec.name << "\"" << (nc > 1 ? ", case \"" + cr.label + "\"" : std::string())
             << ": shape requested at " << parameter << " = " << num(at) << " (/plots/" << plotIndex << "/at/" << k
             << ") not drawn: " << missing[k];
        notes.push_back(note.str());
      }
      chosen.push_back(best);
    }
  }

  // one scale for every panel: the bounding box of all traced chains; long chains, drawn as their
  // centre lines, to the box of the chains drawn (the coils of unstable branches far from any
  // level asked for would shrink them to a few pixels)
  auto boxOf = [&](bool drawnOnly) {
    Eigen::AlignedBox2d box;
    box.extend(Eigen::Vector2d(0.0, 0.0));
    for (size_t o = 0; o < nc; ++o) {
      const CaseResult& cr = run.cases[size_t(spec.cases[o])];
      box.extend(Eigen::Vector2d(cr.chain.length(), 0.0));
      for (const PointRecord& p : cr.points) {
        if (drawnOnly && std::find(chosenOf[o].begin(), chosenOf[o].end(), &p) == chosenOf[o].end()) continue;
        const Eigen::Matrix2Xd P = mechanics::jointPositions(cr.chain, p.q);
        for (Eigen::Index j = 1; j < P.cols(); ++j) box.extend(Eigen::Vector2d(P.col(j)));
      }
    }
    return box;
  };
  Eigen::AlignedBox2d box = boxOf(false);
  const Eigen::Vector2d panel(double(s.width) / double(cols), double(s.height - 60) / double(nc * rowsPerCase));
  bool detailed = true;
  for (size_t c : selected(spec)) detailed = detailed && detailedChain(run.cases[c].chain, box, panel);
  if (!detailed) box = boxOf(true);
  s.body << "set encoding utf8\nset size ratio -1\nunset key\nset grid lc rgb '#eeeeee'\n";
  s.body << "set multiplot layout " << nc * rowsPerCase << "," << cols << " title "
         << quote(!spec.title.empty() ? spec.title
                  : detailed ? std::string("Chain shapes to scale" + scene.units.suffix(Dimension::Length) + "; grey arcs: joint limits, "
                                           "red: joint within 5% of a limit, magenta star: through the clamp or itself")
                             : std::string("Chain shapes to scale" + scene.units.suffix(Dimension::Length) + ", centre lines (base, joints, end); red: "
                                           "joint within 5% of a limit, magenta star: through the clamp or itself"))
         << " font ',11'\n";
  // a margin of 1.2 b around the chains (b the mean half-length: a chain is 2 b n long), or 3 % of a
  // long chain's extent
  double bMean = 0.0;
  for (size_t c : selected(spec)) bMean = std::max(bMean, run.cases[c].chain.length() / (2.0 * run.cases[c].chain.size()));
  const double pad = std::max(1.2 * bMean, 0.03 * box.sizes().maxCoeff());
  const double x0 = box.min().x() - pad, x1 = box.max().x() + pad, y0 = box.min().y() - pad, y1 = box.max().y() + pad;
  for (size_t o = 0; o < nc; ++o) {
    const size_t c = size_t(spec.cases[o]);
    const CaseResult& cr = run.cases[c];
    const std::string& parameter = scene.cases[c].path.parameter;
    for (size_t k = 0; k < na; ++k) {
      const PointRecord* p = chosenOf[o][k];
      BlockFile tri, spr, lim, jnt, near, touch;
      for (BlockFile* f : {&tri, &spr, &lim, &jnt, &near, &touch}) {
        f->begin();
        f->point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
        f->breakLine();
      }
      std::ostringstream title;
      if (p) {
        drawChain(cr.chain, p->q, tri, spr, lim, jnt, near, &touch, detailed);
        // five significant digits, in the scene's unit
        const std::string unit = scene.units.unit(columnDimension(parameter));
        title << (nc > 1 ? cr.label + ": " : std::string()) << parameter << " = " << short5(p->parameter)
              << (unit.empty() ? "" : " " + unit);
        // the nearest traced point is drawn; the title says when it differs from the request
        // beyond the title's rounding (relative to the path's range)
        const PathSpec& path = scene.cases[c].path;
        if (std::abs(p->parameter - spec.at[k]) > 1e-5 * std::max(std::abs(path.from), std::abs(path.to)))
          title << " (asked " << num(spec.at[k]) << ")";
        if (p->haveStiffness && std::isfinite(p->K(0, 0)))
          title << ",  K_{xx} = " << short5(p->K(0, 0)) << ", K_{yy} = " << short5(p->K(1, 1))
                << " " << scene.units.unit(Dimension::Stiffness);
        if (!p->locked.empty()) title << lockedTitle(p->locked);  // locked at a limit
      } else {
        title << (nc > 1 ? cr.label + ": " : std::string()) << parameter << " = " << num(spec.at[k]) << ": not drawn";
        s.body << "set label 1 " << quote(missingOf[o][k]) << " at graph 0.5, graph 0.5 center font ',9' noenhanced\n";
      }
      const std::string base = stem + "_" + std::to_string(c) + "_" + std::to_string(k);
      tri.write(dir / (base + "_tri.dat"));
      spr.write(dir / (base + "_spr.dat"));
      lim.write(dir / (base + "_lim.dat"));
      jnt.write(dir / (base + "_jnt.dat"));
      near.write(dir / (base + "_near.dat"));
      touch.write(dir / (base + "_touch.dat"));
      const double L = cr.chain.length();
      s.body << "set title " << quote(title.str()) << " font ',10'\n";
      s.body << "set xrange [" << num(std::min(x0, -0.1 * L)) << ":" << num(x1) << "]\nset yrange [" << num(y0) << ":"
             << num(y1) << "]\n";
      chainPanel(s.body, base, L, std::string(), true, detailed);
      s.body << "unset label 1\n";
    }
    // the last row of a case that wraps is filled up, so that the next case starts a row
    for (size_t k = na; k < cols * rowsPerCase; ++k) s.body << "set multiplot next\n";
  }
  s.body << "unset multiplot\n";
}

// ---- sudden load --------------------------------------------------------------------------------

// Per case: the energies of the dynamic response against time (total potential Π, kinetic T,
// dissipated W_d and their sum, constant up to the integrator's balance error), then the dynamic
// rest shape beside the quasi-static one, to the same scale, over the unloaded start in grey.
void suddenPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  std::vector<size_t> cases;
  for (size_t c : selected(spec))
    if (run.cases[c].haveSudden) cases.push_back(c);
  const size_t rows = std::max<size_t>(1, cases.size());
  s.width = 1560;
  s.height = std::min<int>(2400, int(420 * rows) + 40);
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\n";
  s.body << "set multiplot layout " << rows << ",3 title "
         << quote(spec.title.empty() ? std::string("Sudden load: energies of the response, rest shape beside the "
                                                   "quasi-static one")
                                     : spec.title)
         << " noenhanced font ',11'\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t c : cases) {
    const CaseResult& cr = run.cases[c];
    const SuddenLoadRecord& r = cr.sudden;
    const std::string& parameter = scene.cases[c].path.parameter;
    const std::string base = stem + "_" + std::to_string(c);
    // energies, full precision: Π + T + W_d is checked against the reported balance error
    {
      std::ostringstream os;
      os << "# sudden load, case " << c << " (" << escape::commentText(cr.label) << "): t potential kinetic dissipated sum\n";
      char buf[160];
      for (const mechanics::TrajectorySample& t : r.trajectory) {
        std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g %.17g %.17g\n", t.t, t.potential, t.kinetic, t.dissipated,
                      t.potential + t.kinetic + t.dissipated);
        os << buf;
      }
      std::ofstream(dir / (base + "_energy.dat")) << os.str();
    }
    std::ostringstream title;
    title << (cases.size() > 1 ? cr.label + ": " : std::string()) << parameter << " = " << num(r.value)
          << " at once, " << (r.inertial ? "inertial dynamics" : "gradient flow") << "; balance error "
          << short4(r.energyBalanceError);
    s.body << "set title " << quote(title.str()) << " noenhanced font ',10'\n";
    // the response is fast and the settling slow: time on a log scale (t = 0 is the start, off it)
    double t1 = 0.0, tEnd = 0.0;
    for (const mechanics::TrajectorySample& t : r.trajectory) {
      if (t1 == 0.0 && t.t > 0.0) t1 = t.t;
      tEnd = std::max(tEnd, t.t);
    }
    s.body << "set key center right font ',9' opaque box\nset size noratio\nset autoscale xy\n"
           << "set xlabel 't (model time; log scale)'\nset ylabel " << quote("energy" + scene.units.suffix(Dimension::Moment))
           << "\n";
    if (t1 > 0.0 && tEnd > t1) s.body << "set logscale x\nset xrange [" << num(t1) << ":" << num(tEnd) << "]\nset format x '10^{%L}'\n";
    s.body << "plot " << quote(base + "_energy.dat") << " using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'Π (total potential)', \\\n"
           << "  '' using 1:3 with lines lw 2 lc rgb '#d62728' title 'T (kinetic)', \\\n"
           << "  '' using 1:4 with lines lw 2 lc rgb '#2ca02c' title 'W_d (dissipated)', \\\n"
           << "  '' using 1:5 with lines lw 1.5 dt 2 lc rgb 'black' title 'Π + T + W_d'\n";

    // the two answers, one scale
    Eigen::AlignedBox2d box;
    box.extend(Eigen::Vector2d(0.0, 0.0));
    for (const Eigen::VectorXd* q : {&cr.q0, &r.rest, &r.staticShape}) {
      if (q->size() != cr.chain.size()) continue;
      const Eigen::Matrix2Xd P = mechanics::jointPositions(cr.chain, *q);
      for (Eigen::Index j = 1; j < P.cols(); ++j) box.extend(Eigen::Vector2d(P.col(j)));
    }
    const double pad = 1.2, L = cr.chain.length();
    const bool ok[2] = {r.rest.size() == cr.chain.size(), r.haveStatic && r.staticShape.size() == cr.chain.size()};
    const bool detailed = detailedChain(cr.chain, box, Eigen::Vector2d(s.width / 3.0, 420.0));
    for (int k = 0; k < 2; ++k) {
      const Eigen::VectorXd& q = k == 0 ? r.rest : r.staticShape;
      const std::string b = base + (k == 0 ? "_rest" : "_static");
      BlockFile tri, spr, lim, jnt, near, start, startSpr, startLim, startJnt, startNear;
      for (BlockFile* f : {&tri, &spr, &lim, &jnt, &near, &start}) {
        f->begin();
        f->point({nan, nan});
        f->breakLine();
      }
      if (ok[k]) drawChain(cr.chain, q, tri, spr, lim, jnt, near, nullptr, detailed);
      if (cr.q0.size() == cr.chain.size())
        drawChain(cr.chain, cr.q0, start, startSpr, startLim, startJnt, startNear, nullptr, detailed);
      tri.write(dir / (b + "_tri.dat"));
      spr.write(dir / (b + "_spr.dat"));
      lim.write(dir / (b + "_lim.dat"));
      jnt.write(dir / (b + "_jnt.dat"));
      near.write(dir / (b + "_near.dat"));
      start.write(dir / (b + "_start.dat"));
      std::ostringstream t;
      if (k == 0)
        t << "dynamic rest: " << (ok[0] ? (r.stable ? "stable" : "not stable") : "none")
          << (r.haveStatic ? ", Π = " + short4(r.potentialDynamic) : std::string());
      else if (ok[1])
        t << "quasi-static: Π = " << short4(r.potentialStatic) << (r.differs ? " (differs" : " (same")
          << ", max |Δq| = " << short4(r.maxDifference) << ")";
      else
        t << "quasi-static: not reached";
      s.body << "set title " << quote(t.str()) << " noenhanced font ',10'\n";
      s.body << "unset key\nunset logscale x\nset format x '% h'\nunset xlabel\nunset ylabel\nset size ratio -1\n";
      s.body << "set xrange [" << num(std::min(box.min().x() - pad, -0.1 * L)) << ":" << num(box.max().x() + pad)
             << "]\nset yrange [" << num(box.min().y() - pad) << ":" << num(box.max().y() + pad) << "]\n";
      chainPanel(s.body, b, L, quote(b + "_start.dat") + " using 1:2 with lines lc rgb '#bbbbbb' lw 1 dt 2", false,
                 detailed);
      s.body << "set autoscale xy\n";
    }
  }
  s.body << "unset multiplot\n";
}

bool executable(const std::string& path) { return ::access(path.c_str(), X_OK) == 0; }

}  // namespace

std::string findGnuplot() {
  if (const char* env = std::getenv("BUCKLE_GNUPLOT")) {
    const std::string p(env);
    return (!p.empty() && executable(p)) ? p : std::string();
  }
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/bin:/bin");
  std::string d;
  while (std::getline(ss, d, ':')) {
    if (d.empty()) continue;
    const std::string candidate = d + "/gnuplot";
    if (executable(candidate)) return candidate;
  }
  return std::string();
}

PlotReport drawPlots(const Scene& scene, const RunResult& run, const std::string& outDir,
                     const continuation::Interrupt& stop) {
  PlotReport report;
  if (scene.plots.empty()) {
    report.gnuplot = "no plots requested";
    return report;
  }
  const fs::path dir = fs::path(outDir) / "plots";
  fs::create_directories(dir);
  const std::string gnuplot = findGnuplot();
  report.gnuplotFound = !gnuplot.empty();
  report.gnuplot = gnuplot.empty() ? "gnuplot is not installed (no executable `gnuplot` on PATH; on Debian: apt-get "
                                     "install gnuplot-nox); the plot data and scripts are in plots/"
                                   : gnuplot;
  const auto stopReason = [&stop]() { return stop.requested() ? stop.describe() : stopSignalReason(); };
  for (const PlotSpec& spec : scene.plots) {
    if (report.stopped.empty()) report.stopped = stopReason();
    if (!report.stopped.empty()) {
      report.notDrawn.push_back(spec.name);
      continue;
    }
    Script s;
    s.name = spec.name;
    switch (spec.type) {
      case PlotType::Bifurcation:
      case PlotType::Stiffness: branchPlot(scene, run, spec, dir, s); break;
      case PlotType::TorqueAngle: torquePlot(scene, run, spec, dir, s); break;
      case PlotType::SuddenLoad: suddenPlot(scene, run, spec, dir, s); break;
      case PlotType::EnergyCurves: energyPlot(scene, run, spec, dir, s); break;
      case PlotType::CriticalCurves: criticalCurvesPlotBody(scene, run, spec, dir.string(), s.body); break;
      case PlotType::Shapes:
        shapesPlot(scene, run, spec, size_t(&spec - scene.plots.data()), dir, s, report.notes);
        break;
    }
    std::ofstream(dir / (spec.name + "_body.gp")) << s.body.str();
    std::ostringstream gp;
    gp << "# gnuplot " << spec.name << ".gp (run from this directory)\n"
       << "set terminal pngcairo size " << s.width << "," << s.height << " enhanced font 'DejaVu Sans,11'\n"
       << "set output " << quote(spec.name + ".png") << "\nload " << quote(spec.name + "_body.gp") << "\n"
       << "set output\nreset\n"
       << "set terminal svg size " << s.width << "," << s.height << " enhanced font 'DejaVu Sans,11' background 'white'\n"
       << "set output " << quote(spec.name + ".svg") << "\nload " << quote(spec.name + "_body.gp") << "\nset output\n";
    std::ofstream(dir / (spec.name + ".gp")) << gp.str();
    if (gnuplot.empty()) continue;
    const ChildOutcome drawn = runChild(gnuplot, {spec.name + ".gp"}, dir.string(), spec.name + ".log", stopReason);
    if (!drawn.stopped.empty()) {  // no half-drawn image: the script and data stay
      report.stopped = drawn.stopped;
      report.notDrawn.push_back(spec.name);
      std::error_code ec;
      for (const char* image : {".png", ".svg"}) fs::remove(dir / (spec.name + image), ec);
      continue;
    }
    const bool ok = drawn.exitedZero && fs::exists(dir / (spec.name + ".png")) && fs::exists(dir / (spec.name + ".svg"));
    if (ok) {
      report.files.push_back("plots/" + spec.name + ".png");
      report.files.push_back("plots/" + spec.name + ".svg");
      std::error_code ec;
      if (fs::file_size(dir / (spec.name + ".log"), ec) == 0) fs::remove(dir / (spec.name + ".log"), ec);
    } else {
      report.failures.push_back(spec.name + " (see plots/" + spec.name + ".log)");
    }
  }
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) report.written.push_back("plots/" + e.path().filename().string());
  std::sort(report.written.begin(), report.written.end());
  return report;
}

}  // namespace buckle::scene
