// Runs the analyses a scene asks for — and only those — and collects the results as plain data
// for the writers and plots (output.h, plot.h).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/interrupt.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/critical_curves.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/energy_landscape.h"
#include "buckle/mechanics/imperfection_sensitivity.h"
#include "buckle/mechanics/koiter.h"
#include "buckle/mechanics/landing.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "scene/progress.h"
#include "scene/scene.h"

namespace buckle::scene {

/// One point of a traced branch, in physical quantities.
struct PointRecord {
  int branch = 0;
  int index = 0;
  double parameter = 0.0;
  mechanics::Wrench F = mechanics::Wrench::Zero();  ///< total end wrench (loads and reactions)
  mechanics::Pose pose = mechanics::Pose::Zero();
  Eigen::VectorXd q;
  bool stable = false;
  int negative = -1;       ///< negative eigenvalues of the stability operator
  double minEigenvalue = 0.0;
  bool haveStiffness = false;
  Eigen::Matrix2d K = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix2d C = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());  ///< C_F
  double Kphi = std::numeric_limits<double>::quiet_NaN();  ///< the end's rotational stiffness (φ free)
  std::string locked;         ///< joints locked at their limits, "3U 5L" (ContactSet::label), "" none
  double contactTorque = 0.0; ///< largest compression of the locked joints (0: none locked)
  std::string wall;           ///< vertices held on the base wall, "5d-" (ContactSet::wallLabel), "" none
  double wallForce = 0.0;     ///< the wall's total push Σ μ_v along +x on the chain (0: none on it)
  /// `frequencies`: the signed natural frequencies ω_i (vibration.h; negative: unstable, minus
  /// the growth rate), NaN beyond the constrained chain's modes; empty otherwise
  Eigen::VectorXd omega;
  /// Along a task path: the inputs' values and their names (mechanics::taskInputName; shared by
  /// the case's records), the columns of branches.csv beside the loads; empty otherwise
  Eigen::VectorXd inputs;
  std::shared_ptr<const std::vector<std::string>> inputNames;
};

struct SpecialRecord {
  std::string type;        ///< "BP" branch point, "LP" fold, "BD" joint limit, "KMIN" stiffness minimum
  std::string field;       ///< "buckling", "quasi-buckling", "jumping"
  int branch = 0;
  double parameter = 0.0;
  mechanics::Wrench F = mechanics::Wrench::Zero();
  mechanics::Pose pose = mechanics::Pose::Zero();
  Eigen::VectorXd q;
  std::string shape;       ///< shapeName of the branch leaving a BP / of q elsewhere
  std::string stabilityBefore, stabilityAfter;
  double accuracy = 0.0;   ///< |Δλ| of the last location iterate
  /// K_F at the point where the report computed it (KMIN, located between traced points), else NaN
  Eigen::Matrix2d K = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double residual = 0.0;   ///< ‖F(u, λ)‖₂ at the point
  bool refined = false;
  int multiplicity = 1;         ///< BP: eigenvalues crossing zero together
  /// Multiple BP: half-branches predicted by the reduced bifurcation equation / traced (−1: none)
  int branchesPredicted = -1, branchesFound = -1;
  std::string note;
  // contact (CT / RL): the joint (0-based, −1 otherwise), its contact torque at the point, and
  // the joints locked after it (ContactSet::label)
  int joint = -1;
  double contactTorque = std::numeric_limits<double>::quiet_NaN();
  std::string lockedAfter;
  // wall contact (WC / WR): the vertex (WallVertex::label, "" otherwise), its wall force at the
  // point, and the vertices on the wall after it (ContactSet::wallLabel)
  std::string vertex;
  double contactForce = std::numeric_limits<double>::quiet_NaN();
  std::string wallAfter;
  // jump analysis (folds only): where the chain lands when released there
  bool jumpTried = false;
  bool jumpSuccess = false;
  std::string jumpLanding;   ///< "stable equilibrium" or "joint limit"
  std::string jumpMessage;
  Eigen::VectorXd jumpQ;
  mechanics::Wrench jumpF = mechanics::Wrench::Zero();
  mechanics::Pose jumpPose = mechanics::Pose::Zero();
  std::string jumpShape;
  double energyReleased = 0.0;
  double jumpDistance = 0.0;
  std::vector<mechanics::JointContact> jumpContacts;  ///< joints in contact at the landing
  /// BC / SC: where the chain touches the wall or itself (NaN otherwise)
  Eigen::Vector2d contactPoint = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// BP: Koiter's coefficients and the imperfection sensitivity (SpecialPointReport)
  mechanics::KoiterCoefficients koiter;
  std::vector<mechanics::ImperfectionSensitivity> imperfections;
  /// `frequencies` at the located point (PointRecord::omega), empty where not computed
  Eigen::VectorXd omega;
  /// Along a task path: the inputs at the point (PointRecord::inputs)
  Eigen::VectorXd inputs;
  std::shared_ptr<const std::vector<std::string>> inputNames;
};

struct BranchRecord {
  int id = 0;
  int parent = -1;
  std::string origin;      ///< "start (increasing)", "BP 2 of branch 0", ...
  std::string stopReason;
  std::string stopMessage;
  int points = 0;
  bool finished = true;    ///< ended on a regular stop (range, boundary); false: could not go on
  /// Traced from an equilibrium the continuation's tree does not reach (equilibria "branches"):
  /// the rank (1-based, in equilibria.csv) of the equilibrium its tree grew from; 0: not so.
  int fromEquilibrium = 0;
  /// ... and the path-parameter value of that equilibrium's set (equilibria `at`).
  double fromEquilibriumAt = 0.0;
  int joins = -1;          ///< the branch it ended on (stop "joined a traced branch"), else -1
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
  std::vector<PointRecord> points;
  std::vector<SpecialRecord> specials;
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
  explicit CaseResult(const mechanics::Chain& c) : chain(c) {}
};

struct RunResult {
  std::vector<CaseResult> cases;
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
};

/// Runs every case of the scene. Never throws for a numerical failure (recorded in problems).
/// The time limit is the scene's /solver/time_limit unless `control.interrupt` already has a
/// deadline (the command line's --time-limit).
RunResult runScene(const Scene& scene, const RunControl& control = RunControl());

}  // namespace buckle::scene
