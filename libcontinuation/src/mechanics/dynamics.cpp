// The dynamics models of dynamics.h: scene data, the common statics, the gradient flow (D1) and
// the inertial model (D2). Their integration (simulate) is in dynamics_integration.cpp.
#include "buckle/mechanics/dynamics.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace buckle::mechanics {

namespace {

std::atomic<long> inertialModelsConstructed{0};

bool fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

bool finite(double v) { return std::isfinite(v); }

/// out = ∇²p_c v for the end coordinate c: ∂²x/∂q_i∂q_j = −C_max(i,j), ∂²y/∂q_i∂q_j = −S_max(i,j)
/// (eq 26–27), ∂²φ = 0; as (G v)_i = g_i Σ_{j≤i} v_j + Σ_{j>i} g_j v_j, O(n).
void applyEndHessian(const ChainData& data, int c, ConstVectorRef v, VectorRef out) {
  const Eigen::Index n = v.size();
  if (c == static_cast<int>(EndCoordinate::Phi)) {
    out.setZero();
    return;
  }
  const Vector& g = c == 0 ? data.C : data.S;
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

}  // namespace

// ---- scene data ------------------------------------------------------------------------------

InertiaData InertiaData::uniformRods(const Chain& chain, double massPerLength) {
  InertiaData data;
  const Vector& l = chain.linkLengths();
  for (int i = 0; i < chain.size(); ++i) {
    LinkInertia link;
    link.mass = massPerLength * l[i + 1];
    link.inertia = link.mass * l[i + 1] * l[i + 1] / 12.0;
    link.comOffset = 0.5 * l[i + 1];
    data.links.push_back(link);
  }
  return data;
}

InertiaData InertiaData::uniform(const Chain& chain, double mass, double inertia) {
  InertiaData data;
  for (int i = 0; i < chain.size(); ++i) {
    LinkInertia link;
    link.mass = mass;
    link.inertia = inertia;
    data.links.push_back(link);
  }
  return data;
}

bool InertiaData::IsValid(const Chain& chain, std::string* why) const {
  const int n = chain.size();
  if (static_cast<int>(links.size()) != n)
    return fail(why, "inertia: " + std::to_string(links.size()) + " links given, the chain has " +
                         std::to_string(n) + " moving links");
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = links[size_t(i)];
    const std::string name = "inertia link " + std::to_string(i + 1) + ": ";
    if (!finite(L.mass) || !(L.mass > 0.0)) return fail(why, name + "mass must be > 0");
    if (!finite(L.inertia) || L.inertia < 0.0) return fail(why, name + "inertia must be >= 0");
    const double len = chain.linkLengths()[i + 1];
    if (!std::isnan(L.comOffset) && (!finite(L.comOffset) || L.comOffset < 0.0 || L.comOffset > len))
      return fail(why, name + "comOffset must lie in [0, link length]");
    const double d = std::isnan(L.comOffset) ? 0.5 * len : L.comOffset;
    // Link i's own angular rate is seen by the kinetic energy only through m d² + I: a link with
    // both zero would make M singular.
    if (!(L.mass * d * d + L.inertia > 0.0)) return fail(why, name + "m d² + I must be > 0 (singular mass matrix)");
  }
  return true;
}

bool DynamicsScene::IsValid(const Chain& chain, std::string* why) const {
  if (!finite(flowDamping) || !(flowDamping > 0.0)) return fail(why, "flowDamping must be > 0");
  if (!jointDamping.empty() && static_cast<int>(jointDamping.size()) != chain.size())
    return fail(why, "jointDamping must be empty or have one entry per joint (" + std::to_string(chain.size()) + ")");
  for (size_t i = 0; i < jointDamping.size(); ++i)
    if (!finite(jointDamping[i]) || jointDamping[i] < 0.0)
      return fail(why, "jointDamping[" + std::to_string(i) + "] must be >= 0");
  if (!finite(constraintStiffness)) return fail(why, "constraintStiffness must be finite");
  if (!finite(baumgarteRate)) return fail(why, "baumgarteRate must be finite");
  if (inertia && !inertia->IsValid(chain, why)) return false;
  return true;
}

// ---- common part -----------------------------------------------------------------------------

