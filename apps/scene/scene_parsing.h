// Internal to the scene parser (scene.h): scene.cpp reads the document and its cases,
// scene_case.cpp parses what one case is (chain, end, path), scene_analyses.cpp what is computed
// for every case (analyses, solver, plots). All of them throw SceneError on bad input.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace buckle::scene::detail {

using nlohmann::json;
using Pointer = json::json_pointer;

/// A number in a message: 6 significant digits.
std::string show(double v);

// ---- one case (scene_case.cpp) ------------------------------------------------------------

/// One case from its document (the scene's chain/end/path with the case's patch applied).
/// needPath: an analysis needs /path (else a default Fx path of zero length is used).
CaseSpec parseCase(const JsonReader& r, const json& doc, const std::string& label, bool needPath);

// ---- analyses, solver, plots (scene_analyses.cpp) -------------------------------------------

AnalysesSpec parseAnalyses(const JsonReader& r, const json& a, const Pointer& p);
/// /analyses/two_parameter (scene_two_parameter.cpp).
TwoParameterSpec parseTwoParameter(const JsonReader& r, const json& v, const Pointer& p);
/// Its segment exists and its range contains every case's value of the parameter.
void checkTwoParameterAgainstCases(const JsonReader& r, const Scene& scene);
/// What the analyses require of every case: 3 segments for energy curves, load-history
/// waypoints and the sudden load inside the path range, rod masses the inertial model can use.
void checkAnalysesAgainstCases(const JsonReader& r, const Scene& scene);
/// /analyses/equilibria (scene_equilibria.cpp): true, false or an object of options.
EquilibriaSpec parseEquilibria(const JsonReader& r, const json& v, const Pointer& p);
/// Its `at` inside every case's path range.
void checkEquilibriaAgainstCases(const JsonReader& r, const Scene& scene);
SolverSpec parseSolver(const JsonReader& r, const json& s, const Pointer& p);
PlotSpec parsePlot(const JsonReader& r, const json& v, const Pointer& p, const AnalysesSpec& a, int maxN, int nCases);
/// The plots of a scene without "plots": one per analysis that has a plot.
std::vector<PlotSpec> defaultPlots(const AnalysesSpec& a, int nCases);

}  // namespace buckle::scene::detail
