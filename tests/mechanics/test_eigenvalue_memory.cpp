#include <catch2/catch.hpp>

#include <cmath>

#include "buckle/mechanics/eigenvalue_memory.h"

using namespace buckle::mechanics;

namespace {
Vector values(std::initializer_list<double> v) {
  Vector x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double d : v) x[i++] = d;
  return x;
}
}  // namespace

TEST_CASE("EigenvalueMemory: a remembered index's latest value, interpolation between, the spacing beyond",
          "[eigenvalue_memory]") {
  EigenvalueMemory m;
  Vector g(3);
  CHECK_FALSE(m.guesses(0, g));  // nothing remembered: no guess
  m.remember(10, values({-2.0, 1.0}));  // μ10 = −2, μ11 = 1
  REQUIRE(m.guesses(10, g.head(2)));
  CHECK(g[0] == -2.0);
  CHECK(g[1] == 1.0);
  // beyond: the two nearest's spacing (3 per index), both sides
  REQUIRE(m.guesses(12, g.head(2)));
  CHECK(g[0] == 4.0);
  CHECK(g[1] == 7.0);
  REQUIRE(m.guesses(8, g.head(2)));
  CHECK(g[0] == -8.0);
  CHECK(g[1] == -5.0);
  // between: linear interpolation
  m.remember(14, values({13.0}));
  REQUIRE(m.guesses(12, g.head(2)));
  CHECK(g[0] == Approx(5.0).epsilon(1e-15));
  CHECK(g[1] == Approx(9.0).epsilon(1e-15));
  // the latest value of an index replaces the older one
  m.remember(11, values({0.5}));
  REQUIRE(m.guesses(11, g.head(1)));
  CHECK(g[0] == 0.5);
  // non-finite values are not remembered
  m.remember(20, values({std::nan("")}));
  REQUIRE(m.guesses(20, g.head(1)));
  CHECK(g[0] == Approx(38.0).epsilon(1e-15));  // from μ14 = 13 and μ11 = 0.5: spacing 12.5/3
}

TEST_CASE("EigenvalueMemory: one value alone moves by its own magnitude per index, the oldest is forgotten first",
          "[eigenvalue_memory]") {
  EigenvalueMemory m;
  Vector g(1);
  m.remember(5, values({-0.25}));
  REQUIRE(m.guesses(7, g));
  CHECK(g[0] == 0.25);  // −0.25 + 2·0.25
  REQUIRE(m.guesses(4, g));
  CHECK(g[0] == -0.5);
  // kSize more indices: index 5 is forgotten, the rest kept
  for (int k = 0; k < EigenvalueMemory::kSize; ++k) m.remember(100 + k, values({double(k)}));
  REQUIRE(m.guesses(100, g));
  CHECK(g[0] == 0.0);
  REQUIRE(m.guesses(100 + EigenvalueMemory::kSize - 1, g));
  CHECK(g[0] == double(EigenvalueMemory::kSize - 1));
  REQUIRE(m.guesses(5, g));
  CHECK(g[0] == -95.0);  // extrapolated from indices 100 and 101 (spacing 1), not the forgotten −0.25
  // remembering an index again makes it the latest: it survives the next kSize − 1 new ones
  m.remember(100, values({42.0}));
  for (int k = 0; k < EigenvalueMemory::kSize - 1; ++k) m.remember(200 + k, values({double(k)}));
  REQUIRE(m.guesses(100, g));
  CHECK(g[0] == 42.0);
  m.clear();
  CHECK_FALSE(m.guesses(100, g));
}
