// The workspace analysis in the outputs (docs/scenes.md, docs/outputs.md): `workspace` of
// special_points.json, workspace_map.csv (the grid) and workspace_curves.csv (the bounding curves).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "scene/runner.h"

namespace buckle::scene {

/// Per case: the inputs, the grid's counts (reached, stable), the stable workspace's extent, the
/// curves (name, cause, points, how they ended, the worst residual) and the problems met.
nlohmann::json workspaceJson(const RunResult& run);
/// One row per grid value: case, the two inputs, reached, the end pose, stability, the smallest
/// eigenvalue of K_q − K_g and of K_F, the folds passed, the residual; why not reached (note).
std::string workspaceMapCsv(const RunResult& run);
/// One row per curve point: case, curve id, cause, name, the inputs, the end pose, stable, residual.
std::string workspaceCurvesCsv(const RunResult& run);

}  // namespace buckle::scene
