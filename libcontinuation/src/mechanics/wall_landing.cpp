// Landing on the base wall (wall_landing.h): the active-set iteration over the vertices on the
// wall, the self contacts and the locked joints.
#include "buckle/mechanics/wall_landing.h"

#include <cmath>
#include <sstream>

#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

namespace {

// Contacts whose force or gap is within this fraction of the chain's units of zero are touching:
// a vertex that reaches the wall with zero force sits on both sides of the test to rounding.
constexpr double kContactSlack = 1e-9;

/// The most pulling contact of `ce` (a wall or self contact force or a locked joint's
/// compression, in the chain's force / torque units) when it pulls by more than the slack: release
/// it and return true.
bool releasePulling(const ConstrainedEquilibrium& ce, double force, double torque, ContactSet& set,
                    std::string& what) {
  double worst = -kContactSlack;
  int wall = -1, joint = -1, self = -1;
  for (int k = 0; k < set.wallCount(); ++k)
    if (ce.wallForces[k] / force < worst) {
      worst = ce.wallForces[k] / force;
      wall = k;
    }
  for (int k = 0; k < set.selfCount(); ++k)
    if (ce.selfForces[k] / force < worst) {
      worst = ce.selfForces[k] / force;
      self = k;
      wall = -1;
    }
  for (const LockedJoint& l : set.joints()) {
    const double c = -double(int(l.side)) * ce.torques[l.joint] / torque;
    if (c < worst) {
      worst = c;
      joint = l.joint;
      wall = self = -1;
    }
  }
  if (self >= 0) {
    const SelfContact c = set.self()[size_t(self)];
    what = "self contact " + c.label() + " released (its force pulled)";
    set.separate(c);
    return true;
  }
  if (wall >= 0) {
    const WallVertex v = set.wall()[size_t(wall)];
    what = "vertex " + v.label() + " released (its wall force pulled)";
    set.leave(v);
    return true;
  }
  if (joint >= 0) {
    what = "joint " + std::to_string(joint + 1) + " released (its contact pulled)";
    set.release(joint);
    return true;
  }
  return false;
}

/// With self contact traced: two links that the solution puts into each other are held apart by
/// the pair by which they touch; a held vertex beyond an end of its edge is held at the base
/// corner on the corner's other edge too, or released past an end it cannot pass. True when the
/// set changed.
bool changeSelfContacts(const Chain& chain, ConstVectorRef q, double length, ContactSet& set, std::string& what) {
  const Eigen::Matrix2Xd P = jointPositions(chain, q);
  for (const SelfContact& c : set.self()) {
    const SelfContactGap g = selfContactGap(chain, q, P, c);
    if (heldAtCorner(chain, c, set.self()) || (g.along >= -kContactSlack && g.along <= 1.0 + kContactSlack)) continue;
    SelfContact next;
    if (g.along > 1.0 && cornerNeighbour(chain, c, next)) {
      what = "self contact " + c.label() + " held at its edge's corner on " + next.edge.label() + " too";
      set.hold(next);
    } else {
      what = "self contact " + c.label() + " released (the vertex slid off its edge)";
      set.separate(c);
    }
    return true;
  }
  int a = -1, b = -1;
  if (!(selfClearanceApart(chain, q, set.self(), &a, &b) < -kContactSlack * length) || a < 0 || b < 0) return false;
  const SelfContact c = touchingPair(chain, q, a, b, set.self());
  what = "self contact " + c.label() + " held (the links were in each other)";
  set.hold(c);
  return true;
}

/// A vertex not on the wall behind it, two links in each other (with `self`), or a free joint past
/// a limit, at q: add it, return true.
bool addPenetrating(const Chain& chain, ConstVectorRef q, double length, bool self, ContactSet& set,
                    std::string& what) {
  const WallApproach a = nearestWallVertex(chain, q, set.wall());
  if (a.distance < -kContactSlack * length) {
    what = "vertex " + a.vertex.label() + " held on the wall (it was behind it)";
    set.touch(a.vertex);
    return true;
  }
  if (self && changeSelfContacts(chain, q, length, set, what)) return true;
  for (int i = 0; i < chain.size(); ++i) {
    if (set.locked(i)) continue;
    const bool above = q[i] > chain.upperLimits()[i] + kContactSlack, below = q[i] < chain.lowerLimits()[i] - kContactSlack;
    if (!above && !below) continue;
    what = "joint " + std::to_string(i + 1) + " locked (it was past its limit)";
    set.lock(i, above ? LimitSide::Upper : LimitSide::Lower);
    return true;
  }
  return false;
}

std::string describeWall(const ContactSet& set, const Vector& forces) {
  std::ostringstream os;
  for (int k = 0; k < set.wallCount(); ++k)
    os << (k ? ", " : "") << "vertex " << set.wall()[size_t(k)].label() << " (wall force " << forces[k] << ")";
  return os.str();
}

std::string describeSelf(const ContactSet& set, const Vector& forces) {
  std::ostringstream os;
  for (int k = 0; k < set.selfCount(); ++k)
    os << (k ? ", " : "") << set.self()[size_t(k)].label() << " (contact force " << forces[k] << ")";
  return os.str();
}

}  // namespace

