// The mirror q → −q (mirror_symmetry.h): when the chain is symmetric, exactly; the equivariance
// F(S u, λ) = S F(u, λ) it rests on; and the tree it gives against the tree traced in full.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <string>

#include "buckle/continuation/interrupt.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/mirror_symmetry.h"

#include "default_scene_path.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

EquilibriumBranchOptions defaultScene(bool mirror) {
  // data/scenes/default.json: Fx from 0 to −2.5, steps 0.02 / 0.05, one switching generation, contact
  EquilibriumBranchOptions o = testing::defaultScenePath();
  o.tracer.detection.lowestEigenvalues = 1;
  o.tree.branchSwitching = 1;
  o.mirror = mirror;
  return o;
}

double relativeDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / std::max(1.0, a.norm());
}

}  // namespace

TEST_CASE("mirror: only an exactly symmetric problem has the reflection", "[mirror_symmetry]") {
  const SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  const Eigen::Vector3d alongX(1, 0, 0);
  {
    EquilibriumProblem problem(Chain::uniform(4, p), EndCondition::clampedPinned(0.0), alongX);
    const cont::Reflection r = mirrorSymmetry(problem);
    REQUIRE(r.enabled());
    CHECK(r.signs == Eigen::VectorXd::Constant(5, -1.0));  // four angles and the y reaction
    CHECK(r.mapText("joint 2 upper limit") == "joint 2 lower limit");
    CHECK(r.mapText("lower, upper") == "upper, lower");
  }
  {  // end held at (x, 0): the x reaction is even
    EquilibriumProblem problem(Chain::uniform(3, p), EndCondition::heldPosition(6.0, 0.0), alongX);
    const cont::Reflection r = mirrorSymmetry(problem);
    REQUIRE(r.enabled());
    CHECK(r.signs == (Eigen::VectorXd(5) << -1, -1, -1, 1, -1).finished());
  }
  // Different triangles keep the symmetry (the springs are mirror images whatever a, b) ...
  SegmentParameters triangles = p;
  triangles.a2 = 0.3;
  triangles.b2 = 1.4;
  CHECK(mirrorSymmetry(EquilibriumProblem(Chain::uniform(3, triangles), EndCondition::clampedPinned(0.0), alongX))
            .enabled());
  // ... different springs, free lengths or user limits do not, nor a transverse load or offset.
  std::vector<SegmentParameters> asymmetric(3, p);
  SECTION("k1 != k2") { asymmetric[1].k2 = 1.0 + 1e-15; }
  SECTION("L1_0 != L2_0") { asymmetric[2].L1_0 = 2.3; }
  SECTION("user limit on one side") { asymmetric[0].qMaxUser = 1.0; }
  SECTION("symmetric user limits keep it") {
    asymmetric[0].qMaxUser = 1.0;
    asymmetric[0].qMinUser = -1.0;
  }
  const bool symmetricLimits = asymmetric[0].qMinUser == -1.0;
  CHECK(mirrorSymmetry(EquilibriumProblem(Chain(asymmetric), EndCondition::clampedPinned(0.0), alongX)).enabled() ==
        symmetricLimits);
  const Chain chain = Chain::uniform(3, p);
  CHECK(!mirrorSymmetry(EquilibriumProblem(chain, EndCondition::clampedPinned(0.0, 0.1), alongX)).enabled());
  CHECK(!mirrorSymmetry(EquilibriumProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 1e-9, 0)))
             .enabled());
  CHECK(!mirrorSymmetry(EquilibriumProblem(chain, EndCondition::freeEnd(Eigen::Vector3d(-1, 0, 1e-3)), alongX))
             .enabled());
  CHECK(mirrorSymmetry(EquilibriumProblem(chain, EndCondition::freeEnd(Eigen::Vector3d(-1, 0, 0)), alongX)).enabled());
}

