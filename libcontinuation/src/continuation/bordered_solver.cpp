#include "buckle/continuation/bordered_solver.h"

#include <cmath>
#include <limits>

namespace buckle::continuation {

Factorization BorderedSolver::factorGeneral(ConstVectorRef, double, ConstMatrixRef, ConstMatrixRef, ConstMatrixRef,
                                            bool) {
  return Factorization::Refused;
}

DenseBorderedSolver::DenseBorderedSolver(Problem &problem)
    : problem_(problem),
      n_(problem.dimension()),
      A_(Matrix::Zero(n_ + 1, n_ + 1)),
      small_(n_ + 1, DenseLU::Rounding::Divide),
      useSmall_(n_ + 1 <= DenseLU::kEigenIdenticalSize),
      lu_(useSmall_ ? 0 : n_ + 1) {}

Factorization DenseBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  general_ = false;
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  A_.setZero();
  if (!problem_.jacobian(u, lambda, A_.topLeftCorner(n_, n_), A_.col(n_).head(n_))) return Factorization::Refused;
  A_.row(n_) = c.transpose();
  if (!A_.allFinite()) return Factorization::Refused;
  int sign = 0;
  double logAbs = 0.0;
  if (useSmall_) {
    small_.matrix() = A_;
    if (!small_.factor() || !signedLogDeterminant(small_.factors(), small_.permutationSign(), sign, logAbs))
      return Factorization::Singular;
  } else {
    lu_.compute(A_);
    if (!signedLogDeterminant(lu_.matrixLU(), lu_.permutationP().determinant() > 0 ? 1 : -1, sign, logAbs))
      return Factorization::Singular;
  }
  sign_ = sign;
  logAbs_ = logAbs;
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
  if (useSmall_) {
    x = b;
    small_.solveInPlace(x);
  } else {
    x = lu_.solve(b);
  }
  return x.allFinite();
}

}  // namespace buckle::continuation
