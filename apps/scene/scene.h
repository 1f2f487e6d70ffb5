// A scene: what the user wants to know about one manipulator (or a few variants of it), read
// from a JSON file. The schema is documented in docs/scenes.md. Parsing validates everything
// up front, so the runner never meets a bad value: a SceneError names the file, the JSON path
// of the offending value (RFC 6901, e.g. /chain/k) and what was expected.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "buckle/mechanics/chain_tracer_options.h"
#include "buckle/mechanics/control_path.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/stiffness_extremum.h"
#include "buckle/mechanics/task_path.h"
#include "buckle/mechanics/workspace_map.h"
#include "buckle/mechanics/segment.h"
#include "scene/json_reader.h"
#include "scene/units.h"

namespace buckle::scene {

/// Bad input: the file, the JSON path of the bad value and what was expected (scene/json_reader.h).
using SceneError = JsonInputError;

/// The most segments a scene may ask for, all cases together, whether as counts or as lists of
/// segment objects: every case is a chain to build, trace and write.
constexpr int kMaxSegments = 100000;

/// The end's coordinates (mechanics::EndCoordinate 0 x, 1 y, 2 φ) and the loads on them, as
/// scenes, outputs and messages name them.
inline constexpr std::array<const char*, 3> kEndCoordinateNames{"x", "y", "phi"};
inline constexpr std::array<const char*, 3> kEndLoadNames{"Fx", "Fy", "Me"};

/// A force at a joint (/point_loads): at the path's start value and its rate along the path.
struct PointLoadSpec {
  int joint = 1;                                    ///< 1 … n
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  ///< (Fx, Fy) at the start value
  Eigen::Vector2d rate = Eigen::Vector2d::Zero();   ///< d(Fx, Fy)/d(path parameter)
};

/// The loads on the chain's body (/gravity, /point_loads; mechanics/body_loads.h): the links'
/// weight as uniform rods of `massPerLength` (the mass model of /analyses/frequencies), a payload
/// mass at the end, point forces at joints.
struct BodySpec {
  bool haveGravity = false;
  double gravity = 0.0;                                   ///< g at the start (acceleration)
  Eigen::Vector2d direction = Eigen::Vector2d(0.0, -1.0); ///< unit vector of g
  double massPerLength = 0.0;                             ///< ≥ 0 (mass / length)
  double payload = 0.0;                                   ///< ≥ 0: a point mass at the end
  std::vector<PointLoadSpec> points;
  bool any() const { return haveGravity || !points.empty(); }
};

/// One chain variant: segment parameters (after preloads for q0 were computed) and its
/// unloaded shape.
struct ChainSpec {
  std::vector<mechanics::SegmentParameters> segments;
  Eigen::VectorXd q0;           ///< unloaded joint angles (zero for a straight start)
  bool preloadsFromQ0 = false;  ///< L1⁰/L2⁰ were computed from a desired q0
};

/// How each end coordinate (x, y, φ) is prescribed at the start of the path.
struct EndSpec {
  mechanics::EndCondition condition;  ///< control and start values
  std::array<bool, 3> heldAtStart{false, false, false};  ///< "held": "start" (use q0's pose)
};

/// Names of the path parameters: Fx Fy Me (loads) and x y phi (held coordinates).
struct PathSpec {
  std::string parameter;       ///< "Fx", "Fy", "Me", "x", "y" or "phi"
  int coordinate = 0;          ///< 0 = x, 1 = y, 2 = φ
  double from = 0.0, to = 0.0; ///< parameter range; contains the start value
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< d(prescribed)/d(parameter)
  /// Displacement control traced through the held coordinate's reaction (mechanics/reaction_path.h):
  /// the scene gave /path/load_limit, or the start is singular for the held coordinate (the
  /// straight chain cannot move its end along x to first order). The branches are traced with the
  /// reaction as parameter, from 0 to ±loadLimit, each ending where the coordinate leaves
  /// [from, to], and reported against the coordinate with displacement-control stability.
  bool throughReaction = false;
  /// The scene's /path/load_limit (its force unit); 0: derived from the critical reactions.
  double loadLimit = 0.0;
  /// A control path (issue 29): the parameter is a control input ("L1_0", "L2_0", "L0", "dL0")
  /// of segment `segment` or of every segment, λ moves the springs' free lengths along
  /// `controlDirection` (origin: `start`) with the end at /end's values (the payload or the held
  /// coordinates); `direction` is zero and `coordinate` unused.
  bool control = false;
  /// The path parameter is the gravity magnitude g (/gravity, "gravity"): λ = g, the
  /// acceleration λ·/gravity/direction; the end values stay those of /end (`direction` zero).
  bool gravity = false;
  int segment = -1;     ///< 0-based; −1: every segment
  mechanics::ControlDirection controlDirection;
  double start = 0.0;   ///< the input's value on the scene's chain (mean over the segments for all)
  /// A task-space path (issue 29; mechanics/task_path.h): the end pose on taskSetup.coordinates
  /// follows the straight legs through `waypoints` from the start pose under /end's payload, the
  /// inputs of taskSetup are unknowns; the parameter is the path's arclength s (from 0), `from`
  /// and `to` its range.
  bool task = false;
  mechanics::TaskSetup taskSetup;
  std::vector<Eigen::VectorXd> waypoints;  ///< each on the task coordinates
};

struct ContinuationSpec {
  bool enabled = false;
  /// Depth of the branch tree (0: primary branch only); −1: not given, see depth().
  int branchSwitching = -1;
  /// The depth used: as given, else 1 for a path traced through the reaction (only the buckled
  /// branches move the held coordinate) and 0 otherwise.
  int depth(bool throughReaction) const { return branchSwitching >= 0 ? branchSwitching : throughReaction ? 1 : 0; }
  /// Switch at the first this many simple branch points along each branch (0: all of them).
  int branchPoints = 0;
  /// Points per switched branch (0: the solver's max_points, as the start branches).
  int childPoints = 0;
  /// Joints that reach a limit lock and the branch goes on under contact (mechanics/contact.h);
  /// false: the branch ends at the limit ("BD").
  bool contact = true;
  /// With contact: the base wall x = 0 holds the vertices that reach it (mechanics/contact.h,
  /// wall_contact.h: WC / WR); false: the chain passes through it, detected only (BC).
  bool wall = false;
  /// With contact: a vertex that reaches another link's triangle is held on its edge
  /// (mechanics/self_contact.h: SH / SR); false: the links pass through each other, detected only (SC).
  bool self = false;
  /// An exactly mirror-symmetric scene (mechanics/mirror_symmetry.h) mirrors the − side child of
  /// every symmetric pitchfork instead of tracing it; false: both traced (for checking).
  bool mirror = true;
  /// Threads that trace the children of different branch points at once (0: all cores, or under
  /// mpirun the cores of this rank); the outputs are the same for any number.
  int threads = 0;
};

struct EnergyCurvesSpec {
  bool enabled = false;
  double x = 0.0, y = 0.0;     ///< end position held while q1 sweeps
  double q1From = -1.0, q1To = 1.0;
  int points = 801;
  bool torque = false;         ///< also the end torque Me(q1) (paper Fig 5)
};

struct TorqueAngleSpec {
  bool enabled = false;
  double qFrom = -2.0, qTo = 2.0;
  int points = 401;
};

struct CriticalForcesSpec {
  bool enabled = false;
  int modes = 3;  ///< how many critical loads of the start configuration to report
};

/// Two-parameter continuation (mechanics/critical_curves.h): the critical loads of the case as
/// curves in a second parameter μ.
struct TwoParameterSpec {
  bool enabled = false;
  std::string parameter;       ///< a, b, k, L0, dL0 (segment parameters) or x, y, phi (end values)
  int segment = -1;            ///< 0-based; −1: every segment
  double from = 0.0, to = 0.0; ///< range of μ (contains the case's value)
  int modes = 1;               ///< BP curves of the straight chain's first `modes` compressive modes
  bool folds = false;          ///< LP curves from the folds of the path traced from the start
};

struct JumpSpec {
  bool enabled = false;
  double perturbation = 1e-3;  ///< ‖δq‖ of the release along the unstable direction
};

/// A quasi-static load history: the path parameter visits the waypoints in turn (up, back
/// down, …); where the stable state ends the chain jumps (mechanics/load_history.h).
struct LoadHistorySpec {
  bool enabled = false;
  std::vector<double> waypoints;  ///< path-parameter values; the first is the start value
  double perturbation = 1e-3;     ///< ‖δq‖ of each release along the unstable direction
};

/// The "sporadic" load: the path parameter jumps from its start value to `value` at once and the
/// chain's dynamic answer is compared with the quasi-static one (mechanics/jump.h). Masses are
/// only modelled when given: without them the response is the overdamped gradient flow.
struct SuddenLoadSpec {
  bool enabled = false;
  double value = 0.0;            ///< path-parameter value applied at once
  double massPerLength = 0.0;    ///< > 0: inertial dynamics with uniform rods
  double damping = 0.0;          ///< viscous joint damping of the inertial model
};

/// Natural frequencies of small oscillations about every traced point (mechanics/vibration.h):
/// the lowest `count` of them, the links slender uniform rods of `massPerLength`.
constexpr int kMaxFrequencies = 50;
struct FrequenciesSpec {
  bool enabled = false;
  int count = 3;
  double massPerLength = 0.0;  ///< > 0 (mass / length in the scene's units)
};

/// Every equilibrium at one state of the controls (mechanics/all_equilibria.h): the case's end
/// condition at each value of the path parameter in `at` (default: its start value).
struct EquilibriaSpec {
  /// At most this many values in `at` (each a complete search).
  static constexpr int kMaxAt = 1000;
  bool enabled = false;
  int starts = 64;             ///< random starting shapes of the deflated Newton search
  int smoothStarts = 64;       ///< random smooth starting shapes
  unsigned seed = 1;           ///< of the random shapes
  /// Path-parameter values, in the scene's order (empty: the case's start value).
  std::vector<double> at;
  int sweepPoints = 4001;      ///< q1 grid of the n = 3 sweep (end held, Me = 0)
  /// Trace the branches through the equilibria the continuation's tree does not reach
  /// (mechanics/disconnected_branches.h); needs /analyses/continuation.
  bool branches = false;
};

/// Workspace and stability maps over two control inputs (mechanics/workspace_map.h): the library's
/// options as they are, their tracer set from /solver when the case runs.
struct WorkspaceSpec {
  bool enabled = false;
  mechanics::WorkspaceMapOptions options;
};

struct AnalysesSpec {
  ContinuationSpec continuation;
  FrequenciesSpec frequencies;
  JumpSpec jump;
  LoadHistorySpec loadHistory;
  SuddenLoadSpec suddenLoad;
  bool stiffness = false;
  /// The measure whose deep minima along a branch are reported as KMIN (quasi-buckling).
  mechanics::StiffnessMeasure stiffnessMeasure = mechanics::StiffnessMeasure::Kxx;
  EnergyCurvesSpec energyCurves;
  TorqueAngleSpec torqueAngle;
  CriticalForcesSpec criticalForces;
  TwoParameterSpec twoParameter;
  EquilibriaSpec equilibria;
  WorkspaceSpec workspace;
};

/// /solver: the tracer settings of every analysis (the library's mechanics::chainTracerOptions(),
/// with what the scene names changed; each analysis sets its own λ range) and the run's limit.
struct SolverSpec {
  continuation::TracerOptions tracer = mechanics::chainTracerOptions();
  double timeLimit = 120.0;    ///< seconds for the whole scene; past it the run stops (exit 1)
};

enum class PlotType {
  Bifurcation,
  Stiffness,
  EnergyCurves,
  TorqueAngle,
  Shapes,
  SuddenLoad,
  CriticalCurves,
  EquilibriumShapes,
  Workspace,
  InputMap
};
const char* toString(PlotType t);

/// Which special points a bifurcation or stiffness plot labels (docs/scenes.md, `plots`): all of
/// them, or a summary (the branch points of the primary branch, jumps, the first fold of each
/// branch; the others small unlabelled markers counted in the key); `Auto` picks the summary
/// above a number of markers (long chains, large trees).
enum class PlotLabels { Auto, All, Summary };

struct PlotSpec {
  PlotType type = PlotType::Bifurcation;
  std::string name;                  ///< output file stem
  std::string x;                     ///< column on the horizontal axis
  std::vector<std::string> y;        ///< columns on the vertical axis
  std::vector<double> at;            ///< shapes: parameter values to draw the chain at
  std::string title;
  std::vector<int> cases;            ///< indices of the cases drawn (default: all)
  PlotLabels labels = PlotLabels::Auto;  ///< bifurcation / stiffness: which special points are labelled
};

/// One complete run: a chain, an end condition and a path.
struct CaseSpec {
  std::string label;
  ChainSpec chain;
  EndSpec end;
  PathSpec path;
  BodySpec body;

