#include "buckle/mechanics/contact_geometry.h"

#include "contact_geometry_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "buckle/continuation/root_finding.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

namespace {

using Point = Eigen::Vector2d;


double pointSegment(const Point& p, const Point& a, const Point& b, Point* nearest = nullptr) {
  const Point d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  const Point c = a + t * d;
  if (nearest) *nearest = c;
  return (p - c).norm();
}

using Triangle = std::array<Point, 3>;

/// A triangle's separating axes, the unit normals of its edges (`valid`: the edge is not a
/// point), and its own extent [lo, hi] along each: computed once a shape for every pair the
/// triangle is measured against.
struct TriangleAxes {
  std::array<Point, 3> normal;
  std::array<double, 3> lo{}, hi{};
  std::array<bool, 3> valid{};
};

/// The extent [lo, hi] of T's projection on the axis u.
void extentAlong(const Triangle& T, const Point& u, double& lo, double& hi) {
  lo = hi = u.dot(T[0]);
  for (int k = 1; k < 3; ++k) lo = std::min(lo, u.dot(T[k])), hi = std::max(hi, u.dot(T[k]));
}

TriangleAxes axesOf(const Triangle& T) {
  TriangleAxes a;
  for (int e = 0; e < 3; ++e) {
    const Point d = T[(e + 1) % 3] - T[e];
    const double len = d.norm();
    a.valid[size_t(e)] = len > 0.0;
    if (!a.valid[size_t(e)]) continue;
    a.normal[size_t(e)] = Point(-d.y(), d.x()) / len;
    extentAlong(T, a.normal[size_t(e)], a.lo[size_t(e)], a.hi[size_t(e)]);
  }
  return a;
}

/// Signed distance of two triangles (either may be flat): the distance while they are disjoint,
/// else the largest projected gap over their edges' normals (separating axes), ≤ 0 and minus the
/// depth of the overlap; continuous at the first touch. onA: the point of A nearest to B (while
/// overlapping, the nearest pair of a vertex and an edge). A separating gap of at least `cutoff`
/// is returned as it is, onA unset: the distance is at least every projected gap, so it is not
/// below the cutoff either (the caller's best so far), and the 18 vertex–edge distances are saved.
double triangleTriangle(const Triangle& A, const TriangleAxes& axesA, const Triangle& B, const TriangleAxes& axesB,
                        Point& onA, double cutoff = std::numeric_limits<double>::infinity()) {
  // the gap of the projections on an axis: > 0 separated by that much, ≤ 0 overlapping
  double gap = -std::numeric_limits<double>::infinity();
  double lo = 0.0, hi = 0.0;
  for (size_t e = 0; e < 3; ++e) {
    if (axesA.valid[e]) {
      extentAlong(B, axesA.normal[e], lo, hi);
      gap = std::max(gap, std::max(lo - axesA.hi[e], axesA.lo[e] - hi));
    }
    if (axesB.valid[e]) {
      extentAlong(A, axesB.normal[e], lo, hi);
      gap = std::max(gap, std::max(axesB.lo[e] - hi, lo - axesB.hi[e]));
    }
  }
  if (gap > 0.0 && gap >= cutoff) return gap;
  double best = std::numeric_limits<double>::infinity();
  Point nearest;
  for (int e = 0; e < 3; ++e) {
    const Point &a0 = A[e], &a1 = A[(e + 1) % 3], &b0 = B[e], &b1 = B[(e + 1) % 3];
    for (int k = 0; k < 3; ++k) {
      const double toA = pointSegment(B[k], a0, a1, &nearest);
      if (toA < best) best = toA, onA = nearest;
      const double toB = pointSegment(A[k], b0, b1);
      if (toB < best) best = toB, onA = A[k];
    }
  }
  return gap > 0.0 ? best : gap;
}

/// The links' rigid bodies (contact_geometry.h): link 0 the clamped proximal triangle of the first
/// segment, link m (1 ≤ m < n) segment m's distal and segment m + 1's proximal triangle (1-based),
/// link n the last segment's distal one; each triangle's apex is its segment's joint.
struct LinkBodies {
  Eigen::Matrix2Xd P;               ///< the joint positions (jointPositions)
  std::vector<Triangle> triangles;  ///< link m's are triangles[first[m]] … [first[m + 1] − 1]
  std::vector<int> first;
};
void linkBodies(const Chain& chain, ConstVectorRef q, LinkBodies& L) {
  const int n = chain.size();
  L.P = jointPositions(chain, q);
  const Eigen::Matrix2Xd& P = L.P;
  L.triangles.clear();
  L.first.clear();
  L.triangles.reserve(size_t(2 * n));
  L.first.reserve(size_t(n + 2));
  double theta = 0.0;
  Point before(1.0, 0.0);  // the links' directions (wall_contact.h: one sine and cosine a joint)
  for (int i = 0; i < n; ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    const Point joint = P.col(i + 1);
    const Point after(std::cos(theta + q[i]), std::sin(theta + q[i]));
    // the proximal triangle closes link i, the distal one opens link i + 1
    L.triangles.push_back({joint, segmentVertex(p, joint, before, after, 1), segmentVertex(p, joint, before, after, 2)});
    L.first.push_back(int(L.triangles.size()) - (i == 0 ? 1 : 2));
    L.triangles.push_back({joint, segmentVertex(p, joint, before, after, 3), segmentVertex(p, joint, before, after, 4)});
    theta += q[i];
    before = after;
  }
  L.first.push_back(int(L.triangles.size()) - 1);
  L.first.push_back(int(L.triangles.size()));
}
LinkBodies linkBodies(const Chain& chain, ConstVectorRef q) {
  LinkBodies L;
  linkBodies(chain, q, L);
  return L;
}

/// selfClearanceOf's working storage, kept across the points of a scan: no allocation per point,
/// and the links' order by x from the last shape, which the next one mostly keeps.
struct ClearanceScratch {
  std::vector<TriangleAxes> axes;
  std::vector<double> reach, xs, radius;
  Eigen::Matrix2Xd mid;
  std::vector<int> byX, candidates;
};

SelfClearance selfClearanceOf(const LinkBodies& bodies, const SelfClearanceHint& hint, bool* exact,
                              ClearanceScratch& scratch);

/// The clearance d_base or d_self at q along a branch: the self clearance measured from the pair
/// nearest at the last call first, so the search prunes the others from its distance at once. The
/// same exact value (the smallest over every pair), a fraction of the cost where nearby shapes
/// follow each other.
class ClearanceProbe {
 public:
  ClearanceProbe(const Chain& chain, bool base) : chain_(chain), base_(base) {}
  double operator()(ConstVectorRef q) {
    if (base_) return baseClearance(chain_, q).distance;
    linkBodies(chain_, q, bodies_);
    const SelfClearance c = selfClearanceOf(bodies_, hint_, nullptr, scratch_);
    hint_.linkA = c.linkA;
    hint_.linkB = c.linkB;
    return c.distance;
  }

