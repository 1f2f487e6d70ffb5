// |x − reference| / |reference|: the tests' relative error (shared, so that unity builds see one).
#pragma once

#include <cmath>

namespace buckle::test {

inline double relativeError(double x, double reference) { return std::abs(x - reference) / std::abs(reference); }

}  // namespace buckle::test