DynamicsModel::DynamicsModel(const Chain& chain, const EndCondition& end)
    : chain_(chain),
      end_(end),
      lengthUnit_(0.0),
      torqueUnit_(0.0),
      held_(end.heldIndices()),
      loaded_(end.loadedIndices()),
      sides_(size_t(chain.size()), 0),
      loads_(Wrench::Zero()),
      data_(chain),
      J_(3, chain.size()),
      grad_(chain.size()),
      stiffness_(chain.size()),
      staticsQ_(chain.size()),
      sinHalf_(chain.size()),
      cosHalf_(chain.size()),
      Jh_(end.heldCount(), chain.size()),
      h_(end.heldCount()),
      A_(end.heldCount(), end.heldCount()),
      llt_(end.heldCount()),
      r_(end.heldCount()),
      tmpM_(end.heldCount()),
      tmpN_(chain.size()) {
  for (int c = 0; c < 3; ++c)
    if (!finite(end.value[c])) throw std::invalid_argument("end condition value " + std::to_string(c) + " must be finite");
  for (int c : loaded_) loads_[c] = end.value[c];
  llt_.compute(Matrix::Identity(heldCount(), heldCount()));  // defines its status flag
  double b = 0.0, k = 0.0;
  for (int i = 0; i < chain.size(); ++i) {
    b += 0.5 * (chain.segment(i).parameters().b1 + chain.segment(i).parameters().b2);
    k += 0.5 * (chain.segment(i).parameters().k1 + chain.segment(i).parameters().k2);
  }
  lengthUnit_ = b / chain.size();
  torqueUnit_ = k / chain.size() * lengthUnit_ * lengthUnit_;
}

void DynamicsModel::evaluateStatics(ConstVectorRef q) {
  const int n = segments();
  if (staticsValid_ && std::equal(q.data(), q.data() + n, staticsQ_.data())) return;
  staticsValid_ = false;
  // E, ∂E/∂q, K_q and the kinematics from one sincos per joint: the springs' half angles also
  // give the link directions (forwardKinematics from half angles, chain.h).
  springEnergy_ = 0.0;
  for (int i = 0; i < n; ++i) {
    const double sh = std::sin(0.5 * q[i]), ch = std::cos(0.5 * q[i]);  // one sincos call at -O2
    sinHalf_[i] = sh;
    cosHalf_[i] = ch;
    const Jet3 e = chain_.segment(i).energyJet(q[i], sh, ch);
    springEnergy_ += e.value;
    grad_[i] = e.d1;
    stiffness_[i] = e.d2;
  }
  forwardKinematics(chain_, q, sinHalf_.data(), cosHalf_.data(), data_);
  endJacobian(data_, J_);
  // ∇Π = ∂E/∂q − J_lᵀ F_l (eq 9, loads_ zero on held coordinates; J rows (−S, C, 1))
  for (int i = 0; i < n; ++i) grad_[i] = grad_[i] + loads_[0] * data_.S[i] - loads_[1] * data_.C[i] - loads_[2];
  staticsQ_ = q;
  staticsValid_ = true;
  const int mh = heldCount(), m = constraintCount();
  if (m == 0) return;
  for (int k = 0; k < mh; ++k) {
    const int c = held_[size_t(k)];
    Jh_.row(k) = J_.row(c);
    h_[k] = data_.pose[c] - end_.value[c];
  }
  // locked joints: rows e_iᵀ, h = q_i − q̄_i (Jh_ holds their zeros since setContacts)
  for (int k = mh; k < m; ++k) {
    const int i = locked_[size_t(k - mh)];
    h_[k] = q[i] - limitAngle(i, sides_[size_t(i)]);
  }
  A_.noalias() = Jh_ * Jh_.transpose();
  // J_h loses rank where the held coordinate is stationary (x held on the straight chain): a
  // relative 1e-12 shift keeps the factorization defined and is invisible at regular points.
  // (Not on the locked rows: unit rows, and the shift would let a locked joint creep.)
  if (mh > 0)
    A_.diagonal().head(mh).array() += 1e-12 * std::max(lengthUnit_ * lengthUnit_, A_.topLeftCorner(mh, mh).trace());
  llt_.compute(A_);
}

double DynamicsModel::potential(ConstVectorRef q) {
  evaluateStatics(q);
  return springEnergy_ - loads_.dot(data_.pose);
}

void DynamicsModel::potentialGradient(ConstVectorRef q, VectorRef g) {
  evaluateStatics(q);
  g = grad_;
}

