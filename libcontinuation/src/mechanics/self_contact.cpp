#include "buckle/mechanics/self_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace buckle::mechanics {

namespace {

using Point = Eigen::Vector2d;

// The links (contact_geometry.h numbering) a vertex belongs to: a joint to both triangles of its
// segment, a base corner to its own triangle's link.
std::pair<int, int> linksOf(const WallVertex& v) {
  if (v.corner == 0) return {v.segment, v.segment + 1};
  return v.distal() ? std::pair{v.segment + 1, v.segment + 1} : std::pair{v.segment, v.segment};
}

// The triangles of link m (0 … n) as (segment, distal).
std::vector<std::pair<int, bool>> trianglesOf(int link, int segments) {
  std::vector<std::pair<int, bool>> t;
  if (link >= 1) t.push_back({link - 1, true});
  if (link <= segments - 1) t.push_back({link, false});
  return t;
}

Point R90(const Point& p) { return Point(-p.y(), p.x()); }

}  // namespace

int TriangleEdge::corner(int k) const {
  // base: (+a, −a), third the apex; side +: (apex, +a), third −a; side −: (apex, −a), third +a
  static const int proximal[3][3] = {{1, 2, 0}, {0, 1, 2}, {0, 2, 1}};
  static const int distalCorners[3][3] = {{3, 4, 0}, {0, 3, 4}, {0, 4, 3}};
  const int e = std::clamp(edge, 0, 2), j = std::clamp(k, 0, 2);
  return distal ? distalCorners[e][j] : proximal[e][j];
}

std::string TriangleEdge::label() const {
  static const char* const ends[3] = {"[+,-]", "[j,+]", "[j,-]"};
  return std::to_string(segment + 1) + (distal ? "d" : "p") + ends[std::clamp(edge, 0, 2)];
}

std::string SelfContact::label() const { return vertex.label() + " on " + edge.label(); }

void checkSelfContact(const SelfContact& c, int segments) {
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument("self contact (vertex segment " + std::to_string(c.vertex.segment + 1) + " corner " +
                                std::to_string(c.vertex.corner) + ", edge segment " +
                                std::to_string(c.edge.segment + 1) + (c.edge.distal ? " distal" : " proximal") +
                                " edge " + std::to_string(c.edge.edge) + "): " + why);
  };
  if (c.vertex.segment < 0 || c.vertex.segment >= segments || c.vertex.corner < 0 || c.vertex.corner > 4)
    fail("the vertex is not one of the chain's (segments 1.." + std::to_string(segments) + ", corners 0..4)");
  if (c.edge.segment < 0 || c.edge.segment >= segments || c.edge.edge < 0 || c.edge.edge > 2)
    fail("the edge is not one of the chain's (segments 1.." + std::to_string(segments) + ", edges 0..2)");
  const auto [l0, l1] = linksOf(c.vertex);
  const int le = c.edge.link();
  if (std::min(std::abs(l0 - le), std::abs(l1 - le)) < 2)
    fail("the vertex and the edge are on the same or adjacent links (a joint's own contact is its limit)");
}

SelfContactGap selfContactGap(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P, const SelfContact& c) {
  SelfContactGap g;
  const int s = c.edge.segment;
  const Point e0 = wallVertexPoint(chain, q, P, WallVertex{s, c.edge.corner(0)});
  const Point e1 = wallVertexPoint(chain, q, P, WallVertex{s, c.edge.corner(1)});
  const Point third = wallVertexPoint(chain, q, P, WallVertex{s, c.edge.corner(2)});
  const Point d = e1 - e0;
  g.edgeLength = d.norm();
  g.normal = Point(d.y(), -d.x()) / g.edgeLength;
  if (g.normal.dot(third - e0) > 0.0) g.normal = -g.normal;  // outward: away from the third corner
  g.vertex = wallVertexPoint(chain, q, P, c.vertex);
  g.gap = g.normal.dot(g.vertex - e0);
  g.along = (g.vertex - e0).dot(d) / (g.edgeLength * g.edgeLength);
  return g;
}

