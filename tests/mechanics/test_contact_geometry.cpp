#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/unloaded_shape.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The Fig 9/10 chain of data/scenes/fig9_fig10.json, case a/b = 0.75 (fig10_shapes_Fx): three
// segments a = 0.75, b = k = 1, preloads making q0 = (θ, −2θ, θ), cos θ = 7/8, the unloaded
// shape (L0 = 2.25 before), all lengths times `length` and stiffnesses times `stiffness`.
Chain fig10Chain(double length = 1.0, double stiffness = 1.0) {
  const double theta = std::acos(7.0 / 8.0);
  const double q0[3] = {theta, -2.0 * theta, theta};
  std::vector<SegmentParameters> segments;
  for (double q : q0) {
    SegmentParameters p = preloadsForAngle(SegmentParameters::symmetric(0.75, 1.0, 1.0, 2.25), q).parameters;
    p.a1 *= length, p.a2 *= length, p.b1 *= length, p.b2 *= length, p.L1_0 *= length, p.L2_0 *= length;
    p.k1 *= stiffness, p.k2 *= stiffness;
    segments.push_back(p);
  }
  return Chain(segments);
}
Vector fig10Q0() {
  const double theta = std::acos(7.0 / 8.0);
  Vector q(3);
  q << theta, -2.0 * theta, theta;
  return q;
}

// Independent signed distance to the wall x = 0: every triangle vertex written out from the
// segment geometry (absolute angles, apexes at the joints), the clamped first triangle left out.
double wallDistance(const Chain& chain, const Vector& q) {
  double px = chain.linkLengths()[0], py = 0.0, theta = 0.0, d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < chain.size(); ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    const double before = theta, after = theta + q[i];
    if (i > 0) {
      d = std::min(d, px);
      for (double s : {-1.0, 1.0}) d = std::min(d, px - p.b1 * std::cos(before) - s * p.a1 * std::sin(before));
    }
    for (double s : {-1.0, 1.0}) d = std::min(d, px + p.b2 * std::cos(after) - s * p.a2 * std::sin(after));
    px += chain.linkLengths()[i + 1] * std::cos(after);
    py += chain.linkLengths()[i + 1] * std::sin(after);
    theta = after;
  }
  return d;
}

// Newton on ∇Π(q) = 0 of the free end under the end force (Fx, 0) (chain.h only).
bool equilibrium(const Chain& chain, double Fx, Vector& q) {
  const int n = chain.size();
  Vector g(n);
  Matrix H(n, n);
  const Wrench W(Fx, 0.0, 0.0);
  const double unit = chain.segment(0).parameters().k1 * std::pow(chain.segment(0).parameters().b1, 2);
  for (int it = 0; it < 60; ++it) {
    totalPotentialGradient(chain, q, W, g);
    if (g.cwiseAbs().maxCoeff() <= 1e-14 * unit) return true;
    totalPotentialHessian(chain, q, W, H);
    q -= H.fullPivLu().solve(g);
  }
  totalPotentialGradient(chain, q, W, g);
  return g.cwiseAbs().maxCoeff() <= 1e-12 * unit;
}

// The BC special points of the Fx path 0 → −2 of the chain.
std::vector<SpecialPointReport> baseContacts(const Chain& chain) {
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench::Zero()), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions options;
  const double forceUnit = chain.segment(0).parameters().k1 * chain.segment(0).parameters().b1;
  options.tracer.lambdaMin = -2.0 * forceUnit;
  options.tracer.lambdaMax = 0.0;
  options.tree.branchSwitching = 0;
  const EquilibriumBranches b =
      traceEquilibria(problem, fig10Q0(), 0.0, cont::InitialDirection::decreasingLambda(), options);
  std::vector<SpecialPointReport> found;
  for (const SpecialPointReport& s : b.reports.at(0).specialPoints)
    if (s.type == EventType::BaseContact) found.push_back(s);
  return found;
}

// Independent outline of link m's body (contact_geometry.h): the triangles written out from the
// segment geometry (apex at the joint, base corners ±a at b before / after it along the links).
using Tri = std::array<Eigen::Vector2d, 3>;
std::vector<std::vector<Tri>> linkTriangles(const Chain& chain, const Vector& q) {
  const int n = chain.size();
  std::vector<std::vector<Tri>> links(size_t(n + 1));
  Eigen::Vector2d joint(chain.linkLengths()[0], 0.0);
  double theta = 0.0;
  for (int i = 0; i < n; ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    const double before = theta, after = theta + q[i];
    const Eigen::Vector2d db(std::cos(before), std::sin(before)), nb(-std::sin(before), std::cos(before));
    const Eigen::Vector2d da(std::cos(after), std::sin(after)), na(-std::sin(after), std::cos(after));
    links[size_t(i)].push_back({joint, joint - p.b1 * db + p.a1 * nb, joint - p.b1 * db - p.a1 * nb});
    links[size_t(i) + 1].push_back({joint, joint + p.b2 * da + p.a2 * na, joint + p.b2 * da - p.a2 * na});
    joint += chain.linkLengths()[size_t(i) + 1] * da;
    theta = after;
  }
  return links;
}

