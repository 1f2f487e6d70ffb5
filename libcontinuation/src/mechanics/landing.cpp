#include "buckle/mechanics/landing.h"

#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/shape_name.h"

namespace buckle::mechanics {

namespace {

void setState(const EquilibriumProblem& problem, const Eigen::VectorXd& q, const Wrench& F, Landing& l) {
  l.q = q;
  l.F = F;
  l.pose = endPose(problem.chain(), q);
  l.shape = shapeName(q, kStraightTolerance);
}

/// The joints in contact (sides ≠ 0) with their torques, the vertices on the wall and the self
/// contacts with their forces; the kind of a successful landing.
template <class Result>
void setContacts(const Result& j, Landing& l) {
  const std::vector<int>& sides = j.contactSides;
  const Eigen::VectorXd& torques = j.contactTorques;
  l.contacts.clear();
  for (size_t i = 0; i < sides.size(); ++i)
    if (sides[i] != 0) l.contacts.push_back({int(i), sides[i], torques.size() > Eigen::Index(i) ? torques[Eigen::Index(i)] : 0.0});
  l.wall.clear();
  for (size_t k = 0; k < j.wallContacts.size() && Eigen::Index(k) < j.wallForces.size(); ++k)
    l.wall.push_back({j.wallContacts[k], j.wallForces[Eigen::Index(k)]});
  l.self.clear();
  for (size_t k = 0; k < j.selfContacts.size() && Eigen::Index(k) < j.selfForces.size(); ++k)
    l.self.push_back({j.selfContacts[k], j.selfForces[Eigen::Index(k)]});
  if (l.success && !l.contacts.empty()) l.kind = "stable equilibrium in contact";
  if (l.success && !l.self.empty()) l.kind = "stable equilibrium held on itself";
  if (l.success && !l.wall.empty()) l.kind = "stable equilibrium on the wall";
}
}  // namespace

Landing jumpFromFold(EquilibriumProblem& problem, const continuation::SpecialPoint& fold, const JumpOptions& options) {
  const int n = problem.segments();
  Landing l;
  l.tried = true;
  try {
    const JumpResult j = simulateJump(problem, fold.u, fold.lambda, options);
    l.success = j.success;
    l.message = j.message;
    l.energyReleased = j.energyReleased;
    if (!j.success && j.stopReason == IntegrationStop::JointLimit && j.restPoint.size() >= n) {
      l.success = true;
      l.kind = "joint limit";
      setState(problem, j.restPoint.head(n), problem.wrench(fold.u, fold.lambda), l);
      l.distance = (l.q - fold.u.head(n)).cwiseAbs().maxCoeff();
      return l;
    }
    l.kind = "stable equilibrium";
    l.interrupted = !j.success && j.stopReason == IntegrationStop::Interrupted;
    l.wallBlocked = !j.success && j.reachedWall;
    if (j.to.size() >= n) setState(problem, j.to.head(n), problem.wrench(j.to, fold.lambda), l);
    setContacts(j, l);
    l.distance = j.distance;
  } catch (const std::invalid_argument& e) {
    l.success = false;
    l.message = e.what();
  }
  return l;
}

Landing landingOf(const EquilibriumProblem& problem, const JumpRecord& j) {
  const int n = problem.segments();
  Landing l;
  l.tried = true;
  l.success = j.success;
  l.wallBlocked = j.wallBlocked;
  l.kind = j.success ? "stable equilibrium" : "none";
  l.message = j.message;
  if (j.to.size() >= n) setState(problem, j.to.head(n), j.load, l);
  setContacts(j, l);
  l.energyReleased = j.energyReleased;
  l.distance = j.distance;
  return l;
}

SpecialPointReport reportJump(const EquilibriumProblem& problem, const JumpRecord& j, const std::string& parameterName) {
  const int n = problem.segments();
  SpecialPointReport s;
  s.type = EventType::Jump;
  s.phenomenon = Phenomenon::Jumping;
  s.parameter = s.lambda = j.lambda;
  s.q = j.from.head(n);
  s.F = problem.wrench(j.from, j.lambda);
  s.pose = endPose(problem.chain(), s.q);
  s.shape = shapeName(s.q, kStraightTolerance);
  s.stabilityBefore = j.trigger == JumpTrigger::UnstableStart ? "unstable" : "critical";
  s.stabilityAfter = j.success ? "stable" : "unknown";
  std::ostringstream note;
  note << "trigger: " << toString(j.trigger) << " at " << parameterName << " = " << j.criticalLambda
       << "; released at " << j.lambda;
  s.note = note.str();
  s.jumps = true;
  return s;
}

}  // namespace buckle::mechanics
