// buckle.run_scene: a scene (a dict with the schema of docs/scenes.md, or a file) through the
// runner of `buckle run` (scene/runner.h); the special points and the summary are the documents
// `buckle run` writes (scene/output.h), the branches the columns of branches.csv as arrays
// (scene_arrays.h), wrapped in the package's RunResult (_result.py).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "bindings.h"
#include "scene/output.h"
#include "scene/output_target.h"
#include "scene/runner.h"
#include "scene/scene.h"
#include "scene/scene_parsing.h"
#include "scene_arrays.h"
#include "sigint_watch.h"

namespace buckle::python {

namespace py = pybind11;
using nlohmann::json;
using Eigen::VectorXd;

py::object toPython(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return py::none();
    case json::value_t::boolean: return py::bool_(v.get<bool>());
    case json::value_t::number_integer: return py::int_(v.get<std::int64_t>());
    case json::value_t::number_unsigned: return py::int_(v.get<std::uint64_t>());
    case json::value_t::number_float: return py::float_(v.get<double>());
    case json::value_t::string: return py::str(v.get_ref<const std::string&>());
    case json::value_t::array: {
      py::list l;
      for (const json& e : v) l.append(toPython(e));
      return l;
    }
    case json::value_t::object: {
      py::dict d;
      for (auto it = v.begin(); it != v.end(); ++it) d[py::str(it.key())] = toPython(it.value());
      return d;
    }
    default: return py::none();  // binary and discarded values do not occur in buckle's documents
  }
}

namespace {

constexpr const char* kInterruption = "interrupted (KeyboardInterrupt)";

/// run_scene's dict (its docstring lists the keys).
py::dict resultDict(const scene::Scene& s, const scene::RunResult& run, const scene::PlotReport& plots) {
  py::dict result;
  result["complete"] = run.complete;
  result["interrupted"] = run.interrupted;
  result["interruption"] = run.interruption;
  result["problems"] = run.problems;
  result["warnings"] = run.warnings;
  result["computed"] = run.computed;
  py::list cases;
  int specials = 0;  // the special points of the cases before
  int segments = 0;
  for (const scene::CaseResult& cr : run.cases) {
    py::dict c;
    c["label"] = cr.label;
    c["segments"] = cr.chain.size();
    c["chain"] = py::cast(cr.chain);
    c["q0"] = cr.q0;
    c["branches"] = branchArrays(s, cr);
    c["special_points"] = specialArrays(s, cr, specials);
    if (!cr.equilibriumSets.empty()) c["equilibria"] = equilibriaArrays(cr);
    if (cr.haveWorkspace) c["workspace"] = workspaceArrays(cr);
    cases.append(c);
    specials += static_cast<int>(cr.specials.size());
    segments = std::max(segments, cr.chain.size());
  }
  result["cases"] = cases;
  const json specialPoints = scene::specialPointsJson(s, run);
  result["special_points"] = toPython(specialPoints["special_points"]);
  result["results"] = toPython(specialPoints);
  result["summary"] = toPython(scene::summaryJson(s, run, plots));
  result["labels"] = columnLabels(s, segments);
  result["plots"] = plotSpecs(s.plots);
  result["default_plots"] = plotSpecs(scene::detail::defaultPlots(s.analyses, static_cast<int>(s.cases.size())));
  return result;
}

/// KeyboardInterrupt after Ctrl-C, carrying the partial result as its `result`.
[[noreturn]] void raiseKeyboardInterrupt(const py::object& result, const std::optional<std::string>& out) {
  const std::string message = "run_scene interrupted (Ctrl-C)" +
                              (out ? "; what was computed is written to " + *out : std::string()) +
                              "; the partial result is this exception's .result";
  py::object error = py::reinterpret_borrow<py::object>(PyExc_KeyboardInterrupt)(message);
  error.attr("result") = result;
  PyErr_SetObject(PyExc_KeyboardInterrupt, error.ptr());
  throw py::error_already_set();
}

scene::Scene parse(const py::object& source) {
  if (py::isinstance<py::dict>(source)) {
    // NumPy scalars and arrays (np.int64, np.float64, ndarray) where a scene has numbers: as the
    // Python numbers and lists they hold (.tolist()); anything else JSON cannot hold is named
    const py::cpp_function plain([](const py::handle& v) -> py::object {
      if (py::hasattr(v, "tolist") && py::hasattr(v, "dtype")) return v.attr("tolist")();
      throw py::type_error("a scene dict holds numbers, strings, lists and dicts; got a value of type " +
                           py::type::of(v).attr("__name__").cast<std::string>() + " (" +
                           py::repr(v).cast<std::string>().substr(0, 60) + ")");
    });
    const std::string text = py::module_::import("json").attr("dumps")(source, py::arg("default") = plain).cast<std::string>();
    return scene::parseScene(text, "<dict>");
  }
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(source) || py::isinstance(source, os.attr("PathLike")))
    return scene::loadScene(os.attr("fspath")(source).cast<std::string>());
  throw std::invalid_argument("run_scene: the scene must be a dict or a file path, got " +
                              py::str(py::type::of(source).attr("__name__")).cast<std::string>());
}

}  // namespace

