// allFinite (finite.h): the corrector's and the bordered solver's finiteness test.
#include "buckle/continuation/internal/finite.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using buckle::continuation::allFinite;

TEST_CASE("allFinite is false exactly when some entry is infinite or NaN, at any position and magnitude",
          "[finite]") {
  // Σ x_i·0 must stay 0 for every finite x_i, the largest and the subnormal ones included, and
  // become NaN from any single ±∞ or NaN; the same answer as Eigen's allFinite().
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  std::uniform_int_distribution<int> E(-1074, 1023);
  const double bad[] = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::quiet_NaN()};
  const double edge[] = {0.0, -0.0, std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                         std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min()};
  for (int n = 0; n <= 30; ++n) {
    std::vector<double> x(static_cast<size_t>(n));
    for (double& v : x) v = std::ldexp(W(rng), E(rng));
    for (int i = 0; i < n; i += 3) x[size_t(i)] = edge[size_t(i / 3) % 6];
    CHECK(allFinite(x.data(), n));
    CHECK(allFinite(x.data(), n) == Eigen::Map<const Eigen::VectorXd>(x.data(), n).allFinite());
    for (int i = 0; i < n; ++i)
      for (double b : bad) {
        const double keep = x[size_t(i)];
        x[size_t(i)] = b;
        CHECK_FALSE(allFinite(x.data(), n));
        CHECK_FALSE(Eigen::Map<const Eigen::VectorXd>(x.data(), n).allFinite());
        CHECK(allFinite(x.data(), i));  // the entries before it only
        x[size_t(i)] = keep;
      }
  }
}