double DynamicsModel::equilibriumResidual(ConstVectorRef q) {
  evaluateStatics(q);
  if (constraintCount() == 0) return grad_.cwiseAbs().maxCoeff();
  // P∇Π = ∇Π − J_hᵀ r with the least-squares reactions r = (J_h J_hᵀ)⁻¹ J_h ∇Π.
  tmpM_.noalias() = Jh_ * grad_;
  llt_.solveInPlace(tmpM_);
  tmpN_ = grad_;
  tmpN_.noalias() -= Jh_.transpose() * tmpM_;
  return std::max(tmpN_.cwiseAbs().maxCoeff(), h_.cwiseAbs().maxCoeff());
}

double DynamicsModel::naturalResidual(ConstVectorRef q) {
  const double raw = equilibriumResidual(q);  // fills grad_ / tmpN_ and h_
  if (constraintCount() == 0) return raw / torqueUnit_;
  const int mh = heldCount();
  // held rows in lengths, locked rows in radians (their own unit)
  double h = mh > 0 ? h_.head(mh).cwiseAbs().maxCoeff() / lengthUnit_ : 0.0;
  if (lockedCount() > 0) h = std::max(h, h_.tail(lockedCount()).cwiseAbs().maxCoeff());
  return std::max(tmpN_.cwiseAbs().maxCoeff() / torqueUnit_, h);
}

double DynamicsModel::constraintViolation(ConstVectorRef q) {
  if (heldCount() == 0) return 0.0;
  evaluateStatics(q);
  double v = 0.0;
  for (int c : held_) v = std::max(v, std::abs(data_.pose[c] - end_.value[c]));
  return v;
}

bool DynamicsModel::projectOntoConstraints(VectorRef q, double tolerance, int maxIterations) {
  if (constraintCount() == 0) return true;
  for (int it = 0; it <= maxIterations; ++it) {
    evaluateStatics(q);
    if (h_.cwiseAbs().maxCoeff() <= tolerance * std::max(1.0, lengthUnit_)) return true;
    if (it == maxIterations) break;
    // Minimum-norm Gauss–Newton correction δq = −J_hᵀ (J_h J_hᵀ)⁻¹ h.
    tmpM_ = h_;
    llt_.solveInPlace(tmpM_);
    q.noalias() -= Jh_.transpose() * tmpM_;
  }
  return false;
}

bool DynamicsModel::withinLimits(ConstVectorRef q) const {
  for (int i = 0; i < segments(); ++i)
    if (sides_[size_t(i)] == 0 && !(q[i] > chain_.lowerLimits()[i] && q[i] < chain_.upperLimits()[i])) return false;
  return true;
}

double DynamicsModel::limitAngle(int joint, int side) const {
  return side > 0 ? chain_.upperLimits()[joint] : chain_.lowerLimits()[joint];
}

void DynamicsModel::setContacts(const std::vector<int>& sides) {
  const int n = segments();
  if (static_cast<int>(sides.size()) != n)
    throw std::invalid_argument("contact sides: " + std::to_string(sides.size()) + " entries for " + std::to_string(n) + " joints");
  for (int s : sides)
    if (s < -1 || s > 1) throw std::invalid_argument("contact sides must be -1, 0 or +1");
  sides_ = sides;
  staticsValid_ = false;  // h_ and the rows depend on the contact set
  locked_.clear();
  for (int i = 0; i < n; ++i)
    if (sides_[size_t(i)] != 0) locked_.push_back(i);
  const int mh = heldCount(), m = constraintCount();
  Matrix held = Jh_.topRows(mh);
  Jh_ = Matrix::Zero(m, n);
  Jh_.topRows(mh) = held;
  for (int k = mh; k < m; ++k) Jh_(k, locked_[size_t(k - mh)]) = 1.0;
  h_ = Vector::Zero(m);
  A_ = Matrix::Identity(m, m);
  llt_.compute(A_);
  r_ = Vector::Zero(m);
  tmpM_ = Vector::Zero(m);
  resizeConstraints();
}

void DynamicsModel::contactTorques(const double* x, VectorRef torques) {
  torques.setZero();
  if (locked_.empty()) return;
  fdPlus_.resize(size_t(stateSize()));
  rhs(x, fdPlus_.data());  // the multipliers r_ at x
  for (int k = 0; k < lockedCount(); ++k) torques[locked_[size_t(k)]] = r_[heldCount() + k];
}

double DynamicsModel::restSpeed(const double* x) {
  tmpN_.resize(segments());
  velocity(x, tmpN_);
  return tmpN_.cwiseAbs().maxCoeff();
}

