#include "branch_report_contacts.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace buckle::mechanics {

namespace cont = buckle::continuation;

namespace {

/// The fields every contact event shares: its type (no phenomenon: a change of the constraints,
/// none of the paper's three), the force and the vertex of the contact at the point, the contacts
/// after it and the stability either side.
void markContactEvent(const EquilibriumProblem& problem, const cont::Branch& b, const cont::SpecialPoint& sp,
                      const std::vector<PointReport>& all, const ContactSet& after, EventType type,
                      const WallVertex& vertex, double force, SpecialPointReport& s) {
  const int n = problem.segments();
  const Eigen::Matrix2Xd P = jointPositions(problem.chain(), sp.u.head(n));
  s.type = type;
  s.phenomenon = Phenomenon::None;
  s.contactForce = force;
  s.contactPoint = wallVertexPoint(problem.chain(), sp.u.head(n), P, vertex);
  s.lockedAfter = after;
  if (size_t(sp.index + 1) < all.size()) s.negativeAfter = all[size_t(sp.index + 1)].negative;
  if (sp.index < int(b.points.size())) s.negativeBefore = all[size_t(sp.index)].negative;
}

/// A boundary after which the branch's vertices on the wall change (continueUnderContact): WC when
/// a vertex reaches the wall, WR when one leaves it.
void reportWallEvent(EquilibriumProblem& problem, const cont::Branch& b, const cont::SpecialPoint& sp,
                     const ContactSet& before, const ContactSet& after, const std::vector<PointReport>& all,
                     SpecialPointReport& s) {
  WallVertex vertex{-1, 0};
  for (const WallVertex& v : after.wall())
    if (!before.touching(v)) vertex = v;
  const bool contact = vertex.segment >= 0;
  if (!contact)
    for (const WallVertex& v : before.wall())
      if (!after.touching(v)) vertex = v;
  if (vertex.segment < 0) return;
  const ContactSet& set = contact ? after : before;
  ContactProblem held(problem, set);
  const Vector mu = held.wallForces(*held.createWorkspace(), sp.u, sp.lambda);
  const auto k = std::lower_bound(set.wall().begin(), set.wall().end(), vertex) - set.wall().begin();
  markContactEvent(problem, b, sp, all, after, contact ? EventType::WallContact : EventType::WallRelease, vertex, mu[k],
                   s);
  s.vertex = vertex;
  std::ostringstream os;
  os.precision(6);
  os << "vertex " << vertex.label() << " at (" << s.contactPoint.x() << ", " << s.contactPoint.y() << "): "
     << (contact ? "reaches the base wall and is held on it" : "wall force returns to zero: leaves the wall")
     << "; wall force = " << s.contactForce
     << "; on the wall after: " << (after.wall().empty() ? std::string("none") : after.wallLabel());
  s.note = os.str();
}

/// A boundary after which the branch's self contacts change (continueUnderContact): SH when a
/// vertex is held on another link's edge, SR when a self contact releases.
void reportSelfEvent(EquilibriumProblem& problem, const cont::Branch& b, const cont::SpecialPoint& sp,
                     const ContactSet& before, const ContactSet& after, const std::vector<PointReport>& all,
                     SpecialPointReport& s) {
  SelfContact changed, left;
  for (const SelfContact& c : after.self())
    if (!before.holding(c)) changed = c;
  for (const SelfContact& c : before.self())
    if (!after.holding(c)) left = c;
  const bool contact = changed.vertex.segment >= 0;
  if (!contact) changed = left;
  // the vertex at the corner its edge shares with the neighbour's (self_contact.h heldAtCorner)
  SelfContact partner;
  const bool corner = changed.vertex.segment >= 0 && cornerNeighbour(problem.chain(), changed, partner) &&
                      before.holding(partner) && after.holding(partner);
  if (changed.vertex.segment < 0) return;
  const ContactSet& set = contact ? after : before;
  ContactProblem held(problem, set);
  const Vector mu = held.selfForces(*held.createWorkspace(), sp.u, sp.lambda);
  const auto k = std::lower_bound(set.self().begin(), set.self().end(), changed) - set.self().begin();
  markContactEvent(problem, b, sp, all, after, contact ? EventType::SelfHold : EventType::SelfRelease, changed.vertex,
                   mu[k], s);
  s.selfContact = changed;
  std::ostringstream os;
  os.precision(6);
  os << "vertex " << changed.vertex.label() << " at (" << s.contactPoint.x() << ", " << s.contactPoint.y() << ") on edge "
     << changed.edge.label() << ": "
     << (corner && contact ? "reaches the corner it shares with edge " + partner.edge.label() +
                                 ": held at the corner on both edges"
         : corner  ? "contact force returns to zero: leaves the corner along edge " + partner.edge.label()
         : contact ? std::string("the links touch and are held apart")
                   : std::string("contact force returns to zero: the links separate"))
     << "; contact force = " << s.contactForce
     << "; self contacts after: " << (after.self().empty() ? std::string("none") : after.selfLabel());
  s.note = os.str();
}

}  // namespace

