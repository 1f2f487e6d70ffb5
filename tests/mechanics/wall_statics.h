// The tests' own geometry and statics of vertices on the base wall x = 0 (wall_contact.h's
// corners), written apart from the library's kinematics (test_geometry.h).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/wall_contact.h"
#include "test_geometry.h"

namespace buckle::test {

// Every moving vertex: the joints 2 … n, the proximal triangles' base corners of segments 2 … n,
// the distal ones of every segment (segment 1's proximal triangle is the clamp).
inline double smallestVertexX(const mechanics::Chain& chain, const Eigen::VectorXd& q) {
  const Geometry g = geometry(chain, q);
  double x = std::numeric_limits<double>::infinity();
  for (int i = 0; i < chain.size(); ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    for (const double s : {1.0, -1.0}) {
      x = std::min(x, (g.P.col(i) + p.b2 * along(g.theta[i + 1]) + s * p.a2 * across(g.theta[i + 1])).x());
      if (i > 0) x = std::min(x, (g.P.col(i) - p.b1 * along(g.theta[i]) + s * p.a1 * across(g.theta[i])).x());
    }
    if (i > 0) x = std::min(x, g.P(0, i));
  }
  return x;
}

// The vertex `v` (wall_contact.h's corners) by the test's own geometry.
inline Eigen::Vector2d vertexAt(const mechanics::Chain& chain, const Eigen::VectorXd& q,
                                const mechanics::WallVertex& v) {
  const Geometry g = geometry(chain, q);
  const mechanics::SegmentParameters& p = chain.segment(v.segment).parameters();
  const int i = v.segment;
  switch (v.corner) {
    case 0: return g.P.col(i);
    case 1: return g.P.col(i) - p.b1 * along(g.theta[i]) + p.a1 * across(g.theta[i]);
    case 2: return g.P.col(i) - p.b1 * along(g.theta[i]) - p.a1 * across(g.theta[i]);
    case 3: return g.P.col(i) + p.b2 * along(g.theta[i + 1]) + p.a2 * across(g.theta[i + 1]);
    default: return g.P.col(i) + p.b2 * along(g.theta[i + 1]) - p.a2 * across(g.theta[i + 1]);
  }
}

// Statics of a state with the end force F and one vertex v pressed on the wall: the wall force μ
// that closes the moment balance of the part beyond the last joint moving v, then the largest
// imbalance over every joint j: −M_j (the spring's torque on the part beyond j) against the
// moments of F and μ e_x about P_j. A joint beyond v's last one carries F only.
struct Statics {
  double mu = 0.0;
  double imbalance = 0.0;  // in the torque unit k b²
  double clampImbalance = 0.0;
};
inline Statics wallStatics(const mechanics::Chain& chain, const Eigen::VectorXd& q, const Eigen::Vector2d& F,
                           const mechanics::WallVertex& v) {
  const int n = chain.size();
  const Geometry g = geometry(chain, q);
  const Eigen::Vector2d at = vertexAt(chain, q, v), ex(1.0, 0.0);
  const int last = v.corner >= 3 ? v.segment : v.segment - 1;
  Eigen::VectorXd dE(n);
  for (int j = 0; j < n; ++j) dE[j] = -chain.segment(j).torque(q[j]);
  Statics s;
  s.mu = (dE[last] - moment(g.end, g.P.col(last), F)) / moment(at, g.P.col(last), ex);
  for (int j = 0; j < n; ++j) {
    const double wall = j <= last ? s.mu * moment(at, g.P.col(j), ex) : 0.0;
    s.imbalance = std::max(s.imbalance, std::abs(dE[j] - moment(g.end, g.P.col(j), F) - wall));
  }
  // The clamp: the reaction R = −(F + μ e_x) at joint 1 and joint 1's spring torque on the clamp
  // balance the moments of F and μ about the origin (the whole moving chain in equilibrium).
  const Eigen::Vector2d R = -(F + s.mu * ex);
  const double clampMoment = dE[0] + moment(g.P.col(0), Eigen::Vector2d::Zero(), -R);
  s.clampImbalance = std::abs(clampMoment - moment(g.end, Eigen::Vector2d::Zero(), F) -
                              moment(at, Eigen::Vector2d::Zero(), s.mu * ex));
  return s;
}

}  // namespace buckle::test
