// buckle.run_scene: a scene (a dict with the schema of docs/scenes.md, or a file) through the
// runner of `buckle run` (scene/runner.h); the special points and the summary are the documents
// `buckle run` writes (scene/output.h), the branches the columns of branches.csv as arrays.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

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

/// The columns of branches.csv for one case (docs/outputs.md), as arrays; q as a P×n matrix.
py::dict branchArrays(const scene::Scene& s, const scene::CaseResult& cr) {
  const auto P = static_cast<Eigen::Index>(cr.points.size());
  py::dict d;
  Eigen::VectorXi branch(P), point(P), negative(P);
  py::array_t<bool> stable(P);
  auto stableView = stable.mutable_unchecked<1>();
  Eigen::MatrixXd q(P, cr.chain.size());
  for (Eigen::Index i = 0; i < P; ++i) {
    const scene::PointRecord& p = cr.points[static_cast<size_t>(i)];
    branch[i] = p.branch;
    point[i] = p.index;
    negative[i] = p.negative;
    stableView(i) = p.stable;
    q.row(i) = p.q.size() == cr.chain.size() ? Eigen::RowVectorXd(p.q.transpose())
                                              : Eigen::RowVectorXd::Constant(cr.chain.size(), NAN);
  }
  d["branch"] = branch;
  d["point"] = point;
  std::vector<std::string> columns{"parameter", "Fx", "Fy", "Me", "x", "y", "phi", "dx", "dy", "min_eig"};
  if (s.analyses.stiffness)
    columns.insert(columns.end(), scene::stiffnessColumns().begin(), scene::stiffnessColumns().end());
  if (s.analyses.frequencies.enabled) {
    const std::vector<std::string> omega = scene::frequencyColumns(s.analyses.frequencies.count);
    columns.insert(columns.end(), omega.begin(), omega.end());
  }
  const std::vector<std::string> inputs = s.inputColumns();  // a task path's inputs
  columns.insert(columns.end(), inputs.begin(), inputs.end());
  for (const std::string& c : columns) {
    VectorXd v(P);
    for (Eigen::Index i = 0; i < P; ++i) v[i] = scene::columnValue(c, cr.points[static_cast<size_t>(i)], cr.pose0);
    d[py::str(c)] = v;
  }
  d["q"] = q;
  d["stable"] = stable;
  d["negative"] = negative;
  return d;
}

