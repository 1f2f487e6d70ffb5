#include "rest_point.h"

#include <algorithm>
#include <limits>

#include "buckle/continuation/bound_problem.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/wall_contact.h"
#include "buckle/mechanics/wall_landing.h"

namespace buckle::mechanics {

namespace cont = continuation;

bool anyContact(const std::vector<int>& sides) {
  return std::any_of(sides.begin(), sides.end(), [](int s) { return s != 0; });
}


/// The landing of dynamics that ended on the base wall or on the chain itself: at rest with
/// vertices on the wall (IntegrationOptions::wall) or self contacts held (IntegrationOptions::self),
/// or stopped at the wall (IntegrationStop::Barrier: the vertex of `chain`, the model's, nearest to
/// the wall). Those contacts and the joints locked then start the active set of landOnWall
/// (wall_landing.h).
RestPoint wallRestPoint(EquilibriumProblem& problem, const Chain& chain, const DynamicsResult& dyn, double lambda,
                        const continuation::CorrectorOptions& options, bool self) {
  RestPoint rp;
  const int n = problem.segments();
  ContactSet start;
  for (int i = 0; i < n && dyn.contactSides.size() == size_t(n); ++i)
    if (dyn.contactSides[size_t(i)] != 0) start.lock(i, dyn.contactSides[size_t(i)] > 0 ? LimitSide::Upper : LimitSide::Lower);
  for (const WallVertex& v : dyn.wallContacts) start.touch(v);
  for (const SelfContact& c : dyn.selfContacts) start.hold(c);
  if (dyn.reason == IntegrationStop::Barrier) start.touch(nearestWallVertex(chain, dyn.q).vertex);
  const WallLanding w = landOnWall(problem, start, dyn.q, lambda, options.tolerance, options.maxIterations, self);
  rp.polished.u = w.u;
  rp.polished.converged = w.converged;
  rp.polished.iterations = w.solves;
  rp.polished.residual = w.residual;
  rp.polished.message = w.message;
  rp.sides.assign(size_t(n), 0);
  for (const LockedJoint& l : w.contacts.joints()) rp.sides[size_t(l.joint)] = int(l.side);
  rp.torques = w.torques.size() == n ? w.torques : Vector::Zero(n);
  rp.stability = w.stability;
  rp.stable = w.stable;
  rp.wall = w.contacts.wall();
  rp.wallForces = w.wallForces;
  rp.self = w.contacts.self();
  rp.selfForces = w.selfForces;
  return rp;
}

/// Whether the dynamics reached the base wall, and where first: the first wall contact event
/// (its vertex's x at that instant), or the vertex nearest to the wall where the caller's
/// barrier stopped them (IntegrationStop::Barrier).
void noteWallReached(const DynamicsModel& model, const DynamicsResult& dyn, bool& reached, WallVertex& vertex,
                     double& gap) {
  for (const ContactEvent& e : dyn.contactEvents) {
    if (e.joint >= 0 || !e.contact || e.self.vertex.segment >= 0) continue;
    reached = true;
    vertex = e.vertex;
    gap = 0.0;
    return;
  }
  if (dyn.reason != IntegrationStop::Barrier) return;
  const WallApproach at = nearestWallVertex(model.chain(), dyn.q);
  reached = true;
  vertex = at.vertex;
  gap = at.distance;
}

/// Whether the integration ended where a landing can be read off: at rest, handed over, or at
/// the wall with a converged constrained equilibrium.
bool arrivedAt(const DynamicsResult& dyn, const RestPoint& rest) {
  return dyn.reason == IntegrationStop::Rest || dyn.reason == IntegrationStop::Settled ||
         (dyn.reason == IntegrationStop::Barrier && rest.polished.converged);
}

/// `settled`: the equilibrium the basin test certified when the integration ended Settled
/// (no joint in contact then: the test runs only without locked joints). `self`: the chain's
/// contact with itself is traced, so every rest point lands by landOnWall's active set.
RestPoint polishRestPoint(EquilibriumProblem& problem, const Chain& chain, const DynamicsResult& dyn, double lambda,
                          const continuation::CorrectorOptions& options, bool self,
                          const PolishResult* settled) {
  RestPoint rp;
  const int n = problem.segments();
  rp.sides = dyn.contactSides.size() == size_t(n) ? dyn.contactSides : std::vector<int>(size_t(n), 0);
  rp.torques = Vector::Zero(n);
  if (dyn.reason == IntegrationStop::Barrier ||
      (dyn.reason == IntegrationStop::Rest && (!dyn.wallContacts.empty() || self)))
    return wallRestPoint(problem, chain, dyn, lambda, options, self);
  if (dyn.reason == IntegrationStop::Settled && settled && !anyContact(rp.sides)) {
    rp.polished = *settled;
    cont::BoundProblem(problem).stability(rp.polished.u, lambda, 3, rp.stability);
    rp.stable = rp.stability.valid() && rp.stability.stable();
    return rp;
  }
  if (dyn.reason != IntegrationStop::Rest) {
    // only a rest point is worth polishing (at a guard the state is no equilibrium)
    rp.polished.u = problem.initialGuess(dyn.q, lambda);
    rp.polished.message = "not polished";
    Vector F(problem.dimension());
    rp.polished.residual = cont::BoundProblem(problem).residual(rp.polished.u, lambda, F)
                               ? F.cwiseAbs().maxCoeff()
                               : std::numeric_limits<double>::infinity();
    return rp;
  }
  if (!anyContact(rp.sides)) {
    rp.polished = polishEquilibrium(problem, dyn.q, lambda, options);
    if (rp.polished.converged) cont::BoundProblem(problem).stability(rp.polished.u, lambda, 3, rp.stability);
    rp.stable = rp.stability.valid() && rp.stability.stable();
    return rp;
  }
  ContactSet locked;
  for (int i = 0; i < n; ++i)
    if (rp.sides[size_t(i)] != 0) locked.lock(i, rp.sides[size_t(i)] > 0 ? LimitSide::Upper : LimitSide::Lower);
  const ConstrainedEquilibrium ce = solveConstrainedEquilibrium(problem, locked, problem.initialGuess(dyn.q, lambda), lambda,
                                                                options.tolerance, options.maxIterations);
  rp.polished.u = ce.u;
  rp.polished.converged = ce.converged;
  rp.polished.iterations = ce.iterations;
  rp.polished.residual = ce.residual;
  rp.polished.message = ce.converged ? "converged with the joints in contact locked" : ce.message;
  if (!rp.polished.converged) return rp;
  rp.torques = ce.torques;
  rp.stability = constrainedStability(problem, locked, ce.u, lambda, 3);
  // a stable constrained equilibrium: the reduced Hessian positive definite and every contact
  // compressive (a contact torque of zero would release at the slightest disturbance)
  bool compressive = true;
  for (int i = 0; i < n; ++i)
    if (rp.sides[size_t(i)] != 0 && !(-rp.sides[size_t(i)] * rp.torques[i] > 0.0)) compressive = false;
  rp.stable = rp.stability.valid() && rp.stability.stable() && compressive;
  return rp;
}

}  // namespace buckle::mechanics
