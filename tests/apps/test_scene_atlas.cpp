// The atlas: straight-chain stability ⇔ κ > 0, the first critical force against eq 17 for three
// segments, supercritical post-buckling in the paper's range (docs/mechanics.md, "What the physics does"),
// the same answers whatever the thread count, and shares computed apart (as MPI ranks do) that
// make the whole atlas.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

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

namespace {

// Same cell, field by field; NaN equals NaN (a cell without a critical load).
void checkSameCell(const AtlasCell& a, const AtlasCell& b) {
  INFO("a = " << a.a << ", L0 = " << a.L0);
  CHECK(a.kappa == b.kappa);
  CHECK(a.straightStable == b.straightStable);
  CHECK((std::isnan(a.firstCritical) ? std::isnan(b.firstCritical) : a.firstCritical == b.firstCritical));
  CHECK(a.firstShape == b.firstShape);
  CHECK(a.postBuckling == b.postBuckling);
  CHECK(a.postSlope == b.postSlope);
  CHECK(a.error == b.error);
}

}  // namespace

TEST_CASE("atlas shares: computed apart, packed and unpacked, they make the whole atlas", "[scene][atlas]") {
  AtlasOptions o;
  o.x = {"a", 0.1, 20.0, 7};  // a/b up to 20: cells that fail, with their error message
  o.y = {"L0", 0.1, 3.0, 4};
  o.threads = 1;
  const std::vector<AtlasCell> whole = buckle::scene::computeAtlas(o);
  REQUIRE(std::count_if(whole.begin(), whole.end(), [](const AtlasCell& c) { return c.postBuckling == "failed"; }) > 0);
  REQUIRE(std::count_if(whole.begin(), whole.end(), [](const AtlasCell& c) { return c.postBuckling == "supercritical"; }) > 0);
  for (int parts : {2, 3}) {  // 28 cells: an even split and an uneven one
    std::vector<AtlasCell> gathered = buckle::scene::atlasGrid(o);
    size_t total = 0;
    for (int part = 0; part < parts; ++part) {
      const buckle::scene::AtlasShare share{part, parts};
      std::vector<AtlasCell> own = buckle::scene::atlasGrid(o);
      const size_t computed = buckle::scene::computeCells(own, share, 1, buckle::continuation::Interrupt{});
      CHECK(computed == share.size(own.size()));
      total += computed;
      for (size_t k = 0; k < own.size(); ++k)
        if (!share.owns(k)) CHECK(own[k].postBuckling == "not computed");
      buckle::scene::unpackAtlasCells(buckle::scene::packAtlasCells(own, share), gathered);
    }
    CHECK(total == whole.size());
    for (size_t k = 0; k < whole.size(); ++k) checkSameCell(gathered[k], whole[k]);
  }
  const buckle::scene::AtlasShare first{0, 2};
  const std::string bytes = buckle::scene::packAtlasCells(whole, first);
  std::vector<AtlasCell> grid = buckle::scene::atlasGrid(o);
  CHECK_THROWS_WITH(buckle::scene::unpackAtlasCells(bytes.substr(0, bytes.size() - 1), grid),
                    Catch::Contains("ends early"));
  std::vector<AtlasCell> small(3);
  CHECK_THROWS_WITH(buckle::scene::unpackAtlasCells(bytes, small), Catch::Contains("outside the grid of 3"));
}

TEST_CASE("an interrupted atlas starts no cell and says why", "[scene][atlas]") {
  AtlasOptions o;
  o.x = {"a", 0.5, 0.6, 3};
  o.y = {"L0", 2.0, 2.5, 2};
  std::atomic<bool> stop{true};
  buckle::continuation::Interrupt interrupt;
  interrupt.watch(&stop, "stop requested");
  std::vector<AtlasCell> cells = buckle::scene::atlasGrid(o);
  CHECK(buckle::scene::computeCells(cells, buckle::scene::AtlasShare{}, 2, interrupt) == 0);
  for (const AtlasCell& c : cells) {
    CHECK(c.postBuckling == "not computed");
    CHECK(c.error == "stopped early: stop requested");
    CHECK(std::isnan(c.firstCritical));
    CHECK(c.kappa == Approx(c.L0 - 2.0 * (1.0 - c.a * c.a)));
  }
}
