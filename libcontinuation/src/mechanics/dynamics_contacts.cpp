#include "dynamics_contacts.h"

#include <algorithm>

namespace buckle::mechanics {

ContactTracker::ContactTracker(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result)
    : model_(model), result_(result), joints_(options.contact), wall_(options.wall),
      torques_(model.segments()) {
  if (wall_) vertices_ = movingVertices(model.chain());
  g_.assign(size_t(model.segments()) + vertices_.size(), 1.0);
}

int ContactTracker::wallIndex(const WallVertex& v) const {
  const auto& held = model_.wallContacts();
  const auto it = std::find(held.begin(), held.end(), v);
  return it == held.end() ? -1 : int(it - held.begin());
}

const std::vector<double>& ContactTracker::events(const double* x) {
  const int n = model_.segments();
  const Eigen::Map<const Vector> q(x, n);
  wallForces_.resize(model_.wallCount());
  model_.contactForces(x, torques_, wallForces_);
  if (joints_) {
    const Vector& lo = model_.chain().lowerLimits();
    const Vector& hi = model_.chain().upperLimits();
    for (int i = 0; i < n; ++i) {
      const int side = model_.contactSides()[size_t(i)];
      g_[size_t(i)] = side == 0 ? std::min(x[i] - lo[i], hi[i] - x[i]) : -side * torques_[i] / model_.torqueUnit();
    }
  }
  if (wall_) {
    movingVertexAbscissae(model_.chain(), q, xs_);
    const double force = model_.torqueUnit() / model_.lengthUnit();
    for (size_t k = 0; k < vertices_.size(); ++k) {
      const int held = wallIndex(vertices_[k]);
      g_[size_t(n) + k] = held < 0 ? xs_[k] / model_.lengthUnit() + kWallSlack : wallForces_[held] / force;
    }
  }
  return g_;
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
  } else {
    const WallVertex v = vertices_[size_t(index - n)];
    std::vector<WallVertex> held = model_.wallContacts();
    const int k = wallIndex(v);
    e.vertex = v;
    e.contact = k < 0;
    if (k < 0) {
      held.push_back(v);
    } else {
      wallForces_.resize(model_.wallCount());
      model_.contactForces(x, torques_, wallForces_);
      e.torque = wallForces_[k];
      held.erase(held.begin() + k);
    }
    model_.setWallContacts(held);
  }
  if (e.contact) {
    e.kineticLost = model_.impact(x);
    wallForces_.resize(model_.wallCount());
    model_.contactForces(x, torques_, wallForces_);
    e.torque = index < n ? torques_[index] : wallForces_[wallIndex(e.vertex)];
  }
  result_.contactEvents.push_back(e);
}

bool ContactTracker::settle(double* x, double t) {
  const int n = model_.segments();
  const int limit = 2 * size() + 2;
  for (int change = 0; change <= limit; ++change) {
    const std::vector<double>& g = events(x);
    int beyond = -1, pulling = -1;
    double worst = 0.0;
    for (int i = 0; i < size(); ++i) {
      const bool inContact = i < n ? model_.contactSides()[size_t(i)] != 0 : wallIndex(vertices_[size_t(i - n)]) >= 0;
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