 private:
  const Chain& chain_;
  bool base_;
  SelfClearanceHint hint_;
  LinkBodies bodies_;  // the probed shape's, its storage reused like scratch_'s
  ClearanceScratch scratch_;
};

/// The largest distance a vertex of the bodies has moved between two shapes of the same chain.
double largestMove(const LinkBodies& now, const LinkBodies& before) {
  double move = 0.0;
  for (size_t t = 0; t < now.triangles.size(); ++t)
    for (size_t k = 0; k < 3; ++k) move = std::max(move, (now.triangles[t][k] - before.triangles[t][k]).norm());
  return move;
}

/// d_base of the bodies: the smallest x of the moving vertices (nearestWallVertex's, from the
/// same positions: the clamped triangle and segment 1's joint left out).
double baseDistanceOf(const LinkBodies& bodies) {
  double x = std::numeric_limits<double>::infinity();
  for (size_t t = 1; t < bodies.triangles.size(); ++t)
    for (size_t k = t == 1 ? 1 : 0; k < 3; ++k) x = std::min(x, bodies.triangles[t][k].x());
  return x;
}

/// The clearances of a branch's points (ClearanceProbe's) as far as a scan for sign changes needs them,
/// the bodies computed once a point for both: d_base exact at every point (when `base`); for the
/// self contact a value with the sign of d_self outside the touching band. At a reference point
/// selfClearance, warm-started from the previous nearest pair and ended by a pair deeper than
/// twice the band (its distance then bounds d_self from above); while every vertex of the bodies
/// has moved by at most δ from the reference, the bound d_ref − 2δ (an exact d_ref) or d_ref + 2δ
/// in its place — a rigid triangle's points move by at most its vertices' largest move (the move
/// is affine in the point), so two bodies' signed distance changes by at most 2δ — as long as the
/// bound keeps the sign of d_ref by the band. O(n) a point while the nearest pair stays the
/// nearest or overlapping; the nearest-pair search (O(n log n)) only where the clearance may
/// change sign.
void scanDistances(const Chain& chain, const continuation::Branch& branch, bool base, std::vector<double>& dBase,
                   std::vector<double>& dSelf) {
  const int n = chain.size();
  const size_t count = branch.points.size();
  dBase.assign(base ? count : 0, 0.0);
  dSelf.assign(count, 0.0);
  const double band = kTouchingBand * chain.length();
  LinkBodies reference, bodies;
  double dRef = std::numeric_limits<double>::quiet_NaN();
  bool exactRef = false;
  SelfClearanceHint hint;
  hint.stopBelow = -2.0 * band;
  ClearanceScratch scratch;
  for (size_t i = 0; i < count; ++i) {
    linkBodies(chain, branch.points[i].u.head(n), bodies);
    if (base) dBase[i] = baseDistanceOf(bodies);
    if (std::isfinite(dRef)) {
      const double moved = 2.0 * largestMove(bodies, reference);
      if (exactRef && dRef - moved > band) {
        dSelf[i] = dRef - moved;
        continue;
      }
      if (dRef + moved < -band) {
        dSelf[i] = dRef + moved;
        continue;
      }
    }
    const SelfClearance c = selfClearanceOf(bodies, hint, &exactRef, scratch);
    dSelf[i] = c.distance;
    hint.linkA = c.linkA;
    hint.linkB = c.linkB;
    std::swap(reference, bodies);
    dRef = dSelf[i];
  }
}

}  // namespace

