// Equilibrium branches of a chain under a load path: the continuation core's bifurcation tree
// (continuation::traceTree: start branches, branch switching with its guards, interruption)
// with every branch reported in physical quantities and every special point named in the
// field's words (branch_report.h). This is the mechanics layer's one entry to the core: the
// command line, the atlas and the tests all trace through it.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/classification.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

struct EquilibriumBranchOptions {
  continuation::TracerOptions tracer;
  /// Options of the switched branches (default: `tracer`), e.g. fewer points to only see
  /// which way a bifurcated branch goes.
  std::optional<continuation::TracerOptions> childTracer;
  continuation::BranchSwitchingOptions switching;
  int switchingDepth = 1;          ///< generations of branch switching (0: only the start branches)
  /// Which branch points to switch at (default: every simple one the tree's guards allow).
  std::function<bool(const continuation::Branch&, const continuation::SpecialPoint&)> switchAt;
  ReportOptions report;            ///< how the branches are reported (stiffness, held coordinate)
  /// Called when a branch is finished, before the next one starts (progress reports).
  std::function<void(const continuation::BranchTree&, const continuation::Branch&)> onBranch;
};

struct EquilibriumBranches {
  continuation::BranchTree tree;
  /// reports[b] reports tree.branches[b].
  std::vector<BranchReport> reports;
  /// classifications[b][s] names tree.branches[b].specialPoints[s].
  std::vector<std::vector<Classification>> classifications;
  bool startUnstable = false;      ///< the start state itself is unstable: "jumping" (Fig 6b)
};

/// Traces from joint angles q0 at λ0 (the held reactions are initialised by least squares, then
/// polished by the tracer's fixed-parameter corrector), one start branch per entry of `starts`.
EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const std::vector<continuation::InitialDirection>& starts,
                                    const EquilibriumBranchOptions& options);

/// One start direction.
EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options);

}  // namespace buckle::mechanics
