// Label placement on crowded diagrams (apps/scene/label_layout.h): the boxes placed are checked
// here against each other and the frame, independently of the placement's own bookkeeping.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "scene/label_layout.h"

using namespace buckle::scene::plot_detail;

namespace {

/// The frame of a bifurcation diagram: Fx from -2.5 to 0.1, q2 from -3 to 3, on 1000 x 700 pixels.
Frame diagramFrame() {
  Frame f;
  f.xlo = -2.5, f.xhi = 0.1, f.ylo = -3.0, f.yhi = 3.0;
  return f;
}

Box plotArea(const Frame& f) { return {f.width * f.left, f.height * f.bottom, f.width * f.right, f.height * f.top}; }

/// Checks the placed labels: each shown box inside the plot area, of the width its text needs,
/// centred where it says, no two shown boxes overlapping; returns how many are shown.
size_t checkPlaced(const std::vector<PlacedLabel>& labels, const Frame& f) {
  const Box area = plotArea(f);
  size_t shown = 0;
  for (size_t i = 0; i < labels.size(); ++i) {
    const PlacedLabel& a = labels[i];
    if (!a.shown) continue;
    ++shown;
    INFO("label " << i << " '" << a.text << "' at " << a.box.x0 << " " << a.box.y0 << " " << a.box.x1 << " " << a.box.y1);
    CHECK(a.box.x0 >= area.x0);
    CHECK(a.box.x1 <= area.x1);
    CHECK(a.box.y0 >= area.y0);
    CHECK(a.box.y1 <= area.y1);
    CHECK(a.box.x1 - a.box.x0 == Approx(kLabelCharWidth * double(glyphs(a.text)) + 4.0));
    CHECK(a.box.y1 - a.box.y0 == Approx(kLabelHeight));
    CHECK(0.5 * (a.box.x0 + a.box.x1) == Approx(a.centre.x()));
    if (a.leader) {  // the leader ends on the box's edge nearest to the point
      CHECK(a.leaderEnd.x() >= a.box.x0 - 1e-9);
      CHECK(a.leaderEnd.x() <= a.box.x1 + 1e-9);
      CHECK(a.leaderEnd.y() >= a.box.y0 - 1e-9);
      CHECK(a.leaderEnd.y() <= a.box.y1 + 1e-9);
    }
    for (size_t j = i + 1; j < labels.size(); ++j)
      if (labels[j].shown) CHECK_FALSE(a.box.overlaps(labels[j].box));
  }
  return shown;
}

std::vector<PlacedLabel> labelsAt(const Frame& f, const std::vector<Eigen::Vector2d>& points, const std::string& stem) {
  std::vector<PlacedLabel> labels;
  for (size_t k = 0; k < points.size(); ++k) {
    PlacedLabel l;
    l.anchor = f.pixel(points[k].x(), points[k].y());
    l.text = stem + " " + std::to_string(k + 1);
    labels.push_back(l);
  }
  return labels;
}

}  // namespace

TEST_CASE("label layout: 30 special points near Fx = 0 get 30 labels apart, inside the frame", "[plot]") {
  const Frame f = diagramFrame();
  // the branch points of a long chain's primary branch: Fx from -0.003 to -0.09, all at q2 = 0,
  // a few pixels apart, along a curve (the straight branch) on the x axis
  std::vector<Eigen::Vector2d> points;
  for (int k = 1; k <= 30; ++k) points.emplace_back(-0.003 * k, 0.0);
  Occupancy curves(f.width, f.height);
  curves.segment(f.pixel(-2.5, 0.0), f.pixel(0.0, 0.0));
  curves.finish();
  std::vector<PlacedLabel> labels = labelsAt(f, points, "BP");
  placeLabels(labels, f, curves, kSummaryLabelRings);
  CHECK(checkPlaced(labels, f) == 30);
  // the labels leave the curve they sit on (a label may cover it only where a free place is far):
  // most of them are off the line, and each covers at most a label's width of it
  size_t onCurve = 0;
  for (const PlacedLabel& l : labels) {
    onCurve += curves.count(l.box) > 0;
    CHECK(curves.count(l.box) <= l.box.x1 - l.box.x0 + 1);
  }
  CHECK(onCurve <= 3);
}

