// The workspace analysis of a scene case (docs/scenes.md): the maps over two control inputs under
// the payload of /end, by mechanics/workspace_map.h, from the chain under that payload reached
// from its unloaded shape (as a control path's start).
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/workspace_map.h"
#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

void CaseRunner::workspaceMap() {
  if (!actuationStart()) return;  // said in the run's problems
  mech::WorkspaceMapOptions o = scene_.analyses.workspace.options;
  o.tracer = solverOptions();
  if (control_.shared.shared()) {  // the rows shared among the processes of the run
    o.share.part = control_.shared.part;
    o.share.parts = control_.shared.parts;
    o.share.rowsOnly = !control_.shared.writer();
    const std::string tag = "workspace map of case " + std::to_string(&spec_ - scene_.cases.data());
    o.share.exchange = [exchange = control_.shared.exchange, tag](const std::string& mine) { return exchange(tag, mine); };
    if (o.threads == 0) o.threads = control_.shared.threads;
  }
  try {
    const mech::InputPlane plane(out_.chain, spec_.end.condition, bodyLoads().atParameter(out_.startValue),
                                 o.first.input, o.second.input);
    out_.workspace = mech::computeWorkspaceMap(plane, out_.qStart, o);
    out_.haveWorkspace = true;
  } catch (const std::exception& e) {  // invalid options, or rows from another process that do not fit
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": workspace map: " + e.what());
    return;
  }
  for (const std::string& p : out_.workspace.problems)
    run_.problems.push_back("case \"" + spec_.label + "\": workspace map: " + p);
  if (out_.workspace.interrupted) interrupted();  // marks the run; what was computed is kept
}

}  // namespace buckle::scene