BaseClearance baseClearance(const Chain& chain, ConstVectorRef q) {
  const WallApproach a = nearestWallVertex(chain, q);  // the vertices of wall_contact.h
  BaseClearance c;
  c.distance = a.distance;
  c.segment = a.vertex.segment;
  c.distal = a.vertex.distal();
  c.point = a.point;
  return c;
}

SelfClearance selfClearance(const Chain& chain, ConstVectorRef q) { return selfClearance(chain, q, {}, nullptr); }

double selfClearanceApart(const Chain& chain, ConstVectorRef q, const std::vector<SelfContact>& held, int* linkA,
                          int* linkB) {
  SelfClearanceHint hint;
  hint.exclude = heldLinkPairs(held);
  const SelfClearance c = selfClearance(chain, q, hint, nullptr);
  if (linkA) *linkA = c.linkA;
  if (linkB) *linkB = c.linkB;
  if (held.empty()) return c.distance;
  int a = -1, b = -1;
  const double pairs = heldPairsClearance(chain, q, jointPositions(chain, q), held, &a, &b);
  if (!(pairs < c.distance)) return c.distance;
  if (linkA) *linkA = a;
  if (linkB) *linkB = b;
  return pairs;
}

SelfClearance selfClearance(const Chain& chain, ConstVectorRef q, const SelfClearanceHint& hint, bool* exact) {
  ClearanceScratch scratch;
  return selfClearanceOf(linkBodies(chain, q), hint, exact, scratch);
}

