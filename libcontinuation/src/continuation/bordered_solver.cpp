#include "buckle/continuation/bordered_solver.h"

#include <cmath>
#include <limits>

namespace buckle::continuation {

Factorization BorderedSolver::factorGeneral(ConstVectorRef, double, ConstMatrixRef, ConstMatrixRef, ConstMatrixRef,
                                            bool) {
  return Factorization::Refused;
}

DenseBorderedSolver::DenseBorderedSolver(Problem &problem)
    : problem_(problem), n_(problem.dimension()), A_(Matrix::Zero(n_ + 1, n_ + 1)), lu_(n_ + 1) {}

Factorization DenseBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  general_ = false;
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

Factorization DenseBorderedSolver::factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C,
                                                 ConstMatrixRef D, bool transposed) {
  general_ = true;
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  const Eigen::Index k = B.cols();
  if (B.rows() != n_ || C.rows() != n_ || C.cols() != k || D.rows() != k || D.cols() != k)
    return Factorization::Refused;
  G_.resize(n_ + k, n_ + k);
  Vector Fl(n_);
  if (!problem_.jacobian(u, lambda, G_.topLeftCorner(n_, n_), Fl)) return Factorization::Refused;
  if (transposed) G_.topLeftCorner(n_, n_).transposeInPlace();
  G_.topRightCorner(n_, k) = B;
  G_.bottomLeftCorner(k, n_) = C.transpose();
  G_.bottomRightCorner(k, k) = D;
  if (!G_.allFinite()) return Factorization::Refused;
  generalLu_.compute(G_);
  const auto &LU = generalLu_.matrixLU();
  int sign = generalLu_.permutationP().determinant() > 0 ? 1 : -1;
  for (Eigen::Index i = 0; i < LU.rows(); ++i) {
    if (LU(i, i) == 0.0 || !std::isfinite(LU(i, i))) return Factorization::Singular;
    if (LU(i, i) < 0.0) sign = -sign;
  }
  sign_ = sign;
  logAbs_ = 0.0;  // not used for general borders
  return Factorization::Regular;
}

bool DenseBorderedSolver::solve(ConstVectorRef b, VectorRef x) {
  if (sign_ == 0) return false;
  if (general_) {
    x = generalLu_.solve(b);
    return x.allFinite();
  }
  x = lu_.solve(b);
  return x.allFinite();
}

}  // namespace buckle::continuation
