// PYBIND11_MODULE entry point of `import buckle`; the bindings themselves are per layer.
#include <pybind11/pybind11.h>

#include "bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(buckle, m) {
  m.doc() =
      "buckle: numerical continuation and bifurcation of compliant serial manipulators built from "
      "dual-triangle segments.\n\n"
      "Units: b (triangle half-length) for lengths, k (spring stiffness) for stiffnesses, k b for forces, "
      "k b^2 for torques and energies, radians for angles. Sign conventions: spring energy "
      "E = 1/2 sum k (L - L0)^2, joint stiffness K_q = d2E/dq2, restoring torque M = -dE/dq, "
      "equilibrium M + J^T F = 0, compression is Fx < 0.\n\n"
      "Mechanics: Segment, Chain, EndCondition, linear_buckling.  Scenes: run_scene (the `buckle run` "
      "runner).  Continuation core: trace (a problem given by Python callables).  Bad input raises "
      "ValueError (SceneError for a scene) with the command line's message; Ctrl-C raises "
      "KeyboardInterrupt within a step.";
  m.attr("__version__") = BUCKLE_VERSION;
  buckle::python::bindMechanics(m);
  buckle::python::bindContinuation(m);
  buckle::python::bindScene(m);
}
