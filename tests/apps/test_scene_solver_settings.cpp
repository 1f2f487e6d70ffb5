// The scene's /solver block (scene/solver_settings.h) against the library's settings: the nested
// keys are the C++ fields, the flat keys of older scenes are their short forms, a setting given
// both ways is refused, the defaults are the library's, and summary.json's block reads back to
// the same settings.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>
#include <string>

#include "buckle/mechanics/chain_tracer_options.h"
#include "scene/solver_settings.h"

using buckle::scene::JsonInputError;
using buckle::scene::JsonReader;
using buckle::scene::parseSolver;
using buckle::scene::solverJson;
using buckle::scene::SolverSpec;
using json = nlohmann::json;
namespace cont = buckle::continuation;

namespace {

SolverSpec parse(const std::string& text) {
  const JsonReader r("scene.json");
  return parseSolver(r, json::parse(text), json::json_pointer("/solver"));
}

// Every setting the block can carry: summary.json's block writes each of them.
void requireSame(const cont::TracerOptions& a, const cont::TracerOptions& b) {
  SolverSpec x, y;
  x.tracer = a;
  y.tracer = b;
  CHECK(solverJson(x) == solverJson(y));
}

// The JSON path and message of the error `text` raises.
std::string refusal(const std::string& text) {
  try {
    parse(text);
  } catch (const JsonInputError& e) {
    return e.path() + ": " + e.message();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("solver: no block, or an empty one, is the library's chain defaults", "[scene][solver]") {
  requireSame(SolverSpec().tracer, buckle::mechanics::chainTracerOptions());
  requireSame(parse("{}").tracer, buckle::mechanics::chainTracerOptions());
  // and those are the core's, with the steps and the point budget of a chain
  const cont::TracerOptions core, chain = buckle::mechanics::chainTracerOptions();
  CHECK(chain.corrector.tolerance == core.corrector.tolerance);
  CHECK(chain.location.tolerance == core.location.tolerance);
  CHECK(chain.validate().empty());
}

TEST_CASE("solver: the nested keys are the C++ fields, the flat keys their short forms", "[scene][solver]") {
  const SolverSpec nested = parse(
      R"({"step": {"initial_step": 0.03, "min_step": 1e-6, "max_step": 0.04}, "corrector": {"tolerance": 1e-9},
          "location": {"tolerance": 1e-8}, "max_points": 77})");
  const SolverSpec flat = parse(
      R"({"initial_step": 0.03, "min_step": 1e-6, "max_step": 0.04, "tolerance": 1e-9, "location_tolerance": 1e-8,
          "max_points": 77})");
  requireSame(nested.tracer, flat.tracer);
  CHECK(nested.tracer.step.initialStep == 0.03);
  CHECK(nested.tracer.step.minStep == 1e-6);
  CHECK(nested.tracer.step.maxStep == 0.04);
  CHECK(nested.tracer.corrector.tolerance == 1e-9);
  CHECK(nested.tracer.location.tolerance == 1e-8);
  CHECK(nested.tracer.maxPoints == 77);
  // what neither names keeps the library's value
  CHECK(nested.tracer.step.rule == buckle::mechanics::chainTracerOptions().step.rule);

  const SolverSpec more = parse(
      R"({"step": {"rule": "curvature", "target_newton_iterations": 5, "min_tangent_cosine": 0.8,
                   "second_order_predictor": true, "fold_pair_guard": true},
          "corrector": {"max_iterations": 20, "line_search": true}, "location": {"max_iterations": 90}})");
  CHECK(more.tracer.step.rule == cont::StepOptions::Rule::Curvature);
  CHECK(more.tracer.step.targetNewtonIterations == 5);
  CHECK(more.tracer.step.minTangentCosine == 0.8);
  CHECK(more.tracer.step.secondOrderPredictor);
  CHECK(more.tracer.step.foldPairGuard);
  CHECK(more.tracer.corrector.maxIterations == 20);
  CHECK(more.tracer.corrector.lineSearch);
  CHECK(more.tracer.location.maxIterations == 90);
}

TEST_CASE("solver: summary.json's block reads back to the same settings", "[scene][solver]") {
  for (const std::string& text :
       {std::string("{}"), std::string(R"({"step": {"rule": "curvature", "max_step": 0.1}, "tolerance": 1e-11})"),
        std::string(R"({"location": {"tolerance": 1e-15, "max_iterations": 3}, "max_points": 2, "time_limit": 5})")}) {
    INFO(text);
    const SolverSpec first = parse(text);
    const json written = solverJson(first);
    const SolverSpec again = parse(written.dump());
    requireSame(first.tracer, again.tracer);
    CHECK(again.timeLimit == first.timeLimit);
    CHECK(solverJson(again) == written);
  }
}

TEST_CASE("solver: a setting given twice, an unknown key or a bad value is refused by its path", "[scene][solver]") {
  CHECK(refusal(R"({"max_step": 0.04, "step": {"max_step": 0.03}})") ==
        "/solver/max_step: given twice: also as /solver/step/max_step (keep one)");
  CHECK(refusal(R"({"tolerance": 1e-9, "corrector": {"tolerance": 1e-9}})").rfind("/solver/tolerance: given twice", 0) ==
        0);
  CHECK(refusal(R"({"location_tolerance": 1e-9, "location": {"tolerance": 1e-9}})")
            .rfind("/solver/location_tolerance: given twice", 0) == 0);
  CHECK(refusal(R"({"step": {"max_stp": 0.1}})").rfind("/solver/step", 0) == 0);
  CHECK(refusal(R"({"step": 0.1})").rfind("/solver/step", 0) == 0);
  CHECK(refusal(R"({"step": {"rule": "secant"}})").rfind("/solver/step/rule", 0) == 0);
  CHECK(refusal(R"({"corrector": {"tolerance": 0.5}})").rfind("/solver/corrector/tolerance", 0) == 0);
  CHECK(refusal(R"({"corrector": {"max_iterations": 0}})").rfind("/solver/corrector/max_iterations", 0) == 0);
  CHECK(refusal(R"({"location": {"tolerance": 1e-20}})").rfind("/solver/location/tolerance", 0) == 0);
  CHECK(refusal(R"({"step": {"min_tangent_cosine": -1}})").rfind("/solver/step/min_tangent_cosine", 0) == 0);
  CHECK(refusal(R"({"step": {"min_step": 0.5}})").rfind("/solver/step/min_step: expected min_step <= initial_step", 0) ==
        0);
  CHECK(refusal(R"({"min_step": 0.5})").rfind("/solver/min_step", 0) == 0);
}