// Distance of two triangles that do not overlap: the smallest vertex-to-edge distance.
double pointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& s0, const Eigen::Vector2d& s1) {
  const Eigen::Vector2d d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - s0 - t * d).norm();
}
double vertexEdgeDistance(const Tri& A, const Tri& B) {
  double d = std::numeric_limits<double>::infinity();
  for (int e = 0; e < 3; ++e)
    for (int k = 0; k < 3; ++k)
      d = std::min({d, pointSegmentDistance(A[size_t(k)], B[size_t(e)], B[size_t(e + 1) % 3]),
                    pointSegmentDistance(B[size_t(k)], A[size_t(e)], A[size_t(e + 1) % 3])});
  return d;
}
// Overlap of the projections on direction u (> 0: they overlap by that much).
double projectedOverlap(const Tri& A, const Tri& B, const Eigen::Vector2d& u) {
  double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
  for (const auto& v : A) a0 = std::min(a0, u.dot(v)), a1 = std::max(a1, u.dot(v));
  for (const auto& v : B) b0 = std::min(b0, u.dot(v)), b1 = std::max(b1, u.dot(v));
  return std::min(a1 - b0, b1 - a0);
}
// Signed distance by brute force over directions: overlapping (every direction's projections
// overlap) → minus the smallest overlap over all directions (the depth: 20 000 directions, then a
// ternary search about the best); else the vertex-edge distance.
double bruteSignedDistance(const Tri& A, const Tri& B) {
  for (int k = 0; k < 180; ++k) {  // separated along a coarse direction: disjoint (the common case)
    const double t = M_PI * k / 180.0;
    if (projectedOverlap(A, B, Eigen::Vector2d(std::cos(t), std::sin(t))) < 0.0) return vertexEdgeDistance(A, B);
  }
  auto overlap = [&](double t) { return projectedOverlap(A, B, Eigen::Vector2d(std::cos(t), std::sin(t))); };
  double depth = std::numeric_limits<double>::infinity(), best = 0.0;
  const double spacing = M_PI / 20000.0;
  for (int k = 0; k < 20000; ++k)
    if (overlap(k * spacing) < depth) depth = overlap(k * spacing), best = k * spacing;
  // the overlap is V-shaped at its minimum: ternary search within one spacing of the best direction
  double lo = best - spacing, hi = best + spacing;
  for (int it = 0; it < 200; ++it) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    (overlap(m1) < overlap(m2) ? hi : lo) = overlap(m1) < overlap(m2) ? m2 : m1;
  }
  depth = std::min(depth, overlap(0.5 * (lo + hi)));
  return depth > 0.0 ? -depth : vertexEdgeDistance(A, B);
}
// d_self by every pair of non-adjacent links' triangles.
double bruteSelfClearance(const Chain& chain, const Vector& q, int& linkA, int& linkB) {
  const auto links = linkTriangles(chain, q);
  double best = std::numeric_limits<double>::infinity();
  for (size_t a = 0; a < links.size(); ++a)
    for (size_t b = a + 2; b < links.size(); ++b)
      for (const Tri& A : links[a])
        for (const Tri& B : links[b]) {
          const double d = bruteSignedDistance(A, B);
          if (d < best) best = d, linkA = int(a), linkB = int(b);
        }
  return best;
}

}  // namespace

