// The bounded sample of a streamed case's points (scene/point_sample.h).
#include <catch2/catch.hpp>

#include <vector>

#include "scene/point_sample.h"

using buckle::mechanics::PointReport;
using buckle::scene::keepSample;
using buckle::scene::sampleBytes;

namespace {

/// `count` points of branch `id` with `n` joint angles, stable below index `unstableFrom`.
std::vector<PointReport> branch(int id, int count, int n, int unstableFrom) {
  std::vector<PointReport> points(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    PointReport& p = points[size_t(i)];
    p.branch = id;
    p.index = i;
    p.q = Eigen::VectorXd::Constant(n, 0.01 * i);
    p.stable = i < unstableFrom;
  }
  return points;
}

}  // namespace

TEST_CASE("a sample within its budget keeps every point", "[scene][sample]") {
  std::vector<PointReport> kept;
  size_t stride = 1, bytes = 0;
  keepSample(kept, branch(0, 50, 10, 20), stride, bytes, size_t(1) << 30);
  keepSample(kept, branch(1, 30, 10, 100), stride, bytes, size_t(1) << 30);
  CHECK(stride == 1);
  REQUIRE(kept.size() == 80);
  CHECK(kept[49].index == 49);
  CHECK(kept[50].branch == 1);
  size_t sum = 0;
  for (const PointReport& p : kept) sum += sampleBytes(p);
  CHECK(bytes == sum);
}

TEST_CASE("a sample over its budget doubles its stride and keeps ends and changes of stability", "[scene][sample]") {
  std::vector<PointReport> kept;
  size_t stride = 1, bytes = 0;
  const size_t one = sampleBytes(branch(0, 1, 20, 0).front());
  const size_t budget = 120 * one;  // room for 120 points of the 1000 given
  for (int b = 0; b < 10; ++b) keepSample(kept, branch(b, 100, 20, 37 + b), stride, bytes, budget);
  CHECK(bytes <= budget);
  CHECK(stride >= 8);
  size_t sum = 0;
  for (const PointReport& p : kept) sum += sampleBytes(p);
  CHECK(bytes == sum);
  for (int b = 0; b < 10; ++b) {
    CAPTURE(b);
    std::vector<int> indices;
    for (const PointReport& p : kept)
      if (p.branch == b) indices.push_back(p.index);
    REQUIRE(indices.size() >= 4);
    CHECK(indices.front() == 0);
    CHECK(indices.back() == 99);
    // both sides of the change of stability at 37 + b
    CHECK(std::count(indices.begin(), indices.end(), 36 + b) == 1);
    CHECK(std::count(indices.begin(), indices.end(), 37 + b) == 1);
    for (int i : indices) CHECK((i % int(stride) == 0 || i == 99 || i == 36 + b || i == 37 + b));
    CHECK(std::is_sorted(indices.begin(), indices.end()));
  }
}
