// Unblocked LU with partial pivoting for the small dense systems of the continuation core.
//
// Per continuation point the core factors two tiny (N+1)×(N+1) bordered matrices: the Keller
// matrix of each Newton iterate (inside KINSOL) and [[F_u, F_λ], [t_prevᵀ]] at the accepted point
// (tangent and determinant test). At N+1 = 4…8 the general libraries spend most of their time
// around the arithmetic: Eigen's PartialPivLU<MatrixXd> dispatches through its blocked driver
// and dynamic-size triangular solvers, SUNDIALS' dense linear solver through SUNMatrix/N_Vector
// calls and a pointer-per-column matrix. This class is the arithmetic alone, on storage sized
// once (nothing is allocated by factor() or solve()).
//
// Rounding. Each of the two roundings reproduces one library's operations bit for bit, so that
// moving a solver onto this class changes no result anywhere downstream — the sign of the
// bordered determinant is the branch-point test, and at degenerate points (a fold of a chain
// with identical joints, where the exact determinant vanishes) that sign is decided by rounding:
//   Divide      multipliers l_ik = a_ik / u_kk, the triangular solves skip zero entries of the
//               partial solution: Eigen's PartialPivLU, which for sizes ≤ 16 runs its unblocked
//               kernel and for sizes ≤ 8 solves each triangle as one panel (identical up to
//               kEigenIdenticalSize; above it Eigen's solve goes through a matrix-vector product
//               with another summation order);
//   Reciprocal  multipliers l_ik = a_ik · (1/u_kk), updates of a column skipped when its pivot-
//               row entry is zero: SUNDIALS' dense GETRF/GETRS (KINSOL's dense linear solver), at
//               any size.
// Both pick the first entry of largest magnitude as pivot and stop at an exactly zero pivot.
#pragma once

#include "buckle/continuation/problem.h"

#include <vector>

namespace buckle::continuation {

class DenseLU {
 public:
  enum class Rounding { Divide, Reciprocal };
  /// Largest size at which Rounding::Divide is bitwise Eigen's PartialPivLU (factors and solve).
  static constexpr int kEigenIdenticalSize = 8;

  DenseLU(int size, Rounding rounding);

  int size() const { return n_; }
  /// The matrix to factor (column-major size×size), written by the caller before factor();
  /// afterwards it holds U on and above the diagonal and the unit-lower L below it.
  Eigen::Map<Matrix> matrix() { return Eigen::Map<Matrix>(lu_.data(), n_, n_); }
  Eigen::Map<const Matrix> factors() const { return Eigen::Map<const Matrix>(lu_.data(), n_, n_); }

  /// P A = L U in place. False at the first exactly zero pivot (A singular; the factors are then
  /// incomplete and solve() must not be used). Non-finite entries are not checked here.
  bool factor();
  /// b ← A⁻¹ b for the last successful factor() (b of length size()).
  void solveInPlace(double *b) const;
  void solveInPlace(VectorRef b) const { solveInPlace(b.data()); }
  /// (−1)^(row interchanges) of the last factor().
  int permutationSign() const { return swaps_ % 2 == 0 ? 1 : -1; }

 private:
  // Fixed > 0: the size as a compile-time constant (sizes up to kEigenIdenticalSize, loops
  // unrolled); 0: the run-time size.
  template <int Fixed, bool reciprocal>
  bool factorImpl();
  template <int Fixed, bool reciprocal>
  void solveImpl(double *b) const;
  template <bool reciprocal>
  bool factorDispatch();
  template <bool reciprocal>
  void solveDispatch(double *b) const;

  int n_;
  Rounding rounding_;
  std::vector<double> lu_;  // column-major, n_×n_
  std::vector<int> pivots_;
  int swaps_ = 0;
};

/// Sign and log |det| of P A = L U from the diagonal of U and the permutation's sign: |det| as
/// mantissa·2^exponent, one log per factorization. False when a pivot is zero or not finite.
bool signedLogDeterminant(const Eigen::Ref<const Matrix> &factors, int permutationSign, int &sign, double &logAbs);

}  // namespace buckle::continuation
