#include "buckle/mechanics/equilibrium_branches.h"

namespace buckle::mechanics {

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options) {
  EquilibriumBranches result;
  const Eigen::VectorXd u0 = problem.initialGuess(q0, lambda0);
  result.tree = continuation::traceTree(problem, u0, lambda0, direction, options.tracer, options.switchingDepth,
                                        options.switching);
  const int n = problem.segments();
  for (const continuation::Branch& branch : result.tree.branches) {
    std::vector<Classification> names;
    for (const continuation::SpecialPoint& sp : branch.specialPoints) names.push_back(classify(problem, sp));
    result.classifications.push_back(std::move(names));
    if (options.stiffnessAlongBranches) {
      std::vector<CartesianStiffness> k;
      k.reserve(branch.points.size());
      for (const continuation::ContinuationPoint& p : branch.points)
        k.push_back(loadedStiffness(problem.chain(), p.u.head(n), problem.wrench(p.u, p.lambda),
                                    problem.endCondition()));
      result.stiffness.push_back(std::move(k));
    }
  }
  if (!result.tree.branches.empty()) result.startUnstable = startIsUnstable(result.tree.branches.front());
  return result;
}

}  // namespace buckle::mechanics