TEST_CASE("label layout: 100 points at one place at the frame's corner leave nothing overlapping", "[plot]") {
  const Frame f = diagramFrame();
  // all at Fx = 0.09, q2 = 2.95: the top-right corner, where half the directions leave the frame
  std::vector<Eigen::Vector2d> points(100, Eigen::Vector2d(0.09, 2.95));
  Occupancy curves(f.width, f.height);
  curves.finish();
  for (const std::vector<double>* rings : {&kLabelRings, &kSummaryLabelRings}) {
    std::vector<PlacedLabel> labels = labelsAt(f, points, "LP");
    placeLabels(labels, f, curves, *rings);
    const size_t shown = checkPlaced(labels, f);
    // the rings reach out 156 / 560 pixels, half of them outside the frame: some labels fit, not all
    CHECK(shown >= 10);
    CHECK(shown < 100);
  }
}

TEST_CASE("label layout: sparse points keep their labels at the point, no leader", "[plot]") {
  const Frame f = diagramFrame();
  std::vector<Eigen::Vector2d> points = {{-0.7063, 0.0}, {-1.3937, 0.0}, {-1.7554, 2.159}, {-1.7554, -2.159}};
  Occupancy curves(f.width, f.height);
  curves.finish();
  std::vector<PlacedLabel> labels = labelsAt(f, points, "BP");
  placeLabels(labels, f, curves);
  CHECK(checkPlaced(labels, f) == 4);
  for (const PlacedLabel& l : labels) {
    CHECK_FALSE(l.leader);
    // beside its marker, not on it
    const Box marker{l.anchor.x() - kMarkerHalf, l.anchor.y() - kMarkerHalf, l.anchor.x() + kMarkerHalf,
                     l.anchor.y() + kMarkerHalf};
    CHECK_FALSE(l.box.overlaps(marker));
  }
}

TEST_CASE("jump path: a short jump is drawn as a hop at least the minimum long, a long one straight", "[plot]") {
  Occupancy curves(200, 200);
  curves.finish();
  const Eigen::Vector2d a(100, 100), b(100, 105.5);  // the default scene's fold: 5.5 pixels
  const std::vector<Eigen::Vector2d> hop = jumpPath(a, b, 36.0, curves);
  REQUIRE(hop.size() == 13);
  CHECK((hop.front() - a).norm() == Approx(0.0).margin(1e-12));
  CHECK((hop.back() - b).norm() == Approx(0.0).margin(1e-12));
  double length = 0.0;
  for (size_t k = 0; k + 1 < hop.size(); ++k) length += (hop[k + 1] - hop[k]).norm();
  CHECK(length >= 36.0 - 1e-9);
  CHECK(length <= 1.5 * 36.0);
  const std::vector<Eigen::Vector2d> straight = jumpPath(a, Eigen::Vector2d(160, 100), 36.0, curves);
  CHECK(straight.size() == 2);

  // the hop bulges to the free side: a curve just right of the chord pushes it left
  Occupancy busy(200, 200);
  for (int x = 101; x < 130; ++x) busy.segment({double(x), 80.0}, {double(x), 125.0});
  busy.finish();
  for (const Eigen::Vector2d& p : jumpPath(a, b, 36.0, busy)) CHECK(p.x() <= 100.0 + 1e-9);
}

TEST_CASE("marker radius: markers of two types a few pixels apart both shrink, apart they stay full", "[plot]") {
  const Eigen::Vector2d lp(100, 100), ct(104, 103);  // 5 pixels apart
  CHECK(markerRadius(lp, {ct}, 5.6, 2.5) == Approx(2.5));
  CHECK(markerRadius(lp, {Eigen::Vector2d(100, 130)}, 5.6, 2.5) == Approx(5.6));
  CHECK(markerRadius(lp, {Eigen::Vector2d(100, 108)}, 5.6, 2.5) == Approx(4.0));
  CHECK(markerRadius(lp, {lp}, 5.6, 2.5) == Approx(2.5));  // at one place: the least size, both drawn
}
