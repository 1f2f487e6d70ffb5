// The scene's /solver block, both ways: read into the library's own tracer settings
// (continuation::TracerOptions, nested as in C++: /solver/step, /solver/corrector,
// /solver/location) and written back in the same shape into summary.json. The keys are the C++
// names in snake case (step.maxStep ↔ /solver/step/max_step). The flat keys of older scenes
// (/solver/max_step, /solver/tolerance, /solver/location_tolerance, ...) are still read, as the
// short form of the nested key they name; a setting given both ways is refused.
#pragma once

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace buckle::scene {

/// /solver into `spec` (its defaults: SolverSpec's, i.e. mechanics::chainTracerOptions()).
SolverSpec parseSolver(const JsonReader& r, const nlohmann::json& s, const nlohmann::json::json_pointer& p);
/// The settings as the nested /solver block, every key parseSolver reads.
nlohmann::json solverJson(const SolverSpec& s);

}  // namespace buckle::scene
