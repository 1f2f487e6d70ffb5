#include "buckle/mechanics/load_history.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_branches.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* toString(JumpTrigger trigger) {
  switch (trigger) {
    case JumpTrigger::UnstableStart: return "unstable start";
    case JumpTrigger::Fold: return "fold";
    case JumpTrigger::BranchPoint: return "branch point";
    case JumpTrigger::LostStability: return "lost stability";
  }
  return "?";
}

std::string LoadHistoryOptions::validate(const EquilibriumProblem& problem, const std::string& prefix) const {
  cont::TracerOptions t = tracer;  // the λ range is set per leg
  t.lambdaMin = -1.0;
  t.lambdaMax = 1.0;
  return cont::firstProblem({cont::requirePositive(prefix, "overshoot", overshoot),
                             cont::require(maxJumps >= 0, prefix, "maxJumps", "must be >= 0"),
                             jump.validate(problem, prefix + "jump."), t.validate(prefix + "tracer.")});
}

namespace {

double potentialAt(EquilibriumProblem& problem, const Vector& u, double lambda) {
  const int n = problem.segments();
  // Π with the reactions as the forces of the held coordinates: the potential whose
  // stationary points on the held manifold are the equilibria.
  // along a control path the springs' free lengths, and so E, are those at λ
  return totalPotential(problem.controlled() ? problem.chainAt(lambda) : problem.chain(), u.head(n),
                        problem.wrench(u, lambda));
}

// Index of the first special point past which the traced branch is no longer stable, or −1.
int firstLossOfStability(const cont::Branch& branch) {
  for (size_t s = 0; s < branch.specialPoints.size(); ++s) {
    const cont::SpecialPoint& sp = branch.specialPoints[s];
    if ((sp.type == cont::SpecialPointType::Fold || sp.type == cont::SpecialPointType::BranchPoint) &&
        sp.inertiaBefore == 0 && sp.inertiaAfter > 0)
      return int(s);
  }
  return -1;
}

// Index of the first simple branch point at which the stable traced branch turns back against
// the loading direction `sign` (the tip of a pitchfork reached from a bifurcated branch while
// unloading), or −1: there the history goes on along the other branch through the point.
int firstTurnAtBranchPoint(const cont::Branch& branch, double sign) {
  for (size_t s = 0; s < branch.specialPoints.size(); ++s) {
    const cont::SpecialPoint& sp = branch.specialPoints[s];
    if (sp.type != cont::SpecialPointType::BranchPoint || sp.multiplicity > 1 || sp.inertiaBefore != 0 ||
        sp.inertiaAfter != 0)
      continue;
    const size_t next = std::min(size_t(sp.index) + 1, branch.points.size() - 1);
    if ((branch.points[next].lambda - sp.lambda) * sign < 0.0) return int(s);
  }
  return -1;
}

// The first of a loss of stability and a turn at a branch point, by arclength (−1: neither).
int firstLeavingPoint(const cont::Branch& branch, double sign, bool& isLoss) {
  const int lost = firstLossOfStability(branch), turn = firstTurnAtBranchPoint(branch, sign);
  isLoss = lost >= 0 && (turn < 0 || branch.specialPoints[size_t(lost)].arclength <=
                                          branch.specialPoints[size_t(turn)].arclength);
  return isLoss ? lost : turn;
}

// The stability of (u, λ) (the problem's unknowns (q, r)) on the contacts `set` it stands on:
// that of the stretch's problem (contact.h), the wall forces recovered for its unknowns.
bool stabilityOn(EquilibriumProblem& problem, const ContactSet& set, const Vector& u, double lambda, int wanted,
                 cont::StabilityInfo& info) {
  if (set.empty()) return cont::BoundProblem(problem).stability(u, lambda, wanted, info);
  const std::unique_ptr<ContactProblem> stretch = lockedProblem(problem, set, EquilibriumBranchOptions().maxContactTorque);
  const Vector x = set.gapCount() > 0 ? stretch->withWallForces(*stretch->createWorkspace(), u, lambda) : u;
  return cont::BoundProblem(*stretch).stability(x, lambda, wanted, info);
}

// Keeps the points of `branch` up to the special point `sp` and ends it there, its contact
// stretches with it. The last point's eigenvalues are evaluated at sp itself, on the contacts
// there (its lowest is zero there, not the traced point's before it); its count stays the
// piece's (the limit from the side the piece was traced on: a stable piece ends stable at its
// fold).
cont::Branch cutAt(EquilibriumProblem& problem, const cont::Branch& branch, std::vector<ContactStretch>& stretches,
                   const cont::SpecialPoint& sp) {
  cont::Branch cut = branch;
  cut.points.resize(std::min(cut.points.size(), size_t(sp.index) + 1));
  cont::ContinuationPoint last = cut.points.back();
  last.u = sp.u;
  last.lambda = sp.lambda;
  last.tangent = sp.tangent;
  last.arclength = sp.arclength;
  last.foldTest = sp.tangent.size() > 0 ? sp.tangent[sp.tangent.size() - 1] : last.foldTest;
  last.spectrum = {};
  const int wanted = std::max<int>(1, int(last.stability.lowest.size()));
  const int lastIndex = int(cut.points.size());
  stretches.erase(std::remove_if(stretches.begin() + 1, stretches.end(),
                                 [&](const ContactStretch& s) { return s.firstPoint > lastIndex; }),
                  stretches.end());
  cont::StabilityInfo info;
  if (stabilityOn(problem, stretches.back().locked, sp.u, sp.lambda, wanted, info) && info.lowest.size() > 0) {
    last.stability.lowest = info.lowest;
    last.stability.smallest = info.smallest;
  }
  cut.points.push_back(last);
  cut.specialPoints.erase(std::remove_if(cut.specialPoints.begin(), cut.specialPoints.end(),
                                         [&](const cont::SpecialPoint& p) { return p.arclength > sp.arclength; }),
                          cut.specialPoints.end());
  return cut;
}

// At the branch point `sp` where the traced branch lost stability or turns back, loading in
// direction `sign`:
// the bifurcated branch the chain follows, if the pitchfork is supercritical (its first point
// lies further along the load and is stable). Of the two sides of a symmetric pitchfork (mirror
// images) the + side of bifurcatingDirection (its largest component positive) is taken first: the documented rule
// standing in for the imperfection that decides in a real chain.
bool followBifurcated(EquilibriumProblem& problem, const cont::SpecialPoint& sp, const cont::TracerOptions& options,
                      double sign, cont::Branch& child) {
  if (sp.type != cont::SpecialPointType::BranchPoint || sp.multiplicity > 1) return false;
  // the tree driver's switching step, stopped at the first side the chain can follow
  auto supercritical = [&](const cont::Branch& c) {
    if (c.stopReason == cont::StopReason::SwitchFailed || c.points.size() < 2) return false;
    const cont::ContinuationPoint& first = c.points[1];
    if ((first.lambda - sp.lambda) * sign <= 0.0) return false;  // bends back: subcritical
    return first.stability.valid() && first.stability.negative == 0;
  };
  cont::Tracer tracer(problem, options);
  std::vector<cont::Branch> sides = cont::switchBothSides(tracer, sp, cont::BranchSwitchingOptions(), nullptr, supercritical);
  if (sides.empty() || !supercritical(sides.back())) return false;
  child = std::move(sides.back());
  return true;
}

ContactSet contactSetOf(const std::vector<int>& sides, const std::vector<WallVertex>& wall = {},
                        const std::vector<SelfContact>& self = {}) {
  ContactSet set;
  for (size_t i = 0; i < sides.size(); ++i)
    if (sides[i] != 0) set.lock(int(i), sides[i] > 0 ? LimitSide::Upper : LimitSide::Lower);
  for (const WallVertex& v : wall) set.touch(v);
  for (const SelfContact& c : self) set.hold(c);
  return set;
}

// Releases the chain from `from` with the load held at `at` (simulateJump; again from a saddle
// it came to rest on) and records the jump; true when it landed.
bool releaseChain(EquilibriumProblem& problem, const LoadHistoryOptions& options, JumpTrigger trigger,
                  const Vector& start, double critical, double at, int fromSegment, LoadHistoryResult& result) {
  const Vector from = start.head(problem.dimension());  // without the wall forces of a piece on the wall
  JumpRecord rec;
  rec.trigger = trigger;
  rec.fromSegment = fromSegment;
  rec.criticalLambda = critical;
  rec.lambda = at;
  rec.from = from;
  JumpResult jr = simulateJump(problem, from, at, options.jump);
  // A release along one unstable direction can come to rest on another unstable equilibrium
  // (a saddle: e.g. the straight start with several equally weak joints, where the flow
  // bends one joint and leaves the others exactly straight). Release again from there; each
  // release strictly lowers Π, and at most n unstable directions can be shed.
  for (int again = 0; !jr.success && jr.polishConverged && !jr.stable && again < problem.segments(); ++again) {
    const Vector saddle = jr.to;
    jr = simulateJump(problem, saddle, at, options.jump);
  }
  rec.success = jr.success;
  rec.wallBlocked = !jr.success && jr.reachedWall;
  rec.message = jr.message;
  if (jr.to.size() == from.size()) {
    rec.to = jr.to;
    rec.load = problem.wrench(jr.to, at);
    rec.energyReleased = potentialAt(problem, from, at) - potentialAt(problem, jr.to, at);
    rec.distance = jr.distance;
    rec.contactSides = jr.contactSides;
    rec.contactTorques = jr.contactTorques;
    rec.wallContacts = jr.wallContacts;
    rec.wallForces = jr.wallForces;
    rec.selfContacts = jr.selfContacts;
    rec.selfForces = jr.selfForces;
  }
  result.jumps.push_back(rec);
  return jr.success;
}

// A quasi-static piece of the history, traced in leg `leg`; the last jump landed on it if it has
// no landing piece yet.
void addSegment(LoadHistoryResult& result, cont::Branch branch, std::vector<ContactStretch> stretches, int leg,
                bool bifurcated) {
  result.segments.push_back(std::move(branch));
  result.segmentContacts.push_back(std::move(stretches));
  result.segmentLeg.push_back(leg);
  result.segmentBifurcated.push_back(bifurcated);
  if (!result.jumps.empty() && result.jumps.back().toSegment < 0)
    result.jumps.back().toSegment = int(result.segments.size()) - 1;
}

}  // namespace

