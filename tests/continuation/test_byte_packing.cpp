// Results as bytes for another process (byte_packing.h): every value comes back bit for bit
// (NaN payloads, −0, subnormals, strings with NUL and invalid UTF-8), and bytes that end early
// or announce more than they hold are refused instead of read past their end.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "buckle/continuation/byte_packing.h"

using buckle::continuation::ByteReader;
using buckle::continuation::ByteWriter;

namespace {

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

TEST_CASE("byte packing: values, strings and vectors come back bit for bit", "[byte_packing]") {
  const double payloadNaN = [] {
    const std::uint64_t b = 0x7ff8'0000'dead'beefULL;
    double v;
    std::memcpy(&v, &b, sizeof v);
    return v;
  }();
  const std::vector<double> values = {0.0, -0.0, 1.0 / 3.0, std::numeric_limits<double>::denorm_min(),
                                      -std::numeric_limits<double>::infinity(), payloadNaN, 1e308};
  const std::string text("a\0b\xff\n\"", 6);
  Eigen::VectorXd v(4);
  v << 1.5, -0.0, payloadNaN, 2e-310;
  ByteWriter out;
  for (double x : values) out.put(x);
  out.put(std::int32_t(-7));
  out.putString(text);
  out.putString("");
  out.putVector(v);
  out.putVector(Eigen::VectorXd());
  const std::string bytes = out.release();

  ByteReader in(bytes, "test");
  for (double x : values) CHECK(bits(in.get<double>()) == bits(x));
  CHECK(in.get<std::int32_t>() == -7);
  CHECK(in.getString() == text);
  CHECK(in.getString().empty());
  const Eigen::VectorXd w = in.getVector();
  REQUIRE(w.size() == v.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) CHECK(bits(w[i]) == bits(v[i]));
  CHECK(in.getVector().size() == 0);
  CHECK(in.done());
}

TEST_CASE("byte packing: bytes that end early or announce too much are refused", "[byte_packing]") {
  ByteWriter out;
  out.putString("abcdef");
  const std::string whole = out.release();
  for (size_t cut = 0; cut < whole.size(); ++cut) {
    const std::string part = whole.substr(0, cut);
    ByteReader in(part, "cells");
    CHECK_THROWS_WITH(in.getString(), "cells: the packed data ends early");
  }
  // a length of 2^61 doubles: refused before anything is allocated
  ByteWriter huge;
  huge.put(std::uint64_t(1) << 61);
  huge.put(1.0);
  const std::string bytes = huge.release();
  ByteReader in(bytes, "rows");
  CHECK_THROWS_AS(in.getVector(), std::runtime_error);
}
