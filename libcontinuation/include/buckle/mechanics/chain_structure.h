// Linear-time linear algebra for the chain's Hessian (docs/mechanics.md, "The O(n) chain structure").
//
// With K_q = diag(κ) and K_g(i, j) = h_max(i,j) (eq 27), the Hessian of the total potential is
//     H = K_q − K_g = U · T · Uᵀ,
// U the upper-triangular matrix of ones and T tridiagonal:
//     T_mm = κ_m + κ_{m+1} − d_m,  T_m,m+1 = −κ_{m+1},  d_m = h_m − h_{m+1}  (κ_{n+1} = h_{n+1} = 0).
// T is the Hessian in absolute link angles θ = Uᵀ q. The identity metric of q-space becomes
// M = U⁻¹U⁻ᵀ in θ-space, again tridiagonal (diagonal 2, …, 2, 1; off-diagonal −1), so for any
// shift σ, H − σI = U (T − σM) Uᵀ: every eigenvalue count of H, and of H restricted to the
// kernel of held end-coordinate rows C, is a count on a tridiagonal matrix, O(n).
//
// Algorithms (all O(n); m = number of border columns, at most kMaxBorder):
//  - factorize(): LDLᵀ of T − σM with Bunch's (1974) tridiagonal pivoting (1×1 or 2×2 pivots,
//    α = (√5 − 1)/2), which bounds element growth without destroying the band. Its pivot
//    blocks give the inertia of T − σM (Sylvester), i.e. the number of eigenvalues of H below σ.
//  - countBelow(): the same count by the plain Sturm recurrence (no storage; Kahan's backward-
//    stable count, zero pivots replaced by −pivmin as in LAPACK dstebz).
//  - hessianInertia(): negative = #{μ < −τ}, zero = #{|μ| ≤ τ} from two counts at σ = ∓τ,
//    τ = zeroTolerance · max(s, ‖H‖_F) (‖H‖_F computed exactly in O(n); s = typicalScale, the
//    chain's stiffness unit k̄b̄², so that the count is the same in any units and H ≈ 0 still
//    counts as zero).
//  - constrainedInertia(): inertia of H on ker C. The rows of C are orthonormalised (modified
//    Gram–Schmidt, twice, rank-revealing with rankTolerance): Q (n×r). With B = U⁻¹Q the bordered
//    matrix K_σ = [[T − σM, B], [Bᵀ, 0]] is congruent to [[H − σI, Q], [Qᵀ, 0]], whose inertia is
//    In(Zᵀ H Z − σI) + (r, r, 0) for Z an orthonormal basis of ker C. Block elimination (Haynsworth):
//    In(K_σ) = In(T − σM) + In(S), S = −Bᵀ(T − σM)⁻¹B (r×r), so
//        #{eigenvalues of ZᵀHZ below σ} = neg(T − σM) + neg(S) − r,
//    O(n r) for the r solves. Singular T (e.g. κ = 0 at F = 0, or σ an eigenvalue of H) is
//    handled by the shift test: counts are taken at σ = ±τ, and if the factorization of T − σM
//    shows a pivot below 1e-10 of its scale (σ too close to an eigenvalue of the *unconstrained*
//    H, where S would be dominated by rounding), σ is moved within [τ/2, 2τ] (an eigenvalue that
//    close to the threshold is ambiguous anyway) and the best-conditioned shift is used.
//  - solve(): H x = r as T z = U⁻¹ r, x = U⁻ᵀ z.
//  - solveBordered(): [[H, V], [Wᵀ, D]] [x; y] = [f; g] (V, W n×p, D p×p, p ≤ kMaxBorder) by block
//    elimination through T, plus one step of iterative refinement with the O(n) product H·x
//    (block elimination with refinement is accurate near folds where H itself is singular,
//    Govaerts 2000, ch. 3). This covers the KKT system (V = W = Cᵀ, D = 0) and the Keller
//    pseudo-arclength system of the corrector. Requires T − 0·M to be nonsingular.
//  - lowestEigenvalues() / smallestEigenvalue(): Newton on det K_σ (constrained) or det(T − σM),
//    whose roots are exactly the eigenvalues wanted (det K_σ = c·Π(ν_j − σ) over the
//    eigenvalues ν_j of ZᵀHZ), its logarithmic derivative carried through the factorization;
//    from a warm start (the previous point's values); without one (or where Newton leaves the
//    counts' bracket) the eigenvalue is isolated by bisection on the counts and polished by
//    Illinois regula falsi. Every result is certified by the counts either side of it: a few
//    O(n) factorizations per eigenvalue from a warm start, a few tens from none.
//
// The workspace is sized once; no function allocates on the heap after construction.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <vector>