namespace {

/// byX sorted by the links' mid-point x: insertion sort from the previous shape's order (a few
/// moves where consecutive shapes are near), std::sort once that costs more than a full sort would.
void sortByX(std::vector<int>& byX, const Eigen::Matrix2Xd& mid) {
  const size_t links = size_t(mid.cols());
  if (byX.size() != links) {
    byX.resize(links);
    for (size_t a = 0; a < links; ++a) byX[a] = int(a);
  }
  const auto lessX = [&mid](int i, int j) { return mid(0, i) < mid(0, j); };
  size_t moves = 0;
  const size_t budget = 8 * links;
  for (size_t i = 1; i < links; ++i) {
    const int v = byX[i];
    size_t j = i;
    for (; j > 0 && lessX(v, byX[j - 1]); --j) byX[j] = byX[j - 1];
    byX[j] = v;
    moves += i - j;
    if (moves > budget) {
      std::sort(byX.begin(), byX.end(), lessX);
      return;
    }
  }
}

SelfClearance selfClearanceOf(const LinkBodies& bodies, const SelfClearanceHint& hint, bool* exact,
                              ClearanceScratch& scratch) {
  const Eigen::Matrix2Xd& P = bodies.P;
  const int links = int(P.cols()) - 1;  // ℓ_0 … ℓ_n: link m from column m to m + 1
  SelfClearance c;
  c.distance = std::numeric_limits<double>::infinity();
  if (exact) *exact = true;
  if (links < 3) return c;
  // Each triangle's circle about its apex (the joint) through its farthest vertex: a pair of
  // triangles is measured only where its circles' lower bound (as the links' below) beats the best.
  std::vector<TriangleAxes>& axes = scratch.axes;
  axes.resize(bodies.triangles.size());
  for (size_t t = 0; t < axes.size(); ++t) axes[t] = axesOf(bodies.triangles[t]);
  std::vector<double>& reach = scratch.reach;
  reach.resize(bodies.triangles.size());
  for (size_t t = 0; t < reach.size(); ++t)
    reach[t] = std::max((bodies.triangles[t][1] - bodies.triangles[t][0]).norm(),
                        (bodies.triangles[t][2] - bodies.triangles[t][0]).norm());
  // the smallest signed distance of two links' triangles; true when it ends the search
  const auto measure = [&](int a, int b) {
    if (!hint.exclude.empty() &&
        std::find(hint.exclude.begin(), hint.exclude.end(), std::pair{a, b}) != hint.exclude.end())
      return false;
    for (int s = bodies.first[size_t(a)]; s < bodies.first[size_t(a) + 1]; ++s)
      for (int t = bodies.first[size_t(b)]; t < bodies.first[size_t(b) + 1]; ++t) {
        const double r = reach[size_t(s)] + reach[size_t(t)];
        const double gap = (bodies.triangles[size_t(t)][0] - bodies.triangles[size_t(s)][0]).norm() - r;
        if ((gap > 0.0 ? gap : -r) >= c.distance) continue;
        Point on = Point::Zero();
        const double d = triangleTriangle(bodies.triangles[size_t(s)], axes[size_t(s)], bodies.triangles[size_t(t)],
                                          axes[size_t(t)], on, c.distance);
        if (d < c.distance) {
          c.distance = d;
          c.linkA = a;
          c.linkB = b;
          c.point = on;
        }
      }
    return c.distance < hint.stopBelow;
  };
  const bool hinted = hint.linkA >= 0 && hint.linkB >= hint.linkA + 2 && hint.linkB < links;
  if (hinted && measure(hint.linkA, hint.linkB)) {
    if (exact) *exact = false;
    return c;
  }
  // Bounding circles of the bodies (the link's mid-point, the farthest vertex), and the links
  // sorted by the x of their mid-points: the pairs scanned are those whose circles could beat the
  // best so far.
  Eigen::Matrix2Xd& mid = scratch.mid;
  mid.resize(2, links);
  std::vector<double>& radius = scratch.radius;
  radius.resize(size_t(links));
  double rmax = 0.0, extent = 0.0;
  for (int a = 0; a < links; ++a) {
    mid.col(a) = 0.5 * (P.col(a) + P.col(a + 1));
    double& r = radius[size_t(a)];
    r = 0.0;
    for (int t = bodies.first[size_t(a)]; t < bodies.first[size_t(a) + 1]; ++t)
      for (const Point& v : bodies.triangles[size_t(t)]) r = std::max(r, (v - mid.col(a)).norm());
    rmax = std::max(rmax, r);
    extent = std::max(extent, mid.col(a).cwiseAbs().maxCoeff() + r);
  }
  std::vector<int>& byX = scratch.byX;
  sortByX(byX, mid);
  std::vector<double>& xs = scratch.xs;
  xs.resize(byX.size());
  for (size_t i = 0; i < byX.size(); ++i) xs[i] = mid(0, byX[i]);
  // A pair's signed distance is at least its circles' gap |Δm| − r_a − r_b where that is
  // positive, and at least −r_a − r_b (every projected gap is) where they overlap: the lower
  // bound below. A pair whose mid-points differ by more than the reach in x or y has disjoint
  // circles and a bound above the best so far (+ a margin far above the rounding of the bound):
  // the all-pairs scan would skip it too, so scanning only the others, in the same order with the
  // same test, gives the same pair, bit for bit.
  const double margin = 1e-9 * extent;
  std::vector<int>& candidates = scratch.candidates;
  for (int a = 0; a < links - 2; ++a) {
    const double ra = radius[size_t(a)];
    candidates.clear();
    if (std::isfinite(c.distance)) {
      const double reach = std::max(c.distance, 0.0) + ra + rmax + margin;
      const auto lo = std::lower_bound(xs.begin(), xs.end(), mid(0, a) - reach);
      const auto hi = std::upper_bound(xs.begin(), xs.end(), mid(0, a) + reach);
      for (auto it = lo; it != hi; ++it) {
        const int b = byX[size_t(it - xs.begin())];
        if (b >= a + 2 && std::abs(mid(1, b) - mid(1, a)) <= reach) candidates.push_back(b);
      }
      std::sort(candidates.begin(), candidates.end());
    } else {
      for (int b = a + 2; b < links; ++b) candidates.push_back(b);
    }
    for (const int b : candidates) {
      const double rb = radius[size_t(b)];
      const double circles = (mid.col(b) - mid.col(a)).norm() - ra - rb;
      const double bound = circles > 0.0 ? circles : -ra - rb;
      if (bound >= c.distance || (hinted && a == hint.linkA && b == hint.linkB)) continue;
      if (measure(a, b)) {
        if (exact) *exact = false;
        return c;
      }
    }
  }
  return c;
}

}  // namespace