double DynamicsModel::impact(double* x) {
  for (int i : locked_) x[i] = limitAngle(i, sides_[size_t(i)]);
  return 0.0;
}

void DynamicsModel::jacobian(const double* x, double* jacobianRowMajor) {
  // Central differences of the analytic right-hand side, step ~ ε^{1/3} scaled to the entry:
  // the stiff stepper only needs its W = I − γhJ to be a good preconditioner-quality matrix;
  // the accuracy of the solution is set by the error control on rhs().
  const int N = stateSize();
  fdState_.assign(x, x + N);
  fdPlus_.resize(size_t(N));
  fdMinus_.resize(size_t(N));
  for (int j = 0; j < N; ++j) {
    const double h = 6e-6 * std::max(1.0, std::abs(x[j]));
    fdState_[size_t(j)] = x[j] + h;
    rhs(fdState_.data(), fdPlus_.data());
    fdState_[size_t(j)] = x[j] - h;
    rhs(fdState_.data(), fdMinus_.data());
    fdState_[size_t(j)] = x[j];
    for (int i = 0; i < N; ++i) jacobianRowMajor[i * N + j] = (fdPlus_[size_t(i)] - fdMinus_[size_t(i)]) / (2.0 * h);
  }
}

bool DynamicsModel::solveLinearized(const double*, double, const double*, double*) { return false; }

// ---- gradient flow (D1) ---------------------------------------------------------------------

GradientFlowModel::GradientFlowModel(const Chain& chain, const EndCondition& end, const DynamicsScene& scene,
                                     ConstVectorRef q0)
    : DynamicsModel(chain, end), c_(scene.flowDamping), kappaH_(scene.constraintStiffness),
      H_(chain.size(), chain.size()), qdot_(chain.size()), structure_(chain.size()), shifted_(chain.size()),
      scaledRhs_(chain.size()), y_(end.heldCount()), zeroM_(Vector::Zero(end.heldCount())),
      V_(chain.size(), end.heldCount()), W_(chain.size(), end.heldCount()) {
  // (held rows only until setContacts() adds locked joints: resizeConstraints())
  if (!finite(c_) || !(c_ > 0.0)) throw std::invalid_argument("flowDamping must be > 0");
  if (q0.size() != chain.size()) throw std::invalid_argument("q0 must have one entry per joint");
  if (!(kappaH_ > 0.0)) {
    Vector kq(chain.size());
    jointStiffness(chain_, q0, kq);
    kappaH_ = 10.0 * std::max(torqueUnit_, kq.cwiseAbs().maxCoeff());
  }
}

void GradientFlowModel::resizeConstraints() {
  const int m = constraintCount();
  y_ = Vector::Zero(m);
  zeroM_ = Vector::Zero(m);
  V_.resize(segments(), m);
  W_.resize(segments(), m);
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
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jac(jacobianRowMajor, N, N);
  Jac.setZero();
  Jac.topLeftCorner(n, n) = -H_ / c_;
  tmpN_.noalias() = H_ * qdot_;
  Jac.bottomLeftCorner(1, n) = -2.0 * tmpN_.transpose();
}

