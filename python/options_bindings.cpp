// buckle.TracerOptions and its groups (StepOptions, CorrectorOptions, LocationOptions,
// DetectionOptions): the continuation core's settings (continuation/tracer_options.h) with the
// library's defaults, nested as in C++ and named as in a scene's /solver block (snake case).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cctype>
#include <string>

#include "bindings.h"
#include "buckle/continuation/tracer_options.h"

namespace buckle::python {

namespace py = pybind11;
namespace cont = buckle::continuation;

std::string snakeCase(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    // an upper-case letter inside an identifier (after a lower-case letter or digit) starts a word
    if (std::isupper(c) && i > 0 && (std::islower(static_cast<unsigned char>(text[i - 1])) ||
                                     std::isdigit(static_cast<unsigned char>(text[i - 1])))) {
      out += '_';
      out += static_cast<char>(std::tolower(c));
    } else {
      out += text[i];
    }
  }
  return out;
}

namespace {

// Every group has the library's defaults and a validate() whose message names the field as
// Python spells it.
template <class Options>
void addValidate(py::class_<Options>& c) {
  c.def("validate", [](const Options& o) { return snakeCase(o.validate()); },
        "'' when the settings are valid, else what is wrong (the field named as here).");
}

}  // namespace

void bindTracerOptions(py::module_& m) {
  py::enum_<cont::StepOptions::Rule>(m, "StepRule")
      .value("CURVATURE", cont::StepOptions::Rule::Curvature)
      .value("NEWTON_COUNT", cont::StepOptions::Rule::NewtonCount);

  py::class_<cont::StepOptions> step(m, "StepOptions",
                                     "The tracer's steps: dimensionless arclengths in the problem's scaled variables.");
  step.def(py::init<>())
      .def_readwrite("initial_step", &cont::StepOptions::initialStep)
      .def_readwrite("min_step", &cont::StepOptions::minStep)
      .def_readwrite("max_step", &cont::StepOptions::maxStep)
      .def_readwrite("rule", &cont::StepOptions::rule)
      .def_readwrite("target_newton_iterations", &cont::StepOptions::targetNewtonIterations)
      .def_readwrite("step_growth", &cont::StepOptions::stepGrowth)
      .def_readwrite("step_shrink", &cont::StepOptions::stepShrink)
      .def_readwrite("slow_contraction", &cont::StepOptions::slowContraction)
      .def_readwrite("target_contraction", &cont::StepOptions::targetContraction)
      .def_readwrite("target_angle", &cont::StepOptions::targetAngle)
      .def_readwrite("min_tangent_cosine", &cont::StepOptions::minTangentCosine)
      .def_readwrite("fold_pair_guard", &cont::StepOptions::foldPairGuard)
      .def_readwrite("second_order_predictor", &cont::StepOptions::secondOrderPredictor);
  addValidate(step);

  py::class_<cont::CorrectorOptions> corrector(m, "CorrectorOptions", "The Newton corrector (KINSOL).");
  corrector.def(py::init<>())
      .def_readwrite("tolerance", &cont::CorrectorOptions::tolerance)
      .def_readwrite("step_tolerance", &cont::CorrectorOptions::stepTolerance)
      .def_readwrite("max_iterations", &cont::CorrectorOptions::maxIterations)
      .def_readwrite("line_search", &cont::CorrectorOptions::lineSearch)
      .def_readwrite("max_newton_step", &cont::CorrectorOptions::maxNewtonStep)
      .def_readwrite("stagnation_factor", &cont::CorrectorOptions::stagnationFactor)
      .def_readwrite("lean_newton", &cont::CorrectorOptions::leanNewton);
  addValidate(corrector);

  py::class_<cont::LocationOptions> location(m, "LocationOptions", "Locating special points and stop events.");
  location.def(py::init<>())
      .def_readwrite("tolerance", &cont::LocationOptions::tolerance)
      .def_readwrite("coarse_tolerance", &cont::LocationOptions::coarseTolerance)
      .def_readwrite("newton_tolerance", &cont::LocationOptions::newtonTolerance)
      .def_readwrite("max_iterations", &cont::LocationOptions::maxIterations)
      .def_readwrite("max_refinement_iterations", &cont::LocationOptions::maxRefinementIterations)
      .def_readwrite("separation_fraction", &cont::LocationOptions::separationFraction)
      .def_readwrite("max_dense_dimension", &cont::LocationOptions::maxDenseDimension);
  addValidate(location);

  py::class_<cont::DetectionOptions> detection(m, "DetectionOptions", "What is looked for at every point.");
  detection.def(py::init<>())
      .def_readwrite("folds", &cont::DetectionOptions::folds)
      .def_readwrite("branch_points", &cont::DetectionOptions::branchPoints)
      .def_readwrite("boundaries", &cont::DetectionOptions::boundaries)
      .def_readwrite("stability", &cont::DetectionOptions::stability)
      .def_readwrite("lowest_eigenvalues", &cont::DetectionOptions::lowestEigenvalues)
      .def_readwrite("certified_counting", &cont::DetectionOptions::certifiedCounting)
      .def_readwrite("touch_tolerance", &cont::DetectionOptions::touchTolerance);
  addValidate(detection);

  py::class_<cont::TracerOptions> tracer(m, "TracerOptions",
                                         "The continuation core's settings (continuation/tracer_options.h), nested: "
                                         "step, corrector, location, detection; defaults are the library's.");
  tracer.def(py::init<>())
      .def_readwrite("step", &cont::TracerOptions::step)
      .def_readwrite("corrector", &cont::TracerOptions::corrector)
      .def_readwrite("location", &cont::TracerOptions::location)
      .def_readwrite("detection", &cont::TracerOptions::detection)
      .def_readwrite("max_points", &cont::TracerOptions::maxPoints)
      .def_readwrite("lambda_min", &cont::TracerOptions::lambdaMin)
      .def_readwrite("lambda_max", &cont::TracerOptions::lambdaMax)
      .def_readwrite("max_arclength", &cont::TracerOptions::maxArclength);
  addValidate(tracer);
}

}  // namespace buckle::python
