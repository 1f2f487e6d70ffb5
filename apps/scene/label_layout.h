// Labels placed apart on a plot whose pixel geometry is fixed before it is drawn: the special
// points of the gnuplot diagrams (plot_branches.cpp); report.html's script follows the same rules
// (apps/scene/report/report.js). Candidate positions on rings around each point, the cheapest free one.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <ostream>
#include <string>
#include <vector>


namespace buckle::scene::plot_detail {

// A 2-D plot whose ranges and margins the script fixes, so that the pixel position of every
// data point is known before gnuplot draws it: labels can then be placed apart (below).
struct Frame {
  int width = 1000, height = 700;
  double left = 0.09, right = 0.76, bottom = 0.1, top = 0.91;  ///< plot area, screen fractions
  double xlo = 0, xhi = 1, ylo = 0, yhi = 1;  ///< with logY or symlog, ylo and yhi are transformed
  bool logY = false;
  /// > 0: a symmetric-log y axis v = asinh(y / symlog), linear within ±symlog and logarithmic
  /// beyond, for values of both signs over decades (a stiffness through a pole).
  double symlog = 0.0;
  double transformY(double y) const { return symlog > 0.0 ? std::asinh(y / symlog) : logY ? std::log10(y) : y; }
  double inverseY(double v) const { return symlog > 0.0 ? symlog * std::sinh(v) : logY ? std::pow(10.0, v) : v; }
  Eigen::Vector2d pixel(double x, double y) const {
    const double v = transformY(y);
    return {width * (left + (right - left) * (x - xlo) / (xhi - xlo)),
            height * (bottom + (top - bottom) * (v - ylo) / (yhi - ylo))};
  }
  Eigen::Vector2d data(const Eigen::Vector2d& px) const {
    const double v = ylo + (px.y() / height - bottom) / (top - bottom) * (yhi - ylo);
    return {xlo + (px.x() / width - left) / (right - left) * (xhi - xlo), inverseY(v)};
  }
  /// The gnuplot commands that fix this frame's margins and ranges (plot.cpp).
  void script(std::ostream& os) const;
};

/// Characters of a UTF-8 string (the width of a label in the font's average advance).
inline size_t glyphs(const std::string& s) {
  return size_t(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// Label metrics of the ',9' font of the pngcairo plots: "BP mode 12" is 72 px wide (7.2 px a
// character, digits and lower case), line height 11 px; a margin on top.
constexpr double kLabelCharWidth = 7.3, kLabelHeight = 13.0, kMarkerHalf = 7.0;

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
extern const std::vector<double> kLabelRings;
/// Summary mode: farther rings as well, so that every label of a crowded stretch (the branch
/// points of a long chain's primary branch) finds a place, on a longer leader.
extern const std::vector<double> kSummaryLabelRings;

/// Places every label near its point without overlapping another label, a marker or (where it
/// can) a curve, inside the plot area: candidate positions on rings of growing radius around
/// the point, the cheapest taken, greedily by priority, then from left to right. A label put away from its point
/// gets a leader line. A label that finds no place free of other labels inside the plot area is
/// left out (its marker and the key still show the point): on a diagram with thousands of special
/// points (long chains) overlapping text would hide the curves.
void placeLabels(std::vector<PlacedLabel>& labels, const Frame& f, const Occupancy& curves,
                 const std::vector<double>& rings = kLabelRings);

/// The drawn path of a jump from `a` to `b` (pixels): the straight segment when it is at least
/// `minPixels` long; else a hop, a quadratic arc from a to b about `minPixels` long, bulging to
/// the side with fewer curve pixels, so that a jump of a few pixels is still seen to leave and
/// land (report.html's script draws the same, apps/scene/report/report.js). 13 points along a hop.
std::vector<Eigen::Vector2d> jumpPath(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double minPixels,
                                      const Occupancy& curves);

/// The radius of a full-size marker at `self` among markers of other types at `others` (pixels):
/// `full`, or half the distance to the nearest of them but at least `least`, so that markers of
/// two types at almost one place (a fold beside the contact it runs into) do not hide each other.
double markerRadius(const Eigen::Vector2d& self, const std::vector<Eigen::Vector2d>& others, double full, double least);

}  // namespace buckle::scene::plot_detail
