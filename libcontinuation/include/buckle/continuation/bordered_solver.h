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

#include "buckle/continuation/dense_lu.h"
#include "buckle/continuation/problem.h"

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

/// Dense partial-pivoting LU of A(c), from Problem::jacobian(). Workspace sized once. Up to
/// DenseLU::kEigenIdenticalSize the unblocked DenseLU (a few hundred instructions at N+1 = 4…8
/// instead of ≈ 1.7 k for PartialPivLU<MatrixXd>'s dispatch, with bitwise the same factors,
/// determinant and solutions); above it Eigen's blocked LU.
class DenseBorderedSolver final : public BorderedSolver {
 public:
  explicit DenseBorderedSolver(Problem &problem);

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override;
  bool solve(ConstVectorRef b, VectorRef x) override;
  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }
  /// Any k (dense LU of the (N+k)² matrix; allocates, special points only).
  int maxGeneralBorder() const override { return 1 << 20; }
  Factorization factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C, ConstMatrixRef D,
                              bool transposed) override;

  /// A(c) of the last factor() (before factorization).
  const Matrix &matrix() const { return A_; }

 private:
  Problem &problem_;
  int n_;
  Matrix A_;
  DenseLU small_;                         // N+1 ≤ kEigenIdenticalSize
  bool useSmall_;
  Eigen::PartialPivLU<Matrix> lu_;        // larger N
  Matrix G_;                              // the last factorGeneral()'s matrix
  Eigen::PartialPivLU<Matrix> generalLu_;
  bool general_ = false;                  // solve() uses generalLu_
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace buckle::continuation
