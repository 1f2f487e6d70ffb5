// The equilibria analysis of a scene case (docs/scenes.md): every equilibrium at one state of the
// controls, by mechanics/all_equilibria.h, at the case's end condition moved to each value of the
// path parameter in `at` (along a control path: the chain with its free lengths there); with
// "branches", the branches through those the continuation's tree does not reach, by
// mechanics/disconnected_branches.h, each set seeding only what the tree and the earlier sets'
// branches do not pass through.
#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/disconnected_branches.h"
#include "scene/case_runner.h"

namespace buckle::scene {

void CaseRunner::equilibria() {
  const EquilibriaSpec& e = scene_.analyses.equilibria;
  const std::vector<double> values = e.at.empty() ? std::vector<double>{out_.startValue} : e.at;
  for (double at : values) {
    if (interrupted()) return;  // a stop keeps the sets found so far
    equilibriaAt(at);
  }
}

void CaseRunner::equilibriaAt(double at) {
  const EquilibriaSpec& e = scene_.analyses.equilibria;
  const mechanics::EndCondition end = loadPath().at(at);
  mechanics::AllEquilibriaOptions options;
  options.randomStarts = e.starts;
  options.smoothStarts = e.smoothStarts;
  options.seed = e.seed;
  options.landscapeSamples = e.sweepPoints;
  options.starts.push_back(out_.q0);  // the case's unloaded shape (preloads from q0)
  options.interrupt = control_.interrupt;
  options.body = bodyLoads().atParameter(at);  // the weight at `at` (a gravity path's g)
  // along a control path the state is the chain with the free lengths at `at` (the loads held)
  const mechanics::ControlDirection control = controlDirection();
  const mechanics::Chain chain = control.active() ? mechanics::chainWithControls(out_.chain, control, at) : out_.chain;
  EquilibriumSet set;
  set.at = at;
  try {
    set.found = mechanics::allEquilibria(chain, end, options);
  } catch (const std::invalid_argument& ex) {
    run_.complete = false;
    std::ostringstream where;
    where << "case \"" << spec_.label << "\": equilibria at " << spec_.path.parameter << " = " << at << ": ";
    run_.problems.push_back(where.str() + ex.what());
    return;
  }
  out_.equilibriumSets.push_back(std::move(set));
  if (out_.equilibriumSets.back().found.interrupted) interrupted();  // marks the run; what was found is kept
}

void CaseRunner::disconnectedBranches() {
  // with no tree (its start failed: the unloaded shape far from a held end) every equilibrium seeds
  if (throughLoad()) return;
  for (EquilibriumSet& set : out_.equilibriumSets) {
    if (interrupted()) return;
    disconnectedBranchesAt(set);
  }
}

void CaseRunner::disconnectedBranchesAt(EquilibriumSet& set) {
  mechanics::EquilibriumProblem problem = pathProblem();
  const double lo = std::min(spec_.path.from, spec_.path.to), hi = std::max(spec_.path.from, spec_.path.to);
  mechanics::DisconnectedBranchOptions opt;
  opt.branches = branchOptions(lo, hi);
  const int before = int(traced_.size());
  opt.branches.tree.onBranch = [this, before](const continuation::BranchTree& t, const continuation::Branch&) {
    branchesSoFar_ = before + static_cast<int>(t.branches.size());
  };
  std::vector<Eigen::VectorXd> q;
  std::vector<bool> stable;
  for (const mechanics::FoundEquilibrium& e : set.found.equilibria) {
    q.push_back(e.q);
    stable.push_back(e.stable);
  }
  const mechanics::DisconnectedBranches d = mechanics::traceDisconnectedBranches(problem, q, set.at, stable, traced_, opt);
  set.onBranch = d.onBranch;
  const auto& branches = d.traced.tree.branches;
  for (size_t i = 0; i < branches.size(); ++i) {
    continuation::Branch b = branches[i];
    const int rank = d.seed[i] + 1;
    std::ostringstream origin;
    const bool increasing = !b.points.empty() && b.points.front().tangent.size() > 0 &&
                            b.points.front().tangent[b.points.front().tangent.size() - 1] > 0.0;
    if (b.parentId < 0)
      origin << "disconnected: from equilibrium " << rank << " at " << spec_.path.parameter << " = "
             << set.at << (increasing ? ", increasing " : ", decreasing ") << spec_.path.parameter;
    else
      origin << "disconnected: BP " << b.parentSpecialPoint << " of branch " << b.parentId
             << (b.direction > 0 ? ", + side" : ", - side");
    mechanics::BranchReport report = d.traced.reports[i];
    if (d.joined[i] >= 0) report.stopMessage = "joins branch " + std::to_string(d.joined[i]) + ", traced already";
    record(b, std::move(report), origin.str());
    out_.branches.back().fromEquilibrium = rank;
    out_.branches.back().fromEquilibriumAt = set.at;
    out_.branches.back().joins = d.joined[i];
    traced_.push_back(b);  // the next set's equilibria on this branch seed nothing more
  }
  if (d.interrupted) interrupted();
}

}  // namespace buckle::scene
