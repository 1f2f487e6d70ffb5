// apps/scene/output_numbers.cpp against the independent formulation it replaces: glibc's
// snprintf "%.*g" for the text and snprintf + strtod for the rounding. Every magnitude from
// subnormal to huge, both signs, and the hard cases: decimals that end in 5 one digit past the
// precision (ties of the decimal rounding) with their neighbouring doubles, carries across a
// decade (9.99…95), powers of ten, integers, zeros.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/output_numbers.h"

using buckle::scene::appendGeneral;
using buckle::scene::appendRoundedJson;
using buckle::scene::roundedSignificant;

namespace {

std::vector<double> hardValues() {
  std::mt19937_64 random(20261203);
  std::uniform_real_distribution<double> mantissa(1.0, 10.0);
  std::uniform_int_distribution<int> exponent(-320, 300), small(-30, 30), digit(0, 9);
  std::vector<double> v{0.0, -0.0, 1.0, -1.0, 0.5, 2.25, 1e-5, 1e-4, 1e11, 1e12, 123456789012.0, 1e15, 1e16,
                        1e17, 5e-324, 1.7976931348623157e308, 2.2250738585072014e-308, 0.1, 1.0 / 3.0, -2.0 / 3.0,
                        9.9999995, 999999.5, 99999950.0, 0.000099999995, 999999999999.5, 0.99999999999995};
  for (int e = -30; e <= 30; ++e)
    for (double m : {1.0, 9.99999, 9.999999999999}) {
      const double p = m * std::pow(10.0, e);
      for (double y : {p, std::nextafter(p, 0.0), std::nextafter(p, 1e300)}) v.push_back(y);
    }
  for (int k = 0; k < 20000; ++k) {
    v.push_back((k % 2 ? -1.0 : 1.0) * mantissa(random) * std::pow(10.0, exponent(random)));
    v.push_back((k % 2 ? -1.0 : 1.0) * mantissa(random) * std::pow(10.0, small(random)));
  }
  // decimals of 3..17 digits ending in 5 (ties at every precision below them) and 9…95 (carries),
  // with the doubles on either side
  for (int k = 0; k < 6000; ++k) {
    const int len = 3 + k % 15;
    std::string s;
    for (int i = 0; i < len - 1; ++i) s += char('0' + (k % 7 == 0 ? 9 : digit(random)));
    if (s[0] == '0') s[0] = '1';
    s += '5';
    s = s.substr(0, 1) + "." + s.substr(1) + "e" + std::to_string(small(random));
    const double x = std::strtod(s.c_str(), nullptr);
    for (double y : {x, std::nextafter(x, 0.0), std::nextafter(x, 1e300)}) {
      v.push_back(y);
      v.push_back(-y);
    }
  }
  return v;
}

}  // namespace

TEST_CASE("appendGeneral writes printf's %.*g to the byte", "[scene][output]") {
  const std::vector<double> values = hardValues();
  for (int precision : {1, 3, 4, 6, 10, 12, 15, 17})
    for (double v : values) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.*g", precision, v);
      std::string got;
      appendGeneral(got, v, precision);
      INFO("precision " << precision << ", v = " << buf);
      REQUIRE(got == buf);
    }
  std::string s;
  appendGeneral(s, std::nan(""), 12);
  appendGeneral(s, -std::numeric_limits<double>::infinity(), 12);
  CHECK(s == "nannan");
}

TEST_CASE("roundedSignificant is the double strtod reads from printf's %.*g", "[scene][output]") {
  const std::vector<double> values = hardValues();
  for (int digits : {1, 3, 4, 6, 10, 15, 17})
    for (double v : values) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.*g", digits, v);
      const double expected = std::strtod(buf, nullptr);
      const double got = roundedSignificant(v, digits);
      INFO(buf << " digits " << digits);
      REQUIRE(std::memcmp(&got, &expected, sizeof got) == 0);  // the same bits
    }
}

TEST_CASE("appendRoundedJson writes nlohmann::json's text of the rounded double to the byte", "[scene][output]") {
  // The independent formulation: dump()'s own conversion (Grisu2) of roundedSignificant's
  // double; the text must read back to that very double. Grisu2 is not always shortest
  // (5e22 rounded to one digit: it writes 4.9999999999999996e+22): there the text may differ
  // from dump()'s only by being shorter.
  const std::vector<double> values = hardValues();
  for (int digits : {1, 3, 4, 6, 10, 15, 17})
    for (double v : values) {
      const double r = roundedSignificant(v, digits);
      std::string expected = "null";
      if (std::isfinite(r)) {
        char buf[64];
        expected.assign(buf, nlohmann::detail::to_chars(buf, buf + sizeof buf, r));
      }
      std::string got;
      appendRoundedJson(got, v, digits);
      INFO(expected << " digits " << digits << ": " << got);
      REQUIRE((got == expected || (std::isfinite(r) && got.size() < expected.size())));
      if (std::isfinite(r)) {
        const double back = std::strtod(got.c_str(), nullptr);
        REQUIRE(std::memcmp(&back, &r, sizeof r) == 0);
      }
    }
  std::string s;
  appendRoundedJson(s, std::nan(""), 6);
  appendRoundedJson(s, std::numeric_limits<double>::infinity(), 6);
  CHECK(s == "nullnull");
}
