// Linear algebra on the bordered Jacobian of a continuation problem.
//
// Everything the tracer solves per step is one matrix shape,
//     A(c) = [[F_u, F_λ], [cᵀ]]   ((N+1)×(N+1), c a border row),
// with c the tangent (Keller corrector, Newton steps), the previous tangent (new tangent:
// A t = e_{N+1}) or e_λ (a solve at fixed λ). Its determinant is the branch-point test function
// (sign change at a simple branch point, none at a fold: Keller 1977).
//
// The core's default is a dense LU (O(N³) per factorization). A problem with structure supplies
// its own solver (Problem::makeStructuredSolver, e.g. the chain's O(n) block elimination in
// mechanics/chain_solver.h); the corrector then hands it to KINSOL as a custom SUNLinearSolver,
// so KINSOL stays the Newton driver and the cost per step follows the problem's structure.
//
// The locator's refinements (structured_refinement.h) solve the same Jacobian with other
// borders, G = [[F_u, B], [Cᵀ, D]] with k ≤ 2 columns (and its transpose for left null
// vectors): factorGeneral(), optional for a structured solver.
#pragma once

#include "buckle/continuation/internal/dense_lu.h"
#include "buckle/continuation/bound_problem.h"

#include <Eigen/LU>

namespace buckle::continuation {

/// How a factorization ended: a singular A(c) is a result (a test function is exactly zero, or
/// the structured elimination broke down), a refused point is outside the problem's domain.
enum class Factorization { Regular, Singular, Refused };

class BorderedSolver {
 public:
  virtual ~BorderedSolver() = default;

  /// Linearises at (u, λ) with border row c (size N+1) and factors A(c).
  virtual Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) = 0;

  /// x = A(c)⁻¹ b for the last successful factor(); b, x of size N+1 and not aliased. After
  /// factorGeneral(), x = G⁻¹ b with b, x of size N+k.
  virtual bool solve(ConstVectorRef b, VectorRef x) = 0;

  /// Sign of det A(c) (0: singular) and log |det A(c)| of the last factor(). Only sign changes
  /// along a branch are used, so a solver may drop a constant positive factor.
  virtual int determinantSign() const = 0;
  virtual double logAbsDeterminant() const = 0;

  // ---- general borders: the locator's augmented systems (fold, branch point) -------------
  /// Largest k accepted by factorGeneral(); 0 (the default): not supported.
  virtual int maxGeneralBorder() const { return 0; }
  /// Factors G = [[F_u, B], [Cᵀ, D]] at (u, λ), or [[F_uᵀ, B], [Cᵀ, D]] when `transposed`
  /// (B, C N×k, D k×k, 1 ≤ k ≤ maxGeneralBorder()); A(c) is B = F_λ, C = c_u, D = c_λ. The
  /// next solve() uses G; the next factor() replaces it. Default: Refused (not supported).
  virtual Factorization factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C,
                                      ConstMatrixRef D, bool transposed);
};

/// G = [[F_u, B], [Cᵀ, D]] (B, C N×k, D k×k) solved through a base solver's factorization of the
/// one-bordered M = [[F_u, b], [cᵀ, 0]], with b, c approximations of the left and right null
/// vectors of F_u: the two-parameter curve systems (fold_curve.h, branch_point_curve.h), whose
/// F_u is singular on the curve. Eliminating through F_u itself (the chain's block elimination)
/// leaves a k×k Schur complement dominated by the rank-one part of F_u⁻¹ along the null vectors
/// (numerically singular for k ≥ 2); M is well conditioned there, and G is equivalent to
///     [[M, B'], [C'ᵀ, D']],  B' = [[B, 0], [0, −1]],  C' = [[C, 0], [0, 1]],  D' = [[D, 0], [0, 0]]
/// with the unknowns (x, s; y, t): the extra rows force s = 0 and t = cᵀx, so the (k+1)×(k+1)
/// Schur complement D' − C'ᵀM⁻¹B' is as well conditioned as G (block elimination on a
/// bordered regular matrix, Govaerts 2000, ch. 3). det of the extended matrix = ±det G with a
/// sign fixed by N and k. O(the base solver's cost) with k + 2 solves per factorization.
class DeflatedBorderedSolve {
 public:
  /// `base` is not owned; it must take general borders (k = 1) at dimension n.
  DeflatedBorderedSolve(BorderedSolver &base, int n);

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef b, ConstVectorRef c, ConstMatrixRef B,
                       ConstMatrixRef C, ConstMatrixRef D);
  /// z = G⁻¹ r (size N + k) after a Regular factor().
  bool solve(ConstVectorRef r, VectorRef z);
  int determinantSign() const { return sign_; }
  double logAbsDeterminant() const { return logAbs_; }

 private:
  BorderedSolver &base_;
  int n_;
  int k_ = 0;
  Matrix Bm_, Cm_, Dm_;          // the one-bordered M's border
  Matrix Bx_, Cx_, X_, S_;       // B', C', M⁻¹B', the Schur complement
  Eigen::PartialPivLU<Matrix> schur_;
  Vector rhs_, sol_, xi_, outer_, y_;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

/// Dense partial-pivoting LU of A(c), from Problem::jacobian(). Workspace sized once. Up to
/// DenseLU::kEigenIdenticalSize the unblocked DenseLU (a few hundred instructions at N+1 = 4…8
/// instead of ≈ 1.7 k for PartialPivLU<MatrixXd>'s dispatch, with bitwise the same factors,
/// determinant and solutions); above it Eigen's blocked LU.
class DenseBorderedSolver final : public BorderedSolver {
 public:
  explicit DenseBorderedSolver(const BoundProblem &problem);

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override;
  bool solve(ConstVectorRef b, VectorRef x) override;
  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }
  /// Any k (dense LU of the (N+k)² matrix; allocates, special points only).
  int maxGeneralBorder() const override { return 1 << 20; }
  Factorization factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C, ConstMatrixRef D,
                              bool transposed) override;

 private:
  BoundProblem problem_;
  int n_;
  Matrix A_;                              // A(c) above kEigenIdenticalSize
  DenseLU small_;                         // N+1 ≤ kEigenIdenticalSize
  bool useSmall_;
  bool writesAll_;                        // Problem::jacobianWritesAllEntries(): no zero fill
  Eigen::PartialPivLU<Matrix> lu_;        // larger N
  Matrix G_;                              // the last factorGeneral()'s matrix
  Eigen::PartialPivLU<Matrix> generalLu_;
  bool general_ = false;                  // solve() uses generalLu_
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace buckle::continuation
