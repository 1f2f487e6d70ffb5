#include "scene/label_layout.h"

#include <limits>

namespace buckle::scene::plot_detail {

const std::vector<double> kLabelRings = {2.0, 18.0, 36.0, 58.0, 84.0, 116.0, 156.0};
const std::vector<double> kSummaryLabelRings = {2.0,   18.0,  36.0,  58.0,  84.0,  116.0, 156.0,
                                                200.0, 250.0, 310.0, 380.0, 460.0, 560.0};

void placeLabels(std::vector<PlacedLabel>& labels, const Frame& f, const Occupancy& curves,
                 const std::vector<double>& rings) {
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

std::vector<Eigen::Vector2d> jumpPath(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double minPixels,
                                      const Occupancy& curves) {
  const Eigen::Vector2d d = b - a;
  const double len = d.norm();
  if (len >= minPixels) return {a, b};
  const Eigen::Vector2d n = len > 1e-9 ? Eigen::Vector2d(-d.y() / len, d.x() / len) : Eigen::Vector2d(0.0, 1.0);
  const double bulge = 0.5 * std::sqrt(std::max(0.0, minPixels * minPixels - len * len));  // the apex off the chord
  const Eigen::Vector2d mid = 0.5 * (a + b);
  auto crowded = [&](double side) {
    const Eigen::Vector2d p = mid + side * bulge * n;
    return curves.count({p.x() - 6.0, p.y() - 6.0, p.x() + 6.0, p.y() + 6.0});
  };
  const double side = crowded(-1.0) < crowded(1.0) ? -1.0 : 1.0;
  const Eigen::Vector2d c = mid + 2.0 * side * bulge * n;  // the control point: the apex is half-way to it
  std::vector<Eigen::Vector2d> out;
  for (int k = 0; k <= 12; ++k) {
    const double t = k / 12.0;
    out.push_back((1 - t) * (1 - t) * a + 2 * t * (1 - t) * c + t * t * b);
  }
  return out;
}

double markerRadius(const Eigen::Vector2d& self, const std::vector<Eigen::Vector2d>& others, double full, double least) {
  double r = full;
  for (const Eigen::Vector2d& o : others) r = std::min(r, std::max(least, 0.5 * (o - self).norm()));
  return r;
}

}  // namespace buckle::scene::plot_detail