WallLanding landOnWall(const EquilibriumProblem& problem, const ContactSet& start, ConstVectorRef q, double lambda,
                       double tolerance, int maxIterations, bool self) {
  WallLanding out;
  out.contacts = start;
  const int n = problem.segments();
  const double length = problem.lengthUnit(), force = problem.stiffnessUnit() * length, torque = force * length;
  Vector u = problem.initialGuess(q, lambda);
  std::string trail;
  // each contact enters and leaves at most once in a consistent sequence: 2 (5n + n) + 2 changes
  const int maxChanges = 12 * n + 2;
  for (int change = 0; change <= maxChanges; ++change) {
    const ConstrainedEquilibrium ce = solveConstrainedEquilibrium(problem, out.contacts, u, lambda, tolerance, maxIterations);
    ++out.solves;
    out.u = ce.u;
    out.residual = ce.residual;
    out.wallForces = ce.wallForces;
    out.selfForces = ce.selfForces;
    out.torques = ce.torques;
    if (!ce.converged) {
      out.message = "the equilibrium with " + (out.contacts.wallCount() ? "vertices " + out.contacts.wallLabel() : "no vertex") +
                    " on the wall" + (out.contacts.selfCount() ? " and the self contacts " + out.contacts.selfLabel() : "") +
                    " did not converge (" + ce.message + ")" + trail;
      return out;
    }
    u = ce.u;
    std::string what;
    if (releasePulling(ce, force, torque, out.contacts, what) ||
        addPenetrating(problem.chain(), ce.u.head(n), length, self, out.contacts, what)) {
      trail += "; " + what;
      continue;
    }
    out.converged = true;
    out.stability = constrainedStability(problem, out.contacts, ce.u, lambda, 3);
    // a contact whose force is zero would release at the slightest disturbance (as a joint stop)
    bool pushing = true;
    for (int k = 0; k < out.contacts.wallCount(); ++k) pushing = pushing && ce.wallForces[k] > 0.0;
    for (int k = 0; k < out.contacts.selfCount(); ++k) pushing = pushing && ce.selfForces[k] > 0.0;
    for (const LockedJoint& l : out.contacts.joints())
      pushing = pushing && -double(int(l.side)) * ce.torques[l.joint] > 0.0;
    out.stable = out.stability.valid() && out.stability.stable() && pushing;
    std::ostringstream os;
    os << (out.stable ? "stable" : "not stable") << " equilibrium";
    if (out.contacts.wallCount() > 0) os << " on the wall: " << describeWall(out.contacts, ce.wallForces);
    else if (out.contacts.selfCount() == 0) os << " off the wall";
    if (out.contacts.selfCount() > 0)
      os << (out.contacts.wallCount() > 0 ? ", " : " ") << "held on itself: " << describeSelf(out.contacts, ce.selfForces);
    if (!out.stability.valid()) os << " (stability not computed)";
    else if (!out.stability.stable()) os << " (" << out.stability.negative << " negative, " << out.stability.zero << " zero eigenvalues on the constrained tangent)";
    else if (!pushing) os << " (a contact force is zero)";
    out.message = os.str() + trail;
    return out;
  }
  out.message = "the contact set did not settle in " + std::to_string(maxChanges) + " changes" + trail;
  return out;
}

std::function<bool(ConstVectorRef)> wallBarrier(const Chain& chain) {
  return [&chain](ConstVectorRef q) { return !(nearestWallVertex(chain, q).distance < 0.0); };
}

std::string behindWall(const Chain& chain, ConstVectorRef q, double length) {
  const WallApproach a = nearestWallVertex(chain, q);
  if (!(a.distance < -kContactSlack * length)) return {};
  std::ostringstream os;
  os << "; the landing is behind the base wall (vertex " << a.vertex.label() << " at x = " << a.distance
     << "; the wall is not traced)";
  return os.str();
}

}  // namespace buckle::mechanics