TEST_CASE("fig10_shapes_Fx: the chain reaches the clamp's wall at the load an independent bisection finds",
          "[contact_geometry]") {
  const Chain chain = fig10Chain();
  const std::vector<SpecialPointReport> bc = baseContacts(chain);
  REQUIRE(bc.size() == 1);  // it goes through the wall once, before the shapes drawn at Fx = −1, −1.4
  const SpecialPointReport& s = bc[0];
  CHECK(std::string(label(s.type)) == "BC");
  CHECK(s.refined);
  CHECK(std::abs(wallDistance(chain, s.q)) < 1e-9);
  CHECK(s.contactPoint.x() == Approx(0.0).margin(1e-9));
  // independent: bisection on the signed distance along the branch, equilibria by Newton
  // continued in small load steps from the unloaded shape (no tracer, no KINSOL)
  Vector q = fig10Q0();
  double F = 0.0, step = -0.01;
  Vector qPrev = q;
  double FPrev = F;
  while (wallDistance(chain, q) > 0.0) {
    qPrev = q;
    FPrev = F;
    F += step;
    REQUIRE(equilibrium(chain, F, q));
    REQUIRE(F > -2.0);
  }
  double lo = F, hi = FPrev;  // d(lo) <= 0 < d(hi)
  Vector qLo = q, qHi = qPrev;
  for (int it = 0; it < 200 && hi - lo > 1e-14; ++it) {
    const double mid = 0.5 * (lo + hi);
    Vector qm = 0.5 * (qLo + qHi);
    REQUIRE(equilibrium(chain, mid, qm));
    if (wallDistance(chain, qm) > 0.0) hi = mid, qHi = qm;
    else lo = mid, qLo = qm;
  }
  CHECK(s.F[0] == Approx(0.5 * (lo + hi)).epsilon(1e-9));
  CHECK(s.F[0] == Approx(-0.4616).margin(1e-4));

  // scaled units: lengths × 1e-3, stiffnesses × 1e6: the same event at Fx × (k b) = Fx × 1e3
  const std::vector<SpecialPointReport> scaled = baseContacts(fig10Chain(1e-3, 1e6));
  REQUIRE(scaled.size() == 1);
  CHECK(scaled[0].F[0] == Approx(1e3 * s.F[0]).epsilon(1e-9));
  CHECK((scaled[0].q - s.q).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("base and self clearance: closed forms, the triangles' outlines, and the cut-off misses nothing (n = 50)",
          "[contact_geometry]") {
  // straight chain: the nearest moving vertices are segment 1's distal corners at x = b1 + b2
  // (its apex is joint 1, fixed at x = b1) and segment 2's proximal corners, also at x = 2
  const Chain straight = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const BaseClearance c0 = baseClearance(straight, Vector::Zero(3));
  CHECK(c0.distance == Approx(2.0).epsilon(1e-15));
  CHECK(selfClearance(straight, Vector::Zero(3)).distance > 0.0);
  // Folded into a U (joints 2 and 3 at a right angle): link 3 (the last segment's distal triangle)
  // runs back parallel to link 1 at the distance ℓ = b1 + b2 = 2, its base corner faces link 1's,
  // so d_self = 2 − 2a in closed form (the centre lines stay 2 apart whatever a).
  Vector u(3);
  u << 0.0, M_PI / 2, M_PI / 2;
  for (double a : {0.3, 0.5, 0.9}) {
    const Chain three = Chain::uniform(3, SegmentParameters::symmetric(a, 1.0, 1.0, 2.25));
    const SelfClearance c = selfClearance(three, u);
    INFO("a = " << a);
    CHECK(c.distance == Approx(2.0 - 2.0 * a).epsilon(1e-14));
    CHECK(c.linkA == 1);
    CHECK(c.linkB == 3);
    CHECK(c.point.y() == Approx(a).epsilon(1e-14));  // link 1's upper base corner
  }
  // Past touching (a = 1.1): the corners overlap; the depth is the brute-force one over directions.
  const Chain wide = Chain::uniform(3, SegmentParameters::symmetric(1.1, 1.0, 1.0, 2.25));
  int bruteA = -1, bruteB = -1;
  const double deep = bruteSelfClearance(wide, u, bruteA, bruteB);
  REQUIRE(deep < 0.0);
  CHECK(selfClearance(wide, u).distance == Approx(deep).epsilon(1e-10));
  // four segments folded back: link 3 runs from (1.823, 1.617) down across link 1 (y = 0)
  const Chain four = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  Vector q(4);
  q << 0.0, 2.2, 2.2, 0.0;
  const SelfClearance crossed = selfClearance(four, q);
  CHECK(crossed.distance < 0.0);
  CHECK(crossed.linkA == 1);
  CHECK(crossed.linkB == 3);
  // the bodies meet before the centre lines do: folding by t at joints 2 and 3, the first t at
  // which the triangles overlap leaves every pair of non-adjacent centre lines apart
  {
    double t = 1.0;
    int a = -1, b = -1;
    for (q << 0.0, t, t, 0.0; bruteSelfClearance(four, q, a, b) > 0.0 && t < 2.2; q << 0.0, t, t, 0.0) t += 0.01;
    REQUIRE(t < 2.2);
    const double d = bruteSelfClearance(four, q, a, b);
    CHECK(selfClearance(four, q).distance == Approx(d).epsilon(1e-10));
    const Eigen::Matrix2Xd P = jointPositions(four, q);
    double centreLines = std::numeric_limits<double>::infinity();
    for (int i = 0; i + 1 < P.cols(); ++i)
      for (int j = i + 2; j + 1 < P.cols(); ++j)
        for (int e : {0, 1}) {
          centreLines = std::min(centreLines, pointSegmentDistance(P.col(j + e), P.col(i), P.col(i + 1)));
          centreLines = std::min(centreLines, pointSegmentDistance(P.col(i + e), P.col(j), P.col(j + 1)));
        }
    CHECK(centreLines > 0.1);
  }

  // n = 50, random shapes: the O(n) base clearance equals the independent vertex loop, and the
  // bounding-circle cut-off gives the all-pairs minimum of the independent triangles
  const Chain chain = Chain::uniform(50, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-0.9, 0.9);
  int clear = 0, touching = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Vector qr(50);
    for (int i = 0; i < 50; ++i) qr[i] = angle(rng);
    CHECK(baseClearance(chain, qr).distance == Approx(wallDistance(chain, qr)).epsilon(1e-14));
    int a = -1, b = -1;
    const double all = bruteSelfClearance(chain, qr, a, b);
    const SelfClearance sc = selfClearance(chain, qr);
    INFO("trial " << trial);
    if (all > 0.0) {
      ++clear;
      CHECK(sc.distance == Approx(all).epsilon(1e-13));
    } else {
      ++touching;
      CHECK(sc.distance == Approx(all).epsilon(1e-10));
    }
  }
  CHECK(clear > 0);
  CHECK(touching > 0);
}

TEST_CASE("self clearance: the swept cut-off finds the all-pairs pair on chains that fold onto themselves",
          "[contact_geometry]") {
  // Spirals of 1.3 to 2.7 turns with random wiggles (n = 120): links meet and overlap far along
  // the chain, the case where a sweep could miss a pair; against every pair of the independent
  // triangles.
  const int n = 120;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> wiggle(-0.02, 0.02), turns(1.3, 2.7);
  for (int trial = 0; trial < 4; ++trial) {
    Vector q(n);
    const double total = 2.0 * M_PI * turns(rng);
    for (int i = 0; i < n; ++i) q[i] = total / n * (1.0 - 0.5 * double(i) / n) + wiggle(rng);
    int bestA = -1, bestB = -1;
    const double best = bruteSelfClearance(chain, q, bestA, bestB);
    const SelfClearance sc = selfClearance(chain, q);
    INFO("trial " << trial << ": brute force " << best << " at links " << bestA << ", " << bestB);
    CHECK(sc.distance == Approx(best).epsilon(best > 0.0 ? 1e-13 : 1e-10).margin(1e-13));
    CHECK(sc.linkA == bestA);
    CHECK(sc.linkB == bestB);
  }
}

TEST_CASE("self clearance from a hint: the same nearest pair, and a pair below stopBelow bounds it from above",
          "[contact_geometry]") {
  // Circles of 1.3 to 2.7 turns (the second turn on the first: overlapping far along the chain)
  // and random 50-segment shapes, each hinted with
  // every 7th pair of links: without a stop the hint changes nothing; with a stop between d_self
  // and 0 the search may end at any pair below it, whose distance is then ≥ the brute-force d_self.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> wiggle(-0.02, 0.02), turns(1.3, 2.7), bend(-0.6, 0.6);
  int stopped = 0, overlapping = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const int n = trial < 4 ? 120 : 50;
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    Vector q(n);
    const double total = 2.0 * M_PI * turns(rng);
    for (int i = 0; i < n; ++i) q[i] = trial < 4 ? total / n + wiggle(rng) : bend(rng);
    const SelfClearance exact = selfClearance(chain, q);
    int bruteA = -1, bruteB = -1;
    const double brute = bruteSelfClearance(chain, q, bruteA, bruteB);
    INFO("trial " << trial << ": d_self " << exact.distance << " at " << exact.linkA << ", " << exact.linkB);
    CHECK(exact.distance == Approx(brute).epsilon(brute > 0.0 ? 1e-13 : 1e-10).margin(1e-13));
    if (exact.distance < 0.0) ++overlapping;
    for (int a = 0; a + 2 <= n; a += 7)
      for (int b = a + 2; b <= n; b += 7) {
        SelfClearanceHint hint;
        hint.linkA = a;
        hint.linkB = b;
        bool isExact = false;
        const SelfClearance plain = selfClearance(chain, q, hint, &isExact);
        CHECK(isExact);
        CHECK(plain.distance == exact.distance);
        CHECK((plain.linkA == exact.linkA && plain.linkB == exact.linkB));
        if (exact.distance >= 0.0) continue;
        hint.stopBelow = 0.5 * exact.distance;
        const SelfClearance early = selfClearance(chain, q, hint, &isExact);
        if (!isExact) {
          ++stopped;
          CHECK(early.distance < hint.stopBelow);
          CHECK(early.distance >= exact.distance);
        } else {
          CHECK(early.distance == exact.distance);
        }
        hint.stopBelow = 2.0 * exact.distance;  // below d_self: never met, the search is complete
        CHECK(selfClearance(chain, q, hint, &isExact).distance == exact.distance);
        CHECK(isExact);
      }
  }
  CHECK(overlapping >= 3);
  CHECK(stopped >= 10);
}

