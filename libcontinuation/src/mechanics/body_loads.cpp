#include "buckle/mechanics/body_loads.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/validation.h"

namespace buckle::mechanics {

namespace {
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace

BodyLoads BodyLoads::weight(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& gravity,
                            const Eigen::Vector2d& gravityRate) {
  std::string why;
  if (!inertia.IsValid(chain, &why)) throw std::invalid_argument(why);
  BodyLoads b;
  const int n = chain.size();
  b.mass.resize(n);
  b.centre.resize(n);
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = inertia.links[size_t(i)];
    b.mass[i] = L.mass;
    b.centre[i] = std::isnan(L.comOffset) ? 0.5 * chain.linkLengths()[i + 1] : L.comOffset;
  }
  b.gravity = gravity;
  b.gravityRate = gravityRate;
  return b;
}

bool BodyLoads::active() const {
  bool any = mass.size() > 0 && mass.cwiseAbs().maxCoeff() > 0.0 &&
             (gravity.cwiseAbs().maxCoeff() > 0.0 || gravityRate.cwiseAbs().maxCoeff() > 0.0);
  for (const PointLoad& p : points) any = any || p.force.cwiseAbs().maxCoeff() > 0.0 || p.rate.cwiseAbs().maxCoeff() > 0.0;
  return any;
}

BodyLoads BodyLoads::atParameter(double lambda) const {
  BodyLoads b = *this;
  b.gravity += lambda * gravityRate;
  b.gravityRate.setZero();
  for (PointLoad& p : b.points) {
    p.force += lambda * p.rate;
    p.rate.setZero();
  }
  return b;
}

void BodyLoads::check(const Chain& chain) const {
  const int n = chain.size();
  if (mass.size() != 0 && mass.size() != n)
    throw std::invalid_argument("body loads: " + std::to_string(mass.size()) + " link masses, the chain has " +
                                std::to_string(n) + " links");
  if (centre.size() != mass.size())
    throw std::invalid_argument("body loads: one centre of mass per link mass is needed");
  for (int i = 0; i < mass.size(); ++i) {
    const std::string link = "body loads: link " + std::to_string(i + 1);
    requireNonNegative(link + " mass", mass[i]);
    requireFinite(link + " centre of mass", centre[i]);
    if (centre[i] < 0.0 || centre[i] > chain.linkLengths()[i + 1])
      throw std::invalid_argument(link + " centre of mass must lie in [0, link length]");
  }
  for (int c = 0; c < 2; ++c) {
    requireFinite("gravity", gravity[c]);
    requireFinite("gravity rate", gravityRate[c]);
  }
  for (const PointLoad& p : points) {
    if (p.joint < 1 || p.joint > n + 1)
      throw std::invalid_argument("point load at joint " + std::to_string(p.joint) + ": joints are 1 … " +
                                  std::to_string(n) + " (" + std::to_string(n + 1) + ": the end)");
    for (int c = 0; c < 2; ++c) {
      requireFinite("point load force", p.force[c]);
      requireFinite("point load rate", p.rate[c]);
    }
  }
}

InertiaData withPayload(const Chain& chain, InertiaData inertia, double mass) {
  std::string why;
  if (!inertia.IsValid(chain, &why)) throw std::invalid_argument(why);
  requireNonNegative("payload mass", mass);
  if (mass == 0.0) return inertia;
  const int n = chain.size();
  const double l = chain.linkLengths()[n];
  LinkInertia& L = inertia.links[size_t(n - 1)];
  const double d = std::isnan(L.comOffset) ? 0.5 * l : L.comOffset;
  const double m = L.mass + mass, c = (L.mass * d + mass * l) / m;
  L.inertia += L.mass * (d - c) * (d - c) + mass * (l - c) * (l - c);
  L.mass = m;
  L.comOffset = c;
  return inertia;
}

void addBodyLoadHessian(const Vector& gamma, MatrixRef H) {
  if (gamma.size() == 0) return;
  if (gamma.size() != H.rows() || H.rows() != H.cols())
    throw std::invalid_argument("body loads: the generator must have one entry per joint");
  for (Eigen::Index j = 0; j < H.cols(); ++j)
    for (Eigen::Index i = 0; i < H.rows(); ++i) H(i, j) += gamma[std::max(i, j)];
}

BodyLoadTerms::BodyLoadTerms(const Chain& chain, const BodyLoads& loads) {
  loads.check(chain);
  const int n = chain.size();
  active_ = loads.active();
  force0_ = force1_ = moment0_ = moment1_ = Eigen::Matrix2Xd::Zero(2, n);
  tau0_ = tau1_ = gamma0_ = gamma1_ = Vector::Zero(n);
  dir_.resize(2, n);
  rel_.resize(2, n);
  for (int i = 0; i < loads.mass.size(); ++i) {
    force0_.col(i) += loads.mass[i] * loads.gravity;
    force1_.col(i) += loads.mass[i] * loads.gravityRate;
    moment0_.col(i) += loads.mass[i] * loads.centre[i] * loads.gravity;
    moment1_.col(i) += loads.mass[i] * loads.centre[i] * loads.gravityRate;
  }
  for (const PointLoad& p : loads.points) {
    if (p.joint <= n) {  // at the start of link `joint`: d = 0
      force0_.col(p.joint - 1) += p.force;
      force1_.col(p.joint - 1) += p.rate;
    } else {  // the end: link n at d = ℓ_n
      const double l = chain.linkLengths()[n];
      force0_.col(n - 1) += p.force;
      force1_.col(n - 1) += p.rate;
      moment0_.col(n - 1) += l * p.force;
      moment1_.col(n - 1) += l * p.rate;
    }
  }
}

void BodyLoadTerms::update(const ChainData& data) {
  const int n = size();
  for (int i = 0; i < n; ++i) {
    dir_(0, i) = std::cos(data.theta[i]);
    dir_(1, i) = std::sin(data.theta[i]);
    rel_(0, i) = -data.C[i];
    rel_(1, i) = -data.S[i];
  }
  // eq (B4), both parts in one sweep from the end
  Eigen::Vector2d F0 = Eigen::Vector2d::Zero(), F1 = Eigen::Vector2d::Zero();
  double A0 = 0.0, A1 = 0.0, B0 = 0.0, B1 = 0.0;
  for (int m = n - 1; m >= 0; --m) {
    const Eigen::Vector2d u = dir_.col(m), r = rel_.col(m);
    F0 += force0_.col(m);
    F1 += force1_.col(m);
    A0 += u.dot(moment0_.col(m)) + force0_.col(m).dot(r);
    A1 += u.dot(moment1_.col(m)) + force1_.col(m).dot(r);
    B0 += cross(u, moment0_.col(m)) + cross(r, force0_.col(m));
    B1 += cross(u, moment1_.col(m)) + cross(r, force1_.col(m));
    gamma0_[m] = A0 - F0.dot(r);
    gamma1_[m] = A1 - F1.dot(r);
    tau0_[m] = B0 - cross(r, F0);
    tau1_[m] = B1 - cross(r, F1);
  }
}

void BodyLoadTerms::generatorDerivative(double lambda, ConstVectorRef dq, double dlambda, VectorRef dgamma) const {
  const int n = size();
  // eq (B5): the suffix Σ_{j>m} τ_j dq_j and the prefix Θ_m
  double suffix = 0.0;
  for (int m = n - 1; m >= 0; --m) {
    dgamma[m] = gamma1_[m] * dlambda + suffix;
    suffix += (tau0_[m] + lambda * tau1_[m]) * dq[m];
  }
  double theta = 0.0;
  for (int m = 0; m < n; ++m) {
    theta += dq[m];
    dgamma[m] += theta * (tau0_[m] + lambda * tau1_[m]);
  }
}

double BodyLoadTerms::rateForce() const {
  return force1_.size() > 0 ? force1_.colwise().norm().sum() : 0.0;
}

double BodyLoadTerms::potential(const ChainData& data, double lambda) const {
  // V = −Σ_i (F_i·p_i + D_i·u_i), p_i = p_end + r_i (eq B1 summed per link)
  const Eigen::Vector2d end(data.pose[0], data.pose[1]);
  double v = 0.0;
  for (int i = 0; i < size(); ++i) {
    const Eigen::Vector2d u(std::cos(data.theta[i]), std::sin(data.theta[i]));
    const Eigen::Vector2d p = end - Eigen::Vector2d(data.C[i], data.S[i]);
    const Eigen::Vector2d F = force0_.col(i) + lambda * force1_.col(i);
    const Eigen::Vector2d D = moment0_.col(i) + lambda * moment1_.col(i);
    v -= F.dot(p) + D.dot(u);
  }
  return v;
}

}  // namespace buckle::mechanics
