// Where a chain lands when it jumps: the outcome of a jump from a fold (jump.h) or of a load
// history's jump (load_history.h), in physical quantities. Joint limits are one-sided contacts
// during the jump (dynamics.h): a chain that comes to rest against limits lands on a stable
// constrained equilibrium ("stable equilibrium in contact"), reported with the joints in contact
// and their contact torques. With the base wall as a contact (JumpOptions::wall) a chain that
// reaches the wall lands on the stable equilibrium with vertices held on it ("stable equilibrium
// on the wall", wall_landing.h), reported with those vertices and their wall forces, or is not
// landed (wallBlocked); without it a landing behind the wall is flagged in the message. Only dynamics run without contact (IntegrationOptions::contact =
// false) still stop at a limit ("joint limit": the state reached, a known outcome, not a failure).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

/// A joint in contact with its limit at a landing.
struct JointContact {
  int joint = -1;        ///< 0-based
  int side = 0;          ///< +1 upper limit, −1 lower
  double torque = 0.0;   ///< contact torque τ_c (jump.h, contactTorques): −side·τ_c > 0
};

/// A vertex held on the base wall at a landing (wall_landing.h).
struct WallSupport {
  WallVertex vertex;
  double force = 0.0;    ///< the wall force μ_v (along +x on the chain): > 0
};

/// A self contact held at a landing (self_contact.h).
struct SelfSupport {
  SelfContact contact;
  double force = 0.0;    ///< pushing the two bodies apart: > 0
};

struct Landing {
  bool tried = false;
  bool success = false;         ///< came to rest on a stable (constrained) equilibrium or on a joint limit
  bool interrupted = false;     ///< the integration was stopped by the time limit or a signal
  /// Not landed because of the base wall: the dynamics stopped at it (JumpOptions::wall) and no
  /// stable equilibrium on it was found.
  bool wallBlocked = false;
  /// "stable equilibrium", "stable equilibrium in contact", "stable equilibrium on the wall",
  /// "stable equilibrium held on itself", "joint limit" or "none"
  std::string kind;
  std::vector<JointContact> contacts;  ///< joints in contact at the landing (empty: none)
  std::vector<WallSupport> wall;       ///< vertices held on the base wall (empty: none)
  std::vector<SelfSupport> self;       ///< self contacts held (empty: none)
  std::string message;
  Eigen::VectorXd q;            ///< joint angles at the landing (empty: none)
  Wrench F = Wrench::Zero();    ///< end wrench there (loads and reactions)
  Pose pose = Pose::Zero();
  std::string shape;
  double energyReleased = 0.0;  ///< Π(from) − Π(to) at the release load
  double distance = 0.0;        ///< ‖q_to − q_from‖∞
};

/// Releases the chain at the fold `fold` of a branch traced on `problem`, the loads frozen
/// there. Invalid options give success = false with the reason in `message` (never throws).
Landing jumpFromFold(EquilibriumProblem& problem, const continuation::SpecialPoint& fold, const JumpOptions& options);

/// The landing of a load history's jump.
Landing landingOf(const EquilibriumProblem& problem, const JumpRecord& jump);

/// A load history's jump (load_history.h) as a special point "JUMP" (jumping); its landing is
/// landingOf(problem, jump). `parameterName` names λ in the note.
SpecialPointReport reportJump(const EquilibriumProblem& problem, const JumpRecord& jump,
                              const std::string& parameterName);

}  // namespace buckle::mechanics
