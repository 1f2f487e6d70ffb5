// A finiteness test for the hot loop's small dense vectors and matrices.
#pragma once

#include <Eigen/Core>

namespace buckle::continuation {

/// True if each of the `count` values from x on is finite. Eigen's allFinite() forms x − x and
/// reduces it with a generic loop on small dynamic objects (≈ 17 instructions per entry, ≈ 0.5 k
/// per continuation point at N + 1 = 4 for the corrector's and the bordered solver's checks);
/// this is two per entry. Σ x_i·0 is 0 unless some x_i is ±∞ or NaN (then it is NaN).
inline bool allFinite(const double *x, Eigen::Index count) {
  double zero = 0.0;
  for (Eigen::Index i = 0; i < count; ++i) zero += x[i] * 0.0;
  return zero == 0.0;
}

}  // namespace buckle::continuation
