#include "buckle/continuation/bordered_solver.h"

#include <cmath>
#include <limits>

namespace buckle::continuation {

DenseBorderedSolver::DenseBorderedSolver(Problem &problem)
    : problem_(problem), n_(problem.dimension()), A_(Matrix::Zero(n_ + 1, n_ + 1)), lu_(n_ + 1) {}

Factorization DenseBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  A_.setZero();
  if (!problem_.jacobian(u, lambda, A_.topLeftCorner(n_, n_), A_.col(n_).head(n_))) return Factorization::Refused;
  A_.row(n_) = c.transpose();
  if (!A_.allFinite()) return Factorization::Refused;
  lu_.compute(A_);
  const auto &LU = lu_.matrixLU();
  int sign = lu_.permutationP().determinant() > 0 ? 1 : -1;
  // |det| as mantissa·2^exponent: one log per factorization instead of one per pivot.
  double mantissa = 1.0;
  long exponent = 0;
  for (int i = 0; i <= n_; ++i) {
    const double pivot = LU(i, i);
    if (pivot == 0.0 || !std::isfinite(pivot)) return Factorization::Singular;
    if (pivot < 0.0) sign = -sign;
    int e = 0;
    mantissa = std::frexp(mantissa * std::abs(pivot), &e);
    exponent += e;
  }
  sign_ = sign;
  logAbs_ = std::log(mantissa) + static_cast<double>(exponent) * 0.6931471805599453;
  return Factorization::Regular;
}

bool DenseBorderedSolver::solve(ConstVectorRef b, VectorRef x) {
  if (sign_ == 0) return false;
  x = lu_.solve(b);
  return x.allFinite();
}

}  // namespace buckle::continuation
