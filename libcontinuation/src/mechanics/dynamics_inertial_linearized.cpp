// The inertial model's exact Jacobian and its O(n) Rosenbrock stage solve (dynamics.h, (D2)).
//
// With x = (q, q̇, W_d) and q̈ = a(q, q̇) from M(q) q̈ = −c(q, q̇) − D q̇ − ∇Π(q) (no constraints),
// differentiating at fixed q̈:
//     M ∂a/∂q = −(H + C_q + G),   M ∂a/∂q̇ = −(C_v + D),
// H = K_q − K_g (eq 27), C_q = ∂c/∂q, C_v = ∂c/∂q̇, G = ∂(M(q) q̈)/∂q at fixed q̈. In absolute
// angles θ = T q (T lower-triangular ones: every one of these is Tᵀ X_θ T) and with
// μ_ij the kinetic-energy coefficients (dynamics.h; μ_ij = ℓ_j w_i for j < i, ℓ_i w_j for j > i):
//     M_θ(i, j)   = μ_ij cos(θ_i − θ_j),
//     C_v,θ(i, j) = 2 μ_ij sin(θ_i − θ_j) θ̇_j                    (c_θ,i = Σ_j μ_ij sin(θ_i − θ_j) θ̇_j²)
//     (C_q + G)_θ(i, j) = μ_ij [sin(θ_i − θ_j) θ̈_j − cos(θ_i − θ_j) θ̇_j²]   (j ≠ i),
//     (C_q + G)_θ(i, i) = Σ_{j≠i} μ_ij [cos(θ_i − θ_j) θ̇_j² − sin(θ_i − θ_j) θ̈_j],
// H_θ = T_H the tridiagonal of chain_structure.h and D_θ = T⁻ᵀ D T⁻¹ tridiagonal
// (diagonal d_i + d_{i+1}, off-diagonal −d_{i+1}). Every off-diagonal term has the form
// μ_ij [cos(θ_i − θ_j) β_j + sin(θ_i − θ_j) γ_j], and cos(θ_i − θ_j)β_j + sin(θ_i − θ_j)γ_j =
// (cos θ_i, sin θ_i)·r_j with r_j = (cos θ_j β_j − sin θ_j γ_j, sin θ_j β_j + cos θ_j γ_j): below
// the diagonal w_i (cos θ_i, sin θ_i)·ℓ_j r_j, above it ℓ_i (cos θ_i, sin θ_i)·w_j r_j — rank 2
// each, products by one forward and one backward sweep (applyCoupling).
//
// A Rosenbrock stage (I − aJ) k = b: the q rows give k_q = b_q + a k_v, the q̇ rows
//     [M + a(C_v + D) + a²(H + C_q + G)] k_v = M b_v − a (H + C_q + G) b_q,
// the energy row k_W = b_W + 2a (D q̇)ᵀ k_v. In θ-space the matrix is A_θ = diag + tridiagonal
// + the rank-2 semiseparable parts with β_j = 1 − a²θ̇_j², γ_j = 2aθ̇_j + a²θ̈_j; with the sums
// s_i = Σ_{j<i} ℓ_j r_j y_j and t_i = Σ_{j>i} w_j r_j y_j as extra unknowns, A_θ y = f is a sparse
// system of 5n unknowns (y_i, s_i, t_i interleaved) with bandwidth 6 — an O(n) LU.
#include "buckle/mechanics/dynamics.h"

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace buckle::mechanics {

struct InertialModel::Linearization {
  explicit Linearization(int n)
      : structure(n), h(n), cosT(n), sinT(n), thetaDot(n), thetaDdot(n), negSquare(n), diagK(n), ones(Vector::Ones(n)),
        zeros(Vector::Zero(n)), twiceRate(n), y(n), z(n), col(n), f(2 * n + 1), rhsTheta(n), beta(n), gamma(n),
        system(5 * n, 5 * n) {}

  ChainStructure structure;  ///< T_H of H = U T_H Uᵀ at the linearization state
  Vector h;
  Vector cosT, sinT;         ///< cos θ_i, sin θ_i at the linearization state
  Vector thetaDot, thetaDdot, negSquare, diagK, ones, zeros, twiceRate;
  Vector y, z, col, f, rhsTheta, beta, gamma;
  // the stage system, its factorization and the state it belongs to
  Eigen::SparseMatrix<double> system;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> lu;
  bool analyzed = false;
  Eigen::Index nonZeros = -1;
  Vector sparseRhs, sparseSolution;
  Vector state;  ///< x of the factored stage system (with factoredFor = a; NaN: none)
  double factoredFor = std::numeric_limits<double>::quiet_NaN();
  // dense route (constraints)
  Matrix jacobian;
  Eigen::PartialPivLU<Matrix> denseLU;
};

InertialModel::~InertialModel() = default;

void InertialModel::LinearizationDeleter::operator()(Linearization* p) const { delete p; }

void InertialModel::applyCoupling(ConstVectorRef beta, ConstVectorRef gamma, ConstVectorRef y, VectorRef out) const {
  const int n = segments();
  const Vector &c = lin_->cosT, &s = lin_->sinT;
  double a0 = 0.0, a1 = 0.0;
  for (int i = 0; i < n; ++i) {
    out[i] = w_[i] * (c[i] * a0 + s[i] * a1);
    a0 += len_[i] * (c[i] * beta[i] - s[i] * gamma[i]) * y[i];
    a1 += len_[i] * (s[i] * beta[i] + c[i] * gamma[i]) * y[i];
  }
  double b0 = 0.0, b1 = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    out[i] += len_[i] * (c[i] * b0 + s[i] * b1);
    b0 += w_[i] * (c[i] * beta[i] - s[i] * gamma[i]) * y[i];
    b1 += w_[i] * (s[i] * beta[i] + c[i] * gamma[i]) * y[i];
  }
}