  /// The path parameter's value at the start: the prescribed value of the path's coordinate, or
  /// along a control path the inputs' value on the chain, or along a gravity path /gravity/value.
  double startValue() const {
    if (path.task) return 0.0;
    return path.control ? path.start : path.gravity ? body.gravity : end.condition.value[path.coordinate];
  }
};

struct Scene {
  std::string file;
  std::string description;
  UnitSystem units;             ///< what the numbers are in, for labels (scene/units.h)
  std::vector<CaseSpec> cases;  ///< at least one
  AnalysesSpec analyses;
  SolverSpec solver;
  std::vector<PlotSpec> plots;
  int maxSegments() const;
  /// The task paths' input columns of branches.csv ("dL0", "L1_0[3]": mechanics::taskInputName),
  /// over every case in order of first appearance; empty without a task path.
  std::vector<std::string> inputColumns() const;
};

/// One segment from the keys of a scene's segment object (a, b, k, L0, a1, b1, a2, b2, k1, k2,
/// L1_0, L2_0, q_min, q_max; absent keys take the scene's defaults), validated exactly as in a
/// scene: the Python Segment uses it, so both refuse the same values with the same words. Throws
/// SceneError (file `source`, the key as path).
mechanics::SegmentParameters segmentFromKeys(const nlohmann::json& keys, const std::string& source);

/// Parses and validates a scene file. Throws SceneError on any bad input.
Scene loadScene(const std::string& file);
/// Same, from text (file is only used in messages).
Scene parseScene(const std::string& text, const std::string& file);

}  // namespace buckle::scene
