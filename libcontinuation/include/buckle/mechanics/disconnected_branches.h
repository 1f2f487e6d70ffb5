// Branches of equilibria the traced tree does not reach (issue 30; docs/mechanics.md,
// "Disconnected branches"): every equilibrium found at one value λ* of the path parameter
// (all_equilibria.h) that lies on no traced branch seeds a continuation in λ, both ways, with
// the main tree's options (folds, branch points and switching, stability, contact). A new
// branch that comes back onto a curve already traced (a known branch, an earlier new one, its
// own start: an isola closed) ends there (StopReason::Joined), so no curve is traced twice; the
// equilibria a new branch passes through at λ* seed nothing more.
//
// On a curve: an equilibrium lies on a branch when the branch's crossing of λ* (Newton at fixed
// λ* from the bracketing interval) equals it; a new point joins a traced curve when it lies on
// the curve's polyline within a fraction of the local chord, with the tangents parallel (so a
// branch that crosses another at a branch point goes on). Both tests work in the tracer's scaled
// variables (Problem::scales()), so they hold for a chain in any units.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

struct DisconnectedBranchOptions {
  /// As the main tree's; the tracer's onStep and the tree's onBranch are kept (called first).
  EquilibriumBranchOptions branches;
  /// An equilibrium lies on a branch when a crossing of λ* is within this of it: max |Δq_i|,
  /// radians (the angles' own unit).
  double onBranchTolerance = 1e-6;
  /// A new point joins a traced curve within this fraction of the chord of the curve (or of the
  /// new step) from it. The tracer's turning guard (minTangentCosine 0.9) bounds a chord's
  /// distance from its arc by ≈ 0.06 of its length.
  double joinFraction = 0.1;
  /// ... with the unit tangents (scaled variables) parallel: |cos| at least this.
  double joinCosine = 0.95;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

struct DisconnectedBranches {
  double lambda = 0.0;               ///< λ* of the equilibria
  int firstId = 0;                   ///< the new branches' ids: firstId + their index in `traced`
  /// The new branches (trees: each seed's start branches and their switched children), ids,
  /// parents and mirror sources renumbered from firstId.
  EquilibriumBranches traced;
  /// onBranch[i]: the id of a branch through equilibrium i (known: < firstId, new: ≥ firstId),
  /// −1 when none could be started from it.
  std::vector<int> onBranch;
  std::vector<int> seed;             ///< seed[b]: the equilibrium the tree of traced branch b grew from
  std::vector<int> joined;           ///< joined[b]: the id of the curve branch b ended on (Joined), else −1
  std::vector<int> seeds;            ///< the equilibria that seeded a trace, in order
  bool interrupted = false;
};

/// The joint angles where `branch` crosses λ = lambda: each bracketing interval's linear
/// interpolant polished by Newton at fixed λ (the interpolant itself, flagged false, where Newton
/// does not converge to the problem's residual scale).
struct Crossing {
  Eigen::VectorXd q;
  bool polished = false;
  double chord = 0.0;                ///< the interval's length in the scaled variables
  double offset = 0.0;               ///< max_i |Δu_i / D_i| the polish moved (0: not polished)
};
std::vector<Crossing> crossings(EquilibriumProblem& problem, const continuation::Branch& branch, double lambda);

/// The branches through the equilibria `q` at λ* = lambda of `problem` that none of `known`
/// passes through (tree in the problem's units, e.g. traceEquilibria's). Stable equilibria seed
/// first, then in the given order. Stops (interrupted) on the tracer's interrupt.
DisconnectedBranches traceDisconnectedBranches(EquilibriumProblem& problem, const std::vector<Eigen::VectorXd>& q,
                                               double lambda, const std::vector<bool>& stable,
                                               const std::vector<continuation::Branch>& known,
                                               const DisconnectedBranchOptions& options);

}  // namespace buckle::mechanics