void bindScene(py::module_& m) {
  // The message of a SceneError is the one `buckle run` prints after "buckle run: bad scene: ".
  static py::exception<scene::SceneError> sceneError(m, "SceneError", PyExc_ValueError);
  sceneError.doc() =
      "A scene that cannot be run: the file, the JSON path of the bad value and what was expected (the message "
      "`buckle run` prints after 'bad scene:'). A ValueError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const scene::SceneError& e) {
      sceneError(e.what());
    } catch (const scene::OutputTargetError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  // run_scene's result is a buckle.RunResult: the dict below with the methods of _result.py
  // (DataFrames, plots); the package's own module, whatever it is imported as
  const std::string moduleName = m.attr("__name__").cast<std::string>();
  const std::string resultModule = moduleName.substr(0, moduleName.rfind('.') + 1) + "_result";
  m.def(
      "run_scene",
      [resultModule](const py::object& source, std::optional<double> timeLimit, std::optional<std::string> out,
                     bool force) {
        if (timeLimit && !(*timeLimit > 0.0))
          throw std::invalid_argument("time_limit must be a positive number of seconds");
        scene::Scene s = parse(source);
        if (timeLimit) s.solver.timeLimit = *timeLimit;  // recorded as such in the summary, as --time-limit
        std::string target;
        if (out) target = scene::checkOutputTarget(*out, {s.file}, force, "out");
        SigintWatch sigint;
        scene::RunControl control;
        control.interrupt.watch(sigint.flag(), kInterruption);
        scene::RunResult run;
        scene::PlotReport plots;
        {
          py::gil_scoped_release release;
          run = scene::runScene(s, control);
          // interrupted or not, `out` gets what was computed, as `buckle run` writes it on SIGINT:
          // after Ctrl-C no plot is drawn (the writers' stop is the same flag)
          if (out) {
            continuation::Interrupt stop;
            stop.watch(sigint.flag(), kInterruption);
            scene::StagingDirectory staging(target);
            plots = scene::writeOutputs(s, run, staging.path(), stop);
            staging.commit();
          }
        }
        if (!out) plots.gnuplot = "not drawn (run_scene without out)";
        py::object result = py::module_::import(resultModule.c_str()).attr("RunResult")(resultDict(s, run, plots));
        if (sigint.interrupted()) raiseKeyboardInterrupt(result, out);
        return result;
      },
      py::arg("scene"), py::kw_only(), py::arg("time_limit") = py::none(), py::arg("out") = py::none(),
      py::arg("force") = false,
      "Runs a scene (a dict with the schema of docs/scenes.md, or the path of a scene file) with the runner of "
      "`buckle run`: only the analyses it asks for. Returns a RunResult (a dict; docs/python.md).\n\n"
      "time_limit: seconds for the whole run (overrides /solver/time_limit); when reached the run stops within a "
      "step and returns what it computed (`complete` False, `interrupted` True). out: also write the output "
      "directory `buckle run --out` writes (CSV, JSON, plots, report.html), with the same --out rules (force: "
      "as --force).\n\n"
      "Ctrl-C stops the run within a step; what was computed is written to `out` (as `buckle run` does on "
      "SIGINT: summary.json says interrupted, no plots drawn) and KeyboardInterrupt is raised, its `result` "
      "attribute holding the partial RunResult.\n\n"
      "The dict: `complete`, `interrupted`, `interruption`, `problems`, `computed`; `cases` (per case: "
      "`label`, `segments`, `chain` (a Chain), `q0`, `branches`: the columns of branches.csv as arrays, in its "
      "order — branch, point, parameter, Fx, Fy, Me, x, y, phi, dx, dy, q (P×n), stable, negative, min_eig, locked "
      "(str), contact_torque, wall (str), wall_force, and Kxx, Kyy, Kxy, Cxx, Cyy, Cxy, Kx_yfree, Ky_xfree, K1, K2, theta1, Kphi with stiffness, "
      "omega1 … with frequencies, a task path's inputs; `special_points`: the case's special points in the same "
      "value columns as arrays, with type, field, shape, branch and index (into the run's `special_points`); with the equilibria analysis `equilibria`: the rows of equilibria.csv as "
      "arrays — at, q (m×n), potential, index, stable, shape, branch (the branch through each, -1: none or not "
      "traced) — and `disconnected_branches` (id, parent, from_equilibrium: the seed's rank, joins); with the "
      "workspace analysis `workspace`: the grid of workspace_map.csv as (count2 × count1) arrays and `curves` "
      "(cause, name, stop, u1, u2, x, y, phi, stable, residual)); "
      "`special_points` (the dicts of special_points.json); `results` (all of special_points.json: "
      "critical_loads, energy_equilibria, ... when asked); `summary` (summary.json, with `units`); `labels` "
      "(column → axis label in the scene's units, as the plots write it). Raises SceneError (a ValueError) for a "
      "bad scene.");
}

}  // namespace buckle::python
