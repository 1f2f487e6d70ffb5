#include "dynamics_contacts.h"

#include <algorithm>

#include "buckle/mechanics/self_contact.h"

namespace buckle::mechanics {

ContactTracker::ContactTracker(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result)
    : model_(model), result_(result), joints_(options.contact), wall_(options.wall), self_(options.self),
      torques_(model.segments()) {
  if (wall_) vertices_ = movingVertices(model.chain());
  g_.assign(size_t(model.segments()) + vertices_.size(), 1.0);
}

int ContactTracker::wallIndex(const WallVertex& v) const {
  const auto& held = model_.wallContacts();
  const auto it = std::find(held.begin(), held.end(), v);
  return it == held.end() ? -1 : int(it - held.begin());
}

void ContactTracker::forcesAt(const double* x) {
  wallForces_.resize(model_.wallCount());
  selfForces_.resize(model_.selfCount());
  model_.contactForces(x, torques_, wallForces_, selfForces_);
}

const std::vector<double>& ContactTracker::events(const double* x) {
  const int n = model_.segments();
  const Eigen::Map<const Vector> q(x, n);
  forcesAt(x);
  if (joints_) {
    const Vector& lo = model_.chain().lowerLimits();
    const Vector& hi = model_.chain().upperLimits();
    for (int i = 0; i < n; ++i) {
      const int side = model_.contactSides()[size_t(i)];
      g_[size_t(i)] = side == 0 ? std::min(x[i] - lo[i], hi[i] - x[i]) : -side * torques_[i] / model_.torqueUnit();
    }
  }
  const double length = model_.lengthUnit(), force = model_.torqueUnit() / length;
  if (wall_) {
    movingVertexAbscissae(model_.chain(), q, xs_);
    for (size_t k = 0; k < vertices_.size(); ++k) {
      const int held = wallIndex(vertices_[k]);
      g_[size_t(n) + k] = held < 0 ? xs_[k] / length + kWallSlack : wallForces_[held] / force;
    }
  }
  if (self_) {
    const std::vector<SelfContact>& held = model_.selfContacts();
    const int s0 = selfBegin();
    g_.resize(size_t(s0) + 1 + 3 * held.size());
    g_[size_t(s0)] = selfClearanceApart(model_.chain(), q, held) / length + kWallSlack;
    const Eigen::Matrix2Xd P = held.empty() ? Eigen::Matrix2Xd() : jointPositions(model_.chain(), q);
    for (size_t k = 0; k < held.size(); ++k) {
      g_[size_t(s0) + 1 + 3 * k] = selfForces_[Eigen::Index(k)] / force;
      const SelfContactGap gap = selfContactGap(model_.chain(), q, P, held[k]);
      const bool corner = heldAtCorner(model_.chain(), held[k], held);
      g_[size_t(s0) + 2 + 3 * k] = corner ? 1.0 : gap.along * gap.edgeLength / length;
      g_[size_t(s0) + 3 + 3 * k] = corner ? 1.0 : (1.0 - gap.along) * gap.edgeLength / length;
    }
  }
  return g_;
}

void ContactTracker::toggleSelf(const double* x, int index, ContactEvent& e) {
  const int n = model_.segments(), k = (index - selfBegin() - 1) / 3;
  const Eigen::Map<const Vector> q(x, n);
  std::vector<SelfContact> held = model_.selfContacts();
  if (index == selfBegin()) {  // two links touch: the vertex–edge pair by which they do is held
    int a = -1, b = -1;
    selfClearanceApart(model_.chain(), q, held, &a, &b);
    e.self = touchingPair(model_.chain(), q, a, b, held);
    e.contact = true;
    held.push_back(e.self);
  } else if ((index - selfBegin() - 1) % 3 == 0) {  // its force returned to zero
    e.self = held[size_t(k)];
    e.contact = false;
    e.torque = selfForces_[k];
    held.erase(held.begin() + k);
  } else {  // the vertex at an end of its edge: pinned at the corner, else it slides off
    const SelfContact c = held[size_t(k)];
    SelfContact next;
    e.contact = (index - selfBegin() - 1) % 3 == 2 && cornerNeighbour(model_.chain(), c, next) &&
                std::find(held.begin(), held.end(), next) == held.end();
    if (e.contact) {
      e.self = next;
      held.push_back(next);
    } else {
      e.self = c;
      e.torque = selfForces_[k];
      held.erase(held.begin() + k);
    }
  }
  model_.setSelfContacts(held);
}

void ContactTracker::toggle(double* x, double t, int index) {
  const int n = model_.segments();
  ContactEvent e;
  e.t = t;
  if (index < n) {
    std::vector<int> sides = model_.contactSides();
    const bool lock = sides[size_t(index)] == 0;
    e.joint = index;
    if (lock) {
      const double lo = model_.chain().lowerLimits()[index], hi = model_.chain().upperLimits()[index];
      sides[size_t(index)] = hi - x[index] <= x[index] - lo ? 1 : -1;
    } else {
      model_.contactTorques(x, torques_);
      e.torque = torques_[index];
      sides[size_t(index)] = 0;
    }
    e.side = lock ? sides[size_t(index)] : model_.contactSides()[size_t(index)];
    e.contact = lock;
    model_.setContacts(sides);
  } else if (index < selfBegin()) {
    const WallVertex v = vertices_[size_t(index - n)];
    std::vector<WallVertex> held = model_.wallContacts();
    const int k = wallIndex(v);
    e.vertex = v;
    e.contact = k < 0;
    if (k < 0) {
      held.push_back(v);
    } else {
      forcesAt(x);
      e.torque = wallForces_[k];
      held.erase(held.begin() + k);
    }
    model_.setWallContacts(held);
  } else {
    forcesAt(x);
    toggleSelf(x, index, e);
  }
  if (e.contact) {
    e.kineticLost = model_.impact(x);
    forcesAt(x);
    if (index < n) {
      e.torque = torques_[index];
    } else if (index < selfBegin()) {
      e.torque = wallForces_[wallIndex(e.vertex)];
    } else {
      const auto& held = model_.selfContacts();
      e.torque = selfForces_[std::find(held.begin(), held.end(), e.self) - held.begin()];
    }
  }
  result_.contactEvents.push_back(e);
}

bool ContactTracker::settle(double* x, double t) {
  const int n = model_.segments();
  for (int change = 0; change <= 2 * size() + 2 + 4 * model_.segments(); ++change) {
    const std::vector<double>& g = events(x);
    int beyond = -1, pulling = -1;
    double worst = 0.0;
    for (int i = 0; i < size(); ++i) {
      // in contact: a locked joint, a vertex on the wall, a held self contact's force
      const bool inContact = i < n            ? model_.contactSides()[size_t(i)] != 0
                             : i < selfBegin() ? wallIndex(vertices_[size_t(i - n)]) >= 0
                                               : i > selfBegin() && (i - selfBegin() - 1) % 3 == 0;
      if (!inContact) {
        if (g[size_t(i)] < 0.0 && beyond < 0) beyond = i;
      } else if (g[size_t(i)] < worst) {
        worst = g[size_t(i)];
        pulling = i;
      }
    }
    if (beyond >= 0) toggle(x, t, beyond);
    else if (pulling >= 0) toggle(x, t, pulling);
    else return true;
  }
  return false;
}

}  // namespace buckle::mechanics