void InertialModel::applyStiffnessTheta(ConstVectorRef y, VectorRef out) const {
  const int n = segments();
  const Linearization& L = *lin_;
  applyCoupling(L.negSquare, L.thetaDdot, y, out);  // off-diagonal (C_q + G)_θ
  for (int i = 0; i < n; ++i) {
    double t = (L.structure.diag[i] + L.diagK[i]) * y[i];
    if (i > 0) t += L.structure.off[i - 1] * y[i - 1];
    if (i + 1 < n) t += L.structure.off[i] * y[i + 1];
    out[i] += t;
  }
}

void InertialModel::linearizeAt(const double* x) {
  const int n = segments();
  if (!lin_) lin_.reset(new Linearization(n));
  Linearization& L = *lin_;
  rhs(x, L.f.data());  // statics, the factored mass matrix, θ̇ and q̈ (acc_) at x
  L.cosT = cos_;
  L.sinT = sin_;
  L.thetaDot = thetaDot_;
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    s += acc_[i];
    L.thetaDdot[i] = s;
  }
  L.negSquare = -L.thetaDot.cwiseProduct(L.thetaDot);
  L.twiceRate = 2.0 * L.thetaDot;
  loadHessianGenerator(data_, loads_, L.h);
  subtractBodyGenerator(L.h);
  assemble(stiffness_, L.h, L.structure);
  // (C_q + G)_θ's diagonal is minus its off-diagonal row sums
  applyCoupling(L.negSquare, L.thetaDdot, L.ones, L.diagK);
  L.diagK = -L.diagK;
}

void InertialModel::jacobian(const double* x, double* jacobianRowMajor) {
  if (constraintCount() > 0) {
    DynamicsModel::jacobian(x, jacobianRowMajor);
    return;
  }
  const int n = segments(), N = 2 * n + 1;
  linearizeAt(x);
  Linearization& L = *lin_;
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jacobianRowMajor, N, N);
  J.setZero();
  for (int i = 0; i < n; ++i) J(i, n + i) = 1.0;
  auto suffixSums = [&](VectorRef v) {
    for (int i = n - 2; i >= 0; --i) v[i] += v[i + 1];
  };
  for (int j = 0; j < n; ++j) {
    L.y.setZero();
    L.y.tail(n - j).setOnes();  // T e_j
    // ∂q̈/∂q_j = −M⁻¹ Tᵀ K_θ T e_j
    applyStiffnessTheta(L.y, L.z);
    L.col = L.z;
    suffixSums(L.col);
    solveMass(L.col);
    J.block(n, j, n, 1) = -L.col;
    // ∂q̈/∂q̇_j = −M⁻¹ (Tᵀ C_v,θ T e_j + d_j e_j)
    applyCoupling(L.zeros, L.twiceRate, L.y, L.z);
    L.col = L.z;
    suffixSums(L.col);
    L.col[j] += d_[j];
    solveMass(L.col);
    J.block(n, n + j, n, 1) = -L.col;
    J(2 * n, n + j) = 2.0 * d_[j] * x[n + j];
  }
}

