// The gradient-flow model (D1) of dynamics.h, c·q̇ = −P∇Π − κ_h J_h⁺h: its right-hand side and the
// O(n) stage solves of the stiff integrator on the chain structure.
#include "buckle/mechanics/dynamics.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace buckle::mechanics {

namespace {

/// out = −G v for the generator form G(i, j) = g_max(i,j): (G v)_i = g_i Σ_{j≤i} v_j + Σ_{j>i} g_j v_j,
/// O(n). The Hessians of the end coordinates and of a wall vertex's x are −G of their generators.
void applyNegativeGenerator(ConstVectorRef g, ConstVectorRef v, VectorRef out) {
  const Eigen::Index n = v.size();
  double head = 0.0, tail = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    head += v[i];
    out[i] = -g[i] * head;
  }
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    out[i] -= tail;
    tail += g[i] * v[i];
  }
}

/// out = ∇²p_c v for the end coordinate c: ∂²x/∂q_i∂q_j = −C_max(i,j), ∂²y/∂q_i∂q_j = −S_max(i,j)
/// (eq 26–27), ∂²φ = 0.
void applyEndHessian(const ChainData& data, int c, ConstVectorRef v, VectorRef out) {
  if (c == static_cast<int>(EndCoordinate::Phi)) out.setZero();
  else applyNegativeGenerator(c == 0 ? data.C : data.S, v, out);
}

}  // namespace

// ---- gradient flow (D1) ---------------------------------------------------------------------

GradientFlowModel::GradientFlowModel(const Chain& chain, const EndCondition& end, const DynamicsScene& scene,
                                     ConstVectorRef q0)
    : DynamicsModel(chain, end), c_(scene.flowDamping), kappaH_(scene.constraintStiffness),
      H_(chain.size(), chain.size()), qdot_(chain.size()), structure_(chain.size()), shifted_(chain.size()),
      scaledRhs_(chain.size()), y_(end.heldCount()), zeroM_(Vector::Zero(end.heldCount())),
      V_(chain.size(), end.heldCount()), W_(chain.size(), end.heldCount()) {
  // (held rows only until setContacts() adds locked joints: resizeConstraints())
  if (!std::isfinite(c_) || !(c_ > 0.0)) throw std::invalid_argument("flowDamping must be > 0");
  if (q0.size() != chain.size()) throw std::invalid_argument("q0 must have one entry per joint");
  if (!(kappaH_ > 0.0)) {
    Vector kq(chain.size());
    jointStiffness(chain_, q0, kq);
    kappaH_ = 10.0 * std::max(torqueUnit_, kq.cwiseAbs().maxCoeff());
  }
}

void GradientFlowModel::resizeConstraints() {
  const int p = constraintCount() + 2 * selfCount();  // the border: rows, and each self contact's rank-2 pair
  y_ = Vector::Zero(p);
  zeroM_ = Vector::Zero(p);
  V_.resize(segments(), p);
  W_.resize(segments(), p);
  factoredFor_ = std::numeric_limits<double>::quiet_NaN();  // the factored system had other rows
}

void GradientFlowModel::packState(ConstVectorRef q, ConstVectorRef, VectorRef x) const {
  x.head(segments()) = q;
  x[segments()] = 0.0;
}

void GradientFlowModel::velocity(const double* x, VectorRef qdot) {
  const int n = segments();
  evaluateStatics(Eigen::Map<const Vector>(x, n));
  if (constraintCount() == 0) {
    qdot = -grad_ / c_;
    return;
  }
  // (D1): c q̇ = −(∇Π − J_hᵀ r), r = (J_h J_hᵀ)⁻¹ (J_h ∇Π − κ_h h); then J_h q̇ = −(κ_h/c) h.
  tmpM_.noalias() = Jh_ * grad_;
  tmpM_ -= kappaH_ * h_;
  llt_.solveInPlace(tmpM_);
  r_ = tmpM_;
  qdot = grad_;
  qdot.noalias() -= Jh_.transpose() * r_;
  qdot /= -c_;
}