namespace {

/// The sign changes (index, entering) of selfClearance between consecutive points, each point's
/// clearance computed afresh: the exact scan the branch scan is checked against.
std::vector<std::pair<int, bool>> exactSelfContacts(const Chain& chain, const cont::Branch& branch) {
  const int n = chain.size();
  std::vector<std::pair<int, bool>> changes;
  for (size_t i = 0; i + 1 < branch.points.size(); ++i) {
    const double a = selfClearance(chain, branch.points[i].u.head(n)).distance;
    const double b = selfClearance(chain, branch.points[i + 1].u.head(n)).distance;
    if ((a > 0.0) != (b > 0.0)) changes.emplace_back(int(i), a > 0.0);
  }
  return changes;
}

/// The self contacts locateGeometricContacts finds along the branch, as (index, entering).
std::vector<std::pair<int, bool>> scannedSelfContacts(EquilibriumProblem& problem, const cont::Branch& branch) {
  std::vector<std::pair<int, bool>> found;
  for (const GeometricContact& g : locateGeometricContacts(problem, branch, {}))
    if (!g.base) found.emplace_back(g.index, g.entering);
  return found;
}

}  // namespace

TEST_CASE("self contacts along a branch: the bounded scan finds every sign change an exact scan finds",
          "[contact_geometry]") {
  // A chain curling into a spiral and back (every joint bent by t, t up and down with steps of
  // varying size, fixed λ: no location, the contacts to the point spacing), its self contacts
  // against the sign changes of selfClearance at every point; in three length units (the bounds
  // and the touching band are relative to the chain's length).
  const int n = 40;
  const double length = GENERATE(1.0, 1e-4, 1e4);
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * length, 1.0 * length, 1.0, 2.25 * length));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench::Zero()), Eigen::Vector3d(1, 0, 0));
  cont::Branch branch;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> step(0.0002, 0.004);
  double t = 0.0;
  for (int sweep = 0; sweep < 4; ++sweep)
    for (int k = 0; k < 300; ++k) {
      t += (sweep % 2 == 0 ? 1.0 : -1.0) * step(rng);
      cont::ContinuationPoint p;
      p.lambda = 0.0;
      p.u = Vector::Zero(problem.dimension());
      for (int i = 0; i < n; ++i) p.u[i] = t * (1.0 + 0.3 * std::sin(0.7 * i));
      branch.points.push_back(p);
    }
  const std::vector<std::pair<int, bool>> exact = exactSelfContacts(chain, branch);
  REQUIRE(exact.size() >= 4);  // the spiral meets itself and separates again, more than once
  CHECK(scannedSelfContacts(problem, branch) == exact);
}

TEST_CASE("self contacts along a branch: unrelated shapes one after another, against the exact scan",
          "[contact_geometry]") {
  // The scan keeps the links' x order from one shape to the next (insertion sort, a full sort
  // once that costs more): here every point is a new random shape, so the order kept is useless
  // and the full sort must take over. The sign changes found are those of selfClearance at each
  // point, and so are the distances at the points around each change.
  const int n = 50;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench::Zero()), Eigen::Vector3d(1, 0, 0));
  cont::Branch branch;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-1.6, 1.6);
  for (int k = 0; k < 200; ++k) {
    cont::ContinuationPoint p;
    p.lambda = 0.0;
    p.u = Vector::Zero(problem.dimension());
    for (int i = 0; i < n; ++i) p.u[i] = (k % 3 == 0 ? 0.2 : 1.0) * angle(rng);
    branch.points.push_back(p);
  }
  const std::vector<std::pair<int, bool>> exact = exactSelfContacts(chain, branch);
  REQUIRE(exact.size() >= 10);
  CHECK(scannedSelfContacts(problem, branch) == exact);
}
