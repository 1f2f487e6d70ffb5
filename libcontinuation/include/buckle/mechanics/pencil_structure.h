// Linear-time linear algebra for the vibration pencil (H, M) of a chain (vibration.h, docs/mechanics.md
// "Vibration: natural frequencies along a branch").
//
// In absolute link angles θ = Uᵀq both halves of the pencil are structured: H = U T Uᵀ with T
// tridiagonal (chain_structure.h) and M = U M_θ Uᵀ with M_θ(i, i) = a_i and M_θ(i, j) = p_iᵀ r_j
// for i > j (dynamics_inertial.cpp, "O(n) mass matrix"). So H − σM = U G_σ Uᵀ with
//     G_σ = T − σ M_θ,   G_σ(i, j) = −σ p_iᵀ r_j + [i = j + 1] e_j   (i > j, e_j = T(j + 1, j)),
// a quasiseparable matrix. Its LDLᵀ keeps the structure (with 1×1 pivots; 2×2 ones below),
//     L(i, j) = −σ p_iᵀ g_j + [i = j + 1] e_j / d_j      (i > j),
// with 2-vectors g_j and pivots d_j from the recursion (P_0 = 0, P_j = Σ_{k<j} d_k g_k g_kᵀ)
//     z_j = −σ P_j p_j + e_{j−1} g_{j−1},
//     d_j = T_jj − σ a_j + σ p_jᵀ z_j − e_{j−1} L(j, j − 1),
//     g_j = (r_j − z_j) / d_j,   P_{j+1} = P_j + d_j g_j g_jᵀ
// (equate L D Lᵀ with G_σ column by column; at T = 0, σ = −1 it is M_θ's own recursion), O(n)
// per factorization, and the solves are two sweeps with 2-vector accumulators.
//
// Counts. M is positive definite, so by Sylvester the number of negative pivots is the number of
// eigenvalues of the pencil below σ. With held rows C (orthonormal basis Q of its rows, rank
// r ≤ 3) and B = U⁻¹Q, the bordered K_σ = [[G_σ, B], [Bᵀ, 0]] is congruent to
// [[H − σM, Q], [Qᵀ, 0]], so (Haynsworth, as chain_structure.h's constrainedCountBelow)
//     #{ω² of (V1) below σ} = neg(G_σ) + neg(S) − r,   S = −Bᵀ G_σ⁻¹ B,
// and det K_σ = det G_σ · det S vanishes exactly at the eigenvalues of (V1). Its logarithmic
// derivative is carried through the recursion (d/dσ of every line above) plus tr(S⁻¹S') with
// S' = −XᵀM_θX, X = G_σ⁻¹B, so the eigenvalue search of the chain structure (isolation by counts,
// Newton on det K_σ from a warm start, Illinois polish, every result certified by the counts)
// runs unchanged on the pencil.
//
// Pivoting. Unpivoted, a tiny pivot d_j (σ near an eigenvalue of a leading block) makes P_{j+1}
// huge, and the next steps cancel it again in rounding: the state, unlike the tridiagonal Sturm
// recurrence's, does not recover. So, as chain_structure.h's tridiagonal LDLᵀ, 2×2 pivots by Bunch's
// test on the coupling c = S(j + 1, j) to the next row (|d_j|·max(scale, |b|) < α c² with
// b = S(j + 1, j + 1): D = [[d_j, c], [c, b]], det D < 0, one eigenvalue of each sign); the recursion then takes the two rows at once,
// P += [ρ_j ρ_{j+1}] D⁻¹ [ρ_j ρ_{j+1}]ᵀ with ρ_k = r_k − z_k, and the tridiagonal channel into row j + 2
// is e_{j+1}(D⁻¹)_{1,:}. An exactly zero 1×1 pivot left (c = 0 too) is replaced by −pivmin (LAPACK
// dstebz): the count is then that just above σ. The determinant's derivative is carried while every
// pivot is 1×1 (NaN otherwise: the search then uses its counts). Solves near an eigenvalue are
// shifted by the caller (vibration_structured.cpp moves the shift while minPivotRatio is tiny).
//
// The workspace is sized once for the longest chain; `n` is the active size (the free joints).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

/// The constant generators of the kinetic energy (dynamics_inertial.cpp, "O(n) mass matrix"):
/// M_θ(i, i) = a_i, M_θ(i, j) = ℓ_j w_i cos(θ_i − θ_j) for i > j.
struct MassGenerators {
  Vector diagonal;  ///< a_i = μ_ii = I_i + m_i d_i² + ℓ_i² Σ_{k>i} m_k
  Vector weight;    ///< w_i = m_i d_i + ℓ_i Σ_{k>i} m_k
  Vector length;    ///< ℓ_i (the link lengths)
  Vector com;       ///< d_i, the centre of mass along link i
};
/// Generators of the chain with the given (valid) inertia data.
MassGenerators massGenerators(const Chain& chain, const InertiaData& inertia);