double GradientFlowModel::restSpeed(const double* x) {
  const int n = segments();
  if (constraintCount() == 0) {
    velocity(x, qdot_);
    return qdot_.cwiseAbs().maxCoeff();
  }
  equilibriumResidual(Eigen::Map<const Vector>(x, n));  // P∇Π into tmpN_
  return tmpN_.cwiseAbs().maxCoeff() / c_;
}

void GradientFlowModel::rhs(const double* x, double* dxdt) {
  const int n = segments();
  velocity(x, qdot_);
  Eigen::Map<Vector>(dxdt, n) = qdot_;
  // Power of the damping forces, c|q̇|² = −dΠ/dt on h = 0.
  dxdt[n] = c_ * qdot_.squaredNorm();
}

void GradientFlowModel::jacobian(const double* x, double* jacobianRowMajor) {
  if (constraintCount() > 0) {
    DynamicsModel::jacobian(x, jacobianRowMajor);
    return;
  }
  // Unconstrained: d q̇/dq = −H/c with H = K_q − K_g (eq 27), and d(c|q̇|²)/dq = −2 (H q̇)ᵀ.
  const int n = segments();
  const int N = n + 1;
  velocity(x, qdot_);  // also runs the statics (kinematics, K_q) at q
  loadMatrix(data_, loads_, H_);
  H_ = -H_;
  H_.diagonal() += stiffness_;
  addBodyHessian(H_);
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jac(jacobianRowMajor, N, N);
  Jac.setZero();
  Jac.topLeftCorner(n, n) = -H_ / c_;
  tmpN_.noalias() = H_ * qdot_;
  Jac.bottomLeftCorner(1, n) = -2.0 * tmpN_.transpose();
}

bool GradientFlowModel::solveLinearizedDense(const double* x, double a, const double* b, double* k) {
  // more rows than the chain structure's border takes: the dense LU of I − aJ̃, J̃ by central
  // differences of the right-hand side (as the inertial model with constraints)
  const int N = stateSize();
  const bool cached = factoredFor_ == a && lastState_.size() == N && std::equal(x, x + N, lastState_.data());
  if (!cached) {
    factoredFor_ = std::numeric_limits<double>::quiet_NaN();
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(N, N);
    DynamicsModel::jacobian(x, J.data());
    denseLU_.compute(Matrix::Identity(N, N) - a * Matrix(J));
    factoredFor_ = a;
    lastState_ = Eigen::Map<const Vector>(x, N);
  }
  Eigen::Map<Vector> kv(k, N);
  kv = denseLU_.solve(Eigen::Map<const Vector>(b, N));
  return kv.allFinite();
}

