// The equilibria analysis of a scene case (docs/scenes.md): every equilibrium at one state of the
// controls, by mechanics/all_equilibria.h, at the case's end condition moved to the path
// parameter `at` (along a control path: the chain with its free lengths at `at`).
#include <stdexcept>

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

}  // namespace buckle::scene
