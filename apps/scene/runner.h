// Runs the analyses a scene asks for — and only those — and collects the results as plain data
// for the writers and plots (output.h, plot.h).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/interrupt.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/critical_curves.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/energy_landscape.h"
#include "buckle/mechanics/imperfection_sensitivity.h"
#include "buckle/mechanics/koiter.h"
#include "buckle/mechanics/landing.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "scene/progress.h"
#include "scene/scene.h"
#include "scene/shared_work.h"

namespace buckle::scene {

/// A special point of a case: the library's report, and beside it where the chain lands when it
/// jumps there (a fold's jump simulated by the `jump` analysis, a load history's JUMP; `tried`
/// false elsewhere). Statics do not depend on dynamics, so the landing is not inside the report.
struct SpecialPointResult : mechanics::SpecialPointReport {
  mechanics::Landing landing;
};

struct BranchRecord {
  int id = 0;
  int parent = -1;
  std::string origin;      ///< "start (increasing)", "BP 2 of branch 0", ...
  std::string stopReason;
  std::string stopMessage;
  int points = 0;
  bool finished = true;    ///< ended on a regular stop (range, boundary); false: could not go on
  std::string skipped;     ///< what its report left out, stopped by the time limit or a signal (BranchReport::skipped)
  /// Traced from an equilibrium the continuation's tree does not reach (equilibria "branches"):
  /// the rank (1-based, in equilibria.csv) of the equilibrium its tree grew from; 0: not so.
  int fromEquilibrium = 0;
  /// ... and the path-parameter value of that equilibrium's set (equilibria `at`).
  double fromEquilibriumAt = 0.0;
  int joins = -1;          ///< the branch it ended on (stop "joined a traced branch"), else -1
  int mirrorOf = -1;       ///< the branch it is the mirror image of (continuation::Branch::mirrorOf), else -1
};

using TorqueCurve = mechanics::TorqueCurve;

/// Every equilibrium found at one state of the controls (equilibria, one value of `at`).
struct EquilibriumSet {
  double at = 0.0;                 ///< the path-parameter value
  mechanics::AllEquilibria found;
  /// with "branches": onBranch[i] the id of a branch through equilibrium i (-1: none); empty when
  /// the branches were not traced.
  std::vector<int> onBranch;
};

/// The dynamic answer to a sudden load, beside the quasi-static one.
struct SuddenLoadRecord {
  double value = 0.0;                ///< path-parameter value applied at once
  bool success = false;
  std::string message;
  bool inertial = false;
  Eigen::VectorXd rest, staticShape;
  mechanics::Pose restPose = mechanics::Pose::Zero(), staticPose = mechanics::Pose::Zero();
  bool stable = false;
  bool haveStatic = false;           ///< the quasi-static history reached the value
  bool differs = false;
  double maxDifference = 0.0;        ///< ‖q_dynamic − q_static‖∞
  double potentialDynamic = 0.0, potentialStatic = 0.0;
  std::string lower;                 ///< which answer is lower in Π
  double peakKinetic = 0.0, maxExcursion = 0.0, duration = 0.0, residual = 0.0;
  double energyBalanceError = 0.0;
  std::vector<mechanics::JointContact> contacts;  ///< joints resting against their limits
  std::vector<mechanics::WallSupport> wall;       ///< vertices resting on the base wall
  std::vector<mechanics::SelfSupport> self;       ///< self contacts held at rest
  /// The contacts made and released during the dynamics (joint stops, the wall, the chain's own
  /// links), in time order.
  std::vector<mechanics::ContactEvent> events;
  std::vector<mechanics::TrajectorySample> trajectory;
};

struct CaseResult {
  std::string label;
  mechanics::Chain chain;
  Eigen::VectorXd q0;
  /// The path's start shape: q0, or along a control path the chain under its payload.
  Eigen::VectorXd qStart;
  std::string startNote;  ///< how the start was reached, when not simply (the payload snapped the chain)
  /// Displacement control traced through the reaction (PathSpec::throughReaction): the load limit
  /// used, whether it was derived, and the critical reaction of smallest magnitude (NaN: unknown).
  double loadLimit = 0.0;
  bool loadLimitDerived = false;
  double firstCriticalReaction = std::numeric_limits<double>::quiet_NaN();
  mechanics::Pose pose0 = mechanics::Pose::Zero();
  double startValue = 0.0;
  std::vector<BranchRecord> branches;
  /// Every reported point of every branch, in the order the branches were reported (the
  /// continuation's branches by id); streamed (RunControl::streamTo): a sample of them, every
  /// pointStride-th point of each branch with its first and last and those next to a change of
  /// stability, for the plots and report.html (branches.csv has every point).
  std::vector<mechanics::PointReport> points;
  /// The points recorded, those streamed and not kept in `points` included.
  size_t recordedPoints = 0;
  /// Every point of the case, streamed or held (a result built by hand counts its `points`).
  size_t pointCount() const { return std::max(recordedPoints, points.size()); }
  /// The sampling of `points` (1: every point).
  size_t pointStride = 1;
  std::vector<SpecialPointResult> specials;
  /// Along a task path: the names of PointReport::inputs (mechanics::taskInputName), else empty.
  std::vector<std::string> inputNames;
  bool haveCritical = false;
  mechanics::LinearBucklingResult critical;
  bool haveAnalytic = false;       ///< the case is the paper's symmetric clamped–pinned 3-chain
  mechanics::AnalyticBuckling3 analytic;
  bool haveLandscape = false;
  mechanics::EnergyLandscape landscape;
  bool haveTorque = false;
  TorqueCurve torque;
  bool haveSudden = false;
  SuddenLoadRecord sudden;
  std::vector<mechanics::CriticalCurve> criticalCurves;  ///< two_parameter: BP curves by mode, then LP curves
  /// equilibria: every equilibrium at each state of the controls asked (`at`), in the scene's order
  std::vector<EquilibriumSet> equilibriumSets;
  /// workspace: the map over two control inputs and its bounding curves
  bool haveWorkspace = false;
  mechanics::WorkspaceMap workspace;
  explicit CaseResult(const mechanics::Chain& c) : chain(c) {}
};

class BranchStream;

struct RunResult {
  std::vector<CaseResult> cases;
  /// The rows of branches.csv written while the branches were traced (RunControl::streamTo,
  /// branch_stream.h); null: the points are all in cases[c].points.
  std::shared_ptr<BranchStream> stream;
  std::vector<std::string> computed;   ///< names of the analyses actually run
  bool complete = true;                ///< false: some computation could not finish (exit 1)
  std::vector<std::string> problems;   ///< why not complete
  std::vector<std::string> warnings;   ///< what the user should know although nothing failed
  std::vector<std::pair<std::string, double>> timings;  ///< seconds per stage
  double totalSeconds = 0.0;
  double worstResidual = 0.0;          ///< max corrector residual over all branch points
  double worstLocation = 0.0;          ///< max |Δλ| over located special points
  /// Stopped early by the time limit or a signal: what was computed until then is kept.
  bool interrupted = false;
  std::string interruption;            ///< why ("time limit of 5 s reached", "SIGINT received")
};

/// How a run is steered from outside: when to stop (the scene's time limit, a signal), and where
/// progress goes.
struct RunControl {
  continuation::Interrupt interrupt;   ///< checked at every step of every stage
  Progress* progress = nullptr;        ///< optional
  /// A directory for the spool files of branches.csv (branch_stream.h): each branch's rows are
  /// written there as soon as it is final and only a bounded sample of its points is kept in
  /// memory (CaseResult::points), so a run's memory follows its largest branch and the chain's
  /// length, not the tree's size. Empty: every point is kept until the outputs are written.
  std::string streamTo;
  /// Other processes sharing the run (shared_work.h); by default this process alone. A part
  /// that is not the writer runs only the stages whose work is shared.
  SharedWork shared;
};

/// Runs every case of the scene. Never throws for a numerical failure (recorded in problems).
/// The time limit is the scene's /solver/time_limit unless `control.interrupt` already has a
/// deadline (the command line's --time-limit).
RunResult runScene(const Scene& scene, const RunControl& control = RunControl());

}  // namespace buckle::scene
