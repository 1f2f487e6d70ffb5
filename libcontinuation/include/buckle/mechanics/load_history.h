// A quasi-static load history with jumps: the load parameter λ goes through a list of waypoints
// (up, back down, …) and the chain follows its stable equilibrium. At a supercritical branch
// point (the branch born there goes on in the loading direction and is stable: the straight
// column buckling into its U shape) the chain follows that branch, as a real column does with the
// least imperfection. Where the equilibrium stops being stable otherwise — a fold under load
// control, a subcritical branch point, or an unstable start — the chain jumps: the load is held just past the critical value, the dynamics (jump.h) carries the chain
// to rest, and continuation resumes from the landing. Going up and back down through the same
// folds produces the hysteresis loop: branch, fold, jump, new branch, … (issue 5).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"

namespace buckle::mechanics {

struct LoadHistoryOptions {
  /// Step control, tolerances and detection; the λ range is set per leg.
  continuation::TracerOptions tracer;
  JumpOptions jump;
  /// The jump is released at λ_c + overshoot·max(λ₀, |λ_c|) (λ₀ the problem's parameter scale)
  /// in the loading direction, just past the critical load λ_c where the stable state ceased to
  /// exist.
  double overshoot = 1e-6;
  int maxJumps = 50;

  /// Empty when valid for `problem`, else what is wrong, the field named by its path.
  std::string validate(const EquilibriumProblem& problem, const std::string& prefix = "") const;
  bool IsValid(const EquilibriumProblem& problem, std::string* why) const {
    return continuation::reportValidity(validate(problem), why);
  }
};

/// Why the equilibrium was left.
enum class JumpTrigger { UnstableStart, Fold, BranchPoint, LostStability };
const char* toString(JumpTrigger trigger);

struct JumpRecord {
  JumpTrigger trigger = JumpTrigger::Fold;
  int fromSegment = -1;      ///< index into LoadHistoryResult::segments (−1: before the first)
  int toSegment = -1;        ///< the segment that starts at the landing (−1: none followed)
  double criticalLambda = 0.0;  ///< λ_c of the special point (start λ for an unstable start)
  double lambda = 0.0;          ///< λ at which the chain was released
  Wrench load = Wrench::Zero(); ///< end wrench at the landing (loads and reactions)
  Vector from, to;              ///< unknowns (q, reactions) before / after
  double energyReleased = 0.0;  ///< Π(from) − Π(to) at the release load
  double distance = 0.0;        ///< ‖q_to − q_from‖∞
  /// Joints in contact at the landing (per joint 0, +1 upper, −1 lower; empty or all 0: none)
  /// and their contact torques (jump.h).
  std::vector<int> contactSides;
  Vector contactTorques;
  /// Vertices held on the base wall at the landing and their forces (jump.h; empty: none).
  std::vector<WallVertex> wallContacts;
  Vector wallForces;
  /// Self contacts held at the landing and their forces (jump.h; empty: none).
  std::vector<SelfContact> selfContacts;
  Vector selfForces;
  bool success = false;
  bool wallBlocked = false;     ///< not landed because of the base wall (landing.h, Landing::wallBlocked)
  std::string message;
};

struct LoadHistoryResult {
  /// Stable quasi-static pieces, in the order they were followed; each ends at a waypoint, at a
  /// point where stability was lost, or where the history stopped.
  std::vector<continuation::Branch> segments;
  /// The contacts of each segment's points: its stretches (equilibrium_branches.h), the first
  /// from its first point; a segment runs on through the joint limits and, with
  /// EquilibriumOptions::wallAsBoundary, the base wall it meets, as a continuation branch does.
  std::vector<std::vector<ContactStretch>> segmentContacts;
  std::vector<int> segmentLeg;     ///< leg (waypoint interval) of each segment
  /// True for a segment that starts at the supercritical branch point ending the one before it
  /// (the chain followed the bifurcated branch there, without a jump).
  std::vector<bool> segmentBifurcated;
  std::vector<JumpRecord> jumps;
  bool success = false;            ///< every waypoint was reached
  std::string message;             ///< why it ended
};

/// Follows λ: waypoints[0] (the start, with joint angles q0) → waypoints[1] → … .
/// Never throws for a computation that fails: what was computed is kept and `message` says why
/// it stopped. Throws std::invalid_argument for invalid options or fewer than two waypoints.
LoadHistoryResult followLoadHistory(EquilibriumProblem& problem, const Eigen::VectorXd& q0,
                                    const std::vector<double>& waypoints, const LoadHistoryOptions& options);

}  // namespace buckle::mechanics