TEST_CASE("mirror: the equations are equivariant, F(S u, lambda) = S F(u, lambda)", "[mirror_symmetry]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-0.4, 0.4), reaction(-2.0, 2.0);
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.3, 2.25);
  p.a2 = 0.35;  // unequal triangles: still symmetric
  p.b2 = 1.2;
  for (const EndCondition& end : {EndCondition::clampedPinned(-0.3), EndCondition::heldPosition(5.5, 0.0)}) {
    EquilibriumProblem problem(Chain::uniform(7, p), end, Eigen::Vector3d(1, 0, 0));
    const cont::Reflection r = mirrorSymmetry(problem);
    REQUIRE(r.enabled());
    const int N = problem.dimension();
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd u(N), Su(N), F(N), FS(N);
      for (int i = 0; i < N; ++i) u[i] = i < 7 ? angle(rng) : reaction(rng);
      Su = u;
      r.apply(Su);
      const double lambda = reaction(rng);
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(Su, lambda, FS));
      r.apply(F);
      CHECK((FS - F).norm() <= 1e-13 * std::max(1.0, F.norm()));
    }
  }
  // Unequal springs: not equivariant (the reflection is only offered when it holds).
  SegmentParameters q = p;
  q.k2 = 1.5;
  EquilibriumProblem problem(Chain::uniform(7, q), EndCondition::clampedPinned(-0.3), Eigen::Vector3d(1, 0, 0));
  cont::Reflection r;
  r.signs = Eigen::VectorXd::Constant(problem.dimension(), -1.0);
  Eigen::VectorXd u = Eigen::VectorXd::Constant(8, 0.2), Su = -u, F(8), FS(8);
  REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, 0.1, F));
  REQUIRE(buckle::continuation::BoundProblem(problem).residual(Su, 0.1, FS));
  CHECK((FS + F).norm() > 1e-3);
}

TEST_CASE("mirror: the mirrored tree equals the traced one (default scene, n = 3 and 8, contact)",
          "[mirror_symmetry]") {
  const int n = GENERATE(3, 8);
  INFO("n = " << n);
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem tracedProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumProblem mirroredProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(n);
  const EquilibriumBranches traced =
      traceEquilibria(tracedProblem, q0, 0.0, cont::InitialDirection::decreasingLambda(), defaultScene(false));
  const EquilibriumBranches mirrored =
      traceEquilibria(mirroredProblem, q0, 0.0, cont::InitialDirection::decreasingLambda(), defaultScene(true));

  REQUIRE(traced.tree.branches.size() == mirrored.tree.branches.size());
  REQUIRE(traced.tree.branches.size() == size_t(2 * (n - 1) + 1));  // every BP of the straight chain, both sides
  int images = 0, contacts = 0;
  for (size_t b = 0; b < traced.tree.branches.size(); ++b) {
    INFO("branch " << b);
    const cont::Branch &x = traced.tree.branches[b], &y = mirrored.tree.branches[b];
    CHECK(x.mirrorOf == -1);
    if (y.mirrorOf >= 0) ++images;
    CHECK(y.mirrorOf == (y.parentId >= 0 && y.direction < 0 ? int(b) - 1 : -1));
    CHECK(x.parentId == y.parentId);
    CHECK(x.direction == y.direction);
    CHECK(x.stopReason == y.stopReason);
    CHECK(x.stopMessage == y.stopMessage);
    REQUIRE(x.points.size() == y.points.size());
    double worst = 0.0;
    for (size_t k = 0; k < x.points.size(); ++k)
      worst = std::max(worst, relativeDifference(x.points[k].state(), y.points[k].state()));
    CHECK(worst <= 1e-9);
    REQUIRE(x.specialPoints.size() == y.specialPoints.size());
    for (size_t k = 0; k < x.specialPoints.size(); ++k) {
      const cont::SpecialPoint &s = x.specialPoints[k], &t = y.specialPoints[k];
      CHECK(s.type == t.type);
      CHECK(std::abs(s.lambda - t.lambda) <= 1e-12 * std::max(1.0, std::abs(s.lambda)));
      CHECK(relativeDifference(s.u, t.u) <= 1e-10);
      CHECK(s.boundaryName == t.boundaryName);
      CHECK(s.inertiaBefore == t.inertiaBefore);
      CHECK(s.inertiaAfter == t.inertiaAfter);
    }
    REQUIRE(traced.contact[b].size() == mirrored.contact[b].size());
    for (size_t k = 0; k < traced.contact[b].size(); ++k) {
      CHECK(traced.contact[b][k].firstPoint == mirrored.contact[b][k].firstPoint);
      CHECK(traced.contact[b][k].locked == mirrored.contact[b][k].locked);
      contacts += traced.contact[b][k].locked.count();
    }
    CHECK(traced.reports[b].points.size() == mirrored.reports[b].points.size());
  }
  CHECK(images == n - 1);
  CHECK(contacts > 0);  // the children reach joint limits and go on locked
}

