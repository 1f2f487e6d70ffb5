// The Python module `buckle` (pybind11): one binding function per layer, called by module.cpp.
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>
#include <string>

namespace buckle::python {

/// Segment, Chain, EndCondition, the chain's energy / torque / kinematics / stiffness at a state
/// and linear_buckling (buckle::mechanics).
void bindMechanics(pybind11::module_& m);
/// all_equilibria(): every equilibrium at one state of the controls (mechanics/all_equilibria.h).
void bindEquilibria(pybind11::module_& m);
/// TracerOptions and its groups: the continuation core's settings, with the library's defaults.
void bindTracerOptions(pybind11::module_& m);
/// trace(): the continuation core on a problem whose residual and Jacobian are Python callables.
void bindContinuation(pybind11::module_& m);
/// run_scene(): a scene (dict or file) through the same runner as `buckle run`.
void bindScene(pybind11::module_& m);

/// "step.maxStep must ..." as Python names the field: "step.max_step must ...".
std::string snakeCase(const std::string& text);

/// A number as Python's repr() writes a float: the shortest digits that read back to the same
/// double ("1e-07", "1e+308", "0.1", "-2.5e-12", "inf"), for reprs and messages. Needs the GIL.
std::string formatNumber(double value);

/// A JSON document as Python objects (dict, list, str, int, float, bool, None).
pybind11::object toPython(const nlohmann::json& value);

}  // namespace buckle::python
