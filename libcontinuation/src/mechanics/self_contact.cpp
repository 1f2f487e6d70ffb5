#include "buckle/mechanics/self_contact.h"

#include <algorithm>
#include <array>
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

// The corners of a segment's proximal (0, 1, 2) or distal (0, 3, 4) triangle.
std::array<int, 3> cornersOf(bool distal) { return distal ? std::array{0, 3, 4} : std::array{0, 1, 2}; }

Point R90(const Point& p) { return Point(-p.y(), p.x()); }

// The corners of a link pair left out of its clearance while it holds the contacts `held`: the
// held vertices and their edges' ends (the vertex reaches those by its edge's boundaries, and
// sits on one while held at a corner).
std::vector<WallVertex> heldCorners(const std::vector<SelfContact>& held) {
  std::vector<WallVertex> out;
  for (const SelfContact& c : held) {
    out.push_back(c.vertex);
    out.push_back(WallVertex{c.edge.segment, c.edge.corner(0)});
    out.push_back(WallVertex{c.edge.segment, c.edge.corner(1)});
  }
  return out;
}

// Whether the contact is between links la and lb (its vertex on one, its edge on the other).
bool onPair(const SelfContact& c, int la, int lb) {
  const auto [l0, l1] = linksOf(c.vertex);
  const int le = c.edge.link();
  return (le == la && (l0 == lb || l1 == lb)) || (le == lb && (l0 == la || l1 == la));
}

// Signed distance of p to triangle (a, b, c): the distance outside, minus the distance to the
// nearest edge inside.
double signedDistance(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point corner[3] = {a, b, c};
  double inside = -std::numeric_limits<double>::infinity(), outside = std::numeric_limits<double>::infinity();
  bool in = true;
  for (int e = 0; e < 3; ++e) {
    const Point& u = corner[e];
    const Point& v = corner[(e + 1) % 3];
    const Point& w = corner[(e + 2) % 3];
    const Point d = v - u;
    Point normal(d.y(), -d.x());
    normal.normalize();
    if (normal.dot(w - u) > 0.0) normal = -normal;
    const double gap = normal.dot(p - u);
    in = in && gap <= 0.0;
    inside = std::max(inside, gap);
    const double t = std::clamp((p - u).dot(d) / d.squaredNorm(), 0.0, 1.0);
    outside = std::min(outside, (p - u - t * d).norm());
  }
  return in ? inside : outside;
}

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

