// Internal to the scene parser (scene.h): scene.cpp reads the document and its cases,
// scene_case.cpp parses what one case is (chain, end, path), scene_analyses.cpp what is computed
// for every case (analyses, solver, plots). All of them throw SceneError on bad input.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "buckle/mechanics/chain.h"
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

/// /gravity and /point_loads of a case (scene_body.cpp) against its chain.
BodySpec parseBody(const JsonReader& r, const json& doc, const mechanics::Chain& chain);
/// A /path with parameter "gravity": the range (≥ 0, containing /gravity/value); no direction.
PathSpec parseGravityPath(const JsonReader& r, const json& path, const Pointer& p, const BodySpec& body);
/// The analyses that do not take body loads refused; one mass model with /analyses/frequencies.
void checkBodyAnalyses(const JsonReader& r, const Scene& scene);

/// A /path whose parameter is a control input (scene_control.cpp): true for "L1_0", "L2_0",
/// "L0", "dL0".
bool isControlPath(const json& path);
/// Parses it against the chain: /path/segment (1-based, optional), the range (containing the
/// inputs' value on the chain, every free length positive over it); /path/direction is refused.
/// A direction in control space at `pd` ({"<complementary input>": rate or [rate per segment]}:
/// /path/direction, a workspace axis's direction): the rates, one value or one per segment (the
/// caller checks the count against the chain); empty for {}.
Eigen::VectorXd parseControlDirection(const JsonReader& r, const json& d, const Pointer& pd,
                                      mechanics::ControlInput input);
PathSpec parseControlPath(const JsonReader& r, const json& path, const Pointer& p, const mechanics::Chain& chain);
/// The analyses a control path cannot run (critical forces, two-parameter, sudden load) refused.
void checkControlPathAnalyses(const JsonReader& r, const Scene& scene);

/// A /path with a "task" (scene_task.cpp): a task-space path.
bool isTaskPath(const json& path);
/// Parses it against the chain and /end (every end coordinate loaded: the payload).
PathSpec parseTaskPath(const JsonReader& r, const json& path, const Pointer& p, const mechanics::Chain& chain,
                       const EndSpec& end);
/// The analyses a task path cannot run refused; /analyses/continuation required.
void checkTaskPathAnalyses(const JsonReader& r, const Scene& scene);

// ---- analyses, solver, plots (scene_analyses.cpp) -------------------------------------------

/// /analyses: every block through the registry (analyses.h), in its order.
AnalysesSpec parseAnalyses(const JsonReader& r, const json& a, const Pointer& p);
/// The blocks of the analyses under /analyses (registered in analyses.cpp), each read into `s`.
void parseContinuation(const JsonReader& r, const json& c, const Pointer& p, AnalysesSpec& s);
void parseStiffness(const JsonReader& r, const json& k, const Pointer& p, AnalysesSpec& s);
void parseEnergyCurves(const JsonReader& r, const json& e, const Pointer& p, AnalysesSpec& s);
void parseTorqueAngle(const JsonReader& r, const json& t, const Pointer& p, AnalysesSpec& s);
void parseCriticalForces(const JsonReader& r, const json& c, const Pointer& p, AnalysesSpec& s);
void parseJump(const JsonReader& r, const json& j, const Pointer& p, AnalysesSpec& s);
void parseLoadHistory(const JsonReader& r, const json& h, const Pointer& p, AnalysesSpec& s);
void parseSuddenLoad(const JsonReader& r, const json& d, const Pointer& p, AnalysesSpec& s);
void parseFrequenciesBlock(const JsonReader& r, const json& f, const Pointer& p, AnalysesSpec& s);
void parseTwoParameterBlock(const JsonReader& r, const json& v, const Pointer& p, AnalysesSpec& s);
void parseEquilibriaBlock(const JsonReader& r, const json& v, const Pointer& p, AnalysesSpec& s);
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
/// /analyses/workspace (scene_workspace.cpp): false or an object of options.
void parseWorkspace(const JsonReader& r, const json& v, const Pointer& p, AnalysesSpec& s);
/// Every case's end holds nothing, the inputs exist on its chain and their ranges contain its own
/// values with every free length positive.
void checkWorkspaceAgainstCases(const JsonReader& r, const Scene& scene);
/// `inputColumns`: the task paths' input columns (taskInputColumns), allowed on the axes too.
PlotSpec parsePlot(const JsonReader& r, const json& v, const Pointer& p, const AnalysesSpec& a, int maxN, int nCases,
                   const std::vector<std::string>& inputColumns = {});
/// The plots of a scene without "plots": one per analysis that has a plot.
std::vector<PlotSpec> defaultPlots(const AnalysesSpec& a, int nCases);

}  // namespace buckle::scene::detail
