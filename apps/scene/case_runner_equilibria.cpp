// The equilibria analysis of a scene case (docs/scenes.md): every equilibrium at one state of the
// controls, by mechanics/all_equilibria.h, at the case's end condition moved to the path
// parameter `at` (along a control path: the chain with its free lengths at `at`); with
// "branches", the branches through those the continuation's tree does not reach, by
// mechanics/disconnected_branches.h.
#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/disconnected_branches.h"
#include "scene/case_runner.h"

namespace buckle::scene {

void CaseRunner::equilibria() {
  const EquilibriaSpec& e = scene_.analyses.equilibria;
  mechanics::EndCondition end = spec_.end.condition;
  out_.equilibriaAt = e.haveAt ? e.at : out_.startValue;
  end.value += (out_.equilibriaAt - out_.startValue) * spec_.path.direction;
  mechanics::AllEquilibriaOptions options;
  options.randomStarts = e.starts;
  options.smoothStarts = e.smoothStarts;
  options.seed = e.seed;
  options.landscapeSamples = e.sweepPoints;
  options.starts.push_back(out_.q0);  // the case's unloaded shape (preloads from q0)
  options.interrupt = control_.interrupt;
  options.body = bodyLoads().atParameter(out_.equilibriaAt);  // the weight at `at` (a gravity path's g)
  // along a control path the state is the chain with the free lengths at `at` (the loads held)
  const mechanics::ControlDirection control = controlDirection();
  const mechanics::Chain chain =
      control.active() ? mechanics::chainWithControls(out_.chain, control, out_.equilibriaAt) : out_.chain;
  try {
    out_.equilibria = mechanics::allEquilibria(chain, end, options);
    out_.haveEquilibria = true;
  } catch (const std::invalid_argument& ex) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": equilibria: " + ex.what());
    return;
  }
  if (out_.equilibria.interrupted) interrupted();  // marks the run; what was found is kept
}

void CaseRunner::disconnectedBranches() {
  // with no tree (its start failed: the unloaded shape far from a held end) every equilibrium seeds
  if (!out_.haveEquilibria || throughLoad() || interrupted()) return;
  mechanics::EquilibriumProblem problem = pathProblem();
  const double lo = std::min(spec_.path.from, spec_.path.to), hi = std::max(spec_.path.from, spec_.path.to);
  mechanics::DisconnectedBranchOptions opt;
  opt.branches = branchOptions(lo, hi);
  const int before = int(traced_.size());
  opt.branches.onBranch = [this, before](const continuation::BranchTree& t, const continuation::Branch&) {
    branchesSoFar_ = before + static_cast<int>(t.branches.size());
  };
  std::vector<Eigen::VectorXd> q;
  std::vector<bool> stable;
  for (const mechanics::FoundEquilibrium& e : out_.equilibria.equilibria) {
    q.push_back(e.q);
    stable.push_back(e.stable);
  }
  const mechanics::DisconnectedBranches d =
      mechanics::traceDisconnectedBranches(problem, q, out_.equilibriaAt, stable, traced_, opt);
  out_.equilibriaOnBranch = d.onBranch;
  const auto& branches = d.traced.tree.branches;
  for (size_t i = 0; i < branches.size(); ++i) {
    continuation::Branch b = branches[i];
    const int rank = d.seed[i] + 1;
    std::ostringstream origin;
    const bool increasing = !b.points.empty() && b.points.front().tangent.size() > 0 &&
                            b.points.front().tangent[b.points.front().tangent.size() - 1] > 0.0;
    if (b.parentId < 0)
      origin << "disconnected: from equilibrium " << rank << " at " << spec_.path.parameter << " = "
             << out_.equilibriaAt << (increasing ? ", increasing " : ", decreasing ") << spec_.path.parameter;
    else
      origin << "disconnected: BP " << b.parentSpecialPoint << " of branch " << b.parentId
             << (b.direction > 0 ? ", + side" : ", - side");
    mechanics::BranchReport report = d.traced.reports[i];
    if (d.joined[i] >= 0) report.stopMessage = "joins branch " + std::to_string(d.joined[i]) + ", traced already";
    record(b, report, problem, origin.str());
    out_.branches.back().fromEquilibrium = rank;
    out_.branches.back().joins = d.joined[i];
  }
  if (d.interrupted) interrupted();
}

}  // namespace buckle::scene