double selfCouplingColumns(ConstVectorRef coupling, ConstVectorRef weights, double mu, MatrixRef R) {
  const double nc = coupling.norm(), nw = weights.norm();
  const double beta = nc > 0.0 && nw > 0.0 ? std::sqrt(nw / nc) : 1.0;
  const double rho = std::sqrt(0.5 * std::abs(mu));
  R.col(0) = rho * (beta * coupling + weights / beta);
  R.col(1) = rho * (beta * coupling - weights / beta);
  return mu < 0.0 ? -1.0 : 1.0;
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

bool cornerNeighbour(const Chain& chain, const SelfContact& c, SelfContact& next) {
  const int s = c.edge.segment, n = chain.size();
  if (c.edge.edge == 0) return false;
  const int other = c.edge.distal ? s + 1 : s - 1;
  if (other < 0 || other >= n) return false;
  const double here = c.edge.distal ? chain.segment(s).parameters().a2 : chain.segment(s).parameters().a1;
  const double there = c.edge.distal ? chain.segment(other).parameters().a1 : chain.segment(other).parameters().a2;
  if (here != there) return false;
  next = SelfContact{c.vertex, TriangleEdge{other, !c.edge.distal, c.edge.edge}};
  return true;
}

bool heldAtCorner(const Chain& chain, const SelfContact& c, const std::vector<SelfContact>& held) {
  SelfContact partner;
  return cornerNeighbour(chain, c, partner) && std::find(held.begin(), held.end(), partner) != held.end();
}

std::vector<std::pair<int, int>> heldLinkPairs(const std::vector<SelfContact>& held) {
  std::vector<std::pair<int, int>> pairs;
  for (const SelfContact& c : held) {
    const auto [l0, l1] = linksOf(c.vertex);
    for (const int lv : {l0, l1})
      if (std::abs(lv - c.edge.link()) >= 2) pairs.push_back({std::min(lv, c.edge.link()), std::max(lv, c.edge.link())});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

double heldPairsClearance(const Chain& chain, ConstVectorRef q, const Eigen::Matrix2Xd& P,
                          const std::vector<SelfContact>& held, int* linkA, int* linkB) {
  const int n = chain.size();
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [la, lb] : heldLinkPairs(held)) {
    std::vector<SelfContact> here;
    for (const SelfContact& c : held)
      if (onPair(c, la, lb)) here.push_back(c);
    const std::vector<WallVertex> skip = heldCorners(here);
    for (const auto& [vl, el] : {std::pair{la, lb}, std::pair{lb, la}})
      for (const auto& [vs, vd] : trianglesOf(vl, n))
        for (const int corner : cornersOf(vd)) {
          const WallVertex v{vs, corner};
          if (std::find(skip.begin(), skip.end(), v) != skip.end()) continue;
          const Point p = wallVertexPoint(chain, q, P, v);
          for (const auto& [es, ed] : trianglesOf(el, n)) {
            const std::array<int, 3> t = cornersOf(ed);
            const double d = signedDistance(p, wallVertexPoint(chain, q, P, {es, t[0]}),
                                            wallVertexPoint(chain, q, P, {es, t[1]}), wallVertexPoint(chain, q, P, {es, t[2]}));
            if (d < best) {
              best = d;
              if (linkA) *linkA = la;
              if (linkB) *linkB = lb;
            }
          }
        }
  }
  return best;
}

SelfContact touchingPair(const Chain& chain, ConstVectorRef q, int linkA, int linkB, const std::vector<SelfContact>& held) {
  const int n = chain.size();
  if (linkA < 0 || linkB < 0 || linkA > n || linkB > n || std::abs(linkA - linkB) < 2)
    throw std::invalid_argument("self contact: links " + std::to_string(linkA) + " and " + std::to_string(linkB) +
                                " cannot touch (links 0.." + std::to_string(n) + ", two or more apart)");
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  std::vector<SelfContact> here;  // contacts the pair already holds: their corners are left out
  for (const SelfContact& c : held)
    if (onPair(c, linkA, linkB)) here.push_back(c);
  const std::vector<WallVertex> skip = heldCorners(here);
  SelfContact best;
  double bestGap = std::numeric_limits<double>::infinity();
  // t on the edge to rounding of the located touch
  constexpr double kSlack = 1e-9;
  // a vertex inside a triangle of the other link (beyond the slack): the deepest one, on the edge
  // it is nearest to (the dynamics' and the landing's steps can end there)
  SelfContact deepest;
  double depth = 0.0;
  for (const auto& [vl, el] : {std::pair{linkA, linkB}, std::pair{linkB, linkA}})
    for (const auto& [vs, vd] : trianglesOf(vl, n))
      for (const int corner : cornersOf(vd))
        for (const auto& [es, ed] : trianglesOf(el, n)) {
          SelfContact nearest;
          double inside = -std::numeric_limits<double>::infinity();
          for (int edge = 0; edge < 3; ++edge) {
            const SelfContact c{WallVertex{vs, corner}, TriangleEdge{es, ed, edge}};
            if (std::find(skip.begin(), skip.end(), c.vertex) != skip.end()) continue;
            const auto [l0, l1] = linksOf(c.vertex);
            if (std::min(std::abs(l0 - el), std::abs(l1 - el)) < 2) continue;  // a joint shared with a neighbour
            const SelfContactGap g = selfContactGap(chain, q, P, c);
            if (!(g.edgeLength > 0.0)) continue;
            if (g.gap > inside) inside = g.gap, nearest = c;
            if (g.along < -kSlack || g.along > 1.0 + kSlack) continue;
            if (std::abs(g.gap) < bestGap) bestGap = std::abs(g.gap), best = c;
          }
          const double length = std::max(chain.segment(es).parameters().b1, chain.segment(es).parameters().a1);
          if (std::isfinite(inside) && inside < -kSlack * length && inside < depth) depth = inside, deepest = nearest;
        }
  if (depth < 0.0) return deepest;
  if (!std::isfinite(bestGap))
    throw std::invalid_argument("self contact: no vertex of link " + std::to_string(linkA) + " or " +
                                std::to_string(linkB) + " lies over an edge of the other");
  return best;
}

}  // namespace buckle::mechanics
