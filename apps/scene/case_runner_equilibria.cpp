// The equilibria analysis of a scene case (docs/scenes.md): every equilibrium at one state of the
// controls, by mechanics/all_equilibria.h, at the case's end condition moved to the path
// parameter `at`.
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
  try {
    out_.equilibria = mechanics::allEquilibria(out_.chain, end, options);
    out_.haveEquilibria = true;
  } catch (const std::invalid_argument& ex) {
    run_.complete = false;
    run_.problems.push_back("case \"" + spec_.label + "\": equilibria: " + ex.what());
    return;
  }
  if (out_.equilibria.interrupted) interrupted();  // marks the run; what was found is kept
}

}  // namespace buckle::scene
