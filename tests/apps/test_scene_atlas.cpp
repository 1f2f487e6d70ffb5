// The atlas: straight-chain stability ⇔ κ > 0, the first critical force against eq 17 for three
// segments, supercritical post-buckling in the paper's range (docs/mechanics.md, "What the physics does"),
// and the same answers whatever the thread count.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

#include "scene/atlas.h"

using buckle::scene::AtlasCell;
using buckle::scene::AtlasOptions;

TEST_CASE("atlas over a/b x L0/b matches eq 17 and the stability condition", "[scene][atlas]") {
  AtlasOptions o;
  o.x = {"a", 0.1, 1.1, 6};
  o.y = {"L0", 1.0, 3.0, 5};
  o.n = 3;
  o.threads = 2;
  const auto cells = buckle::scene::computeAtlas(o);
  REQUIRE(cells.size() == 30);
  int stable = 0;
  for (const AtlasCell& c : cells) {
    INFO("a = " << c.a << ", L0 = " << c.L0 << ": " << c.postBuckling << " " << c.error);
    const double kappa = c.L0 - 2.0 * (1.0 - c.a * c.a);
    CHECK(c.kappa == Approx(kappa));
    if (std::abs(kappa) < 1e-9) continue;
    CHECK(c.straightStable == (kappa > 0.0));
    if (kappa > 0.0) {
      ++stable;
      CHECK(c.firstCritical == Approx((std::sqrt(21.0) - 14.0) / 10.0 * kappa).epsilon(1e-10));
      CHECK(c.firstShape == "U");
      CHECK(c.postBuckling == "supercritical");
      CHECK(c.postSlope > 0.0);
    } else {
      CHECK(c.postBuckling == "unstable start");
    }
  }
  CHECK(stable > 10);

  o.threads = 1;
  const auto serial = buckle::scene::computeAtlas(o);
  for (size_t i = 0; i < cells.size(); ++i) {
    CHECK(serial[i].postBuckling == cells[i].postBuckling);
    if (std::isfinite(cells[i].firstCritical)) CHECK(serial[i].firstCritical == cells[i].firstCritical);
  }
}

TEST_CASE("atlas over n x L0/b", "[scene][atlas]") {
  AtlasOptions o;
  o.x = {"n", 2, 6, 5};
  o.y = {"L0", 2.0, 2.5, 2};
  const auto cells = buckle::scene::computeAtlas(o);
  REQUIRE(cells.size() == 10);
  for (const AtlasCell& c : cells) {
    CHECK(c.n == static_cast<int>(std::lround(c.x)));
    CHECK(c.straightStable);
    CHECK(c.firstCritical < 0.0);
    CHECK(c.postBuckling == "supercritical");
  }
}

TEST_CASE("atlas options are validated", "[scene][atlas]") {
  AtlasOptions o;
  o.x = {"a", 0.1, 1.0, 3};
  o.y = {"a", 0.1, 1.0, 3};
  CHECK_THROWS_AS(buckle::scene::validateAtlas(o), std::invalid_argument);
  o.y = {"k", 0.1, 1.0, 3};
  CHECK_THROWS_WITH(buckle::scene::validateAtlas(o), Catch::Contains("--y must be one of"));
  o.y = {"L0", -1.0, 1.0, 3};
  CHECK_THROWS_WITH(buckle::scene::validateAtlas(o), Catch::Contains("L0/b must be > 0"));
}
