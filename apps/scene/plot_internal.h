// What the plot files share (plot.cpp: the driver; plot_branches.cpp, plot_curves.cpp,
// plot_shapes.cpp: the plot types): colours, number formats, gnuplot data blocks and scripts, and
// the placement of labels on a frame whose pixel geometry is fixed before gnuplot draws it.
#pragma once

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

namespace buckle::scene::plot_detail {

namespace fs = std::filesystem;


inline const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
inline std::string color(size_t i) { return kColors[i % (sizeof kColors / sizeof kColors[0])]; }

inline std::string num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

/// Four significant digits, for titles.
inline std::string short4(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

/// Five significant digits, for titles.
inline std::string short5(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.5g", v);
  return buf;
}

/// gnuplot string literal of any text, a scene's included (escape.h).
inline std::string quote(const std::string& s) { return escape::gnuplotString(s); }

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

inline std::vector<size_t> selected(const PlotSpec& spec) {
  std::vector<size_t> out;
  for (int c : spec.cases) out.push_back(static_cast<size_t>(c));
  return out;
}

struct Script {
  std::string name;
  int width = 1000, height = 700;
  std::ostringstream body;
};

inline std::string parameterColumnLabel(const Scene& scene, const std::string& column) {
  if (column == "parameter") return columnLabel(scene.cases.front().path.parameter, scene.units);
  return columnLabel(column, scene.units);
}

inline void header(Script& s, const std::string& title) {
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
inline size_t glyphs(const std::string& s) {
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
inline const std::vector<double> kLabelRings = {2.0, 18.0, 36.0, 58.0, 84.0, 116.0, 156.0};
/// Summary mode: farther rings as well, so that every label of a crowded stretch (the branch
/// points of a long chain's primary branch) finds a place, on a longer leader.
inline const std::vector<double> kSummaryLabelRings = {2.0,   18.0,  36.0,  58.0,  84.0,  116.0, 156.0,
                                                200.0, 250.0, 310.0, 380.0, 460.0, 560.0};

/// Places every label near its point without overlapping another label, a marker or (where it
/// can) a curve, inside the plot area: candidate positions on rings of growing radius around
/// the point, the cheapest taken, greedily by priority, then from left to right. A label put away from its point
/// gets a leader line. A label that finds no place free of other labels inside the plot area is
/// left out (its marker and the key still show the point): on a diagram with thousands of special
/// points (long chains) overlapping text would hide the curves.
inline void placeLabels(std::vector<PlacedLabel>& labels, const Frame& f, const Occupancy& curves,
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


// ---- the plot types -----------------------------------------------------------------------------

void branchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void torquePlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void energyPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void suddenPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
/// `equilibrium_shapes` (plot_shapes.cpp): every equilibrium of the `equilibria` analysis, one
/// panel each in ascending potential, stable ones marked.
void equilibriumShapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s);
void shapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, size_t plotIndex, const fs::path& dir,
                Script& s, std::vector<std::string>& notes);

}  // namespace buckle::scene::plot_detail