/// The equilibria of one case (the rows of equilibria.csv) as arrays, q as an m×n matrix; with
/// "branches", the branch through each (−1: none) and the disconnected branches' seeds.
py::dict equilibriaArrays(const scene::CaseResult& cr) {
  const std::vector<mechanics::FoundEquilibrium>& list = cr.equilibria.equilibria;
  const auto m = static_cast<Eigen::Index>(list.size());
  py::dict d;
  Eigen::MatrixXd q(m, cr.chain.size());
  VectorXd potential(m);
  Eigen::VectorXi index(m), branch = Eigen::VectorXi::Constant(m, -1);
  py::array_t<bool> stable(m);
  auto stableView = stable.mutable_unchecked<1>();
  std::vector<std::string> shape;
  for (Eigen::Index k = 0; k < m; ++k) {
    const mechanics::FoundEquilibrium& e = list[static_cast<size_t>(k)];
    q.row(k) = e.q.transpose();
    potential[k] = e.potential;
    index[k] = e.index;
    stableView(k) = e.stable;
    shape.push_back(e.shape);
    if (static_cast<size_t>(k) < cr.equilibriaOnBranch.size()) branch[k] = cr.equilibriaOnBranch[static_cast<size_t>(k)];
  }
  d["at"] = cr.equilibriaAt;
  d["q"] = q;
  d["potential"] = potential;
  d["index"] = index;
  d["stable"] = stable;
  d["shape"] = shape;
  d["branch"] = branch;
  py::list disconnected;
  for (const scene::BranchRecord& b : cr.branches)
    if (b.fromEquilibrium > 0) {
      py::dict r;
      r["id"] = b.id;
      r["parent"] = b.parent;
      r["from_equilibrium"] = b.fromEquilibrium;
      r["joins"] = b.joins >= 0 ? py::object(py::int_(b.joins)) : py::object(py::none());
      disconnected.append(r);
    }
  d["disconnected_branches"] = disconnected;
  return d;
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

  m.def(
      "run_scene",
      [](const py::object& source, std::optional<double> timeLimit, std::optional<std::string> out, bool force) {
        if (timeLimit && !(*timeLimit > 0.0))
          throw std::invalid_argument("time_limit must be a positive number of seconds");
        scene::Scene s = parse(source);
        if (timeLimit) s.solver.timeLimit = *timeLimit;  // recorded as such in the summary, as --time-limit
        std::string target;
        if (out) target = scene::checkOutputTarget(*out, {s.file}, force, "out");
        SigintWatch sigint;
        scene::RunControl control;
        control.interrupt.watch(sigint.flag(), "interrupted (KeyboardInterrupt)");
        scene::RunResult run;
        scene::PlotReport plots;
        {
          py::gil_scoped_release release;
          run = scene::runScene(s, control);
          if (out && !sigint.flag()->load()) {
            scene::StagingDirectory staging(target);
            plots = scene::writeOutputs(s, run, staging.path());
            staging.commit();
          }
        }
        sigint.raiseIfInterrupted();
        if (!out) plots.gnuplot = "not drawn (run_scene without out)";
        py::dict result;
        result["complete"] = run.complete;
        result["interrupted"] = run.interrupted;
        result["interruption"] = run.interruption;
        result["problems"] = run.problems;
        result["computed"] = run.computed;
        py::list cases;
        for (const scene::CaseResult& cr : run.cases) {
          py::dict c;
          c["label"] = cr.label;
          c["segments"] = cr.chain.size();
          c["chain"] = py::cast(cr.chain);
          c["q0"] = cr.q0;
          c["branches"] = branchArrays(s, cr);
          if (cr.haveEquilibria) c["equilibria"] = equilibriaArrays(cr);
          cases.append(c);
        }
        result["cases"] = cases;
        const json specials = scene::specialPointsJson(s, run);
        result["special_points"] = toPython(specials["special_points"]);
        result["results"] = toPython(specials);
        result["summary"] = toPython(scene::summaryJson(s, run, plots));
        return result;
      },
      py::arg("scene"), py::kw_only(), py::arg("time_limit") = py::none(), py::arg("out") = py::none(),
      py::arg("force") = false,
      "Runs a scene (a dict with the schema of docs/scenes.md, or the path of a scene file) with the runner of "
      "`buckle run`: only the analyses it asks for.\n\n"
      "time_limit: seconds for the whole run (overrides /solver/time_limit); when reached the run stops within a "
      "step and returns what it computed (`complete` False, `interrupted` True). out: also write the output "
      "directory `buckle run --out` writes (CSV, JSON, plots, report.html), with the same --out rules (force: "
      "as --force). Ctrl-C raises KeyboardInterrupt.\n\n"
      "Returns a dict: `complete`, `interrupted`, `interruption`, `problems`, `computed`; `cases` (per case: "
      "`label`, `segments`, `chain` (a Chain), `q0`, `branches`: the columns of branches.csv as arrays — branch, "
      "point, parameter, Fx, Fy, Me, x, y, phi, dx, dy, q (P×n), stable, negative, min_eig, and Kxx, Kyy, Kxy, Cxx, Cyy, Cxy, Kx_yfree, Ky_xfree, K1, K2, theta1 with "
      "stiffness; with the equilibria analysis `equilibria`: the rows of equilibria.csv as arrays — at, q (m×n), "
      "potential, index, stable, shape, branch (the branch through each, -1: none or not traced) — and "
      "`disconnected_branches` (id, parent, from_equilibrium: the seed's rank, joins)); `special_points` (the dicts of special_points.json); `results` (all of special_points.json: "
      "critical_loads, energy_equilibria, ... when asked); `summary` (summary.json). Raises SceneError (a "
      "ValueError) for a bad scene.");
}

}  // namespace buckle::python