bool GradientFlowModel::solveLinearized(const double* x, double a, const double* b, double* k) {
  const int n = segments();
  const int mh = heldCount(), m = constraintCount();
  if (!(a > 0.0)) return false;
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
    structure_.kappa = stiffness_;
    assemble(structure_.kappa, structure_.h, structure_);
    // (I − aJ̃) k = b with s = a/c: (I + s(P H_r + κ_h J_h⁺J_h − J_h⁺E)) k = b. With
    // y = s A⁻¹(J_h(κ_h − H_r) − E) k this is (I + sH_r) k + J_hᵀ y = b, A y + s (J_h(H_r − κ_h I) + E) k
    // = 0; dividing the first row by s (y' = y/s):
    //   [[H_r + I/s, J_hᵀ], [J_h (H_r − κ_h I) + E, A]] [k; y'] = [b/s; 0].
    if (m > 0) {
      V_ = Jh_.transpose();
      for (int j = 0; j < m; ++j) {
        applyHessian(structure_, V_.col(j), W_.col(j));
        W_.col(j) -= kappaH_ * V_.col(j);
        if (j >= mh) continue;  // a locked joint's row e_iᵀ is constant: no E term
        applyEndHessian(data_, held_[size_t(j)], qdot_, tmpN_);
        W_.col(j) -= c_ * tmpN_;
      }
    }
    // H_r + σI is the chain structure of K_q + σI (U (T + σM) Uᵀ, chain_structure.h)
    shifted_ = structure_.kappa.array() + c_ / a;
    assemble(shifted_, structure_.h, structure_);
    // (own copies: rhs() between the stages overwrites A_ and qdot_ at other states)
    factoredA_ = A_;
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

// ---- inertial (D2) ---------------------------------------------------------------------------
//
// O(n) mass matrix. In absolute angles θ = T q, M_θ(i, i) = a_i = μ_ii and, for i > j,
// M_θ(i, j) = ℓ_j w_i cos(θ_i − θ_j) = p_iᵀ r_j with p_i = w_i (cos θ_i, sin θ_i),
// r_j = ℓ_j (cos θ_j, sin θ_j): a diagonal-plus-semiseparable matrix of rank 2. Its LDLᵀ keeps
// that structure, L(i, j) = p_iᵀ g_j (i > j), with 2-vectors g_j and pivots d_j from
//     P_0 = 0,  d_j = a_j − p_jᵀ P_j p_j,  g_j = (r_j − P_j p_j) / d_j,  P_{j+1} = P_j + d_j g_j g_jᵀ
// (equate L D Lᵀ with M_θ column by column; P_j = Σ_{k<j} d_k g_k g_kᵀ), and the solves are two
// sweeps with 2-vector accumulators. M = Tᵀ M_θ T, so M⁻¹ f = T⁻¹ M_θ⁻¹ T⁻ᵀ f with T⁻ᵀ, T⁻¹
// differences. The velocity terms and the kinetic energy are prefix and suffix sums of the same
// generators. Everything the model does per right-hand side is O(n m).

InertialModel::InertialModel(const Chain& chain, const EndCondition& end, const InertiaData& inertia,
                             const std::vector<double>& jointDamping, double baumgarteRate, ConstVectorRef q0)
    : DynamicsModel(chain, end) {
  const int n = chain.size();
  const int m = heldCount();
  std::string why;
  if (!inertia.IsValid(chain, &why)) throw std::invalid_argument(why);
  if (!jointDamping.empty() && static_cast<int>(jointDamping.size()) != n)
    throw std::invalid_argument("jointDamping must be empty or have one entry per joint");
  if (q0.size() != n) throw std::invalid_argument("q0 must have one entry per joint");
  if (!finite(baumgarteRate)) throw std::invalid_argument("baumgarteRate must be finite");
  ++inertialModelsConstructed;

  const Vector& l = chain.linkLengths();
  mass_.resize(n);
  inertia_.resize(n);
  com_.resize(n);
  d_ = Vector::Zero(n);
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = inertia.links[size_t(i)];
    mass_[i] = L.mass;
    inertia_[i] = L.inertia;
    com_[i] = std::isnan(L.comOffset) ? 0.5 * l[i + 1] : L.comOffset;
    if (!jointDamping.empty()) {
      if (!finite(jointDamping[size_t(i)]) || jointDamping[size_t(i)] < 0.0)
        throw std::invalid_argument("jointDamping[" + std::to_string(i) + "] must be >= 0");
      d_[i] = jointDamping[size_t(i)];
    }
  }
  tailMass_ = Vector::Zero(n);
  for (int i = n - 2; i >= 0; --i) tailMass_[i] = tailMass_[i + 1] + mass_[i + 1];
  // μ_ij of the kinetic energy ½ Σ μ_ij cos(θ_i − θ_j) θ̇_i θ̇_j (see dynamics.h): link k's
  // centre of mass moves with ℓ_p θ̇_p for every link p before it and d_k θ̇_k for itself, so
  // μ_ii = I_i + m_i d_i² + ℓ_i² Σ_{k>i} m_k and μ_ij = ℓ_i w_j (i < j), w_j = m_j d_j + ℓ_j Σ_{k>j} m_k.
  muDiag_.resize(n);
  w_.resize(n);
  len_ = l.tail(n);
  for (int i = 0; i < n; ++i) {
    const double li = l[i + 1];
    muDiag_[i] = inertia_[i] + mass_[i] * com_[i] * com_[i] + li * li * tailMass_[i];
    w_[i] = mass_[i] * com_[i] + li * tailMass_[i];
  }
  cos_.resize(n);
  sin_.resize(n);
  pivot_.resize(n);
  gen_.resize(n, 2);
  massQ_.resize(n);
  thetaDot_.resize(n);
  cTheta_.resize(n);
  f_.resize(n);
  acc_.resize(n);
  B_.resize(n, m);
  S_.resize(m, m);
  sllt_.compute(Matrix::Identity(m, m));

  timeUnit_ = std::sqrt(muDiag_.mean() / torqueUnit_);
  omega_ = baumgarteRate;
  if (!(omega_ > 0.0)) {
    // Ten times the fastest uncoupled joint frequency √(|∂²Π/∂q_i²| / M_ii): the constraint
    // error then decays faster than anything the chain does, without making the ODE much stiffer.
    // H_ii = K_q,ii − h_i (eq 27); M_ii = Σ_{k,l≥i} M_θ(k, l) by a suffix recursion.
    evaluateStatics(q0);
    factorMass(q0);
    Vector h(n);
    loadHessianGenerator(data_, loads_, h);
    double w = 0.0, tail = 0.0, tailC = 0.0, tailS = 0.0;
    for (int i = n - 1; i >= 0; --i) {
      tail += muDiag_[i] + 2.0 * len_[i] * (cos_[i] * tailC + sin_[i] * tailS);
      tailC += w_[i] * cos_[i];
      tailS += w_[i] * sin_[i];
      w = std::max(w, std::sqrt(std::abs(stiffness_[i] - h[i]) / tail));
    }
    omega_ = 10.0 * (w > 0.0 ? w : 1.0);
  }
}