bool InertialModel::solveLinearized(const double* x, double a, const double* b, double* k) {
  const int n = segments(), N = 2 * n + 1;
  if (!lin_) lin_.reset(new Linearization(n));
  Linearization& L = *lin_;
  const bool cached = L.factoredFor == a && L.state.size() == N && std::equal(x, x + N, L.state.data());
  Eigen::Map<const Vector> bv(b, N);
  Eigen::Map<Vector> kv(k, N);
  if (constraintCount() > 0) {
    // held coordinates or locked joints: dense LU of I − aJ with the central-difference J
    if (!cached) {
      L.factoredFor = std::numeric_limits<double>::quiet_NaN();
      L.jacobian.resize(N, N);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Jr(N, N);
      DynamicsModel::jacobian(x, Jr.data());
      L.jacobian = Matrix::Identity(N, N) - a * Matrix(Jr);
      L.denseLU.compute(L.jacobian);
      L.factoredFor = a;
      L.state = Eigen::Map<const Vector>(x, N);
    }
    kv = L.denseLU.solve(bv);
    return kv.allFinite();
  }
  if (!cached) {
    L.factoredFor = std::numeric_limits<double>::quiet_NaN();
    linearizeAt(x);
    const double a2 = a * a;
    L.beta = Vector::Ones(n) + a2 * L.negSquare;
    L.gamma = a * L.twiceRate + a2 * L.thetaDdot;
    L.triplets.clear();
    L.triplets.reserve(size_t(19 * n));
    auto add = [&](int r, int c, double v) { L.triplets.emplace_back(r, c, v); };
    for (int i = 0; i < n; ++i) {
      const int y = 5 * i;
      const double dNext = i + 1 < n ? d_[i + 1] : 0.0;
      add(y, y, muDiag_[i] + a * (d_[i] + dNext) + a2 * (L.structure.diag[i] + L.diagK[i]));
      if (i > 0) add(y, y - 5, -a * d_[i] + a2 * L.structure.off[i - 1]);
      if (i + 1 < n) add(y, y + 5, -a * dNext + a2 * L.structure.off[i]);
      add(y, y + 1, w_[i] * L.cosT[i]);
      add(y, y + 2, w_[i] * L.sinT[i]);
      add(y, y + 3, len_[i] * L.cosT[i]);
      add(y, y + 4, len_[i] * L.sinT[i]);
      for (int c = 0; c < 2; ++c) {
        // s_i = s_{i−1} + ℓ_{i−1} r_{i−1} y_{i−1}
        add(y + 1 + c, y + 1 + c, 1.0);
        if (i > 0) {
          const int j = i - 1;
          const double r = c == 0 ? L.cosT[j] * L.beta[j] - L.sinT[j] * L.gamma[j]
                                  : L.sinT[j] * L.beta[j] + L.cosT[j] * L.gamma[j];
          add(y + 1 + c, y - 5 + 1 + c, -1.0);
          add(y + 1 + c, y - 5, -len_[j] * r);
        }
        // t_i = t_{i+1} + w_{i+1} r_{i+1} y_{i+1}
        add(y + 3 + c, y + 3 + c, 1.0);
        if (i + 1 < n) {
          const int j = i + 1;
          const double r = c == 0 ? L.cosT[j] * L.beta[j] - L.sinT[j] * L.gamma[j]
                                  : L.sinT[j] * L.beta[j] + L.cosT[j] * L.gamma[j];
          add(y + 3 + c, y + 5 + 3 + c, -1.0);
          add(y + 3 + c, y + 5, -w_[j] * r);
        }
      }
    }
    L.system.setFromTriplets(L.triplets.begin(), L.triplets.end());
    if (!L.analyzed || L.system.nonZeros() != L.nonZeros) {
      L.lu.analyzePattern(L.system);
      L.analyzed = true;
      L.nonZeros = L.system.nonZeros();
    }
    L.lu.factorize(L.system);
    if (L.lu.info() != Eigen::Success) return false;
    L.factoredFor = a;
    L.state = Eigen::Map<const Vector>(x, N);
  }
  // f_θ = M_θ T b_v − a K_θ T b_q
  double s = 0.0;
  for (int i = 0; i < n; ++i) L.y[i] = (s += b[n + i]);  // T b_v
  applyCoupling(L.ones, L.zeros, L.y, L.rhsTheta);
  L.rhsTheta += muDiag_.cwiseProduct(L.y);
  s = 0.0;
  for (int i = 0; i < n; ++i) L.y[i] = (s += b[i]);  // T b_q
  applyStiffnessTheta(L.y, L.z);
  L.rhsTheta -= a * L.z;
  L.sparseRhs = Vector::Zero(5 * n);
  for (int i = 0; i < n; ++i) L.sparseRhs[5 * i] = L.rhsTheta[i];
  L.sparseSolution = L.lu.solve(L.sparseRhs);
  if (L.lu.info() != Eigen::Success) return false;
  // k_v = T⁻¹ y, k_q = b_q + a k_v, k_W = b_W + 2a (D q̇)ᵀ k_v
  double energy = 0.0;
  for (int i = 0; i < n; ++i) {
    const double kvi = L.sparseSolution[5 * i] - (i > 0 ? L.sparseSolution[5 * (i - 1)] : 0.0);
    k[n + i] = kvi;
    k[i] = b[i] + a * kvi;
    energy += d_[i] * x[n + i] * kvi;
  }
  k[2 * n] = b[2 * n] + 2.0 * a * energy;
  return kv.allFinite();
}

}  // namespace buckle::mechanics
