// Following a task path (task_path.h) leg by leg: the points with their inputs, stability and
// stiffness at fixed inputs, and where the path cannot be followed by a stable equilibrium the
// special point that says why (docs/mechanics.md, "Task-space paths").
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/task_path.h"

namespace buckle::mechanics {

/// Why a task path ends, or what a special point on it is.
enum class TaskPathEvent {
  Completed,      ///< the last waypoint reached
  Fold,           ///< a fold of the task map: the inputs cannot move the end further along the path
  BranchPoint,    ///< the task continuation branches: the path is not followed uniquely
  StabilityLoss,  ///< the equilibrium at fixed inputs loses its stability
  JointLimit,
  InputBound,
  EigenvalueCoalescence,  ///< rule (c): the optimised smallest eigenvalue meets the next (task_path.h)
  MaxPoints,      ///< the tracer's point limit reached on a leg (TracerOptions::maxPoints)
  Failed,         ///< the continuation could not go on (its message says why)
  Interrupted,    ///< time limit or signal
};
/// "completed", "fold", "branch point", "loss of stability", "joint limit", "input bound", "eigenvalue coalescence",
/// "max points", "failed", "interrupted".
const char* toString(TaskPathEvent event);

struct TaskPathOptions {
  continuation::TracerOptions tracer;  ///< the λ range is set per leg; stability is the problem's boundary
  bool stiffness = true;               ///< K_F, C_F at fixed inputs at every point (O(n))

  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const { return tracer.validate(prefix + "tracer."); }
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

struct TaskPathPoint {
  int leg = 0;
  double s = 0.0;          ///< path parameter (arclength of the task path)
  Vector q, inputs;
  Pose pose = Pose::Zero();
  Vector target;           ///< t(s) on the task coordinates
  Inertia inertia;         ///< of H = K_q − K_g at fixed inputs
  double minEigenvalue = 0.0;
  bool stable = false;
  /// End stiffness at fixed inputs, rotation free: C_F = J_p H⁻¹ J_pᵀ, K_F = C_F⁻¹ (NaN where H is singular).
  Eigen::Matrix2d K = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix2d C = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
};

struct TaskPathSpecial {
  TaskPathEvent event = TaskPathEvent::Fold;
  TaskPathPoint point;
  std::string note;         ///< in words, with the boundary's name
  double accuracy = 0.0;    ///< |Δs| of the location
};

struct TaskPathResult {
  std::vector<TaskPathPoint> points;
  std::vector<TaskPathSpecial> specials;
  TaskPathEvent end = TaskPathEvent::Failed;
  std::string message;
  /// Waypoints as path-parameter values: 0 (the start pose) and the end of every leg.
  std::vector<double> legEnds;
  /// The largest corrector residual over the points (ContinuationPoint::residualNorm).
  double worstResidual = 0.0;
};

/// The metric arclength of a task-path leg: ‖Δ‖ with an angle counted as angleLength·Δφ.
double taskLegLength(const TaskSetup& setup, const Vector& from, const Vector& to, double angleLength);

/// Follows the task path from the equilibrium q0 at the inputs' start values (an equilibrium under
/// the payload; its pose on the task coordinates is the path's start) through `waypoints` (each m
/// values on the task coordinates). The path parameter s is the arclength (taskLegLength with
/// angleLength). Stops at the first special point (the path cannot be followed stably past it).
/// Never throws for numerical failures (end = Failed, message).
TaskPathResult traceTaskPath(TaskPathProblem& problem, const Vector& q0, const std::vector<Vector>& waypoints,
                             double angleLength, const TaskPathOptions& options = {});

/// The task path as branch `id`'s report (branch_report.h) under the end wrench `payload`: its
/// points with their inputs, and each special point typed (LP, BP, LS, BD, IB) with the stability
/// at fixed inputs before it and at it, its location's accuracy, why the path ends there in the
/// note. Stiffness columns where `stiffness` (TaskPathOptions::stiffness) computed them.
BranchReport reportTaskPath(const TaskPathResult& path, const Wrench& payload, bool stiffness, int id = 0);

/// A point's record from u (stability and, with `stiffness`, K_F, C_F at fixed inputs). False outside the domain.
bool taskPathPoint(TaskPathProblem& problem, const Vector& u, double s, bool stiffness, TaskPathPoint& out);

}  // namespace buckle::mechanics
