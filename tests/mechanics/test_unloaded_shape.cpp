#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "buckle/mechanics/unloaded_shape.h"

#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::rejection;

}  // namespace

TEST_CASE("equal preloads on a monotonic segment: the unloaded angle is 0", "[unloaded]") {
  const Segment s(SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const SegmentUnloadedAngle r = unloadedAngle(s);
  REQUIRE(r.found);
  CHECK(r.root.q == 0.0);
  CHECK(r.root.stable);
  CHECK(r.root.stiffness == Approx(1.0 * 2.25 - 2 * (1 - 0.25)).epsilon(1e-12));
}

TEST_CASE("non-monotonic segment: the stable root nearest 0 is chosen, the others reported", "[unloaded]") {
  // κ = b L0 − 2(b² − a²) < 0: q = 0 is an unstable root between two stable ones (Fig 2)
  const Segment s(SegmentParameters::symmetric(0.2, 1.0, 1.0, 1.0));
  REQUIRE(s.straightStiffness() < 0.0);
  const SegmentUnloadedAngle r = unloadedAngle(s);
  REQUIRE(r.found);
  CHECK(r.root.stable);
  CHECK(r.root.q != 0.0);
  CHECK(std::abs(s.torque(r.root.q)) < 1e-12);
  // eq 10: M = 2k sin(q/2) [2(b² − a²) cos(q/2) − b L0] = 0 → cos(q/2) = b L0 / (2 (b² − a²))
  CHECK(std::abs(r.root.q) == Approx(2 * std::acos(1.0 / (2 * 0.96))).epsilon(1e-12));
  REQUIRE(r.others.size() == 2);
  int unstableAtZero = 0, mirror = 0;
  for (const TorqueRoot& o : r.others) {
    if (o.q == 0.0 && !o.stable) ++unstableAtZero;
    if (o.stable && std::abs(o.q + r.root.q) < 1e-12) ++mirror;
  }
  CHECK(unstableAtZero == 1);
  CHECK(mirror == 1);
  // a chain of such segments is not all-stable only if a root is unstable: here all stable
  const UnloadedShape shape = unloadedShape(Chain::uniform(3, SegmentParameters::symmetric(0.2, 1.0, 1.0, 1.0)));
  CHECK(shape.allFound);
  CHECK(shape.allStable);
}

TEST_CASE("round trip: preloads -> unloaded angles -> preloads", "[unloaded]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> A(0.1, 0.8), B(0.7, 1.4), K(0.5, 3.0), L(2.3, 3.0), Q(-0.6, 0.6);
  for (int trial = 0; trial < 40; ++trial) {
    SegmentParameters p;
    p.a1 = A(rng); p.a2 = A(rng); p.b1 = B(rng); p.b2 = B(rng); p.k1 = K(rng); p.k2 = K(rng);
    p.L1_0 = L(rng); p.L2_0 = L(rng);
    const double q0 = Q(rng);
    const PreloadResult pre = preloadsForAngle(p, q0);
    CHECK(pre.parameters.L1_0 + pre.parameters.L2_0 == Approx(p.L1_0 + p.L2_0).epsilon(1e-14));
    const Segment s(pre.parameters);
    CHECK(std::abs(s.torque(q0)) < 1e-12 * (p.k1 + p.k2));
    REQUIRE(pre.stable);
    CHECK(pre.stiffness == Approx(s.stiffness(q0)).epsilon(1e-14));
    // preloads → angle
    const SegmentUnloadedAngle r = unloadedAngle(s);
    REQUIRE(r.found);
    CHECK(r.root.q == Approx(q0).margin(1e-12));
    // angle → preloads again (unchanged)
    const PreloadResult again = preloadsForAngle(pre.parameters, r.root.q);
    CHECK(again.parameters.L1_0 == Approx(pre.parameters.L1_0).epsilon(1e-11));
    CHECK(again.parameters.L2_0 == Approx(pre.parameters.L2_0).epsilon(1e-11));
    // and the original preloads come back from their own unloaded angle
    const SegmentUnloadedAngle r0 = unloadedAngle(Segment(p));
    REQUIRE(r0.found);
    const PreloadResult back = preloadsForAngle(pre.parameters, r0.root.q);
    CHECK(back.parameters.L1_0 == Approx(p.L1_0).epsilon(1e-10));
    CHECK(back.parameters.L2_0 == Approx(p.L2_0).epsilon(1e-10));
  }
}

TEST_CASE("eq 19 check: symmetric geometry, unequal preloads", "[unloaded]") {
  const double a = 0.75, b = 1.0, k = 2.0, q0 = 0.4;
  const PreloadResult pre = preloadsForAngle(SegmentParameters::symmetric(a, b, k, 2.25), q0);
  const double L1 = pre.parameters.L1_0, L2 = pre.parameters.L2_0;
  const double eq19 = 2 * k * (b * b - a * a) * std::sin(q0) - k * L1 * (a * std::cos(q0 / 2) + b * std::sin(q0 / 2)) +
                      k * L2 * (a * std::cos(q0 / 2) - b * std::sin(q0 / 2));
  CHECK(std::abs(eq19) < 1e-12);
  CHECK(L1 < L2);  // spring 1 closes for q > 0: its free length is shorter
}

TEST_CASE("the paper's non-straight start: q0 = (t, -2t, t), cos t = 7/8, ends at (5.5b, 0)", "[unloaded]") {
  for (double aOverB : {0.75, 0.9, 1.1}) {
    const double b = 1.0;
    const double theta = std::acos(7.0 / 8.0);
    const Eigen::Vector3d q0(theta, -2 * theta, theta);
    const std::vector<SegmentParameters> segs =
        preloadsForShape(std::vector<SegmentParameters>(3, SegmentParameters::symmetric(aOverB * b, b, 1.0, 2.25 * b)), q0);
    const Chain chain(segs);
    const UnloadedShape shape = unloadedShape(chain);
    REQUIRE(shape.allFound);
    CHECK(shape.allStable);
    CHECK((shape.q - Vector(q0)).lpNorm<Eigen::Infinity>() < 1e-12);
    const Pose p = endPose(chain, shape.q);
    CHECK(p[0] == Approx(5.5 * b).epsilon(1e-13));
    CHECK(std::abs(p[1]) < 1e-13);
    CHECK(std::abs(p[2]) < 1e-13);
    // segments 1 and 3 get the same preloads, segment 2 the mirrored ones
    CHECK(segs[0].L1_0 == Approx(segs[2].L1_0).epsilon(1e-14));
    CHECK(segs[0].L1_0 + segs[0].L2_0 == Approx(4.5).epsilon(1e-14));
    CHECK(segs[1].L1_0 > segs[1].L2_0);
  }
}

TEST_CASE("impossible preload requests are rejected naming segment and parameter", "[unloaded]") {
  const SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  const double qmax = Segment(p).geometricUpperLimit();
  CHECK_THAT(rejection([&] { preloadsForAngle(p, qmax + 0.01); }), Catch::Contains("q0") && Catch::Contains("limits"));
  CHECK_THAT(rejection([&] { preloadsForAngle(p, qmax); }), Catch::Contains("q0"));
  CHECK_THAT(rejection([&] { preloadsForAngle(p, std::nan("")); }), Catch::Contains("q0"));
  SegmentParameters user = p;
  user.qMaxUser = 0.3;
  CHECK_THAT(rejection([&] { preloadsForAngle(user, 0.4); }), Catch::Contains("q0"));
  CHECK(rejection([&] { preloadsForAngle(user, 0.25); }) == "accepted");
  // a small total free length cannot hold a large angle: a free length would be negative
  const SegmentParameters shortSprings = SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.25);
  CHECK_THAT(rejection([&] { preloadsForAngle(shortSprings, 2.0); }), Catch::Contains("_0 would be"));
  std::vector<SegmentParameters> segs(3, p);
  CHECK_THAT(rejection([&] { preloadsForShape(segs, Eigen::Vector3d(0.1, 3.0, 0.1)); }),
             Catch::Contains("segment 2") && Catch::Contains("q0"));
  CHECK_THAT(rejection([&] { preloadsForShape(segs, Eigen::Vector2d(0.1, 0.1)); }), Catch::Contains("one angle per segment"));
}