#include "buckle/mechanics/chain.h"

namespace buckle::mechanics {

/// Eigenvalue counts of a symmetric operator.
struct Inertia {
  int negative = 0;
  int zero = 0;
  int positive = 0;
  int size() const { return negative + zero + positive; }
};

/// Workspace for one chain length; T, its factorization and the border storage.
struct ChainStructure {
  /// Border columns of the bordered solves: m ≤ 3 held rows, the tracer's one (F_λ | c), one
  /// more for the locator's branch-point system (chain_solver.h), and a contact problem's gap
  /// rows with two coupling columns per self contact (contact_solver.cpp).
  static constexpr int kMaxBorder = 8;
  using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxBorder, kMaxBorder>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxBorder, 1>;

  explicit ChainStructure(int n);
  int size() const { return n; }

  int n;
  Vector kappa, h;     ///< inputs of the last assemble(): K_q diagonal and h_m
  Vector diag, off;    ///< T: diagonal (n) and off-diagonal (n − 1 used)
  double frobeniusH = 0.0;  ///< ‖H‖_F
  /// The typical eigenvalue of H (the chain's k̄b̄²): floor of the zero thresholds. Set by the
  /// owner (EquilibriumProblem, linearBuckling); 1 for a chain in the paper's units.
  double typicalScale = 1.0;

  // Factorization of T − σM (Bunch pivoting); valid after factorize().
  double shift = 0.0;
  std::vector<unsigned char> blockStart;  ///< 1: 1×1 pivot at k; 2: 2×2 pivot at (k, k+1); 0: second row of a 2×2
  Vector pivA, pivE;   ///< pivot entries: 1×1: pivA[k]; 2×2: [[pivA[k], pivE[k]], [pivE[k], pivA[k+1]]]
  Vector l1, l2;       ///< multipliers: row below a 1×1 at k: l1[k]; row k+2 below a 2×2 at k: (l1[k], l2[k])
  Inertia factorInertia;     ///< inertia of T − σM from the pivots
  double minPivotRatio = 0;  ///< smallest |1×1 pivot| / scale: near 0 means T − σM nearly singular
  bool singular = false;     ///< an exactly zero pivot was replaced
  double logAbsDet = 0.0;    ///< log |det(T − σM)|
  int detSign = 1;           ///< sign of det(T − σM)
  double dLogAbsDet = 0.0;   ///< d log|det(T − σM)|/dσ (with the determinant; NaN without)
  long factorizations = 0;   ///< factorize() calls on this workspace (the eigenvalue searches' cost)

  // Border storage (n × kMaxBorder) and scratch.
  Matrix Q, B, X, V2, W2;
  Vector t1, t2, t3;
  Matrix zeroBorder;  ///< kMaxBorder² zeros (the D block of solveKKT)
  SmallMatrix S;
  int rank = 0;  ///< rank of the last C (rows kept after orthonormalisation)
  /// Coupling borders (setCoupling): columns rank … rank + couplingCount − 1 of B hold U⁻¹R of a
  /// term R E Rᵀ (E = diag(couplingSign), each ±1) added to H on ker C. Reset by setConstraints().
  int couplingCount = 0;
  Eigen::Matrix<double, kMaxBorder, 1> couplingSign = Eigen::Matrix<double, kMaxBorder, 1>::Zero();