LoadHistoryResult followLoadHistory(EquilibriumProblem& problem, const Eigen::VectorXd& q0,
                                    const std::vector<double>& waypoints, const LoadHistoryOptions& options) {
  std::string why;
  if (!options.IsValid(problem, &why)) throw std::invalid_argument("LoadHistoryOptions: " + why);
  if (waypoints.size() < 2) throw std::invalid_argument("load history: at least two waypoints are needed");
  for (double w : waypoints)
    if (!std::isfinite(w)) throw std::invalid_argument("load history: waypoints must be finite");
  if (q0.size() != problem.segments()) throw std::invalid_argument("load history: q0 has the wrong size");
  // λ's own scale (EquilibriumProblem::scales()): the load history's λ tolerances are relative to it.
  const double lambdaUnit = problem.scales().parameter;

  LoadHistoryResult result;
  double lambda = waypoints[0];
  PolishResult start = polishEquilibrium(problem, q0, lambda);
  if (!start.converged) {
    result.message = "the start is not an equilibrium: " + start.message;
    return result;
  }
  Vector u = start.u;

  // Joints in contact with their limits (a landing against them, or a branch run into them):
  // the quasi-static pieces are traced with them locked (contact.h) until they release.
  ContactSet locked;

  cont::StabilityInfo info;
  if (cont::BoundProblem(problem).stability(u, lambda, 3, info) && info.negative > 0) {
    if (!releaseChain(problem, options, JumpTrigger::UnstableStart, u, lambda, lambda, -1, result)) {
      result.message = "the unstable start did not come to a stable rest: " + result.jumps.back().message;
      return result;
    }
    u = result.jumps.back().to;
    locked = contactSetOf(result.jumps.back().contactSides, result.jumps.back().wallContacts,
                              result.jumps.back().selfContacts);
  }

  for (size_t leg = 1; leg < waypoints.size(); ++leg) {
    const double target = waypoints[leg];
    while (lambda != target) {
      if (options.tracer.interrupt.requested()) {
        result.message = options.tracer.interrupt.describe();
        return result;
      }
      if (int(result.jumps.size()) > options.maxJumps) {
        result.message = "more than " + std::to_string(options.maxJumps) + " jumps";
        return result;
      }
      const double sign = target > lambda ? 1.0 : -1.0;
      cont::TracerOptions legOptions = options.tracer;
      legOptions.lambdaMin = std::min(lambda, target);
      legOptions.lambdaMax = std::max(lambda, target);
      const cont::InitialDirection direction =
          sign > 0 ? cont::InitialDirection::increasingLambda() : cont::InitialDirection::decreasingLambda();
      // A piece starts with the contacts it stands on (a landing against joint stops or on the
      // base wall, a piece before it run into them) and, as the continuation's branches, goes
      // on through the joint limits and the wall (EquilibriumOptions::wallAsBoundary) it meets:
      // a contact holds until its force returns to zero (continueUnderContact).
      const EquilibriumBranchOptions contact;  // the continuation's bound on contact torques
      std::unique_ptr<ContactProblem> stretchProblem;
      if (!locked.empty()) stretchProblem = lockedProblem(problem, locked, contact.maxContactTorque);
      // a piece with vertices on the wall has their forces among its unknowns (contact.h)
      if (stretchProblem && u.size() == problem.dimension() && locked.gapCount() > 0)
        u = stretchProblem->withWallForces(*stretchProblem->createWorkspace(), u, lambda);
      else if (u.size() > problem.dimension() && (!stretchProblem || locked.gapCount() == 0))
        u = Vector(u.head(problem.dimension()));
      cont::Branch branch = stretchProblem ? cont::trace(*stretchProblem, u, lambda, direction, legOptions)
                                           : cont::trace(problem, u, lambda, direction, legOptions);
      std::vector<ContactStretch> stretches =
          continueUnderContact(problem, branch, legOptions, contact.maxContactTorque, locked);
      if (branch.points.empty()) {
        result.message = "continuation could not start at lambda = " + std::to_string(lambda) + ": " + branch.stopMessage;
        return result;
      }
      bool isLoss = false, bifurcated = false;
      int lost = firstLeavingPoint(branch, sign, isLoss);
      // supercritical branch points (and the pitchfork's tip reached while unloading): the chain
      // goes on along the stable branch through the point that continues in the loading direction
      cont::Branch child;
      // (the bifurcated branch is traced on the free chain: at a branch point with contacts the
      // chain jumps instead)
      while (lost >= 0 && lockedAt(stretches, branch.specialPoints[size_t(lost)].index + 1).empty() &&
             followBifurcated(problem, branch.specialPoints[size_t(lost)], legOptions, sign, child)) {
        cont::Branch piece = cutAt(problem, branch, stretches, branch.specialPoints[size_t(lost)]);
        addSegment(result, std::move(piece), std::move(stretches), int(leg), bifurcated);
        branch = std::move(child);
        stretches = {ContactStretch{}};
        bifurcated = true;
        lost = firstLeavingPoint(branch, sign, isLoss);
      }
      if (lost >= 0 && !isLoss) lost = firstLossOfStability(branch);  // a turn not followed: as before
      if (lost < 0) {
        locked = stretches.back().locked;
        addSegment(result, branch, std::move(stretches), int(leg), bifurcated);
        const cont::ContinuationPoint& end = branch.points.back();
        if (branch.stopReason != cont::StopReason::LambdaRange || std::abs(end.lambda - target) > 1e-9 * std::max(lambdaUnit, std::abs(target))) {
          result.message = "leg " + std::to_string(leg) + " stopped before its waypoint: " + branch.stopMessage;
          return result;
        }
        u = end.u;
        lambda = target;
        break;
      }
      const cont::SpecialPoint sp = branch.specialPoints[size_t(lost)];
      cont::Branch piece = cutAt(problem, branch, stretches, sp);
      addSegment(result, std::move(piece), std::move(stretches), int(leg), bifurcated);
      const double at = sp.lambda + sign * options.overshoot * std::max(lambdaUnit, std::abs(sp.lambda));
      const JumpTrigger trigger = sp.type == cont::SpecialPointType::Fold ? JumpTrigger::Fold : JumpTrigger::BranchPoint;
      if (!releaseChain(problem, options, trigger, sp.u, sp.lambda, at, int(result.segments.size()) - 1, result)) {
        result.message = std::string("jump after the ") + toString(trigger) + " at lambda = " + std::to_string(sp.lambda) +
                         " failed: " + result.jumps.back().message;
        return result;
      }
      u = result.jumps.back().to;
      lambda = at;
      locked = contactSetOf(result.jumps.back().contactSides, result.jumps.back().wallContacts,
                              result.jumps.back().selfContacts);
      if ((target - lambda) * sign <= 0.0) break;  // the overshoot passed the waypoint
    }
  }
  result.success = true;
  result.message = "all waypoints reached";
  return result;
}

}  // namespace buckle::mechanics
