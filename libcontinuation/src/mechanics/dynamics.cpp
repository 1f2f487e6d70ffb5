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
  forwardKinematics(chain_, q, data_);
  endJacobian(data_, J_);
  // ∇Π = ∂E/∂q − J_lᵀ F_l (eq 9); loads_ is zero on held coordinates.
  energyGradient(chain_, q, grad_);
  grad_.noalias() -= J_.transpose() * loads_;
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
  forwardKinematics(chain_, q, data_);
  return energy(chain_, q) - loads_.dot(data_.pose);
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
  forwardKinematics(chain_, q, data_);
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
  Eigen::Map<const Vector> q(x, n);
  velocity(x, qdot_);  // also runs the kinematics for q
  loadMatrix(data_, loads_, H_);
  H_ = -H_;
  jointStiffness(chain_, q, tmpN_);
  H_.diagonal() += tmpN_;
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
    assemble(chain_, data_, q, total, structure_);  // H_r = U T Uᵀ
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
  // centre of mass moves with ℓ_p θ̇_p for every link p before it and d_k θ̇_k for itself.
  mu_.resize(n, n);
  for (int i = 0; i < n; ++i) {
    const double li = l[i + 1];
    mu_(i, i) = inertia_[i] + mass_[i] * com_[i] * com_[i] + li * li * tailMass_[i];
    for (int j = i + 1; j < n; ++j) {
      mu_(i, j) = li * (mass_[j] * com_[j] + l[j + 1] * tailMass_[j]);
      mu_(j, i) = mu_(i, j);
    }
  }
  Mtheta_.resize(n, n);
  M_.resize(n, n);
  cos_.resize(n);
  sin_.resize(n);
  // Size the factorizations once by factoring an identity (copy-assigning an LLT(size) would
  // copy its not-yet-initialized status flag).
  mllt_.compute(Matrix::Identity(n, n));
  thetaDot_.resize(n);
  cTheta_.resize(n);
  f_.resize(n);
  acc_.resize(n);
  B_.resize(n, m);
  S_.resize(m, m);
  sllt_.compute(Matrix::Identity(m, m));

  double meanInertia = 0.0;
  for (int i = 0; i < n; ++i) meanInertia += mu_(i, i) / n;
  timeUnit_ = std::sqrt(meanInertia / torqueUnit_);
  omega_ = baumgarteRate;
  if (!(omega_ > 0.0)) {
    // Ten times the fastest uncoupled joint frequency √(|∂²Π/∂q_i²| / M_ii): the constraint
    // error then decays faster than anything the chain does, without making the ODE much stiffer.
    Matrix H(n, n), M(n, n);
    totalPotentialHessian(chain_, q0, loads_, H);
    massMatrix(q0, M);
    double w = 0.0;
    for (int i = 0; i < n; ++i) w = std::max(w, std::sqrt(std::abs(H(i, i)) / M(i, i)));
    omega_ = 10.0 * (w > 0.0 ? w : 1.0);
  }
}

InertialModel::~InertialModel() = default;

long InertialModel::constructedCount() { return inertialModelsConstructed.load(); }

void InertialModel::computeMassMatrix(ConstVectorRef) {
  const int n = segments();
  for (int i = 0; i < n; ++i) {
    cos_[i] = std::cos(data_.theta[i]);
    sin_[i] = std::sin(data_.theta[i]);
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) Mtheta_(i, j) = mu_(i, j) * (cos_[i] * cos_[j] + sin_[i] * sin_[j]);
  // M = Tᵀ M_θ T with θ = T q, T lower-triangular ones: (M_θ T)(i, j) = Σ_{k≥j} M_θ(i, k) is a
  // suffix sum along each row, and Tᵀ(·) a suffix sum along each column. O(n²), no temporaries.
  M_ = Mtheta_;
  for (int j = n - 2; j >= 0; --j) M_.col(j) += M_.col(j + 1);
  for (int i = n - 2; i >= 0; --i) M_.row(i) += M_.row(i + 1);
  // The two sweeps add in different orders above and below the diagonal; mirror the lower
  // triangle so M is symmetric to the last bit (the kinetic energy sees only the symmetric part).
  for (int j = 1; j < n; ++j)
    for (int i = 0; i < j; ++i) M_(i, j) = M_(j, i);
}

void InertialModel::massMatrix(ConstVectorRef q, MatrixRef M) {
  forwardKinematics(chain_, q, data_);
  computeMassMatrix(q);
  M = M_;
}

void InertialModel::velocityTerms(ConstVectorRef q, ConstVectorRef qdot, VectorRef c) {
  const int n = segments();
  forwardKinematics(chain_, q, data_);
  computeMassMatrix(q);
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    s += qdot[i];
    thetaDot_[i] = s;
  }
  // Lagrange in absolute angles: c_θ,i = Σ_j μ_ij sin(θ_i − θ_j) θ̇_j², then c = Tᵀ c_θ.
  for (int i = 0; i < n; ++i) {
    double ci = 0.0;
    for (int j = 0; j < n; ++j)
      ci += mu_(i, j) * (sin_[i] * cos_[j] - cos_[i] * sin_[j]) * thetaDot_[j] * thetaDot_[j];
    cTheta_[i] = ci;
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
  const double before = kineticEnergy(x);  // also the mass matrix M_ at q
  evaluateStatics(q);                     // the constraint rows C = Jh_ at q
  // Inelastic impact: the admissible velocity nearest in the kinetic metric,
  // q̇⁺ = q̇⁻ − M⁻¹Cᵀ(CM⁻¹Cᵀ)⁻¹C q̇⁻ (C q̇⁺ = 0: locked joints stop, held coordinates stay held).
  mllt_.compute(M_);
  B_ = Jh_.transpose();
  mllt_.solveInPlace(B_);
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
  forwardKinematics(chain_, q, data_);
  computeMassMatrix(q);
  return 0.5 * v.dot(M_ * v);
}

void InertialModel::rhs(const double* x, double* dxdt) {
  const int n = segments();
  const int mh = heldCount(), m = constraintCount();
  Eigen::Map<const Vector> q(x, n), v(x + n, n);
  evaluateStatics(q);  // kinematics, ∇Π, J_h, h
  velocityTerms(q, v, f_);  // c(q, q̇) into f_ (mass matrix and θ̇ as by-products)
  // (D2) right-hand side f = −c − D q̇ − ∇Π.
  f_ = -f_;
  f_.array() -= d_.array() * v.array() + grad_.array();
  mllt_.compute(M_);
  acc_ = f_;
  mllt_.solveInPlace(acc_);
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
    mllt_.solveInPlace(B_);
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
