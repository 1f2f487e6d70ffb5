// Where a chain lands when it jumps: the outcome of a jump from a fold (jump.h) or of a load
// history's jump (load_history.h), in physical quantities, with the one rule for a jump that
// ends on a geometric joint limit (the triangles meet: the smooth model ends there, a known
// outcome reported with the state reached, not a failure).
#pragma once

#include <Eigen/Core>
#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/load_history.h"

namespace buckle::mechanics {

struct Landing {
  bool tried = false;
  bool success = false;         ///< came to rest on a stable equilibrium or on a joint limit
  bool interrupted = false;     ///< the integration was stopped by the time limit or a signal
  std::string kind;             ///< "stable equilibrium", "joint limit" or "none"
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

}  // namespace buckle::mechanics
