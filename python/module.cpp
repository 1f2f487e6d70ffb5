// PYBIND11_MODULE entry point of buckle._core, the compiled part of the package `buckle`
// (python/buckle/__init__.py re-exports it); the bindings themselves are per layer.
#include <pybind11/pybind11.h>

#include "bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "buckle: numerical continuation and bifurcation of compliant serial manipulators built from "
      "dual-triangle segments.\n\n"
      "Units: whatever consistent units the segment parameters and the scene are written in (a, b, L0 in a "
      "length unit, k in force per length): lengths, forces, torques (force x length) and stiffnesses come out in "
      "those units, angles in radians; a scene may name them (`units`, docs/scenes.md). Sign conventions: spring energy "
      "E = 1/2 sum k (L - L0)^2, joint stiffness K_q = d2E/dq2, restoring torque M = -dE/dq, "
      "equilibrium M + J^T F = 0, compression is Fx < 0.\n\n"
      "Mechanics: Segment, Chain, EndCondition, linear_buckling, all_equilibria.  Scenes: run_scene (the `buckle run` "
      "runner), returning a RunResult: a dict of NumPy arrays with DataFrames (pandas) and plots (matplotlib) "
      "when those are installed.  Continuation core: trace (a problem given by Python callables) with TracerOptions.  Bad input raises "
      "ValueError (SceneError for a scene) with the command line's message; Ctrl-C raises "
      "KeyboardInterrupt within a step (run_scene first writes what was computed to `out`). docs/python.md.";
  m.attr("__version__") = BUCKLE_VERSION;
  buckle::python::bindMechanics(m);
  buckle::python::bindEquilibria(m);
  buckle::python::bindTracerOptions(m);
  buckle::python::bindContinuation(m);
  buckle::python::bindScene(m);
}
