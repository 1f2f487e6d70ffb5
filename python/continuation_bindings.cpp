// buckle.trace: the continuation core (continuation::traceTree) on a problem F(u, λ) = 0 whose
// residual and Jacobian are Python callables. Meant for small systems: every evaluation crosses
// into Python (with the GIL, which is released between evaluations).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "bindings.h"
#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/problem.h"
#include "buckle/continuation/tracer.h"
#include "sigint_watch.h"

namespace buckle::python {

namespace py = pybind11;
namespace cont = buckle::continuation;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// The Problem interface over Python callables. An exception raised by a callable (or a result
/// of the wrong shape) is kept, every later evaluation refuses the point so the tracer ends
/// quickly, and trace() re-raises it.
class PythonProblem : public cont::Problem {
 public:
  PythonProblem(int n, py::function residual, py::function jacobian, py::object stability)
      : n_(n), residual_(std::move(residual)), jacobian_(std::move(jacobian)), stability_(std::move(stability)) {}

  int dimension() const override { return n_; }

  bool residual(cont::ProblemWorkspace&, cont::ConstVectorRef u, double lambda, cont::VectorRef F) const override {
    return call([&] {
      const VectorXd r = vector(residual_(VectorXd(u), lambda), "residual(u, lam)", "an array of N numbers");
      expectSize(r.size(), n_, "residual");
      F = r;
      return r.allFinite();
    });
  }

  bool jacobian(cont::ProblemWorkspace&, cont::ConstVectorRef u, double lambda, cont::MatrixRef Fu,
                cont::VectorRef Flambda) const override {
    return call([&] {
      const py::object returned = jacobian_(VectorXd(u), lambda);
      if (!py::isinstance<py::tuple>(returned) && !py::isinstance<py::list>(returned))
        throw py::type_error("jacobian(u, lam) returned " + describe(returned) + "; expected a pair (F_u, F_lambda)");
      const auto pair = py::reinterpret_borrow<py::sequence>(returned);
      if (pair.size() != 2) throw std::invalid_argument("jacobian must return (F_u, F_lambda)");
      const MatrixXd J = matrix(pair[0], "jacobian(u, lam): F_u");
      const VectorXd Fl = vector(pair[1], "jacobian(u, lam): F_lambda", "an array of N numbers");
      if (J.rows() != n_ || J.cols() != n_)
        throw std::invalid_argument("jacobian: F_u is " + std::to_string(J.rows()) + "×" + std::to_string(J.cols()) +
                                    ", expected " + std::to_string(n_) + "×" + std::to_string(n_));
      expectSize(Fl.size(), n_, "jacobian: F_lambda");
      Fu = J;
      Flambda = Fl;
      return J.allFinite() && Fl.allFinite();
    });
  }

  bool hasStabilityOperator() const override { return !stability_.is_none(); }

  bool stabilityOperator(cont::ProblemWorkspace&, cont::ConstVectorRef u, double lambda, MatrixXd& H,
                         MatrixXd& C) const override {
    return call([&] {
      H = matrix(stability_(VectorXd(u), lambda), "stability(u, lam)");
      if (H.rows() != n_ || H.cols() != n_)
        throw std::invalid_argument("stability must return an " + std::to_string(n_) + "×" + std::to_string(n_) +
                                    " symmetric matrix");
      C.resize(0, n_);
      return H.allFinite();
    });
  }

  /// Re-raises what a callable raised (needs the GIL).
  void raiseStored() {
    if (error_) throw *error_;
    if (!typeMessage_.empty()) throw py::type_error(typeMessage_);
    if (!message_.empty()) throw std::invalid_argument(message_);
  }

