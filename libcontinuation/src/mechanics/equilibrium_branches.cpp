#include "buckle/mechanics/equilibrium_branches.h"

namespace buckle::mechanics {

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const std::vector<continuation::InitialDirection>& starts,
                                    const EquilibriumBranchOptions& options) {
  EquilibriumBranches result;
  const Eigen::VectorXd u0 = problem.initialGuess(q0, lambda0);
  continuation::TreeOptions tree;
  tree.maxDepth = options.switchingDepth;
  tree.switching = options.switching;
  tree.switchAt = options.switchAt;
  tree.childTracer = options.childTracer;
  tree.onBranch = options.onBranch;
  result.tree = continuation::traceTree(problem, u0, lambda0, starts, options.tracer, tree);
  for (const continuation::Branch& branch : result.tree.branches) {
    std::vector<Classification> names;
    for (const continuation::SpecialPoint& sp : branch.specialPoints) names.push_back(classify(problem, sp));
    result.classifications.push_back(std::move(names));
    result.reports.push_back(reportBranch(problem, branch, options.report));
  }
  if (!result.tree.branches.empty()) result.startUnstable = startIsUnstable(result.tree.branches.front());
  return result;
}

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options) {
  return traceEquilibria(problem, q0, lambda0, std::vector<continuation::InitialDirection>{direction}, options);
}

}  // namespace buckle::mechanics
