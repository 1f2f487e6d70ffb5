#include "scene/solver_settings.h"

namespace buckle::scene {

namespace {

using nlohmann::json;
using Pointer = json::json_pointer;

using Rule = continuation::StepOptions::Rule;

// The nested value of `key` in group `group`, or its flat short form; null when neither is given.
const json* setting(const JsonReader& r, const json& s, const Pointer& p, const char* group, const char* key,
                    const char* shortForm, Pointer& where) {
  const json* nested = s.contains(group) && s[group].contains(key) ? &s[group][key] : nullptr;
  const json* flat = shortForm && s.contains(shortForm) ? &s[shortForm] : nullptr;
  if (nested && flat)
    r.fail(p / shortForm, std::string("given twice: also as ") + (p / group / key).to_string() + " (keep one)");
  where = nested ? p / group / key : p / (shortForm ? shortForm : key);
  return nested ? nested : flat;
}

void readStep(const JsonReader& r, const json& s, const Pointer& p, continuation::StepOptions& o) {
  Pointer at;
  if (const json* v = setting(r, s, p, "step", "initial_step", "initial_step", at)) o.initialStep = r.positive(*v, at);
  if (const json* v = setting(r, s, p, "step", "min_step", "min_step", at)) o.minStep = r.positive(*v, at);
  if (const json* v = setting(r, s, p, "step", "max_step", "max_step", at)) o.maxStep = r.positive(*v, at);
  if (!s.contains("step")) return;
  const json& g = s["step"];
  const Pointer pg = p / "step";
  if (g.contains("rule")) {
    const std::string rule = r.string(g["rule"], pg / "rule");
    if (rule != "newton_count" && rule != "curvature")
      r.expected(pg / "rule", g["rule"], "\"newton_count\" (AUTO-07p's iteration count) or \"curvature\"");
    o.rule = rule == "curvature" ? Rule::Curvature : Rule::NewtonCount;
  }
  if (g.contains("target_newton_iterations"))
    o.targetNewtonIterations = r.integer(g["target_newton_iterations"], pg / "target_newton_iterations", 1, 50);
  if (g.contains("min_tangent_cosine")) {
    o.minTangentCosine = r.number(g["min_tangent_cosine"], pg / "min_tangent_cosine");
    if (!(o.minTangentCosine > -1.0 && o.minTangentCosine <= 1.0))
      r.expected(pg / "min_tangent_cosine", g["min_tangent_cosine"], "a cosine in (-1, 1] (default 0.9)");
  }
  if (g.contains("second_order_predictor"))
    o.secondOrderPredictor = r.boolean(g["second_order_predictor"], pg / "second_order_predictor");
  if (g.contains("fold_pair_guard")) o.foldPairGuard = r.boolean(g["fold_pair_guard"], pg / "fold_pair_guard");
}

void readCorrector(const JsonReader& r, const json& s, const Pointer& p, continuation::CorrectorOptions& o) {
  Pointer at;
  if (const json* v = setting(r, s, p, "corrector", "tolerance", "tolerance", at)) {
    o.tolerance = r.positive(*v, at);
    // a residual norm in the chain's units: beyond 1e-3 a point is no equilibrium to plot
    if (o.tolerance > 1e-3) r.expected(at, *v, "a number in (0, 1e-3] (default 1e-10)");
  }
  if (!s.contains("corrector")) return;
  const json& g = s["corrector"];
  const Pointer pg = p / "corrector";
  if (g.contains("max_iterations")) o.maxIterations = r.integer(g["max_iterations"], pg / "max_iterations", 1, 1000);
  if (g.contains("line_search")) o.lineSearch = r.boolean(g["line_search"], pg / "line_search");
}

void readLocation(const JsonReader& r, const json& s, const Pointer& p, continuation::LocationOptions& o) {
  Pointer at;
  if (const json* v = setting(r, s, p, "location", "tolerance", "location_tolerance", at)) {
    // relative to the parameter's scale: below 1e-15 no double resolves it, above 1e-2 it is no location
    o.tolerance = r.number(*v, at);
    if (!(o.tolerance >= 1e-15 && o.tolerance <= 1e-2)) r.expected(at, *v, "a relative tolerance in [1e-15, 1e-2]");
  }
  if (!s.contains("location")) return;
  const json& g = s["location"];
  const Pointer pg = p / "location";
  if (g.contains("max_iterations")) o.maxIterations = r.integer(g["max_iterations"], pg / "max_iterations", 1, 10000);
}

}  // namespace

SolverSpec parseSolver(const JsonReader& r, const json& s, const Pointer& p) {
  r.onlyKeys(s, p, {"step", "corrector", "location", "max_points", "time_limit", "initial_step", "min_step", "max_step",
                    "tolerance", "location_tolerance"});
  for (const char* group : {"step", "corrector", "location"})
    if (s.contains(group)) r.requireObject(s[group], p / group);
  if (s.contains("step"))
    r.onlyKeys(s["step"], p / "step",
               {"initial_step", "min_step", "max_step", "rule", "target_newton_iterations", "min_tangent_cosine",
                "second_order_predictor", "fold_pair_guard"});
  if (s.contains("corrector")) r.onlyKeys(s["corrector"], p / "corrector", {"tolerance", "max_iterations", "line_search"});
  if (s.contains("location")) r.onlyKeys(s["location"], p / "location", {"tolerance", "max_iterations"});
  SolverSpec o;
  continuation::TracerOptions& t = o.tracer;
  readStep(r, s, p, t.step);
  readCorrector(r, s, p, t.corrector);
  readLocation(r, s, p, t.location);
  if (s.contains("max_points")) t.maxPoints = r.integer(s["max_points"], p / "max_points", 2, 10000000);
  if (s.contains("time_limit")) o.timeLimit = r.positive(s["time_limit"], p / "time_limit");
  auto stepKey = [&](const char* key) { return s.contains(key) ? p / key : p / "step" / key; };
  if (!(t.step.minStep <= t.step.initialStep)) r.fail(stepKey("min_step"), "expected min_step <= initial_step");
  if (!(t.step.initialStep <= t.step.maxStep)) r.fail(stepKey("max_step"), "expected max_step >= initial_step");
  // what the parser's ranges let through and the library still refuses (none expected)
  const std::string why = t.validate();
  if (!why.empty()) r.fail(p, "invalid tracer settings: " + why);
  return o;
}

json solverJson(const SolverSpec& s) {
  const continuation::TracerOptions& t = s.tracer;
  return json{{"step",
               {{"initial_step", t.step.initialStep},
                {"min_step", t.step.minStep},
                {"max_step", t.step.maxStep},
                {"rule", t.step.rule == Rule::Curvature ? "curvature" : "newton_count"},
                {"target_newton_iterations", t.step.targetNewtonIterations},
                {"min_tangent_cosine", t.step.minTangentCosine},
                {"second_order_predictor", t.step.secondOrderPredictor},
                {"fold_pair_guard", t.step.foldPairGuard}}},
              {"corrector",
               {{"tolerance", t.corrector.tolerance},
                {"max_iterations", t.corrector.maxIterations},
                {"line_search", t.corrector.lineSearch}}},
              {"location", {{"tolerance", t.location.tolerance}, {"max_iterations", t.location.maxIterations}}},
              {"max_points", t.maxPoints},
              {"time_limit", s.timeLimit}};
}

}  // namespace buckle::scene
