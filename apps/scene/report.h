// report.html: one self-contained page per run that opens offline (docs/outputs.md). The run's
// data are embedded as JSON and drawn by the page's own inline script on SVG: the bifurcation
// diagram with branches coloured by stability, the special points in a table with their
// accuracy, the chain's shape at any point (hover or click; joint positions computed here), and
// the views the scene's plots ask for. Nothing is fetched when the page is viewed.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "buckle/mechanics/chain.h"
#include "scene/runner.h"
#include "scene/scene.h"

namespace buckle::scene {

/// v to `digits` significant digits as the page embeds it: the double nearest to printf's
/// "%.*g" of v (null for a non-finite v: JSON has no NaN).
nlohmann::json roundedForPage(double v, int digits);

/// The complete page for a run; `specialPoints` and `summary` are the documents written as
/// special_points.json and summary.json (output.h), shown as tables.
std::string reportHtml(const Scene& scene, const RunResult& run, const nlohmann::json& specialPoints,
                       const nlohmann::json& summary);

/// Writes reportHtml() as dir/report.html (throws std::runtime_error when it cannot).
void writeReport(const Scene& scene, const RunResult& run, const nlohmann::json& specialPoints,
                 const nlohmann::json& summary, const std::string& dir);

}  // namespace buckle::scene