bool GradientFlowModel::solveLinearized(const double* x, double a, const double* b, double* k) {
  const int n = segments();
  const int mh = heldCount(), m = constraintCount(), s = selfCount(), p = m + 2 * s;
  if (!(a > 0.0)) return false;
  if (p > ChainStructure::kMaxBorder) return solveLinearizedDense(x, a, b, k);
  Eigen::Map<const Vector> q(x, n), bq(b, n);
  Eigen::Map<Vector> kq(k, n);
  // q̇ and the reactions r at x (kinematics, J_h and A = J_h J_hᵀ as the flow uses them). The
  // Jacobian of (D1) is J̃ = −(P H_r + κ_h J_h⁺J_h − J_h⁺E)/c with H_r the Hessian of Π under the
  // end wrench F_l + r (the reactions load the chain like end forces: eq 26–27) and the rows
  // E_k = −c (∇²p_k q̇)ᵀ (from differentiating J_h in r = A⁻¹(J_h∇Π − κ_h h)).
  // A Rosenbrock step solves its stages at one x and a: factor once, reuse (the key is x and a).
  const bool cached = factoredFor_ == a && lastState_.size() == n + 1 &&
                      std::equal(x, x + n + 1, lastState_.data());
  if (!cached) {
    factoredFor_ = std::numeric_limits<double>::quiet_NaN();
    velocity(x, qdot_);
    Wrench total = loads_;
    for (int j = 0; j < mh; ++j) total[held_[size_t(j)]] += r_[j];
    // H_r = U T Uᵀ from the statics velocity() evaluated (K_q and the kinematics at q)
    loadHessianGenerator(data_, total, structure_.h);
    subtractBodyGenerator(structure_.h);
    // the wall forces' −Σ μ_v ∂²x_v and the self contacts' −Σ μ ∂²g: the generator h gains −μ g
    // (wall_contact.h, self_contact.h; the self contacts' rank-2 part is bordered below)
    for (int k = 0; k < wallCount() + s; ++k) structure_.h -= r_[wallRowBegin() + k] * wallGen_.col(k);
    structure_.kappa = stiffness_;
    assemble(structure_.kappa, structure_.h, structure_);
    // (I − aJ̃) k = b with s = a/c: (I + s(P H_r + κ_h J_h⁺J_h − J_h⁺E)) k = b. With
    // y = s A⁻¹(J_h(κ_h − H_r) − E) k this is (I + sH_r) k + J_hᵀ y = b, A y + s (J_h(H_r − κ_h I) + E) k
    // = 0; dividing the first row by s (y' = y/s):
    //   [[H_r + I/s, J_hᵀ], [J_h (H_r − κ_h I) + E, A]] [k; y'] = [b/s; 0].
    // A self contact's rank-2 part R = U D Uᵀ of H_r (U = [c, w], D = −μ[[0, 1], [1, 0]]) is
    // bordered with z = Uᵀk: columns U D beside J_hᵀ, rows Uᵀk − z = 0, and J_h R k = (J_h U D) z.
    if (m > 0) {
      V_.leftCols(m) = Jh_.transpose();
      for (int j = 0; j < m; ++j) {
        applyHessian(structure_, V_.col(j), W_.col(j));
        W_.col(j) -= kappaH_ * V_.col(j);
        if (j >= mh && j < wallRowBegin()) continue;  // a locked joint's row e_iᵀ is constant: no E term
        if (j < mh) applyEndHessian(data_, held_[size_t(j)], qdot_, tmpN_);
        else applyNegativeGenerator(wallGen_.col(j - wallRowBegin()), qdot_, tmpN_);  // ∇²x_v q̇, −G(γ)q̇
        if (j >= selfRowBegin()) {  // ∇²g q̇ = −G(γ)q̇ + c (wᵀq̇) + w (cᵀq̇)
          const auto c = selfCoupling_.col(j - selfRowBegin()), w = selfWeights_.col(j - selfRowBegin());
          tmpN_ += c * w.dot(qdot_) + w * c.dot(qdot_);
        }
        W_.col(j) -= c_ * tmpN_;
      }
    }
    factoredA_.setZero(p, p);
    factoredA_.topLeftCorner(m, m) = A_;
    for (int k = 0; k < s; ++k) {
      const double mu = r_[selfRowBegin() + k];
      const auto c = selfCoupling_.col(k), w = selfWeights_.col(k);
      V_.col(m + 2 * k) = -mu * w;
      V_.col(m + 2 * k + 1) = -mu * c;
      W_.col(m + 2 * k) = c;
      W_.col(m + 2 * k + 1) = w;
      factoredA_.block(0, m + 2 * k, m, 2).noalias() = Jh_ * V_.middleCols(m + 2 * k, 2);
      factoredA_.block(m + 2 * k, m + 2 * k, 2, 2) = -Eigen::Matrix2d::Identity();
    }
    // H_r + σI is the chain structure of K_q + σI (U (T + σM) Uᵀ, chain_structure.h)
    shifted_ = structure_.kappa.array() + c_ / a;
    assemble(shifted_, structure_.h, structure_);
    // (own copies: rhs() between the stages overwrites A_ and qdot_ at other states)
    factoredQdot_ = qdot_;
    if (!factorBordered(structure_, V_, W_, factoredA_)) return false;
    factoredFor_ = a;
    lastState_ = Eigen::Map<const Vector>(x, n + 1);
  }
  scaledRhs_ = (c_ / a) * bq;
  const bool ok = solveFactoredBordered(structure_, V_, W_, factoredA_, scaledRhs_, zeroM_, kq, y_);
  // the dissipated energy's row: d(c|q̇|²)/dq = 2c q̇ᵀ J̃ and aJ̃ k_q = k_q − b_q
  k[n] = b[n] + 2.0 * c_ * factoredQdot_.dot(kq - bq);
  return ok && kq.allFinite() && std::isfinite(k[n]);
}

}  // namespace buckle::mechanics