 private:
  // a 1-unknown problem may answer with scalars: NumPy's atleast_1d/2d make them arrays
  static py::module_ numpy() { return py::module_::import("numpy"); }
  /// "None", "the str 'abc'": what a callable returned, for a message.
  static std::string describe(const py::handle& v) {
    if (v.is_none()) return "None";
    std::string r = py::repr(v).cast<std::string>();
    if (r.size() > 60) r = r.substr(0, 57) + "...";
    return "the " + py::type::of(v).attr("__name__").cast<std::string>() + " " + r;
  }
  /// The numbers `v` holds as float64 (NumPy's own conversion), or a TypeError naming the
  /// callable `what` and what it returned.
  static py::object numbers(const py::handle& v, const std::string& what, const std::string& expected) {
    // None and text are refused before NumPy, which makes NaN of None and a number of "1.5"
    if (!v.is_none() && !py::isinstance<py::str>(v) && !py::isinstance<py::bytes>(v)) {
      try {
        return numpy().attr("asarray")(v, py::arg("dtype") = "float64");
      } catch (const py::error_already_set&) {  // objects NumPy cannot make numbers of
      }
    }
    throw py::type_error(what + " returned " + describe(v) + "; expected " + expected);
  }
  static VectorXd vector(const py::handle& v, const std::string& what, const std::string& expected) {
    return numpy().attr("atleast_1d")(numbers(v, what, expected)).cast<VectorXd>();
  }
  static MatrixXd matrix(const py::handle& v, const std::string& what) {
    return numpy().attr("atleast_2d")(numbers(v, what, "an N×N array of numbers")).cast<MatrixXd>();
  }

  static void expectSize(Eigen::Index got, int n, const char* what) {
    if (got != n)
      throw std::invalid_argument(std::string(what) + " returned " + std::to_string(got) + " values, expected " +
                                  std::to_string(n));
  }

  template <class Body>
  bool call(Body body) const {
    if (failed_) return false;
    py::gil_scoped_acquire gil;
    try {
      return body();
    } catch (py::error_already_set& e) {
      error_.emplace(e);
    } catch (const py::type_error& e) {  // a callable returned no numbers
      typeMessage_ = e.what();
    } catch (const std::exception& e) {  // a wrong shape
      message_ = e.what();
    }
    failed_ = true;
    return false;
  }

  int n_;
  py::function residual_, jacobian_;
  py::object stability_;
  // The first error a callable raised, for trace() to re-raise: the Python callables run one at
  // a time under the GIL and the module traces one problem per call, so the const evaluations
  // record it here (mutable) rather than in a workspace.
  mutable bool failed_ = false;
  mutable std::optional<py::error_already_set> error_;
  mutable std::string message_, typeMessage_;
};

py::dict specialPointDict(const cont::SpecialPoint& s) {
  py::dict d;
  d["type"] = cont::label(s.type);
  d["index"] = s.index;
  d["u"] = s.u;
  d["lambda"] = s.lambda;
  d["tangent"] = s.tangent;
  d["accuracy"] = s.lambdaAccuracy;
  d["residual"] = s.residualNorm;
  d["refined"] = s.refined;
  d["multiplicity"] = s.multiplicity;
  d["inertia_before"] = s.inertiaBefore;
  d["inertia_after"] = s.inertiaAfter;
  d["test_function"] = s.testFunctionValue;
  d["boundary"] = s.boundaryName;
  d["note"] = s.note;
  return d;
}

py::dict branchDict(const cont::Branch& b, int n) {
  const auto P = static_cast<Eigen::Index>(b.points.size());
  MatrixXd u(P, n);
  VectorXd lambda(P), arclength(P);
  Eigen::VectorXi negative(P);
  for (Eigen::Index i = 0; i < P; ++i) {
    const cont::ContinuationPoint& p = b.points[static_cast<size_t>(i)];
    u.row(i) = p.u.transpose();
    lambda[i] = p.lambda;
    arclength[i] = p.arclength;
    negative[i] = p.stability.negative;
  }
  py::dict d;
  d["id"] = b.id;
  d["parent"] = b.parentId;
  d["parent_special_point"] = b.parentSpecialPoint;
  d["u"] = u;
  d["lambda"] = lambda;
  d["arclength"] = arclength;
  d["negative"] = negative;
  py::list specials;
  for (const cont::SpecialPoint& s : b.specialPoints) specials.append(specialPointDict(s));
  d["special_points"] = specials;
  d["stop_reason"] = cont::toString(b.stopReason);
  d["stop_message"] = b.stopMessage;
  return d;
}

}  // namespace