TEST_CASE("mirror: no image when the scene is not symmetric", "[mirror_symmetry]") {
  std::vector<SegmentParameters> segments(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  segments[2].qMaxUser = 1.2;  // a stop on one side of one joint: the pitchforks stay symmetric
  const Chain chain(segments);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = defaultScene(true);
  o.tracer.lambdaMin = -1.2;
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(4);
  const EquilibriumBranches r = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(r.tree.branches.size() > 1);
  for (const cont::Branch& b : r.tree.branches) CHECK(b.mirrorOf == -1);
}

TEST_CASE("mirror: an image's base and self contacts, mirrored from its source, equal those located on it",
          "[mirror_symmetry]") {
  // traceEquilibria reports an image branch with its source's contacts mirrored
  // (mirrored(Reflection, GeometricContact)); the independent route locates them on the image's
  // own points (reportBranch without given contacts: Illinois on the image's distances, Newton
  // solves with the image's locked joints). Also in a tree interrupted after its second image
  // (no contact stretches then: the reports of an interrupted run).
  const int n = GENERATE(8, 12);
  const bool interrupt = GENERATE(false, true);
  INFO("n = " << n << (interrupt ? ", interrupted" : ""));
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = defaultScene(true);
  std::atomic<bool> stop{false};
  int imagesFinished = 0;
  if (interrupt) {
    o.tracer.interrupt = cont::Interrupt().watch(&stop, "test stop");
    o.tree.onBranch = [&](const cont::BranchTree&, const cont::Branch& finished) {
      if (finished.mirrorOf >= 0 && ++imagesFinished == 2) stop = true;
    };
  }
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  int geometric = 0, images = 0, lockedPoints = 0;
  for (size_t b = 0; b < r.tree.branches.size(); ++b) {
    const cont::Branch& branch = r.tree.branches[b];
    // every point's largest compression (one residual per point) against ContactProblem's, joint by joint
    for (const PointReport& p : r.reports[b].points) {
      if (p.locked.empty()) continue;
      ++lockedPoints;
      ContactProblem contact(problem, p.locked);
      const cont::ContinuationPoint& at = branch.points[size_t(p.index)];
      double largest = 0.0;
      for (const LockedJoint& l : p.locked.joints())
        largest = std::max(largest, contact.compression(*contact.createWorkspace(), at.u, at.lambda, l.joint));
      CHECK(p.contactTorque == largest);
    }
    if (branch.mirrorOf < 0) continue;
    ++images;
    INFO("branch " << b << " (image of " << branch.mirrorOf << ")");
    GeometricContacts located;  // not given: located here on the image
    const BranchReport own = reportBranch(problem, branch, o.report, r.contact[b], &located);
    const BranchReport& reported = r.reports[b];
    REQUIRE(own.specialPoints.size() == reported.specialPoints.size());
    for (size_t k = 0; k < own.specialPoints.size(); ++k) {
      const SpecialPointReport &x = own.specialPoints[k], &y = reported.specialPoints[k];
      CHECK(label(x.type) == std::string(label(y.type)));
      CHECK(x.index == y.index);
      CHECK(x.note == y.note);
      CHECK(x.shape == y.shape);
      CHECK(x.stabilityBefore == y.stabilityBefore);
      CHECK(x.stabilityAfter == y.stabilityAfter);
      CHECK(x.refined == y.refined);
      CHECK(std::abs(x.lambda - y.lambda) <= 1e-13 * std::max(1.0, std::abs(x.lambda)));
      CHECK(relativeDifference(x.q, y.q) <= 1e-12);
      CHECK(relativeDifference(x.F, y.F) <= 1e-12);
      if (x.type == EventType::BaseContact || x.type == EventType::SelfContact) {
        ++geometric;
        CHECK((x.contactPoint - y.contactPoint).norm() <= 1e-12 * std::max(1.0, x.contactPoint.norm()));
      }
    }
    // the mirror of the source's contacts, one by one, against those located on the image
    GeometricContacts source;
    reportBranch(problem, r.tree.branches[size_t(branch.mirrorOf)], o.report, r.contact[size_t(branch.mirrorOf)],
                 &source);
    REQUIRE(source.list.size() == located.list.size());
    for (size_t k = 0; k < located.list.size(); ++k) {
      const GeometricContact m = mirrored(mirrorSymmetry(problem), source.list[k]);
      const GeometricContact& g = located.list[k];
      CHECK(m.base == g.base);
      CHECK(m.entering == g.entering);
      CHECK(m.located == g.located);
      CHECK(m.index == g.index);
      CHECK(m.segment == g.segment);
      CHECK(m.linkA == g.linkA);
      CHECK(m.linkB == g.linkB);
      CHECK(std::abs(m.lambda - g.lambda) <= 1e-13 * std::max(1.0, std::abs(g.lambda)));
      CHECK(relativeDifference(m.u, g.u) <= 1e-12);
      CHECK((m.point - g.point).norm() <= 1e-12 * std::max(1.0, g.point.norm()));
      // the mirror itself: u → S u (every joint angle and the y reaction change sign), y → −y
      CHECK(m.u.head(n) == -source.list[k].u.head(n));
      CHECK(m.point.y() == -source.list[k].point.y());
      CHECK_FALSE((std::signbit(m.point.y()) && m.point.y() == 0.0));  // +0 on the axis, as recomputed
    }
  }
  CHECK(r.tree.interrupted == interrupt);
  CHECK(images == (interrupt ? 2 : n - 1));
  CHECK(geometric > 0);  // the children's coils reach the wall or themselves
  CHECK((lockedPoints > 0) == !interrupt);  // joints lock on the contact stretches only
}

TEST_CASE("mirror: a held self contact's image holds the mirrored chain with the same gap and force",
          "[mirror_symmetry][self_contact]") {
  // a symmetric chain at q and −q: the image of vertex v on edge e is v's other-side corner on the
  // same triangle's other side edge, its gap and its derivatives' sizes the same
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-0.6, 0.6);
  const int n = 7;
  const Chain chain(std::vector<SegmentParameters>(size_t(n), SegmentParameters::symmetric(0.3, 1.0, 1.0, 2.25)));
  int checked = 0;
  for (int trial = 0; trial < 10; ++trial) {
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = angle(rng);
    const Eigen::Matrix2Xd P = jointPositions(chain, q), Pm = jointPositions(chain, -q);
    for (const int corner : {0, 3, 4})
      for (int edge = 0; edge < 3; ++edge)
        for (const bool distal : {false, true}) {
          const SelfContact c{WallVertex{6, corner}, TriangleEdge{2, distal, edge}};
          ContactSet set;
          set.hold(c);
          const std::vector<ContactStretch> image = mirrored(std::vector<ContactStretch>{ContactStretch{0, set}});
          REQUIRE(image[0].locked.selfCount() == 1);
          const SelfContact m = image[0].locked.self()[0];
          CHECK(mirrorText(c.label()) == m.label());
          const SelfContactGap g = selfContactGap(chain, q, P, c), gm = selfContactGap(chain, -q, Pm, m);
          CHECK(gm.gap == Approx(g.gap).margin(1e-13));
          // (a base edge runs from its +a to its −a corner: the image runs the other way)
          CHECK(gm.along == Approx(edge == 0 ? 1.0 - g.along : g.along).margin(1e-13));
          ++checked;
        }
  }
  CHECK(checked == 180);
  CHECK(mirrorText("8d- on 3p[j,+]; 2p+ on 5d[+,-]") == "8d+ on 3p[j,-]; 2p- on 5d[+,-]");
}
