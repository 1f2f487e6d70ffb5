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
  try {
    const mech::InputPlane plane(out_.chain, spec_.end.condition, bodyLoads().atParameter(out_.startValue),
                                 o.first.input, o.second.input);
    out_.workspace = mech::computeWorkspaceMap(plane, out_.qStart, o);
    out_.haveWorkspace = true;
  } catch (const std::invalid_argument& e) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": workspace map: " + e.what());
    return;
  }
  for (const std::string& p : out_.workspace.problems)
    run_.problems.push_back("case \"" + spec_.label + "\": workspace map: " + p);
  if (out_.workspace.interrupted) interrupted();  // marks the run; what was computed is kept
}

}  // namespace buckle::scene