void bindContinuation(py::module_& m) {
  m.def(
      "trace",
      [](py::function residual, py::function jacobian, const VectorXd& u0, double lambda0,
         const cont::TracerOptions& given, int direction, std::optional<double> lambdaMin,
         std::optional<double> lambdaMax, std::optional<int> maxPoints, std::optional<double> initialStep,
         std::optional<double> minStep, std::optional<double> maxStep, std::optional<double> tolerance,
         std::optional<double> locationTolerance, int branchSwitching, py::object stability,
         std::optional<double> timeLimit) {
        if (u0.size() < 1) throw std::invalid_argument("u0 must have at least one unknown");
        if (direction != 1 && direction != -1) throw std::invalid_argument("direction must be +1 or -1");
        if (branchSwitching < 0) throw std::invalid_argument("branch_switching must be >= 0");
        if (timeLimit && !(*timeLimit > 0.0))
          throw std::invalid_argument("time_limit must be a positive number of seconds");
        // the keywords are short forms of the options' fields (one name each: max_step is
        // options.step.max_step); what they do not name keeps the given options' value
        cont::TracerOptions options = given;
        if (lambdaMin) options.lambdaMin = *lambdaMin;
        if (lambdaMax) options.lambdaMax = *lambdaMax;
        if (maxPoints) options.maxPoints = *maxPoints;
        if (initialStep) options.step.initialStep = *initialStep;
        if (minStep) options.step.minStep = *minStep;
        if (maxStep) options.step.maxStep = *maxStep;
        if (tolerance) options.corrector.tolerance = *tolerance;
        if (locationTolerance) options.location.tolerance = *locationTolerance;
        options.detection.stability = !stability.is_none();
        const std::string why = options.validate();
        if (!why.empty()) throw std::invalid_argument("invalid continuation options: " + snakeCase(why));
        PythonProblem problem(static_cast<int>(u0.size()), std::move(residual), std::move(jacobian), stability);
        SigintWatch sigint;
        if (timeLimit) options.interrupt = cont::Interrupt::after(*timeLimit);
        options.interrupt.watch(sigint.flag(), "interrupted (KeyboardInterrupt)");
        cont::BranchTree tree;
        {
          py::gil_scoped_release release;
          cont::TreeOptions treeOptions;
          treeOptions.branchSwitching = branchSwitching;
          tree = cont::traceTree(problem, u0, lambda0,
                                 {direction > 0 ? cont::InitialDirection::increasingLambda()
                                                : cont::InitialDirection::decreasingLambda()},
                                 options, treeOptions);
        }
        problem.raiseStored();
        sigint.raiseIfInterrupted();
        py::list branches;
        for (const cont::Branch& b : tree.branches) branches.append(branchDict(b, static_cast<int>(u0.size())));
        py::dict out;
        out["branches"] = branches;
        out["interrupted"] = tree.interrupted;
        out["message"] = tree.message;
        return out;
      },
      py::arg("residual"), py::arg("jacobian"), py::arg("u0"), py::arg("lambda0"), py::kw_only(),
      py::arg("options") = cont::TracerOptions(), py::arg("direction") = 1, py::arg("lambda_min") = py::none(),
      py::arg("lambda_max") = py::none(), py::arg("max_points") = py::none(), py::arg("initial_step") = py::none(),
      py::arg("min_step") = py::none(), py::arg("max_step") = py::none(), py::arg("tolerance") = py::none(),
      py::arg("location_tolerance") = py::none(), py::arg("branch_switching") = 0,
      py::arg("stability") = py::none(), py::arg("time_limit") = py::none(),
      "Traces the solution branches of F(u, λ) = 0 from (u0, λ0) by pseudo-arclength continuation, locating folds "
      "(LP) and branch points (BP) and, with branch_switching = d > 0, switching at branch points down to d "
      "generations.\n\n"
      "residual(u, lam) -> F (array of N); jacobian(u, lam) -> (F_u (N×N), F_lambda (N)), exact; optional "
      "stability(u, lam) -> symmetric N×N H (a state is stable where H is positive definite). direction: sign of "
      "dλ/ds at the start. options: a TracerOptions (its defaults are the library's); the keywords lambda_min, "
      "lambda_max, max_points, initial_step, min_step, max_step, tolerance and location_tolerance are short forms of "
      "its fields (options.step.max_step, options.corrector.tolerance, options.location.tolerance, ...). "
      "time_limit (s) stops the trace within a step, keeping what it computed (`interrupted`).\n\n"
      "Returns {'branches': [...], 'interrupted', 'message'}; each branch a dict with u (P×N), lambda, arclength, "
      "negative (negative eigenvalues of H, -1 without stability), special_points (dicts: type 'LP'/'BP'/'BD'/'EP', "
      "u, lambda, accuracy |Δλ|, residual, refined, ...), stop_reason, stop_message, id, parent. An exception "
      "raised by a callable is re-raised; Ctrl-C raises KeyboardInterrupt.");
}

}  // namespace buckle::python
