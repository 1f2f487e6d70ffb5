// The one-sided contacts during an integration (dynamics.h, file comment): the joint limits
// (IntegrationOptions::contact) and the base wall (IntegrationOptions::wall) as event functions,
// and the contact set's update at an event. Internal to simulate (dynamics_integration.cpp).
#pragma once

#include <vector>

#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

class ContactTracker {
 public:
  ContactTracker(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result);

  /// Whether any contact is tracked (joint limits or the wall).
  bool active() const { return joints_ || wall_; }
  /// Number of event functions: one per joint, then one per moving vertex (with the wall).
  int size() const { return int(g_.size()); }

  /// Event functions at x, in the chain's own units, ≥ 0 while the contact set stays as it is:
  /// index i < n for joint i — a free joint's distance to its nearer limit (radians), a locked
  /// one's compression −side·τ_c / k̄b̄² (1 when the joint limits are not tracked); index n + k
  /// for the k-th moving vertex (movingVertices) — off the wall x_v / b̄ + kWallSlack, on it its
  /// wall force μ_v / k̄b̄.
  const std::vector<double>& events(const double* x);

  /// Changes contact `index` (as events()) at time t: locks a free joint at its nearer limit or
  /// holds a vertex on the wall (with the impact), releases a locked joint or a vertex on the
  /// wall; records the event.
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

  DynamicsModel& model_;
  DynamicsResult& result_;
  bool joints_, wall_;
  std::vector<WallVertex> vertices_;  ///< every moving vertex (with the wall)
  std::vector<double> g_, xs_;
  Vector torques_, wallForces_;
};

}  // namespace buckle::mechanics
