#include "buckle/continuation/bordered_solver.h"

#include "buckle/continuation/internal/finite.h"

#include <cmath>
#include <limits>

namespace buckle::continuation {

Factorization BorderedSolver::factorGeneral(ConstVectorRef, double, ConstMatrixRef, ConstMatrixRef, ConstMatrixRef,
                                            bool) {
  return Factorization::Refused;
}

DenseBorderedSolver::DenseBorderedSolver(const BoundProblem &problem)
    : problem_(problem),
      n_(problem.dimension()),
      A_(Matrix::Zero(n_ + 1, n_ + 1)),
      small_(n_ + 1, DenseLU::Rounding::Divide),
      useSmall_(n_ + 1 <= DenseLU::kEigenIdenticalSize),
      writesAll_(problem.jacobianWritesAllEntries()),
      lu_(useSmall_ ? 0 : n_ + 1) {}

Factorization DenseBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  general_ = false;
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  // A(c) written straight into the matrix that is factored (the small LU's own storage).
  const auto fill = [&](auto &&A) {
    if (!writesAll_) A.setZero();
    if (!problem_.jacobian(u, lambda, A.topLeftCorner(n_, n_), A.col(n_).head(n_))) return false;
    A.row(n_) = c.transpose();
    return allFinite(A.data(), A.size());  // both contiguous: the small LU's storage, A_
  };
  int sign = 0;
  double logAbs = 0.0;
  if (useSmall_) {
    if (!fill(small_.matrix())) return Factorization::Refused;
    if (!small_.factor() || !signedLogDeterminant(small_.factors(), small_.permutationSign(), sign, logAbs))
      return Factorization::Singular;
  } else {
    if (!fill(A_)) return Factorization::Refused;
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
  return allFinite(x.data(), x.size());  // a Ref with unit inner stride: contiguous
}

DeflatedBorderedSolve::DeflatedBorderedSolve(BorderedSolver &base, int n)
    : base_(base),
      n_(n),
      Bm_(n, 1),
      Cm_(n, 1),
      Dm_(Matrix::Zero(1, 1)),
      rhs_(n + 1),
      sol_(n + 1),
      xi_(n + 1) {}

Factorization DeflatedBorderedSolve::factor(ConstVectorRef u, double lambda, ConstVectorRef b, ConstVectorRef c,
                                            ConstMatrixRef B, ConstMatrixRef C, ConstMatrixRef D) {
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  const int n = n_;
  const int k = int(B.cols());
  if (k < 1 || B.rows() != n || C.rows() != n || C.cols() != k || D.rows() != k || D.cols() != k || b.size() != n ||
      c.size() != n)
    return Factorization::Refused;
  k_ = k;
  Bm_.col(0) = b;
  Cm_.col(0) = c;
  const Factorization f = base_.factorGeneral(u, lambda, Bm_, Cm_, Dm_, false);
  if (f != Factorization::Regular) return f;
  // B', C' ((N+1)×(k+1)), X = M⁻¹B', S = D' − C'ᵀX
  Bx_ = Matrix::Zero(n + 1, k + 1);
  Cx_ = Matrix::Zero(n + 1, k + 1);
  Bx_.topLeftCorner(n, k) = B;
  Bx_(n, k) = -1.0;
  Cx_.topLeftCorner(n, k) = C;
  X_.resize(n + 1, k + 1);
  for (int j = 0; j <= k; ++j) {
    rhs_ = Bx_.col(j);
    if (!base_.solve(rhs_, sol_)) return Factorization::Singular;
    X_.col(j) = sol_;
  }
  S_ = Matrix::Zero(k + 1, k + 1);
  S_.topLeftCorner(k, k) = D;
  S_.noalias() -= Cx_.transpose() * X_;
  S_.row(k) -= X_.row(n);  // the s-row: C' column k is e_{N+1}
  if (!S_.allFinite()) return Factorization::Singular;
  schur_.compute(S_);
  const double detS = schur_.determinant();
  if (!(detS != 0.0) || !std::isfinite(detS)) return Factorization::Singular;
  sign_ = base_.determinantSign() * (detS > 0.0 ? 1 : -1);
  logAbs_ = base_.logAbsDeterminant() + std::log(std::abs(detS));
  return Factorization::Regular;
}

bool DeflatedBorderedSolve::solve(ConstVectorRef r, VectorRef z) {
  if (sign_ == 0 || r.size() != n_ + k_ || z.size() != n_ + k_) return false;
  const int n = n_, k = k_;
  rhs_.head(n) = r.head(n);
  rhs_[n] = 0.0;
  if (!base_.solve(rhs_, xi_)) return false;
  outer_.resize(k + 1);
  outer_.head(k) = r.tail(k);
  outer_[k] = 0.0;
  outer_.noalias() -= Cx_.transpose() * xi_;
  outer_[k] -= xi_[n];
  y_ = schur_.solve(outer_);
  xi_.noalias() -= X_ * y_;
  z.head(n) = xi_.head(n);
  z.tail(k) = y_.head(k);
  return z.allFinite();
}

}  // namespace buckle::continuation