void selfContactDerivatives(const Eigen::Matrix2Xd& P, const SelfContact& c, const SelfContactGap& g, VectorRef gradient,
                            VectorRef generator, VectorRef coupling, VectorRef weights) {
  gradient.setZero();
  generator.setZero();
  coupling.setZero();
  weights.setZero();
  const int lv = c.vertex.lastJoint(), le = c.edge.lastJoint();
  const double sigma = lv > le ? 1.0 : -1.0;
  const int lo = std::min(lv, le), hi = std::max(lv, le);
  for (int m = lo + 1; m <= hi; ++m) {  // joint m sits at P column m + 1
    const Point arm = g.vertex - P.col(m + 1);
    gradient[m] = sigma * g.normal.dot(R90(arm));
    coupling[m] = -g.normal.dot(arm);  // c_m
    generator[m] = -sigma * coupling[m];
  }
  if (sigma > 0.0)
    for (int m = 0; m <= lo; ++m) weights[m] = -1.0;
  else
    for (int m = 0; m <= hi; ++m) weights[m] = 1.0;
}

bool slideOntoNeighbour(const Chain& chain, const SelfContact& c, double along, SelfContact& next) {
  const int s = c.edge.segment, n = chain.size();
  if (c.edge.edge == 0 || along < 0.5) return false;
  const int other = c.edge.distal ? s + 1 : s - 1;
  if (other < 0 || other >= n) return false;
  const double here = c.edge.distal ? chain.segment(s).parameters().a2 : chain.segment(s).parameters().a1;
  const double there = c.edge.distal ? chain.segment(other).parameters().a1 : chain.segment(other).parameters().a2;
  if (here != there) return false;
  next = SelfContact{c.vertex, TriangleEdge{other, !c.edge.distal, c.edge.edge}};
  return true;
}

SelfContact touchingPair(const Chain& chain, ConstVectorRef q, int linkA, int linkB) {
  const int n = chain.size();
  if (linkA < 0 || linkB < 0 || linkA > n || linkB > n || std::abs(linkA - linkB) < 2)
    throw std::invalid_argument("self contact: links " + std::to_string(linkA) + " and " + std::to_string(linkB) +
                                " cannot touch (links 0.." + std::to_string(n) + ", two or more apart)");
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  SelfContact best;
  double bestGap = std::numeric_limits<double>::infinity();
  // t on the edge to rounding of the located touch
  constexpr double kSlack = 1e-9;
  for (const auto& [vl, el] : {std::pair{linkA, linkB}, std::pair{linkB, linkA}})
    for (const auto& [vs, vd] : trianglesOf(vl, n))
      for (const int corner : vd ? std::vector<int>{0, 3, 4} : std::vector<int>{0, 1, 2})
        for (const auto& [es, ed] : trianglesOf(el, n))
          for (int edge = 0; edge < 3; ++edge) {
            const SelfContact c{WallVertex{vs, corner}, TriangleEdge{es, ed, edge}};
            const auto [l0, l1] = linksOf(c.vertex);
            if (std::min(std::abs(l0 - el), std::abs(l1 - el)) < 2) continue;  // a joint shared with a neighbour
            const SelfContactGap g = selfContactGap(chain, q, P, c);
            if (!(g.edgeLength > 0.0) || g.along < -kSlack || g.along > 1.0 + kSlack) continue;
            if (std::abs(g.gap) < bestGap) bestGap = std::abs(g.gap), best = c;
          }
  if (!std::isfinite(bestGap))
    throw std::invalid_argument("self contact: no vertex of link " + std::to_string(linkA) + " or " +
                                std::to_string(linkB) + " lies over an edge of the other");
  return best;
}

}  // namespace buckle::mechanics
