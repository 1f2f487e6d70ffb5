// The inertial model (D2) of dynamics.h, M(q)q̈ + c(q, q̇) + Dq̇ + ∇Π = J_hᵀr: uniform rods, the O(n)
// mass matrix and velocity terms, joint damping, the held constraints by Baumgarte stabilisation.
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/pencil_structure.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace buckle::mechanics {

namespace {

std::atomic<long> inertialModelsConstructed{0};

}  // namespace

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
  if (!std::isfinite(baumgarteRate)) throw std::invalid_argument("baumgarteRate must be finite");
  ++inertialModelsConstructed;

  mass_.resize(n);
  inertia_.resize(n);
  d_ = Vector::Zero(n);
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = inertia.links[size_t(i)];
    mass_[i] = L.mass;
    inertia_[i] = L.inertia;
    if (!jointDamping.empty()) {
      if (!std::isfinite(jointDamping[size_t(i)]) || jointDamping[size_t(i)] < 0.0)
        throw std::invalid_argument("jointDamping[" + std::to_string(i) + "] must be >= 0");
      d_[i] = jointDamping[size_t(i)];
    }
  }
  // μ_ij of the kinetic energy ½ Σ μ_ij cos(θ_i − θ_j) θ̇_i θ̇_j: M_θ's generators (pencil_structure.h)
  MassGenerators gen = massGenerators(chain, inertia);
  muDiag_ = std::move(gen.diagonal);
  w_ = std::move(gen.weight);
  len_ = std::move(gen.length);
  com_ = std::move(gen.com);
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
      // a wall vertex: q̇ᵀ∇²x_v q̇ = −Σ_{i,j} g_max(i,j) q̇_i q̇_j = −Σ_m g_m (θ̇_m² − θ̇_(m−1)²)
      // a self contact: q̇ᵀ∂²g q̇ = −q̇ᵀG(γ)q̇ + 2(cᵀq̇)(wᵀq̇) (self_contact.h), the first term as the wall's
      if (k >= wallRowBegin()) {
        const int r = k - wallRowBegin();
        const auto g = wallGen_.col(r);
        const int last = r < wallCount() ? wall_[size_t(r)].lastJoint() : n - 1;
        double previous = 0.0;
        for (int i = 0; i <= last; ++i) {
          const double square = thetaDot_[i] * thetaDot_[i];
          jdot -= g[i] * (square - previous);
          previous = square;
        }
        if (k >= selfRowBegin())
          jdot += 2.0 * selfCoupling_.col(k - selfRowBegin()).dot(v) * selfWeights_.col(k - selfRowBegin()).dot(v);
      }
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

}  // namespace buckle::mechanics