TEST_CASE("a root where K_q is zero to rounding is classified by the torque either side, in any units",
          "[unloaded]") {
  // The borderline segment of eq 4, L0 = 2b(1 − (a/b)²): M'(0) = 0 exactly, so K_q(0) is rounding
  // noise whose sign changes with the units. The energy is quartic there; the restoring torque
  // M = −dE/dq either side decides, and must decide the same in every system of units.
  const double a = 0.5, b = 1.0, k = 1.0;
  const double L0 = 2.0 * b * (1.0 - (a / b) * (a / b));
  bool reference = false;
  int systems = 0;
  for (const auto& [length, stiffness] : std::vector<std::pair<double, double>>{
           {1.0, 1.0}, {1e-4, 1e-8}, {1e4, 1e8}, {0.02, 2000.0}, {1e3, 1e-6}, {3.0, 7.0}}) {
    const Segment seg(SegmentParameters::symmetric(a * length, b * length, k * stiffness, L0 * length));
    const SegmentUnloadedAngle u = unloadedAngle(seg);
    REQUIRE(u.found);
    CHECK(u.root.q == 0.0);
    CHECK(std::abs(u.root.stiffness) <= 1e-12 * stiffness * length * length);
    // independent: the signs of M a little way either side of the root
    const bool restoring = seg.torque(-1e-2) > 0.0 && seg.torque(1e-2) < 0.0;
    CHECK(u.root.stable == restoring);
    if (systems++ == 0) reference = u.root.stable;
    CHECK(u.root.stable == reference);
    const TorqueCurve curve = torqueCurve(seg, -1.0, 1.0, 11);
    REQUIRE(curve.equilibria.size() == 1);
    CHECK(curve.equilibria[0].second == reference);
  }
  CHECK(reference);  // the quartic term of the borderline segment is positive (Fig 2's flat-topped curve)
}
