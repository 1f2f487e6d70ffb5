#include "buckle/mechanics/contact_geometry.h"

#include "contact_geometry_report.h"

#include <algorithm>
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

double cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Signed distance of segments [a, b] and [c, d] (file comment of the header): the distance
/// while disjoint, minus the smallest end-point-to-other-segment distance while they cross.
double segmentSegment(const Point& a, const Point& b, const Point& c, const Point& d, Point& onAB) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  const bool crossing = ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0));
  Point pc, pd, tmp;
  const double dc = pointSegment(c, a, b, &pc), dd = pointSegment(d, a, b, &pd);
  const double da = pointSegment(a, c, d, &tmp), db = pointSegment(b, c, d, &tmp);
  double best = dc;
  onAB = pc;
  if (dd < best) best = dd, onAB = pd;
  if (da < best) best = da, onAB = a;
  if (db < best) best = db, onAB = b;
  if (crossing) {
    // the crossing point itself is where the links meet
    const double t = d1 / (d1 - d2);
    onAB = c + t * (d - c);
    return -best;
  }
  return best;
}

double distanceAt(const Chain& chain, ConstVectorRef q, bool base) {
  return base ? baseClearance(chain, q).distance : selfClearance(chain, q).distance;
}

/// The clearances of a branch's points (distanceAt) as far as a scan for sign changes needs them:
/// exact at the base, and for the self contact exact at a reference point and, while every joint
/// has moved by at most δ from it, the bound d_ref − 2δ (or d_ref + 2δ) in its place — two links'
/// distance changes by at most 2δ when their ends move by δ — as long as the bound keeps the sign
/// of d_ref by a margin far above rounding. O(n) a point, the nearest-pair search (O(n log n))
/// only where the clearance may change sign.
std::vector<double> scannedDistances(const Chain& chain, const continuation::Branch& branch, bool base) {
  const int n = chain.size();
  const size_t count = branch.points.size();
  std::vector<double> d(count);
  Eigen::Matrix2Xd reference;
  double dRef = std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < count; ++i) {
    const auto q = branch.points[i].u.head(n);
    if (base) {
      d[i] = distanceAt(chain, q, true);
      continue;
    }
    const Eigen::Matrix2Xd P = jointPositions(chain, q);
    if (std::isfinite(dRef) && P.cols() == reference.cols()) {
      const double moved = 2.0 * (P - reference).colwise().norm().maxCoeff();
      const double margin = 1e-9 * std::max(1.0, P.cwiseAbs().maxCoeff());
      if (dRef - moved > margin) {
        d[i] = dRef - moved;
        continue;
      }
      if (dRef + moved < -margin) {
        d[i] = dRef + moved;
        continue;
      }
    }
    d[i] = selfClearance(chain, q).distance;
    reference = P;
    dRef = d[i];
  }
  return d;
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

SelfClearance selfClearance(const Chain& chain, ConstVectorRef q) {
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  const int links = int(P.cols()) - 1;  // ℓ_0 … ℓ_n: link m from column m to m + 1
  SelfClearance c;
  c.distance = std::numeric_limits<double>::infinity();
  if (links < 3) return c;
  // Bounding circles of the links (mid-point, half length), and the links sorted by the x of
  // their mid-points: the pairs scanned are those whose circles could beat the best so far.
  Eigen::Matrix2Xd mid(2, links);
  Eigen::VectorXd radius(links);
  double rmax = 0.0, extent = 0.0;
  for (int a = 0; a < links; ++a) {
    mid.col(a) = 0.5 * (P.col(a) + P.col(a + 1));
    radius[a] = 0.5 * (P.col(a + 1) - P.col(a)).norm();
    rmax = std::max(rmax, radius[a]);
    extent = std::max(extent, mid.col(a).cwiseAbs().maxCoeff() + radius[a]);
  }
  std::vector<int> byX(static_cast<size_t>(links));
  for (int a = 0; a < links; ++a) byX[size_t(a)] = a;
  std::sort(byX.begin(), byX.end(), [&mid](int i, int j) { return mid(0, i) < mid(0, j); });
  std::vector<double> xs(byX.size());
  for (size_t i = 0; i < byX.size(); ++i) xs[i] = mid(0, byX[i]);
  // A pair whose mid-points differ by more than reach in x or y has bound = |Δm| − r_a − r_b >
  // the best so far (+ a margin far above the rounding of the bound): the all-pairs scan below
  // would skip it too, so scanning only the others, in the same order with the same test, gives
  // the same pair, bit for bit.
  const double margin = 1e-9 * extent;
  std::vector<int> candidates;
  candidates.reserve(static_cast<size_t>(links));
  for (int a = 0; a < links - 2; ++a) {
    const Point a0 = P.col(a), a1 = P.col(a + 1);
    const Point ma = 0.5 * (a0 + a1);
    const double ra = 0.5 * (a1 - a0).norm();
    candidates.clear();
    if (std::isfinite(c.distance)) {
      const double reach = c.distance + ra + rmax + margin;
      if (reach < 0.0) continue;  // every bound ≥ −r_a − r_b exceeds a crossing this deep
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
      const Point b0 = P.col(b), b1 = P.col(b + 1);
      const double rb = 0.5 * (b1 - b0).norm();
      // bounding circles: a lower bound of the pair's distance, exact evaluation only if it
      // could beat the best so far
      const double bound = (0.5 * (b0 + b1) - ma).norm() - ra - rb;
      if (bound >= c.distance) continue;
      Point on;
      const double d = segmentSegment(a0, a1, b0, b1, on);
      if (d < c.distance) {
        c.distance = d;
        c.linkA = a;
        c.linkB = b;
        c.point = on;
      }
    }
  }
  return c;
}

std::vector<GeometricContact> locateGeometricContacts(EquilibriumProblem& problem, const continuation::Branch& branch,
                                                      const std::vector<ContactSet>& locked, double tolerance,
                                                      const continuation::Interrupt& interrupt) {
  std::vector<GeometricContact> found;
  const Chain& chain = problem.chain();
  const int n = chain.size();
  const size_t count = branch.points.size();
  if (count < 2) return found;
  const double lambdaScale = problem.scales().parameter;
  for (bool base : {true, false}) {
    if (base && problem.wallIsBoundary()) continue;  // the wall is a constraint: WC / WR (contact.h)
    std::vector<double> d = scannedDistances(chain, branch, base);
    for (size_t i = 0; i + 1 < count; ++i) {
      if ((d[i] > 0.0) == (d[i + 1] > 0.0) || !std::isfinite(d[i]) || !std::isfinite(d[i + 1])) continue;
      // a sign change: the clearances themselves on both sides (a bound has only their sign)
      d[i] = distanceAt(chain, branch.points[i].u.head(n), base);
      d[i + 1] = distanceAt(chain, branch.points[i + 1].u.head(n), base);
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
          const double f = distanceAt(chain, e.u.head(n), base);
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
    for (const PointReport& p : all) locked.push_back(p.locked);
    found.list = locateGeometricContacts(problem, branch, locked, 1e-12, options.interrupt);
  }
  for (const GeometricContact& g : found.list) {
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
