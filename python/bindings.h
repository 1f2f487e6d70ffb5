// The Python module `buckle` (pybind11): one binding function per layer, called by module.cpp.
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

namespace buckle::python {

/// Segment, Chain, EndCondition, the chain's energy / torque / kinematics / stiffness at a state
/// and linear_buckling (buckle::mechanics).
void bindMechanics(pybind11::module_& m);
/// trace(): the continuation core on a problem whose residual and Jacobian are Python callables.
void bindContinuation(pybind11::module_& m);
/// run_scene(): a scene (dict or file) through the same runner as `buckle run`.
void bindScene(pybind11::module_& m);

/// A JSON document as Python objects (dict, list, str, int, float, bool, None).
pybind11::object toPython(const nlohmann::json& value);

}  // namespace buckle::python