/// A boundary after which the branch's locked joints change (continueUnderContact): CT when a
/// joint locks, RL when one releases; s is left a plain boundary otherwise.
void reportContactEvent(EquilibriumProblem& problem, const cont::Branch& b, const cont::SpecialPoint& sp,
                        const std::vector<ContactStretch>& stretches, const std::vector<PointReport>& all,
                        SpecialPointReport& s) {
  // The stretch this event starts: contacts changing together at one point (continueUnderContact)
  // start stretches from the same point, one per event, in the events' order.
  int occurrence = 0;
  for (const cont::SpecialPoint& other : b.specialPoints) {
    if (&other == &sp) break;
    if (other.index == sp.index && other.type == cont::SpecialPointType::Boundary) ++occurrence;
  }
  size_t k = 0;
  while (k < stretches.size() && !(stretches[k].firstPoint == sp.index + 1 && occurrence-- == 0)) ++k;
  if (k == 0 || k == stretches.size()) return;
  const ContactSet& before = stretches[k - 1].locked;
  const ContactSet& after = stretches[k].locked;
  int joint = -1;
  for (const LockedJoint& l : after.joints())
    if (!before.locked(l.joint)) joint = l.joint;
  const bool contact = joint >= 0;
  if (!contact)
    for (const LockedJoint& l : before.joints())
      if (!after.locked(l.joint)) joint = l.joint;
  if (joint < 0) {
    if (before.self() != after.self())
      reportSelfEvent(problem, b, sp, before, after, all, s);
    else
      reportWallEvent(problem, b, sp, before, after, all, s);
    return;
  }
  const LimitSide side = contact ? after.side(joint) : before.side(joint);
  ContactProblem locked(problem, contact ? after : before);
  s.type = contact ? EventType::Contact : EventType::Release;
  s.phenomenon = Phenomenon::None;  // a change of the constraints, none of the paper's three phenomena
  s.joint = joint;
  s.contactTorque = locked.contactTorque(*locked.createWorkspace(), sp.u, sp.lambda, joint);
  s.lockedAfter = after;
  if (size_t(sp.index + 1) < all.size()) s.negativeAfter = all[size_t(sp.index + 1)].negative;
  if (sp.index < int(b.points.size())) s.negativeBefore = all[size_t(sp.index)].negative;
  const double limit = limitAngle(problem.chain(), joint, side);
  std::ostringstream os;
  os.precision(6);
  os << "joint " << joint + 1 << " " << toString(side) << " limit " << limit << " rad: "
     << (contact ? "locks (contact starts)" : "contact torque returns to zero: released")
     << "; contact torque tau_c = " << s.contactTorque << ", |q - limit| = " << std::abs(sp.u[joint] - limit)
     << "; locked after: " << (after.empty() ? std::string("none") : after.label());
  s.note = os.str();
}

}  // namespace buckle::mechanics