/// Workspace of the pencil G_σ = T − σ M_θ.
struct PencilStructure {
  /// Border columns: at most 3 held rows and two coupling columns per self contact.
  static constexpr int kMaxBorder = ChainStructure::kMaxBorder;
  using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxBorder, kMaxBorder>;

  explicit PencilStructure(int capacity);

  int capacity;
  int n = 0;        ///< active size (≤ capacity)
  Vector t, e;      ///< T: diagonal, sub-diagonal e[i] = T(i + 1, i)
  Vector a;         ///< M_θ diagonal
  Matrix p, r;      ///< capacity × 2: M_θ(i, j) = p_iᵀ r_j for i > j
  double scale = 1.0;  ///< a typical |ω²| (the unit of the search's tolerance): max_i Σ_j |T_ij| / a_i

  // LDLᵀ of G_σ, valid after factorizePencil(σ)
  double shift = 0.0;
  std::vector<unsigned char> block;  ///< 1: 1×1 pivot at k; 2: 2×2 pivot at (k, k + 1); 0: its second row
  Vector d;         ///< 1×1: the pivot; 2×2 at k: D⁻¹ = [[d[k], dOff[k]], [dOff[k], d[k + 1]]]
  Vector dOff;
  Vector tri;       ///< L(i, k) += tri[k] for i the first row after k's pivot block (the T channel)
  Matrix g;         ///< capacity × 2 generators of L: L(i, k) = −σ p_iᵀ g_k beyond k's block
  int twoByTwo = 0;            ///< 2×2 pivots used
  int negative = 0;            ///< negative eigenvalues of D: eigenvalues of the pencil below σ
  double minPivotRatio = 0.0;  ///< smallest |pivot| / scale of G_σ
  bool singular = false;       ///< a zero pivot was replaced by −pivmin
  double logAbsDet = 0.0;      ///< log |det G_σ| (NaN without the determinant)
  int detSign = 1;
  double dLogAbsDet = 0.0;     ///< d log|det G_σ| / dσ (NaN without the determinant)
  long factorizations = 0;

  // held rows: Q orthonormal (first `rank` columns), B = U⁻¹Q, X = G_σ⁻¹B, S = −BᵀX; then the
  // coupling's columns U⁻¹R (setPencilCoupling), S = diag(0, −E) − BᵀX
  Matrix Q, B, X;
  int rank = 0;
  int couplingCount = 0;
  Eigen::Matrix<double, kMaxBorder, 1> couplingSign = Eigen::Matrix<double, kMaxBorder, 1>::Zero();
  SmallMatrix S;
  Vector work;  ///< scratch (mass products)
  Vector guessChunk;  ///< the warm start of one chunk of the eigenvalue search (resized only when the chunk size changes)
};

/// LDLᵀ of G_σ by the recursion above; with `determinant` also log|det|, its sign and derivative.
void factorizePencil(PencilStructure& ws, double sigma, bool determinant = true);
/// y ← G_σ⁻¹ y after factorizePencil(σ).
void solvePencil(const PencilStructure& ws, VectorRef y);
/// y = M_θ x (y must not alias x), O(n).
void applyPencilMass(const PencilStructure& ws, ConstVectorRef x, VectorRef y);
/// True if M_θ is positive definite to rounding (every pivot of its LDLᵀ positive).
bool pencilMassPositive(const PencilStructure& ws);
/// Orthonormalise the rows of C (m×n active, m ≤ 3) into Q; B = U⁻¹Q. Rows whose remainder is
/// below rankTolerance of the largest row norm are dropped. Returns the rank.
int setPencilConstraints(PencilStructure& ws, const Eigen::Ref<const Matrix>& C, double rankTolerance = 1e-10);
/// After setPencilConstraints(): the pencil's stiffness becomes H + R E Rᵀ on ker C (R m×c active,
/// E = diag(signs), each ±1, rank + c ≤ kMaxBorder), bordered as chain_structure.h's setCoupling
/// (a self contact's rank-2 term, self_contact.h): the counts subtract #{E_jj > 0}.
void setPencilCoupling(PencilStructure& ws, const Eigen::Ref<const Matrix>& R, const Eigen::Ref<const Vector>& signs);
/// Number of eigenvalues of the pencil on ker C below σ (refactorizes at σ; X and S at σ after).
int pencilCountBelow(PencilStructure& ws, double sigma, bool determinant = true);
/// Eigenvalues first … first + k − 1 (ascending; k = min(count, n − rank − first)) of the pencil on
/// ker C to absolute accuracy tolerance · max(scale, max |ω²|) (the latter within a factor 4, from
/// counts that confirm the search's outer bound), by the certified search of chain_structure.h;
/// `guess` (e.g. the previous point's values, indexed from `first`) starts Newton. Returns k.
int pencilEigenvalues(PencilStructure& ws, int first, int count, VectorRef out, double tolerance = 1e-13,
                      const Vector* guess = nullptr);

}  // namespace buckle::mechanics
