// The one-sided contacts during an integration (dynamics.h, file comment): the joint limits
// (IntegrationOptions::contact), the base wall (IntegrationOptions::wall) and the chain's contact
// with itself (IntegrationOptions::self) as event functions, and the contact set's update at an
// event. Internal to simulate (dynamics_integration.cpp).
#pragma once

#include <vector>

#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

class ContactTracker {
 public:
  ContactTracker(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result);

  /// Whether any contact is tracked (joint limits, the wall or self contact).
  bool active() const { return joints_ || wall_ || self_; }
  /// Number of event functions: one per joint, then one per moving vertex (with the wall), then
  /// (with self contact) the clearance and two per held self contact. It changes with the held
  /// self contacts: compare events() only between two toggles.
  int size() const { return int(g_.size()); }

  /// Event functions at x, in the chain's own units, ≥ 0 while the contact set stays as it is:
  /// index i < n for joint i — a free joint's distance to its nearer limit (radians), a locked
  /// one's compression −side·τ_c / k̄b̄² (1 when the joint limits are not tracked); index n + k
  /// for the k-th moving vertex (movingVertices) — off the wall x_v / b̄ + kWallSlack, on it its
  /// wall force μ_v / k̄b̄; then the clearance of the link pairs holding no self contact
  /// (selfClearanceApart / b̄ + kWallSlack) and, per held self contact k, its force μ / k̄b̄ and
  /// its vertex's distances to its edge's apex end t·|e| / b̄ and base corner (1 − t)·|e| / b̄ (1
  /// for a vertex held at a corner).
  const std::vector<double>& events(const double* x);

  /// Changes contact `index` (as events()) at time t: locks a free joint at its nearer limit,
  /// holds a vertex on the wall or on the touching link (with the impact), releases a locked
  /// joint, a vertex on the wall or a self contact; a held vertex at its edge's base corner is
  /// held on the corner's other edge too (self_contact.h cornerNeighbour), and one at an end it
  /// cannot pass is released (it slides off the edge). Records the event.
  void toggle(double* x, double t, int index);

  /// The contact set consistent at x (after an event or at the start): free joints beyond a
  /// limit are locked and vertices behind the wall held, then the contact pulling hardest is
  /// released, one at a time (an active-set iteration). False when it does not settle.
  bool settle(double* x, double t);

  /// A vertex off the wall counts as reaching it at x_v = −kWallSlack·b̄, so that one released
  /// at x_v = 0 to rounding (its row held it there) is not held again at once.
  static constexpr double kWallSlack = 1e-9;

 private:
  int wallIndex(const WallVertex& v) const;
  /// The first self contact event (the clearance), after the joints' and the wall's.
  int selfBegin() const { return model_.segments() + int(vertices_.size()); }
  /// Every contact's force at x into torques_, wallForces_, selfForces_.
  void forcesAt(const double* x);
  /// The self contact events' part of toggle(): e.self and e.contact set, the model's set changed.
  void toggleSelf(const double* x, int index, ContactEvent& e);

  DynamicsModel& model_;
  DynamicsResult& result_;
  bool joints_, wall_, self_;
  std::vector<WallVertex> vertices_;  ///< every moving vertex (with the wall)
  std::vector<double> g_, xs_;
  Vector torques_, wallForces_, selfForces_;
};

}  // namespace buckle::mechanics
