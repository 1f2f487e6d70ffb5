#include "contact_events.h"

#include <algorithm>

#include "buckle/continuation/bound_problem.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

BoundaryEvent endEvent(const EquilibriumProblem& base, const continuation::Problem& problem,
                      const continuation::Branch& branch, const ContactSet& contacts) {
  const std::vector<WallVertex>& wall = contacts.wall();
  BoundaryEvent e;
  const int segments = base.segments();
  if (branch.stopReason != continuation::StopReason::Boundary || branch.specialPoints.empty()) return e;
  const continuation::SpecialPoint& sp = branch.specialPoints.back();
  if (sp.type != continuation::SpecialPointType::Boundary) return e;
  for (int k = 0; k < std::min(problem.boundaryCount(), 2 * segments); ++k)
    if (problem.boundaryName(k) == sp.boundaryName) {
      e.joint = limitOfBoundary(k, segments);
      return e;
    }
  if (base.wallIsBoundary() && sp.boundaryName == EquilibriumProblem::wallBoundaryName()) {
    e.vertex = nearestWallVertex(base.chain(), sp.u.head(segments), wall).vertex;
    return e;
  }
  for (const WallVertex& v : wall)
    if (sp.boundaryName == wallReleaseName(v)) {
      e.vertex = v;
      e.wallRelease = true;
    }
  if (base.selfContactIsBoundary() && sp.boundaryName == EquilibriumProblem::selfContactBoundaryName()) {
    int a = -1, b = -1;
    selfClearanceApart(base.chain(), sp.u.head(segments), contacts.self(), &a, &b);
    if (a >= 0 && b >= 0) {
      e.self = touchingPair(base.chain(), sp.u.head(segments), a, b, contacts.self());
      e.onSelf = true;
    }
  }
  for (const SelfContact& c : contacts.self()) {
    if (sp.boundaryName == selfReleaseName(c)) e.self = c, e.onSelf = e.selfRelease = true;
    if (sp.boundaryName == selfEdgeName(c)) e.self = c, e.onSelf = e.selfEdgeEnd = true;
  }
  return e;
}

ContactChange changeOf(const EquilibriumProblem& problem, const continuation::SpecialPoint& at, const BoundaryEvent& hit,
                       const ContactSet& before) {
  ContactChange c;
  c.after = before;
  ContactSet& locked = c.after;
  if (hit.joint.joint >= 0) {
    c.release = locked.locked(hit.joint.joint) && locked.side(hit.joint.joint) == hit.joint.side;
    if (c.release)
      locked.release(hit.joint.joint);
    else
      locked.lock(hit.joint.joint, hit.joint.side);
    c.what = std::string(c.release ? "release of joint " : "contact of joint ") + std::to_string(hit.joint.joint + 1) +
             " " + toString(hit.joint.side);
    return c;
  }
  if (!hit.onSelf) {
    c.release = hit.wallRelease;
    if (c.release)
      locked.leave(hit.vertex);
    else
      locked.touch(hit.vertex);
    c.what = std::string(c.release ? "release of vertex " : "wall contact of vertex ") + hit.vertex.label();
    c.index = int(std::lower_bound(locked.wall().begin(), locked.wall().end(), hit.vertex) - locked.wall().begin());
    return c;
  }
  c.release = hit.selfRelease;
  SelfContact held = hit.self;
  c.what = std::string(c.release ? "release of self contact " : "self contact ") + hit.self.label();
  const Eigen::VectorXd q = at.u.head(problem.segments());
  const Eigen::Matrix2Xd P = jointPositions(problem.chain(), q);
  if (hit.selfEdgeEnd) {
    // At the base corner the force can only turn into the corner's normal cone with the vertex
    // pinned there: the corner's other edge is held too (the vertex leaves the corner later by
    // the release of either). Past the corner along its edge the vertex would lose its support.
    c.followed = selfContactGap(problem.chain(), q, P, hit.self).along >= 0.5 &&
                 cornerNeighbour(problem.chain(), hit.self, held);
    if (!c.followed) return c;
    c.what += " reaches its edge's corner: held there on " + held.edge.label() + " too";
  }
  if (c.release)
    locked.separate(hit.self);
  else
    locked.hold(held);
  c.index = int(std::lower_bound(locked.self().begin(), locked.self().end(), held) - locked.self().begin());
  if (SelfContact partner; c.release && cornerNeighbour(problem.chain(), hit.self, partner) && locked.holding(partner))
    c.slidesOn = int(std::lower_bound(locked.self().begin(), locked.self().end(), partner) - locked.self().begin());
  return c;
}

double contactRate(EquilibriumProblem& problem, const ContactSet& before, const BoundaryEvent& hit,
                   const ContactChange& change, const continuation::ContinuationPoint& p0) {
  const bool release = change.release;
  const int wallIndex = change.index;
  const int n = problem.segments(), D = int(p0.u.size());
  if (hit.onSelf) {  // a self contact's force (wallIndex: its index), or a released one's gap ∇g·t_q
    if (!release) return p0.tangent[problem.dimension() + before.wallCount() + wallIndex];
    const Eigen::Matrix2Xd P = jointPositions(problem.chain(), p0.u.head(n));
    const SelfContactGap g = selfContactGap(problem.chain(), p0.u.head(n), P, hit.self);
    continuation::Vector grad(n), gen(n), coupling(n), weights(n);
    selfContactDerivatives(P, hit.self, g, grad, gen, coupling, weights);
    return (change.slidesOn >= 0 ? -1.0 : 1.0) * grad.dot(p0.tangent.head(n));
  }
  if (hit.joint.joint >= 0) {
    const int i = hit.joint.joint;
    const double sideSign = hit.joint.side == LimitSide::Upper ? 1.0 : -1.0;
    if (release) return -sideSign * p0.tangent[i];
    ContactProblem prior(problem, before);  // the same wall vertices: the same unknowns
    continuation::Matrix Fu(D, D);
    continuation::Vector Fl(D);
    if (!continuation::BoundProblem(prior).jacobian(p0.u, p0.lambda, Fu, Fl)) return 0.0;
    return -sideSign * (Fu.row(i).dot(p0.tangent.head(D)) + Fl[i] * p0.tangent[D]);
  }
  if (!release) return p0.tangent[D - before.wallCount() - 1 + wallIndex];
  const Eigen::Matrix2Xd P = jointPositions(problem.chain(), p0.u.head(n));
  continuation::Vector grad(n), gen(n);
  wallVertexDerivatives(P, wallVertexPoint(problem.chain(), p0.u.head(n), P, hit.vertex), hit.vertex, grad, gen);
  return grad.dot(p0.tangent.head(n));
}

}  // namespace buckle::mechanics
