// The tests' own chain geometry, written apart from the library's kinematics: joints P_j
// (0-based joint j at column j), the end and the absolute link angles θ_m, from the link lengths
// b_11, b_i2 + b_(i+1)1, b_n2.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "buckle/mechanics/chain.h"

namespace buckle::test {

inline Eigen::Vector2d along(double t) { return {std::cos(t), std::sin(t)}; }
inline Eigen::Vector2d across(double t) { return {-std::sin(t), std::cos(t)}; }

/// The moment about c of a force f applied at r: (r − c) × f.
inline double moment(const Eigen::Vector2d& r, const Eigen::Vector2d& c, const Eigen::Vector2d& f) {
  const Eigen::Vector2d d = r - c;
  return d.x() * f.y() - d.y() * f.x();
}

struct Geometry {
  Eigen::Matrix2Xd P;
  Eigen::Vector2d end;
  Eigen::VectorXd theta;  // θ_m of link m (m = 0 … n)
};

inline Geometry geometry(const mechanics::Chain& chain, const Eigen::VectorXd& q) {
  const int n = chain.size();
  Geometry g;
  g.P.resize(2, n);
  g.theta = Eigen::VectorXd::Zero(n + 1);
  Eigen::Vector2d at(chain.segment(0).parameters().b1, 0.0);
  for (int j = 0; j < n; ++j) {
    g.P.col(j) = at;
    g.theta[j + 1] = g.theta[j] + q[j];
    const double link = chain.segment(j).parameters().b2 + (j + 1 < n ? chain.segment(j + 1).parameters().b1 : 0.0);
    at += link * along(g.theta[j + 1]);
  }
  g.end = at;
  return g;
}

}  // namespace buckle::test
