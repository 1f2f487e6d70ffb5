#include "buckle/mechanics/wall_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace buckle::mechanics {

namespace {

using Point = Eigen::Vector2d;

Point dir(double t) { return Point(std::cos(t), std::sin(t)); }

}  // namespace

Point segmentVertex(const SegmentParameters& p, const Point& joint, double before, double after, int corner) {
  return segmentVertex(p, joint, dir(before), dir(after), corner);
}

Point segmentVertex(const SegmentParameters& p, const Point& joint, const Point& before, const Point& after,
                    int corner) {
  // the link's normal is its direction turned by +90°
  switch (corner) {
    case 0: return joint;
    case 1: return joint - p.b1 * before + p.a1 * Point(-before.y(), before.x());
    case 2: return joint - p.b1 * before - p.a1 * Point(-before.y(), before.x());
    case 3: return joint + p.b2 * after + p.a2 * Point(-after.y(), after.x());
    default: return joint + p.b2 * after - p.a2 * Point(-after.y(), after.x());
  }
}

std::string WallVertex::label() const {
  static const char* const names[] = {"j", "p+", "p-", "d+", "d-"};
  return std::to_string(segment + 1) + names[std::clamp(corner, 0, 4)];
}

void checkWallVertex(const WallVertex& v, int segments) {
  if (v.segment < 0 || v.segment >= segments || v.corner < 0 || v.corner > 4 || (v.segment == 0 && v.corner < 3))
    throw std::invalid_argument("wall contact: vertex (segment " + std::to_string(v.segment + 1) + ", corner " +
                                std::to_string(v.corner) + ") is not a moving vertex of the chain of " +
                                std::to_string(segments) +
                                " segments (segments 1.." + std::to_string(segments) +
                                ", corners 0..4; segment 1 has only its distal corners 3, 4)");
}

Eigen::Vector2d wallVertexPoint(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P, const WallVertex& v) {
  double before = 0.0;
  for (int j = 0; j < v.segment; ++j) before += q[j];
  return segmentVertex(chain.segment(v.segment).parameters(), P.col(v.segment + 1), before, before + q[v.segment], v.corner);
}

void wallVertexDerivatives(const Eigen::Matrix2Xd& P, const Eigen::Vector2d& point, const WallVertex& v,
                           VectorRef gradient, VectorRef generator) {
  gradient.setZero();
  generator.setZero();
  for (int j = 0; j <= v.lastJoint(); ++j) {  // joint j sits at P column j + 1
    gradient[j] = -(point.y() - P(1, j + 1));
    generator[j] = point.x() - P(0, j + 1);
  }
}

namespace {

/// Calls visit(vertex, point) for every moving vertex at q, in the order of movingVertices. One
/// sine and cosine per joint, nothing allocated.
template <class Visit>
void forEachMovingVertex(const Chain& chain, ConstVectorRef q, Visit visit) {
  const int n = chain.size();
  if (q.size() != n)
    throw std::invalid_argument("joint angles: " + std::to_string(q.size()) + " values for a chain of " +
                                std::to_string(n) + " segments");
  const Vector& length = chain.linkLengths();
  // the joint positions summed as jointPositions sums them, without its matrix
  Point joint(length[0], 0.0);
  double theta = 0.0;
  Point before = dir(0.0);
  for (int i = 0; i < n; ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    theta += q[i];
    const Point after = dir(theta);
    // segment 1's proximal triangle is clamped; a proximal corner on the previous segment's distal
    // one (equal half-heights: the link's two triangles share their base) is that vertex
    const bool shared = i > 0 && p.a1 == chain.segment(i - 1).parameters().a2;
    for (int corner = i > 0 ? 0 : 3; corner <= 4; ++corner) {
      if (shared && (corner == 1 || corner == 2)) continue;
      visit(WallVertex{i, corner}, segmentVertex(p, joint, before, after, corner));
    }
    joint += length[i + 1] * after;
    before = after;
  }
}

}  // namespace

std::vector<WallVertex> movingVertices(const Chain& chain) {
  std::vector<WallVertex> out;
  forEachMovingVertex(chain, Vector::Zero(chain.size()), [&](const WallVertex& v, const Point&) { out.push_back(v); });
  return out;
}

void movingVertexAbscissae(const Chain& chain, ConstVectorRef q, std::vector<double>& xs) {
  xs.clear();
  forEachMovingVertex(chain, q, [&](const WallVertex&, const Point& x) { xs.push_back(x.x()); });
}

WallApproach nearestWallVertex(const Chain& chain, ConstVectorRef q, const std::vector<WallVertex>& exclude) {
  WallApproach c;
  c.distance = std::numeric_limits<double>::infinity();
  forEachMovingVertex(chain, q, [&](const WallVertex& v, const Point& x) {
    if (x.x() < c.distance && std::find(exclude.begin(), exclude.end(), v) == exclude.end()) {
      c.distance = x.x();
      c.vertex = v;
      c.point = x;
    }
  });
  return c;
}

}  // namespace buckle::mechanics
