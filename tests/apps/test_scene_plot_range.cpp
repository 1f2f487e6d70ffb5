#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "scene/plot_range.h"

using namespace buckle::scene;

TEST_CASE("niceRange: round tic steps that contain the data", "[plot]") {
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{{0.3, 7.9}, {-12.0, 0.0}, {1e-9, 3e-9}, {-2e7, 5e6}}) {
    const auto [a, b] = niceRange(lo, hi);
    CHECK(a <= lo);
    CHECK(b >= hi);
    // the widening is less than one tic step (a sixth or so of the range) on either side
    CHECK(lo - a <= 0.5 * (hi - lo));
    CHECK(b - hi <= 0.5 * (hi - lo));
    // both ends on a multiple of a round step 1, 2 or 5 × 10^k near a sixth of the range
    const double mag = std::pow(10.0, std::floor(std::log10((hi - lo) / 6.0)));
    bool round = false;
    for (double m : {1.0, 2.0, 5.0, 10.0}) {
      const double ka = a / (m * mag), kb = b / (m * mag);
      round = round || (std::abs(ka - std::round(ka)) < 1e-6 && std::abs(kb - std::round(kb)) < 1e-6);
    }
    CHECK(round);
  }
  const auto [a, b] = niceRange(2.0, 2.0);  // a point: a range around it
  CHECK(a < 2.0);
  CHECK(b > 2.0);
}

TEST_CASE("framedNiceRange: data at a round end are framed apart from the axis line", "[plot]") {
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{{-2.5, 0.0}, {0.0, 1.7}, {0.3, 7.9}, {-12.0, 0.0}}) {
    const auto [a, b] = framedNiceRange(lo, hi);
    const auto [na, nb] = niceRange(lo, hi);
    // never closer than the margin to the data, and never wider than the margin beyond the round range
    CHECK(lo - a >= kFrameMargin * (nb - na) * (1 - 1e-12));
    CHECK(b - hi >= kFrameMargin * (nb - na) * (1 - 1e-12));
    CHECK(a >= na - kFrameMargin * (nb - na) * (1 + 1e-12));
    CHECK(b <= nb + kFrameMargin * (nb - na) * (1 + 1e-12));
  }
  // an end the round range keeps away from the data stays round: 0.3 .. 7.9 → [0, 8]
  CHECK(framedNiceRange(0.3, 7.9).first == niceRange(0.3, 7.9).first);
  CHECK(framedNiceRange(-2.5, 0.0).second > 0.0);  // Fx = 0 is inside, not on the frame
}

TEST_CASE("framedRange: the whole of a smooth curve, the bulk of a curve through a pole", "[plot]") {
  std::vector<double> smooth;
  for (int i = 0; i <= 200; ++i) smooth.push_back(std::sin(0.05 * i) * 3.0 + 1.0);
  const double lo = *std::min_element(smooth.begin(), smooth.end()), hi = *std::max_element(smooth.begin(), smooth.end());
  std::vector<double> copy = smooth;
  const auto [a, b] = framedRange(copy);
  CHECK(a == lo);
  CHECK(b == hi);

  // K = 1/C with C through zero at x = 0.5: the samples nearest the pole reach ±1e4, the rest is O(1)
  std::vector<double> pole;
  for (int i = 0; i <= 200; ++i) {
    const double x = (i + 0.5) / 201.0 - 0.5;
    pole.push_back(1.0 / (x * (1.0 + x)) * 1e-2 + 2.0);
  }
  copy = pole;
  const auto [c, d] = framedRange(copy);
  std::vector<double> sorted = pole;
  std::sort(sorted.begin(), sorted.end());
  CHECK(c > sorted.front());  // clipped on both sides
  CHECK(d < sorted.back());
  CHECK(c <= sorted[10]);     // and the 5th to 95th percentile is inside the frame
  CHECK(d >= sorted[190]);

  // a constant with one pole value: the constant stays in view, the pole does not stretch it
  std::vector<double> flat(100, 5.0);
  flat.push_back(1e9);
  const auto [e, f] = framedRange(flat);
  CHECK(e == 5.0);
  CHECK(f == Approx(10.0));

  std::vector<double> none{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()};
  const auto [g, h] = framedRange(none);
  CHECK(g > h);
}

TEST_CASE("symlogThreshold: a symmetric-log axis for both signs over decades, scale-free", "[plot]") {
  for (double unit : {1.0, 1e-8, 1e8}) {
    INFO("unit " << unit);
    // a stiffness from 3 (unit) through a pole to −2000 (unit): both signs, three decades
    std::vector<double> v;
    for (int i = 0; i < 100; ++i) v.push_back(unit * (3.0 + i * 0.5));
    for (int i = 0; i < 20; ++i) v.push_back(-unit * (10.0 + 100.0 * i));
    const double lo = *std::min_element(v.begin(), v.end()), hi = *std::max_element(v.begin(), v.end());
    const double c = symlogThreshold(v, lo, hi);
    // the 10th percentile of the magnitudes is about 7.5 (unit): the linear part is one decade of unit
    CHECK(c == Approx(unit).epsilon(1e-12));
    // asinh(y/c) is monotone and maps the largest magnitude a few units out (logarithmic there)
    CHECK(std::asinh(lo / c) < std::asinh(-10.0 * unit / c));
    // one sign only: a log or linear axis serves
    std::vector<double> positive(v.begin(), v.begin() + 100);
    CHECK(symlogThreshold(positive, unit * 3.0, unit * 52.5) == 0.0);
    // both signs within two decades of the threshold: linear
    const std::vector<double> narrow{-2.0 * unit, -1.0 * unit, 1.0 * unit, 5.0 * unit};
    CHECK(symlogThreshold(narrow, -2.0 * unit, 5.0 * unit) == 0.0);
  }
}
