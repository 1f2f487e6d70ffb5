#include <string>

#include "bindings.h"

namespace buckle::python {

std::string formatNumber(double value) { return pybind11::repr(pybind11::float_(value)).cast<std::string>(); }

}  // namespace buckle::python
