// The equilibria analysis in the outputs (docs/scenes.md, docs/outputs.md): `equilibria` of
// special_points.json and equilibria.csv.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "scene/runner.h"

namespace buckle::scene {

/// Per case: the search (method, guarantee, counts, Morse check) and every equilibrium found.
nlohmann::json equilibriaJson(const RunResult& run);
/// One row per equilibrium: case, rank (ascending Π), Π, index, stable, shape, the end wrench,
/// the end pose, the accuracy and the joint angles q1 … qn.
std::string equilibriaCsv(const RunResult& run);

}  // namespace buckle::scene