long InertialModel::constructedCount() { return inertialModelsConstructed.load(); }

bool InertialModel::factorMass(ConstVectorRef q) {
  const int n = segments();
  evaluateStatics(q);
  if (massFactored_ && std::equal(q.data(), q.data() + n, massQ_.data())) return true;
  massFactored_ = false;
  for (int i = 0; i < n; ++i) {
    cos_[i] = std::cos(data_.theta[i]);
    sin_[i] = std::sin(data_.theta[i]);
  }
  double P00 = 0.0, P01 = 0.0, P11 = 0.0;  // P_j (symmetric 2×2)
  bool positive = true;
  for (int j = 0; j < n; ++j) {
    const double p0 = w_[j] * cos_[j], p1 = w_[j] * sin_[j];
    const double Pp0 = P00 * p0 + P01 * p1, Pp1 = P01 * p0 + P11 * p1;
    const double d = muDiag_[j] - (p0 * Pp0 + p1 * Pp1);
    if (!(d > 0.0)) positive = false;
    const double g0 = (len_[j] * cos_[j] - Pp0) / d, g1 = (len_[j] * sin_[j] - Pp1) / d;
    pivot_[j] = d;
    gen_(j, 0) = g0;
    gen_(j, 1) = g1;
    P00 += d * g0 * g0;
    P01 += d * g0 * g1;
    P11 += d * g1 * g1;
  }
  massQ_ = q;
  massFactored_ = positive;
  return positive;
}

void InertialModel::solveMass(VectorRef f) const {
  const int n = segments();
  // T⁻ᵀ f (T lower-triangular ones: Tᵀ is a suffix sum, its inverse a difference)
  for (int i = 0; i + 1 < n; ++i) f[i] -= f[i + 1];
  // L y = f, then D, then Lᵀ x = z (L(i, j) = p_iᵀ g_j)
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double y = f[i] - w_[i] * (cos_[i] * s0 + sin_[i] * s1);
    s0 += gen_(i, 0) * y;
    s1 += gen_(i, 1) * y;
    f[i] = y / pivot_[i];
  }
  double t0 = 0.0, t1 = 0.0;
  for (int j = n - 1; j >= 0; --j) {
    const double x = f[j] - (gen_(j, 0) * t0 + gen_(j, 1) * t1);
    t0 += w_[j] * cos_[j] * x;
    t1 += w_[j] * sin_[j] * x;
    f[j] = x;
  }
  // T⁻¹ α: q̈_i = α_i − α_{i−1}
  for (int i = n - 1; i > 0; --i) f[i] -= f[i - 1];
}