  // Bordered factorization (factorBordered): Schur complement S = D − Wᵀ H⁻¹ V and its LU.
  SmallMatrix schur;
  Eigen::FullPivLU<SmallMatrix> schurLU;
  int borderSize = -1;          ///< p of the last successful factorBordered (−1: none)
  double borderedLogAbsDet = 0; ///< log |det [[H, V], [Wᵀ, D]]|
  int borderedDetSign = 1;      ///< its sign
};

// ---- assembly ----------------------------------------------------------------------------
/// T from the joint stiffnesses κ (K_q diagonal) and the load generator h (K_g(i,j) = h_max(i,j)).
void assemble(ConstVectorRef kappa, ConstVectorRef h, ChainStructure& ws);
/// T at joint angles q under the end wrench F (data must hold forwardKinematics(q)).
void assemble(const Chain& chain, const ChainData& data, ConstVectorRef q, const Wrench& F, ChainStructure& ws);

// ---- O(n) products with U (tail sums) ---------------------------------------------------
/// y = U x (y_i = Σ_{k≥i} x_k); y = U⁻¹ x (y_i = x_i − x_{i+1}); y = Uᵀ x (prefix sums);
/// y = U⁻ᵀ x (y_i = x_i − x_{i−1}). In place allowed.
void applyU(ConstVectorRef x, VectorRef y);
void applyUInverse(ConstVectorRef x, VectorRef y);
void applyUTranspose(ConstVectorRef x, VectorRef y);
void applyUInverseTranspose(ConstVectorRef x, VectorRef y);

/// y = H x = U T Uᵀ x, O(n) (y must not alias x).
void applyHessian(const ChainStructure& ws, ConstVectorRef x, VectorRef y);
/// Dense T (tests and cross-checks).
Matrix tridiagonalMatrix(const ChainStructure& ws);

// ---- factorization and counts ------------------------------------------------------------
/// LDLᵀ of T − σM with Bunch pivoting; fills the factor fields and factorInertia, and with
/// `determinant` detSign and logAbsDet (without it logAbsDet is NaN: a count needs neither).
void factorize(ChainStructure& ws, double sigma = 0.0, bool determinant = true);
/// Number of eigenvalues of H below σ (Sturm count of T − σM; no factor stored).
int countBelow(const ChainStructure& ws, double sigma);
/// Solve (T − σM) Z = Y in place for the first `cols` columns of Y (after factorize(σ)).
void solveFactored(const ChainStructure& ws, MatrixRef Y, int cols);
void solveFactored(const ChainStructure& ws, VectorRef y);

/// Rows of a constraint Jacobian whose remainder falls below this (relative to the largest row
/// norm) do not constrain: x held on a straight chain (J_x = 0). setConstraints()' default, and
/// the vibration pencil's (vibration.h).
inline constexpr double kConstraintRankTolerance = 1e-10;

/// Zero threshold τ = zeroTolerance · max(typicalScale, ‖H‖_F).
double zeroThreshold(const ChainStructure& ws, double zeroTolerance);

/// Inertia of H (n eigenvalues). Two O(n) Sturm counts.
Inertia hessianInertia(const ChainStructure& ws, double zeroTolerance = 1e-13);

/// Orthonormalise the rows of C (m×n, m ≤ 3) into ws.Q (first ws.rank columns) and form
/// B = U⁻¹Q. Rows whose remainder falls below rankTolerance (relative to the largest row norm)
/// are dropped, so rank-deficient C (e.g. x held on a straight chain, J_x = 0) is handled.
int setConstraints(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, double rankTolerance = kConstraintRankTolerance);
/// Number of eigenvalues of Zᵀ H Z below σ (after setConstraints()); refactorizes at σ (with the
/// determinant of T − σM only if `determinant`).
int constrainedCountBelow(ChainStructure& ws, double sigma, bool determinant = true);
/// Inertia of H on ker C (n − rank(C) eigenvalues). C may have zero rows.
Inertia constrainedInertia(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, double zeroTolerance = 1e-13,
                           double rankTolerance = kConstraintRankTolerance);

/// After setConstraints(): the constrained counts, eigenvalues and eigenvectors (useConstraints)
/// become those of H + R E Rᵀ on ker C, E = diag(signs) with each sign ±1 (R n×c, rank + c ≤
/// kMaxBorder), still O(n c) a count: the term is bordered as [[H − σI, Q, R], [Qᵀ, 0, 0],
/// [Rᵀ, 0, −E]], whose Schur complement on the last block is H + R E Rᵀ − σI (Haynsworth), so
///     #{eigenvalues below σ} = neg(T − σM) + neg(S) − r − #{E_jj > 0},
/// S = diag(0, −E) − Bᵀ(T − σM)⁻¹B with B = U⁻¹[Q R] (a self contact's rank-2 term: self_contact.h).
void setCoupling(ChainStructure& ws, const Eigen::Ref<const Matrix>& R, const Eigen::Ref<const Vector>& signs);
/// Inertia of H (with its coupling) on ker C as set by setConstraints() and setCoupling().
Inertia borderedInertia(ChainStructure& ws, double zeroTolerance = 1e-13);

/// The `count` lowest eigenvalues (ascending) of H, or of Zᵀ H Z (after setConstraints()) when
/// useConstraints, to absolute accuracy ~tolerance · max(1, ‖H‖_F), written to out[0 … k−1];
/// returns k = min(count, dimension). `guess` (optional, e.g. the previous continuation point's
/// values) brackets each eigenvalue with a few counts before falling back to bisection.
int lowestEigenvalues(ChainStructure& ws, bool useConstraints, int count, VectorRef out, double tolerance = 1e-13,
                      const Vector* guess = nullptr);
/// Eigenvalues with ascending indices first … first + k − 1 (k = min(count, dimension − first)) of H
/// or of Zᵀ H Z, as lowestEigenvalues (which is first = 0): the same isolation on the counts, so
/// the eigenvalues next to zero of a chain with many negative ones cost O(n) each too.
int eigenvaluesFrom(ChainStructure& ws, bool useConstraints, int first, int count, VectorRef out,
                    double tolerance = 1e-13, const Vector* guess = nullptr);
/// Smallest eigenvalue (lowestEigenvalues with count 1; 0 if the dimension is 0).
double smallestEigenvalue(ChainStructure& ws, bool useConstraints, double tolerance = 1e-13);
/// The unit eigenvector v of H, or of Zᵀ H Z in q-space (v in ker C, after setConstraints()) when
/// useConstraints, for the eigenvalue σ as eigenvaluesFrom() found it: `iterations` steps of
/// inverse iteration from a fixed start, one factorization of T − σM and, per step, O(n r) solves
/// with the r border columns. Each step shrinks the other eigenvectors' parts by
/// |σ − μ|/|σ − μ_i|: from σ within τ = 1e−13·‖H‖ of μ, one step leaves them at τ/gap, and a
/// Rayleigh quotient or a derivative vᵀ dH v off by that relative to ‖dH‖ (another eigenvalue
/// within the accuracy: v is some vector of their eigenspace). False when a solve breaks down (v
/// not finite). Uses the factor and X, S, t1.
bool eigenvectorAt(ChainStructure& ws, bool useConstraints, double sigma, VectorRef v, int iterations = 1);

/// Small chains (n ≤ kSmallDense): inertia of H on ker C and its `count` lowest eigenvalues
/// (written to lowest[0 … found−1]) from a dense, heap-free eigen-solve: Householder
/// reflectors map the orthonormalised rows of C onto the first r coordinates, the trailing
/// (n − r)² block of the reflected H is Zᵀ H Z; cyclic Jacobi (block ≤ 4×4) or Eigen's QR solver
/// gives its eigenvalues.
/// Zeros are counted as by
/// continuation::projectedInertia: |μ| ≤ zeroTolerance · max(typicalScale, max|μ|). For n ≲ 30 this is
/// faster than the O(n) counts plus eigenvalue isolation (benchmarks/RESULTS.md).
constexpr int kSmallDense = 32;
Inertia smallDenseInertia(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, int count, VectorRef lowest,
                          int& found, double zeroTolerance = 1e-13, double rankTolerance = kConstraintRankTolerance);

// ---- solves --------------------------------------------------------------------------------
/// H x = r (x may alias r). Factorizes T at σ = 0; false if T is singular to working precision.
bool solve(ChainStructure& ws, ConstVectorRef r, VectorRef x);
/// [[H, V], [Wᵀ, D]] [x; y] = [f; g] with V, W n×p, D p×p, p ≤ kMaxBorder (x, y may not alias inputs).
/// Factorizes T at σ = 0; false if T or the p×p Schur complement is singular.
bool solveBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                   const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x, VectorRef y);
/// solveBordered in two parts, for several right-hand sides with one factorization: T at σ = 0,
/// T⁻¹U⁻¹V, U⁻¹W and the p×p Schur complement S = D − WᵀH⁻¹V with its LU, plus
/// det [[H, V], [Wᵀ, D]] = det T · det S (borderedDetSign, borderedLogAbsDet). False if T or S is
/// singular to working precision.
bool factorBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                    const Eigen::Ref<const Matrix>& D);
/// Solve after factorBordered() with the same V, W, D; one step of iterative refinement.
bool solveFactoredBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                           const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x,
                           VectorRef y);
/// KKT system [[H, Cᵀ], [C, 0]] [x; y] = [f; g] (C m×n, full row rank).
bool solveKKT(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, ConstVectorRef f, ConstVectorRef g, VectorRef x,
              VectorRef y);

}  // namespace buckle::mechanics