std::vector<GeometricContact> locateGeometricContacts(EquilibriumProblem& problem, const continuation::Branch& branch,
                                                      const std::vector<ContactSet>& locked, double tolerance,
                                                      const continuation::Interrupt& interrupt) {
  std::vector<GeometricContact> found;
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const size_t count = branch.points.size();
  if (count < 2) return found;
  const double lambdaScale = problem.scales().parameter;
  // the wall and self contact as constraints: WC / WR and SH / SR (contact.h), not scanned
  const bool scanBase = !problem.wallIsBoundary(), scanSelf = !problem.selfContactIsBoundary();
  if (!scanBase && !scanSelf) return found;
  std::vector<double> dBase, dSelf;
  scanDistances(chain, branch, scanBase, dBase, dSelf);
  for (bool base : {true, false}) {
    if ((base && !scanBase) || (!base && !scanSelf)) continue;
    std::vector<double>& d = base ? dBase : dSelf;
    ClearanceProbe distance(chain, base);
    // Bodies that rest on each other (a vertex on the wall, triangles meeting where joints lock at
    // their limits) keep their distance within rounding of zero, of either sign: the sign changes
    // that count are between points clear of that band, each in the interval where the sign flips.
    const double band = kTouchingBand * chain.length();
    for (size_t i = 0; i < count; ++i)
      if (std::abs(d[i]) <= band) d[i] = distance(branch.points[i].u.head(n));  // not a bound
    std::vector<size_t> changes;
    int lastSign = 0;
    size_t lastClear = 0;
    for (size_t i = 0; i < count; ++i) {
      if (!std::isfinite(d[i])) {
        lastSign = 0;
        continue;
      }
      const int sign = d[i] > band ? 1 : (d[i] < -band ? -1 : 0);
      if (sign == 0) continue;
      if (lastSign != 0 && sign != lastSign)
        for (size_t j = lastClear; j < i; ++j)
          if ((d[j] > 0.0) != (d[j + 1] > 0.0)) {
            changes.push_back(j);
            break;
          }
      lastSign = sign;
      lastClear = i;
    }
    for (const size_t i : changes) {
      // the clearances themselves on both sides (a bound has only their sign)
      d[i] = distance(branch.points[i].u.head(n));
      d[i + 1] = distance(branch.points[i + 1].u.head(n));
      const continuation::ContinuationPoint &p0 = branch.points[i], &p1 = branch.points[i + 1];
      GeometricContact g;
      g.base = base;
      g.entering = d[i] > 0.0;
      g.index = int(i);
      // to the point spacing: the point nearer the wall / the other link
      const bool first = std::abs(d[i]) <= std::abs(d[i + 1]);
      g.lambda = first ? p0.lambda : p1.lambda;
      g.u = first ? p0.u : p1.u;
      g.accuracy = std::abs(p1.lambda - p0.lambda);
      const ContactSet set = locked.empty() ? ContactSet() : locked[std::min(i, locked.size() - 1)];
      const bool sameSet = locked.empty() || (i + 1 < locked.size() && locked[i + 1] == set);
      if (p0.lambda != p1.lambda && sameSet && !interrupt.requested()) {
        // Illinois on λ over the interval: each trial an equilibrium at fixed λ from the
        // interpolated unknowns (the stretch's locked joints fixed)
        const bool increasing = p1.lambda > p0.lambda;
        continuation::IllinoisBracket bracket{increasing ? p0.lambda : p1.lambda, increasing ? p1.lambda : p0.lambda,
                                              increasing ? d[i] : d[i + 1], increasing ? d[i + 1] : d[i]};
        double bestF = std::numeric_limits<double>::infinity();
        bool solved = true;
        for (int it = 0; it < 100; ++it) {
          const double s = bracket.next();
          const double w = (s - p0.lambda) / (p1.lambda - p0.lambda);
          const continuation::Vector guess = (1.0 - w) * p0.u + w * p1.u;
          const ConstrainedEquilibrium e = solveConstrainedEquilibrium(problem, set, guess, s);
          if (!e.converged) {
            solved = false;
            break;
          }
          const double f = distance(e.u.head(n));
          if (std::abs(f) < bestF) {
            bestF = std::abs(f);
            g.lambda = s;
            g.u = e.u;
          }
          if (f == 0.0) {
            bracket.left = bracket.right = s;
            break;
          }
          bracket.update(s, f);
          if (bracket.width() <= tolerance * std::max(lambdaScale, std::abs(s))) break;
        }
        g.located = solved && bracket.width() <= tolerance * std::max(lambdaScale, std::abs(g.lambda));
        if (g.located) g.accuracy = bracket.width();
      }
      const continuation::Vector q = g.u.head(n);
      if (base) {
        const BaseClearance c = baseClearance(chain, q);
        g.segment = c.segment;
        g.point = c.point;
      } else {
        const SelfClearance c = selfClearance(chain, q);
        g.linkA = c.linkA;
        g.linkB = c.linkB;
        g.point = c.point;
      }
      found.push_back(std::move(g));
    }
  }
  return found;
}

