#include "buckle/mechanics/dynamics.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/ublas/matrix.hpp>
#include <boost/numeric/ublas/vector.hpp>

namespace buckle::mechanics {

namespace {

std::atomic<long> inertialModelsConstructed{0};

bool fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

bool finite(double v) { return std::isfinite(v); }

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
  const int m = heldCount();
  if (m == 0) return;
  for (int k = 0; k < m; ++k) {
    const int c = held_[size_t(k)];
    Jh_.row(k) = J_.row(c);
    h_[k] = data_.pose[c] - end_.value[c];
  }
  A_.noalias() = Jh_ * Jh_.transpose();
  // J_h loses rank where the held coordinate is stationary (x held on the straight chain): a
  // relative 1e-12 shift keeps the factorization defined and is invisible at regular points.
  A_.diagonal().array() += 1e-12 * std::max(lengthUnit_ * lengthUnit_, A_.trace());
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
  if (heldCount() == 0) return grad_.cwiseAbs().maxCoeff();
  // P∇Π = ∇Π − J_hᵀ r with the least-squares reactions r = (J_h J_hᵀ)⁻¹ J_h ∇Π.
  tmpM_.noalias() = Jh_ * grad_;
  llt_.solveInPlace(tmpM_);
  tmpN_ = grad_;
  tmpN_.noalias() -= Jh_.transpose() * tmpM_;
  return std::max(tmpN_.cwiseAbs().maxCoeff(), h_.cwiseAbs().maxCoeff());
}

double DynamicsModel::naturalResidual(ConstVectorRef q) {
  const double raw = equilibriumResidual(q);  // fills grad_ / tmpN_ and h_
  if (heldCount() == 0) return raw / torqueUnit_;
  return std::max(tmpN_.cwiseAbs().maxCoeff() / torqueUnit_, h_.cwiseAbs().maxCoeff() / lengthUnit_);
}

double DynamicsModel::constraintViolation(ConstVectorRef q) {
  if (heldCount() == 0) return 0.0;
  forwardKinematics(chain_, q, data_);
  double v = 0.0;
  for (int c : held_) v = std::max(v, std::abs(data_.pose[c] - end_.value[c]));
  return v;
}

bool DynamicsModel::projectOntoConstraints(VectorRef q, double tolerance, int maxIterations) {
  if (heldCount() == 0) return true;
  for (int it = 0; it <= maxIterations; ++it) {
    evaluateStatics(q);
    if (h_.cwiseAbs().maxCoeff() <= tolerance * lengthUnit_) return true;
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
    if (!(q[i] > chain_.lowerLimits()[i] && q[i] < chain_.upperLimits()[i])) return false;
  return true;
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

// ---- gradient flow (D1) ---------------------------------------------------------------------

GradientFlowModel::GradientFlowModel(const Chain& chain, const EndCondition& end, const DynamicsScene& scene,
                                     ConstVectorRef q0)
    : DynamicsModel(chain, end), c_(scene.flowDamping), kappaH_(scene.constraintStiffness),
      H_(chain.size(), chain.size()), qdot_(chain.size()) {
  if (!finite(c_) || !(c_ > 0.0)) throw std::invalid_argument("flowDamping must be > 0");
  if (q0.size() != chain.size()) throw std::invalid_argument("q0 must have one entry per joint");
  if (!(kappaH_ > 0.0)) {
    Vector kq(chain.size());
    jointStiffness(chain_, q0, kq);
    kappaH_ = 10.0 * std::max(torqueUnit_, kq.cwiseAbs().maxCoeff());
  }
}

void GradientFlowModel::packState(ConstVectorRef q, ConstVectorRef, VectorRef x) const {
  x.head(segments()) = q;
  x[segments()] = 0.0;
}

void GradientFlowModel::velocity(const double* x, VectorRef qdot) {
  const int n = segments();
  evaluateStatics(Eigen::Map<const Vector>(x, n));
  if (heldCount() == 0) {
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

void GradientFlowModel::rhs(const double* x, double* dxdt) {
  const int n = segments();
  velocity(x, qdot_);
  Eigen::Map<Vector>(dxdt, n) = qdot_;
  // Power of the damping forces, c|q̇|² = −dΠ/dt on h = 0.
  dxdt[n] = c_ * qdot_.squaredNorm();
}

void GradientFlowModel::jacobian(const double* x, double* jacobianRowMajor) {
  if (heldCount() > 0) {
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
  const int m = heldCount();
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
      const int c = held_[size_t(k)];
      // J̇_h q̇: ẍ = −Σ ℓ_i (cos θ_i θ̇_i² + sin θ_i θ̈_i), ÿ = −Σ ℓ_i (sin θ_i θ̇_i² − cos θ_i θ̈_i), φ̈ = Σ q̈.
      double jdot = 0.0;
      if (c != static_cast<int>(EndCoordinate::Phi))
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

// ---- integration -----------------------------------------------------------------------------

bool IntegrationOptions::IsValid(std::string* why) const {
  if (!finite(absoluteTolerance) || !(absoluteTolerance > 0.0)) return fail(why, "absoluteTolerance must be > 0");
  if (!finite(relativeTolerance) || relativeTolerance < 0.0) return fail(why, "relativeTolerance must be >= 0");
  if (!finite(initialStep) || !(initialStep > 0.0)) return fail(why, "initialStep must be > 0");
  if (!finite(maxStep) || maxStep < 0.0) return fail(why, "maxStep must be >= 0 (0: unlimited)");
  if (!finite(minStep) || !(minStep > 0.0)) return fail(why, "minStep must be > 0");
  if (maxStep > 0.0 && maxStep < minStep) return fail(why, "maxStep must be >= minStep");
  if (!(maxTime > 0.0) || std::isnan(maxTime)) return fail(why, "maxTime must be > 0");
  if (maxSteps < 1) return fail(why, "maxSteps must be >= 1");
  if (!finite(velocityTolerance) || !(velocityTolerance > 0.0)) return fail(why, "velocityTolerance must be > 0");
  if (!finite(residualTolerance) || !(residualTolerance > 0.0)) return fail(why, "residualTolerance must be > 0");
  if (!finite(recordInterval) || recordInterval < 0.0) return fail(why, "recordInterval must be >= 0");
  if (maxSamples < 2) return fail(why, "maxSamples must be >= 2");
  return true;
}

const char* toString(StopReason reason) {
  switch (reason) {
    case StopReason::Rest: return "rest";
    case StopReason::MaxTime: return "max time";
    case StopReason::MaxSteps: return "max steps";
    case StopReason::JointLimit: return "joint limit";
    case StopReason::StepSizeUnderflow: return "step size underflow";
    case StopReason::NonFinite: return "non-finite state";
    case StopReason::Interrupted: return "interrupted";
  }
  return "unknown";
}

namespace {

namespace odeint = boost::numeric::odeint;
namespace ublas = boost::numeric::ublas;
using ExplicitState = std::vector<double>;
using StiffState = ublas::vector<double>;

struct ExplicitSystem {
  DynamicsModel* model;
  void operator()(const ExplicitState& x, ExplicitState& dxdt, double) const { model->rhs(x.data(), dxdt.data()); }
};

struct StiffSystem {
  DynamicsModel* model;
  void operator()(const StiffState& x, StiffState& dxdt, double) const { model->rhs(&x.data()[0], &dxdt.data()[0]); }
};

struct StiffJacobian {
  DynamicsModel* model;
  void operator()(const StiffState& x, ublas::matrix<double>& J, const double&, StiffState& dfdt) const {
    // ublas::matrix is row-major by default: its storage is exactly the layout jacobian() fills.
    model->jacobian(&x.data()[0], &J.data()[0]);
    std::fill(dfdt.begin(), dfdt.end(), 0.0);  // autonomous
  }
};

/// The accepted-step loop shared by all steppers: guards, monitoring, recording, rest.
class Monitor {
 public:
  Monitor(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result)
      : model_(model), options_(options), result_(result), qdot_(model.segments()) {}

  void start(const double* x) {
    result_.initialEnergy = energy(x);
    record(0.0, x, true);
  }

  /// After an accepted step: true to stop (reason set).
  bool accepted(double t, const double* x) {
    Eigen::Map<const Vector> q(x, model_.segments());
    result_.maxConstraintViolation = std::max(result_.maxConstraintViolation, model_.constraintViolation(q));
    result_.maxEnergyBalanceError = std::max(result_.maxEnergyBalanceError, std::abs(energy(x) - result_.initialEnergy));
    record(t, x, false);
    model_.velocity(x, qdot_);
    const double speed = qdot_.cwiseAbs().maxCoeff();
    if (speed <= options_.velocityTolerance && model_.naturalResidual(q) <= options_.residualTolerance)
      return stop(StopReason::Rest, "at rest: |qdot| and the equilibrium residual are below tolerance at t = " + num(t));
    return false;
  }

  bool stop(StopReason reason, const std::string& message) {
    result_.reason = reason;
    result_.message = message;
    return true;
  }

  void finish(double t, const double* x) {
    const int n = model_.segments();
    Eigen::Map<const Vector> q(x, n);
    result_.time = t;
    result_.q = q;
    model_.velocity(x, qdot_);
    result_.qdot = qdot_;
    result_.speed = qdot_.cwiseAbs().maxCoeff();
    result_.potential = model_.potential(q);
    result_.kinetic = model_.kineticEnergy(x);
    result_.dissipated = model_.dissipated(x);
    result_.residual = model_.equilibriumResidual(q);
    if (options_.recordTrajectory && (result_.trajectory.empty() || result_.trajectory.back().t < t)) forceRecord(t, x);
  }

 private:
  static std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }

  double energy(const double* x) {
    Eigen::Map<const Vector> q(x, model_.segments());
    return model_.potential(q) + model_.kineticEnergy(x) + model_.dissipated(x);
  }

  void record(double t, const double* x, bool first) {
    if (!options_.recordTrajectory) return;
    if (!first && t - lastRecorded_ < options_.recordInterval) return;
    forceRecord(t, x);
  }

  void forceRecord(double t, const double* x) {
    if (result_.trajectory.size() >= options_.maxSamples) {
      result_.trajectoryTruncated = true;
      return;
    }
    const int n = model_.segments();
    Eigen::Map<const Vector> q(x, n);
    TrajectorySample s;
    s.t = t;
    s.q = q;
    model_.velocity(x, qdot_);
    s.qdot = qdot_;
    s.potential = model_.potential(q);
    s.kinetic = model_.kineticEnergy(x);
    s.dissipated = model_.dissipated(x);
    s.residual = model_.equilibriumResidual(q);
    s.constraintViolation = model_.constraintViolation(q);
    result_.trajectory.push_back(std::move(s));
    lastRecorded_ = t;
  }

  DynamicsModel& model_;
  const IntegrationOptions& options_;
  DynamicsResult& result_;
  Vector qdot_;
  double lastRecorded_ = 0.0;
};

// FSAL controllers keep dx/dt of the last accepted state: after a rollback it must be dropped.
template <class C>
auto resetController(C& controller, int) -> decltype(controller.reset(), void()) {
  controller.reset();
}
template <class C>
void resetController(C&, long) {}

template <class Controller, class System, class State>
void runLoop(Controller& controller, System system, State& x, const double* (*data)(const State&),
             DynamicsModel& model, const IntegrationOptions& options, Monitor& monitor, DynamicsResult& result) {
  double t = 0.0, dt = options.initialStep;
  const int n = model.segments();
  monitor.start(data(x));
  State previous = x;
  for (;;) {
    if (options.interrupt.requested()) {
      monitor.stop(StopReason::Interrupted, options.interrupt.describe() + " at t = " + std::to_string(t));
      break;
    }
    if (result.steps >= options.maxSteps) {
      monitor.stop(StopReason::MaxSteps, "maximum number of steps (" + std::to_string(options.maxSteps) + ") reached");
      break;
    }
    if (t >= options.maxTime * (1.0 - 1e-15)) {
      monitor.stop(StopReason::MaxTime, "maximum time reached before rest");
      break;
    }
    dt = std::min(dt, options.maxTime - t);
    if (options.maxStep > 0.0) dt = std::min(dt, options.maxStep);
    previous = x;
    const double tPrevious = t, dtTried = dt;
    const odeint::controlled_step_result res = controller.try_step(system, x, t, dt);
    if (res == odeint::fail) {
      ++result.rejectedSteps;
      if (!(dt >= options.minStep)) {
        monitor.stop(StopReason::StepSizeUnderflow, "the step size fell below minStep at t = " + std::to_string(t));
        break;
      }
      continue;
    }
    // The error control cannot see a step that leaves the model's domain (a NaN error estimate
    // compares false and is accepted; past a joint limit a spring would pass through zero
    // length). Such a step is rolled back and retried at half the size, which bisects the time
    // at which a joint reaches its limit down to minStep; the chain then stops there.
    const double* xs = data(x);
    bool finiteState = true;
    for (int i = 0; finiteState && i < model.stateSize(); ++i) finiteState = std::isfinite(xs[i]);
    const bool inside = finiteState && model.withinLimits(Eigen::Map<const Vector>(xs, n));
    if (!inside) {
      x = previous;
      t = tPrevious;
      resetController(controller, 0);
      ++result.rejectedSteps;
      dt = 0.5 * dtTried;
      if (dt < options.minStep) {
        const double* xp = data(x);
        int joint = 0;
        double margin = std::numeric_limits<double>::infinity();
        for (int i = 0; i < n; ++i) {
          const double mi = std::min(xp[i] - model.chain().lowerLimits()[i], model.chain().upperLimits()[i] - xp[i]);
          if (mi < margin) {
            margin = mi;
            joint = i;
          }
        }
        // A trial that only failed by being non-finite far from every limit is a model failure.
        if (!finiteState && margin > 1e-6) {
          monitor.stop(StopReason::NonFinite, "the right-hand side became non-finite at t = " + std::to_string(t));
        } else {
          monitor.stop(StopReason::JointLimit, "joint " + std::to_string(joint + 1) + " reached its limit (q = " +
                                                   std::to_string(xp[joint]) + ") at t = " + std::to_string(t));
        }
        break;
      }
      continue;
    }
    ++result.steps;
    if (monitor.accepted(t, data(x))) break;
  }
  monitor.finish(t, data(x));
}

const double* explicitData(const ExplicitState& x) { return x.data(); }
const double* stiffData(const StiffState& x) { return &x.data()[0]; }

}  // namespace

DynamicsResult simulate(DynamicsModel& model, ConstVectorRef q0, ConstVectorRef qdot0, const IntegrationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("IntegrationOptions: " + why);
  const int n = model.segments();
  if (q0.size() != n) throw std::invalid_argument("q0 must have one entry per joint");
  if (qdot0.size() != 0 && qdot0.size() != n) throw std::invalid_argument("qdot0 must be empty or have one entry per joint");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(q0[i]) || (qdot0.size() == n && !std::isfinite(qdot0[i])))
      throw std::invalid_argument("the initial state must be finite");

  // The options' times and rest tolerances are in the model's natural units (dynamics.h).
  const double T = model.timeUnit();
  IntegrationOptions natural = options;
  natural.initialStep *= T;
  natural.maxStep *= T;
  natural.minStep *= T;
  natural.maxTime *= T;
  natural.recordInterval *= T;
  natural.velocityTolerance /= T;
  const auto wallStart = std::chrono::steady_clock::now();
  DynamicsResult result;
  result.kind = model.kind();
  const int N = model.stateSize();
  Vector x0(N);
  model.packState(q0, qdot0, x0);
  Monitor monitor(model, natural, result);

  if (natural.stepper == StepperKind::Rosenbrock4) {
    StiffState x(static_cast<size_t>(N));
    std::copy(x0.data(), x0.data() + N, x.begin());
    odeint::rosenbrock4_controller<odeint::rosenbrock4<double>> controller(natural.absoluteTolerance,
                                                                           natural.relativeTolerance);
    runLoop(controller, std::make_pair(StiffSystem{&model}, StiffJacobian{&model}), x, stiffData, model, natural,
            monitor, result);
  } else {
    ExplicitState x(x0.data(), x0.data() + N);
    if (natural.stepper == StepperKind::DormandPrince5) {
      auto controller = odeint::make_controlled(natural.absoluteTolerance, natural.relativeTolerance,
                                                odeint::runge_kutta_dopri5<ExplicitState>());
      runLoop(controller, ExplicitSystem{&model}, x, explicitData, model, natural, monitor, result);
    } else {
      auto controller = odeint::make_controlled(natural.absoluteTolerance, natural.relativeTolerance,
                                                odeint::runge_kutta_cash_karp54<ExplicitState>());
      runLoop(controller, ExplicitSystem{&model}, x, explicitData, model, natural, monitor, result);
    }
  }
  result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
  return result;
}

}  // namespace buckle::mechanics
