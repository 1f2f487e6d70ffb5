// Parameter checks shared by the mechanics layer: every rejection names the parameter.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

inline void requireFinite(const std::string& name, double value) {
  if (!std::isfinite(value)) {
    std::ostringstream os;
    os << name << " must be a finite number (got " << value << ")";
    throw std::invalid_argument(os.str());
  }
}

inline void requirePositive(const std::string& name, double value) {
  requireFinite(name, value);
  if (!(value > 0.0)) {
    std::ostringstream os;
    os << name << " must be > 0 (got " << value << ")";
    throw std::invalid_argument(os.str());
  }
}

inline void requireNonNegative(const std::string& name, double value) {
  requireFinite(name, value);
  if (value < 0.0) {
    std::ostringstream os;
    os << name << " must be >= 0 (got " << value << ")";
    throw std::invalid_argument(os.str());
  }
}

}  // namespace buckle::mechanics
