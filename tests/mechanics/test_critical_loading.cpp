// Which linear-buckling problem a path asks (critical_loading.h): the released coordinate along a
// held one, the path's direction without the held components along loads; the closed forms
// (eq 15–18) applied exactly where they hold, and there equal to the O(n) / dense solve.
#include <catch2/catch.hpp>

#include <cmath>

#include "buckle/mechanics/critical_loading.h"
#include "buckle/mechanics/linear_buckling.h"

using namespace buckle::mechanics;

namespace {

Chain paper(int n) { return Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)); }

}  // namespace

TEST_CASE("criticalLoading: a held coordinate is released and loaded along itself, loads keep their free part",
          "[critical_loading]") {
  EndCondition held = EndCondition::clampedPinned(0.0);
  held.control[0] = Control::Held;  // x and y held: displacement control along x
  const CriticalLoading r = criticalLoading(held, 0, Eigen::Vector3d(0.3, 0.7, 0.1));
  CHECK(!r.end.isHeld(EndCoordinate::X));
  CHECK(r.end.isHeld(EndCoordinate::Y));
  CHECK(r.direction == Eigen::Vector3d::UnitX());

  const CriticalLoading l = criticalLoading(EndCondition::clampedPinned(0.0), 0, Eigen::Vector3d(1.0, 0.3, 0.2));
  CHECK(l.end.isHeld(EndCoordinate::Y));
  CHECK(l.direction == Eigen::Vector3d(1.0, 0.0, 0.2));  // y carries a reaction, not a load
  CHECK_THROWS_AS(criticalLoading(held, 3, Eigen::Vector3d::UnitX()), std::invalid_argument);
}

TEST_CASE("clampedPinned3Applies: exactly the paper's symmetric straight three-segment column, where eq 17 is "
          "the solve's answer",
          "[critical_loading]") {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const CriticalLoading column = criticalLoading(EndCondition::clampedPinned(0.0), 0, Eigen::Vector3d::UnitX());
  REQUIRE(clampedPinned3Applies(paper(3), zero, column));
  // eq 17 against the eigen-solve of the same column
  const AnalyticBuckling3 an = analyticClampedPinned3(0.5, 1.0, 1.0, 2.25);
  LinearBucklingOptions opt;
  opt.direction = column.direction;
  const LinearBucklingResult lb = linearBuckling(paper(3), zero, column.end, opt);
  bool u = false, z = false;
  for (const BucklingMode& m : lb.modes) {
    u = u || std::abs(m.lambda - an.FxU) <= 1e-12 * std::abs(an.FxU);
    z = z || std::abs(m.lambda - an.FxZ) <= 1e-12 * std::abs(an.FxZ);
  }
  CHECK(u);
  CHECK(z);

  CHECK(!clampedPinned3Applies(paper(4), Eigen::Vector4d::Zero(), column));
  CHECK(!clampedPinned3Applies(paper(3), Eigen::Vector3d(0.0, 1e-3, 0.0), column));
  CHECK(!clampedPinned3Applies(paper(3), zero, criticalLoading(EndCondition::freeEnd(), 0, Eigen::Vector3d::UnitX())));
  CHECK(!clampedPinned3Applies(paper(3), zero, criticalLoading(EndCondition::clampedPinned(0.0), 0,
                                                                Eigen::Vector3d(1.0, 0.0, 0.5))));
  std::vector<SegmentParameters> segments(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  for (int i = 0; i < 3; ++i) {
    std::vector<SegmentParameters> odd = segments;
    odd[size_t(i)].L2_0 = 2.3;  // one unequal spring
    CHECK(!clampedPinned3Applies(Chain(odd), zero, column));
    odd = segments;
    odd[size_t(i)].a1 = 0.45;
    odd[size_t(i)].a2 = 0.45;  // one segment unlike the others
    CHECK(!clampedPinned3Applies(Chain(odd), zero, column));
  }
}
