// Equilibrium branches of a chain under a load path: the continuation core's bifurcation tree
// with every special point named in the field's words and, when asked, the loaded Cartesian
// stiffness K_F at every point (eq 29). This is the mechanics layer's entry to the core.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/classification.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/stiffness.h"

namespace buckle::mechanics {

struct EquilibriumBranchOptions {
  continuation::TracerOptions tracer;
  continuation::BranchSwitchingOptions switching;
  int switchingDepth = 1;          ///< generations of branch switching (0: only the first branch)
  bool stiffnessAlongBranches = false;
};

struct EquilibriumBranches {
  continuation::BranchTree tree;
  /// classifications[b][s] names tree.branches[b].specialPoints[s].
  std::vector<std::vector<Classification>> classifications;
  /// stiffness[b][p] at tree.branches[b].points[p]; empty unless asked.
  std::vector<std::vector<CartesianStiffness>> stiffness;
  bool startUnstable = false;      ///< the start state itself is unstable: "jumping" (Fig 6b)
};

/// Traces from joint angles q0 at λ0 (the held reactions are initialised by least squares).
EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options);

}  // namespace buckle::mechanics