void reportGeometricContacts(EquilibriumProblem& problem, const continuation::Branch& branch,
                             const std::vector<PointReport>& all, const ReportOptions& options, BranchReport& r,
                             GeometricContacts* contacts) {
  const int n = problem.segments();
  GeometricContacts local;
  GeometricContacts& found = contacts ? *contacts : local;
  if (!found.given) {
    std::vector<ContactSet> locked;
    locked.reserve(all.size());
    for (const PointReport& p : all) locked.push_back(p.locked);
    found.list = locateGeometricContacts(problem, branch, locked, 1e-12, options.interrupt);
  }
  for (const GeometricContact& g : found.list) {
    if (!g.located && options.interrupt.requested()) r.skip("the location of base and self contacts");
    SpecialPointReport s;
    s.type = g.base ? EventType::BaseContact : EventType::SelfContact;
    s.index = g.index;
    s.lambda = g.lambda;
    s.q = g.u.head(n);
    s.F = problem.wrench(g.u, g.lambda);
    s.pose = endPose(problem.chain(), s.q);
    s.parameter = options.heldCoordinate >= 0 ? s.pose[options.heldCoordinate] : g.lambda;
    s.shape = shapeName(s.q, 1e-6);  // straightness in radians, as the report's
    s.accuracy = g.accuracy;
    s.refined = g.located;
    if (size_t(g.index) + 1 < all.size()) {
      s.negativeBefore = all[size_t(g.index)].negative;
      s.negativeAfter = all[size_t(g.index) + 1].negative;
    }
    std::ostringstream os;
    os.precision(6);
    if (g.base)
      os << "base contact: segment " << g.segment + 1 << "'s triangle " << (g.entering ? "reaches" : "leaves")
         << " the clamp's wall x = 0 at y = " << g.point.y();
    else
      os << "self contact: links " << g.linkA << " and " << g.linkB << " " << (g.entering ? "meet" : "separate")
         << " at (" << g.point.x() << ", " << g.point.y() << ")";
    os << (g.located                      ? std::string("; located on the branch (equilibria at fixed load)")
           : options.interrupt.requested() ? "; to the point spacing (not located: " + options.interrupt.describe() + ")"
                                           : std::string("; to the point spacing"))
       << " — detected only: the model lets the chain pass through";
    s.note = os.str();
    s.contactPoint = g.point;
    r.specialPoints.push_back(std::move(s));
  }
}

}  // namespace buckle::mechanics
