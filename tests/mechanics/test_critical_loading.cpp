// Which linear-buckling problem a path asks (critical_loading.h): the released coordinate along a
// held one, the path's direction without the held components along loads; the closed forms
// (eq 15–18) applied exactly where they hold, and there equal to the O(n) / dense solve.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

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

TEST_CASE("criticalLoadCount: the critical loads passed, against eq 17 and the eigen-solve's list, in any units",
          "[critical_loading]") {
  const CriticalLoading column = criticalLoading(EndCondition::clampedPinned(0.0), 0, Eigen::Vector3d::UnitX());
  const AnalyticBuckling3 an = analyticClampedPinned3(0.5, 1.0, 1.0, 2.25);  // FxU = −0.7063, FxZ = −1.3937
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  CHECK(criticalLoadCount(paper(3), zero, column, 0.999 * an.FxU) == 0);
  CHECK(criticalLoadCount(paper(3), zero, column, 1.001 * an.FxU) == 1);
  CHECK(criticalLoadCount(paper(3), zero, column, 0.999 * an.FxZ) == 1);
  CHECK(criticalLoadCount(paper(3), zero, column, 1.001 * an.FxZ) == 2);
  CHECK(criticalLoadCount(paper(3), zero, column, 2.0) == 0);  // tension never buckles the column
  // long chains: as many as the eigen-solve lists below the load (dense pencil up to 300, the
  // O(n) isolation above), in the paper's units and in lengths ×1e-4, stiffness ×1e8
  for (int n : {40, 300, 1000}) {
    for (const double L : {1.0, 1e-4}) {
      const double K = L == 1.0 ? 1.0 : 1e8;
      const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, K, 2.25 * L));
      LinearBucklingOptions opt;
      opt.count = 12;
      const LinearBucklingResult lb = linearBuckling(chain, Vector::Zero(n), column.end, opt);
      REQUIRE(lb.modes.size() >= 12);
      std::vector<double> compressive;
      for (const BucklingMode& m : lb.modes)
        if (m.lambda < 0.0) compressive.push_back(m.lambda);
      REQUIRE(compressive.size() >= 8);
      std::sort(compressive.begin(), compressive.end(), [](double a, double b) { return a > b; });
      for (int k : {1, 5, 8}) {
        INFO("n = " << n << ", L = " << L << ", between critical loads " << k << " and " << k + 1);
        const double between = 0.5 * (compressive[size_t(k - 1)] + compressive[size_t(k)]);
        CHECK(criticalLoadCount(chain, Vector::Zero(n), column, between) == k);
      }
    }
  }
}