void InertialModel::massMatrix(ConstVectorRef q, MatrixRef M) {
  const int n = segments();
  evaluateStatics(q);
  // M_θ dense from its generators, then M = Tᵀ M_θ T by suffix sums along rows and columns
  for (int j = 0; j < n; ++j) {
    const double cj = std::cos(data_.theta[j]), sj = std::sin(data_.theta[j]);
    M(j, j) = muDiag_[j];
    for (int i = j + 1; i < n; ++i)
      M(i, j) = M(j, i) = len_[j] * w_[i] * (std::cos(data_.theta[i]) * cj + std::sin(data_.theta[i]) * sj);
  }
  for (int j = n - 2; j >= 0; --j) M.col(j) += M.col(j + 1);
  for (int i = n - 2; i >= 0; --i) M.row(i) += M.row(i + 1);
  // the two sweeps add in different orders above and below the diagonal: symmetric to the last bit
  for (int j = 1; j < n; ++j)
    for (int i = 0; i < j; ++i) M(i, j) = M(j, i);
}

void InertialModel::velocityTerms(ConstVectorRef q, ConstVectorRef qdot, VectorRef c) {
  const int n = segments();
  factorMass(q);
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    s += qdot[i];
    thetaDot_[i] = s;
  }
  // Lagrange in absolute angles: c_θ,i = Σ_j μ_ij sin(θ_i − θ_j) θ̇_j², split at j = i:
  //   j < i: μ_ij = ℓ_j w_i → w_i (sin θ_i A_c − cos θ_i A_s), A = Σ_{j<i} ℓ_j (cos θ_j, sin θ_j) θ̇_j²
  //   j > i: μ_ij = ℓ_i w_j → ℓ_i (sin θ_i B_c − cos θ_i B_s), B = Σ_{j>i} w_j (cos θ_j, sin θ_j) θ̇_j²
  double ac = 0.0, as = 0.0;
  for (int i = 0; i < n; ++i) {
    cTheta_[i] = w_[i] * (sin_[i] * ac - cos_[i] * as);
    const double e = len_[i] * thetaDot_[i] * thetaDot_[i];
    ac += e * cos_[i];
    as += e * sin_[i];
  }
  double bc = 0.0, bs = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    cTheta_[i] += len_[i] * (sin_[i] * bc - cos_[i] * bs);
    const double e = w_[i] * thetaDot_[i] * thetaDot_[i];
    bc += e * cos_[i];
    bs += e * sin_[i];
  }
  double acc = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    acc += cTheta_[i];
    c[i] = acc;
  }
}

void InertialModel::centresOfMass(ConstVectorRef q, Eigen::Ref<Eigen::Matrix2Xd> G) const {
  const Vector& l = chain_.linkLengths();
  double px = l[0], py = 0.0, theta = 0.0;
  for (int i = 0; i < segments(); ++i) {
    theta += q[i];
    G(0, i) = px + com_[i] * std::cos(theta);
    G(1, i) = py + com_[i] * std::sin(theta);
    px += l[i + 1] * std::cos(theta);
    py += l[i + 1] * std::sin(theta);
  }
}

void InertialModel::resizeConstraints() {
  const int m = constraintCount();
  B_.resize(segments(), m);
  S_.resize(m, m);
  sllt_.compute(Matrix::Identity(m, m));
}

double InertialModel::impact(double* x) {
  DynamicsModel::impact(x);
  const int n = segments();
  const int m = constraintCount();
  if (m == 0) return 0.0;
  Eigen::Map<const Vector> q(x, n);
  Eigen::Map<Vector> v(x + n, n);
  const double before = kineticEnergy(x);  // also the factored mass matrix at q
  evaluateStatics(q);                     // the constraint rows C = Jh_ at q
  // Inelastic impact: the admissible velocity nearest in the kinetic metric,
  // q̇⁺ = q̇⁻ − M⁻¹Cᵀ(CM⁻¹Cᵀ)⁻¹C q̇⁻ (C q̇⁺ = 0: locked joints stop, held coordinates stay held).
  B_ = Jh_.transpose();
  for (int k = 0; k < m; ++k) solveMass(B_.col(k));
  S_.noalias() = Jh_ * B_;
  sllt_.compute(S_);
  tmpM_.noalias() = Jh_ * v;
  sllt_.solveInPlace(tmpM_);
  v.noalias() -= B_ * tmpM_;
  const double lost = std::max(0.0, before - kineticEnergy(x));
  x[2 * n] += lost;
  return lost;
}

