// all_equilibria(): every equilibrium of a chain at one state of the controls
// (mechanics/all_equilibria.h), with the options the scene's `equilibria` analysis takes under the
// same names (docs/scenes.md), as a dict of the result's fields.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.h"
#include "buckle/mechanics/all_equilibria.h"
#include "sigint_watch.h"

namespace buckle::python {

namespace py = pybind11;
namespace mech = buckle::mechanics;

namespace {

py::dict equilibriumDict(const mech::FoundEquilibrium& e) {
  py::dict d;
  d["q"] = Eigen::VectorXd(e.q);
  d["index"] = e.index;
  d["stable"] = e.stable;
  d["potential"] = e.potential;
  d["shape"] = e.shape;
  d["wrench"] = Eigen::VectorXd(e.wrench);
  d["pose"] = Eigen::VectorXd(e.pose);
  d["reactions"] = Eigen::VectorXd(e.reactions);
  d["accuracy"] = e.accuracy;
  d["zero_eigenvalues"] = e.zeroEigenvalues;
  d["by_deflation"] = e.byDeflation;
  d["by_sweep"] = e.bySweep;
  return d;
}

py::dict resultDict(const mech::AllEquilibria& a) {
  py::list list;
  for (const mech::FoundEquilibrium& e : a.equilibria) list.append(equilibriumDict(e));
  py::dict morse;
  morse["applies"] = a.morse.applies;
  morse["sum"] = a.morse.sum;
  morse["expected"] = a.morse.expected;
  morse["holds"] = a.morse.holds();
  morse["basis"] = a.morse.basis;
  py::dict d;
  d["equilibria"] = list;
  d["method"] = a.method;
  d["guarantee"] = a.guarantee;
  d["starts"] = a.starts;
  d["newton_runs"] = a.newtonRuns;
  d["newton_failures"] = a.newtonFailures;
  d["duplicates"] = a.duplicates;
  d["outside_limits"] = a.outsideLimits;
  d["sweep_count"] = a.sweepCount;
  d["morse"] = morse;
  d["seconds"] = a.seconds;
  return d;
}

}  // namespace

void bindEquilibria(py::module_& m) {
  m.def(
      "all_equilibria",
      [](const mech::Chain& chain, const mech::EndCondition& end, int starts, int smoothStarts, long seed,
         int sweepPoints, const std::vector<Eigen::VectorXd>& extraStarts) {
        mech::AllEquilibriaOptions options;  // the library's defaults, the scene's names
        if (starts < 0) throw std::invalid_argument("starts must be >= 0, got " + std::to_string(starts));
        if (smoothStarts < 0)
          throw std::invalid_argument("smooth_starts must be >= 0, got " + std::to_string(smoothStarts));
        if (seed < 0 || seed > 2147483647L)
          throw std::invalid_argument("seed must be in [0, 2147483647], got " + std::to_string(seed));
        if (sweepPoints < 3) throw std::invalid_argument("sweep_points must be >= 3, got " + std::to_string(sweepPoints));
        for (size_t i = 0; i < extraStarts.size(); ++i)
          if (extraStarts[i].size() != chain.size() || !extraStarts[i].allFinite())
            throw std::invalid_argument("starts_q[" + std::to_string(i) + "] must hold " + std::to_string(chain.size()) +
                                        " finite joint angles");
        options.randomStarts = starts;
        options.smoothStarts = smoothStarts;
        options.seed = unsigned(seed);
        options.landscapeSamples = sweepPoints;
        options.starts = extraStarts;
        SigintWatch sigint;
        options.interrupt.watch(sigint.flag(), "interrupted (KeyboardInterrupt)");
        mech::AllEquilibria a;
        {
          py::gil_scoped_release release;
          a = mech::allEquilibria(chain, end, options);
        }
        sigint.raiseIfInterrupted();
        return resultDict(a);
      },
      py::arg("chain"), py::arg("end"), py::kw_only(), py::arg("starts") = 64, py::arg("smooth_starts") = 64,
      py::arg("seed") = 1, py::arg("sweep_points") = 4001, py::arg("starts_q") = std::vector<Eigen::VectorXd>(),
      "Every equilibrium of `chain` within its joint limits under `end` (loads and held coordinates, the "
      "values as given): deflated Newton from the straight and unloaded shapes, `starts_q` (further joint-angle "
      "vectors), `starts` random and `smooth_starts` random smooth shapes (seed `seed`); for three segments with "
      "x and y held and phi free also the complete E(q1) sweep of `sweep_points` samples (docs/mechanics.md, "
      "\"All equilibria at one state of the controls\"). Returns a dict: `equilibria` (ascending potential; each "
      "q, index, stable, potential, shape, wrench (Fx, Fy, Me), pose (x, y, phi), reactions of the held "
      "coordinates, accuracy, zero_eigenvalues, by_deflation, by_sweep), `method`, `guarantee`, `starts`, "
      "`newton_runs`, `newton_failures`, `duplicates`, `outside_limits`, `sweep_count`, `morse` (applies, sum, "
      "expected, holds, basis), `seconds`. Ctrl-C raises KeyboardInterrupt.");
}

}  // namespace buckle::python
