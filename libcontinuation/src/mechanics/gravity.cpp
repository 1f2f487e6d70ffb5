#include "buckle/mechanics/gravity.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

GravityPotential::GravityPotential(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& acceleration)
    : chain_(chain), g_(acceleration) {
  std::string why;
  if (!inertia.IsValid(chain, &why)) throw std::invalid_argument(why);
  if (!g_.allFinite()) throw std::invalid_argument("the gravitational acceleration must be finite");
  const int n = chain.size();
  mass_.resize(n);
  com_.resize(n);
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = inertia.links[size_t(i)];
    mass_[i] = L.mass;
    com_[i] = std::isnan(L.comOffset) ? 0.5 * chain.linkLengths()[i + 1] : L.comOffset;
  }
}

Eigen::Matrix2Xd GravityPotential::centresOfMass(ConstVectorRef q) const {
  const int n = chain_.size();
  const Eigen::Matrix2Xd P = jointPositions(chain_, q);  // column i + 1: the joint of q_i
  Eigen::Matrix2Xd r(2, n);
  double theta = 0.0;
  for (int i = 0; i < n; ++i) {
    theta += q[i];
    r.col(i) = P.col(i + 1) + com_[i] * Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
  return r;
}

void GravityPotential::moments(ConstVectorRef q, Eigen::Matrix2Xd& v) const {
  const int n = chain_.size();
  const Eigen::Matrix2Xd P = jointPositions(chain_, q);
  const Eigen::Matrix2Xd r = centresOfMass(q);
  v.resize(2, n);
  double W = 0.0;
  Eigen::Vector2d C = Eigen::Vector2d::Zero();
  for (int j = n - 1; j >= 0; --j) {
    W += mass_[j];
    C += mass_[j] * r.col(j);
    v.col(j) = C - W * P.col(j + 1);
  }
}

double GravityPotential::value(ConstVectorRef q) const {
  if (q.size() != chain_.size()) throw std::invalid_argument("GravityPotential: q must have one angle per joint");
  return -(g_.transpose() * centresOfMass(q) * mass_)(0);
}

void GravityPotential::gradient(ConstVectorRef q, VectorRef grad) const {
  if (q.size() != chain_.size() || grad.size() != chain_.size())
    throw std::invalid_argument("GravityPotential: q and the gradient must have one entry per joint");
  Eigen::Matrix2Xd v;
  moments(q, v);
  for (int j = 0; j < chain_.size(); ++j) grad[j] = -(g_.y() * v(0, j) - g_.x() * v(1, j));  // −g·R v, eq (G2)
}

void GravityPotential::hessianGenerator(ConstVectorRef q, VectorRef gamma) const {
  if (q.size() != chain_.size() || gamma.size() != chain_.size())
    throw std::invalid_argument("GravityPotential: q and γ must have one entry per joint");
  Eigen::Matrix2Xd v;
  moments(q, v);
  gamma = (g_.transpose() * v).transpose();  // eq (G3)
}

void GravityPotential::hessian(ConstVectorRef q, MatrixRef G) const {
  const int n = chain_.size();
  if (G.rows() != n || G.cols() != n) throw std::invalid_argument("GravityPotential: the Hessian must be n×n");
  Vector gamma(n);
  hessianGenerator(q, gamma);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) G(j, k) = gamma[std::max(j, k)];
}

}  // namespace buckle::mechanics
