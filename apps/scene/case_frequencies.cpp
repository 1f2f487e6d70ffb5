// `frequencies` (docs/scenes.md): the natural frequencies of small oscillations about every
// reported point of the traced branches, from the library's vibration analysis
// (mechanics/vibration.h) of the constrained chain at that point: its held end coordinates, the
// joints locked at their limits and the vertices held on the base wall or on other links there.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "scene/case_runner.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;

Eigen::VectorXd CaseRunner::naturalFrequencies(const Eigen::VectorXd& q, const mech::Wrench& F,
                                               const mech::ContactSet& contacts, const Eigen::VectorXd& wallForces,
                                               const Eigen::VectorXd& selfForces, double parameter) {
  const FrequenciesSpec& spec = scene_.analyses.frequencies;
  Eigen::VectorXd omega = Eigen::VectorXd::Constant(spec.count, std::numeric_limits<double>::quiet_NaN());
  try {
    // along a control path the springs' free lengths are those at the point (the masses are not)
    const mech::ControlDirection control = controlDirection();
    if (!vibration_ || control.active())
      vibration_ = std::make_unique<mech::VibrationAnalysis>(
          control.active() ? mech::chainWithControls(out_.chain, control, parameter) : out_.chain,
          caseInertia(spec.massPerLength));
    if (wallForces.size() != contacts.wallCount() || selfForces.size() != contacts.selfCount()) return omega;
    Eigen::VectorXd forces(wallForces.size() + selfForces.size());
    forces << wallForces, selfForces;
    // with weight or point loads the Hessian's generator h − γ (body_loads.h, eq B3)
    if (!bodyProblem_ && spec_.body.any()) bodyProblem_ = std::make_unique<mech::EquilibriumProblem>(pathProblem());
    const Eigen::VectorXd gamma = bodyProblem_ ? bodyProblem_->bodyLoadGenerator(q, parameter) : Eigen::VectorXd();
    const mech::VibrationModes m =
        vibration_->modes(q, F, spec_.end.condition.heldIndices(), contacts, forces, spec.count, false, gamma);
    for (int i = 0; i < m.omegaSquared.size(); ++i) omega[i] = mech::signedFrequency(m.omegaSquared[i]);
  } catch (const std::exception& e) {
    if (!vibrationFailed_) {
      vibrationFailed_ = true;
      run_.complete = false;
      run_.problems.push_back("case \"" + spec_.label + "\": natural frequencies at " + spec_.path.parameter + " = " +
                              std::to_string(parameter) + " (and any later failures of this case): " + e.what());
    }
  }
  return omega;
}

}  // namespace buckle::scene