void InertialModel::packState(ConstVectorRef q, ConstVectorRef qdot, VectorRef x) const {
  const int n = segments();
  x.head(n) = q;
  if (qdot.size() == n) x.segment(n, n) = qdot;
  else x.segment(n, n).setZero();
  x[2 * n] = 0.0;
}

void InertialModel::velocity(const double* x, VectorRef qdot) { qdot = Eigen::Map<const Vector>(x + segments(), segments()); }

double InertialModel::kineticEnergy(const double* x) {
  const int n = segments();
  Eigen::Map<const Vector> q(x, n), v(x + n, n);
  factorMass(q);
  // K = ½ θ̇ᵀ M_θ θ̇ = ½ Σ a_i θ̇_i² + Σ_i w_i θ̇_i (cos θ_i, sin θ_i)·Σ_{j<i} ℓ_j θ̇_j (cos θ_j, sin θ_j)
  double k = 0.0, omega = 0.0, ac = 0.0, as = 0.0;
  for (int i = 0; i < n; ++i) {
    omega += v[i];
    k += 0.5 * muDiag_[i] * omega * omega + w_[i] * omega * (cos_[i] * ac + sin_[i] * as);
    ac += len_[i] * omega * cos_[i];
    as += len_[i] * omega * sin_[i];
  }
  return k;
}

void InertialModel::rhs(const double* x, double* dxdt) {
  const int n = segments();
  const int mh = heldCount(), m = constraintCount();
  Eigen::Map<const Vector> q(x, n), v(x + n, n);
  evaluateStatics(q);  // kinematics, ∇Π, J_h, h
  velocityTerms(q, v, f_);  // c(q, q̇) into f_ (the factored mass matrix and θ̇ as by-products)
  // (D2) right-hand side f = −c − D q̇ − ∇Π.
  f_ = -f_;
  f_.array() -= d_.array() * v.array() + grad_.array();
  acc_ = f_;
  solveMass(acc_);
  if (m > 0) {
    // Index-1 form with Baumgarte stabilization: J_h q̈ = γ, γ = −J̇_h q̇ − 2ω J_h q̇ − ω² h, so
    // ḧ + 2ω ḣ + ω² h = 0 and drift decays critically damped. Schur complement of the KKT
    // system: q̈ = M⁻¹(f + J_hᵀ r), (J_h M⁻¹ J_hᵀ) r = γ − J_h M⁻¹ f.
    const Vector& l = chain_.linkLengths();
    for (int k = 0; k < m; ++k) {
      const int c = k < mh ? held_[size_t(k)] : -1;
      // J̇_h q̇: ẍ = −Σ ℓ_i (cos θ_i θ̇_i² + sin θ_i θ̈_i), ÿ = −Σ ℓ_i (sin θ_i θ̇_i² − cos θ_i θ̈_i), φ̈ = Σ q̈.
      double jdot = 0.0;  // 0 for a locked joint's constant row e_iᵀ
      if (k < mh && c != static_cast<int>(EndCoordinate::Phi))
        for (int i = 0; i < n; ++i)
          jdot -= l[i + 1] * (c == 0 ? cos_[i] : sin_[i]) * thetaDot_[i] * thetaDot_[i];
      tmpM_[k] = -jdot - 2.0 * omega_ * Jh_.row(k).dot(v) - omega_ * omega_ * h_[k];
    }
    tmpM_.noalias() -= Jh_ * acc_;
    B_ = Jh_.transpose();
    for (int k = 0; k < m; ++k) solveMass(B_.col(k));
    S_.noalias() = Jh_ * B_;
    sllt_.compute(S_);
    sllt_.solveInPlace(tmpM_);
    r_ = tmpM_;
    acc_.noalias() += B_ * r_;
  }
  Eigen::Map<Vector>(dxdt, n) = v;
  Eigen::Map<Vector>(dxdt + n, n) = acc_;
  dxdt[2 * n] = (d_.array() * v.array().square()).sum();  // q̇ᵀ D q̇
}

std::unique_ptr<DynamicsModel> makeDynamicsModel(const Chain& chain, const EndCondition& end,
                                                 const DynamicsScene& scene, ConstVectorRef q0) {
  std::string why;
  if (!scene.IsValid(chain, &why)) throw std::invalid_argument(why);
  if (scene.inertia)
    return std::make_unique<InertialModel>(chain, end, *scene.inertia, scene.jointDamping, scene.baumgarteRate, q0);
  return std::make_unique<GradientFlowModel>(chain, end, scene, q0);
}

}  // namespace buckle::mechanics
