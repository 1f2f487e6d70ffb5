#include "buckle/mechanics/task_path_solver.h"

#include <limits>

#include "buckle/mechanics/task_path.h"

namespace buckle::mechanics {

using continuation::ConstMatrixRef;
using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::VectorRef;

TaskPathBorderedSolver::TaskPathBorderedSolver(const TaskPathProblem& problem,
                                               continuation::ProblemWorkspace& problemWorkspace)
    : problem_(problem),
      problemWorkspace_(problemWorkspace),
      n_(problem.segments()),
      m_(problem.taskCount()),
      ws_(problem.segments()),
      x_(Vector::Zero(n_)) {
  if (problem.dimension() <= kDenseFallback)
    dense_ = std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(problem, problemWorkspace));
}

template <class DenseFactor>
Factorization TaskPathBorderedSolver::eliminate(DenseFactor dense) {
  y_.resize(V_.cols());
  if (factorBordered(ws_, V_, W_, D_)) {
    sign_ = ws_.borderedDetSign;
    logAbs_ = ws_.borderedLogAbsDet;
    return Factorization::Regular;
  }
  if (!dense_) return Factorization::Singular;
  usingDense_ = true;
  const Factorization f = dense();
  sign_ = dense_->determinantSign();
  logAbs_ = dense_->logAbsDeterminant();
  return f;
}

// Borders of A(c) (header): the inputs' columns B beside H, the task rows J_c below it.
Factorization TaskPathBorderedSolver::factor(ConstVectorRef u, double s, ConstVectorRef c) {
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  usingDense_ = false;
  if (!c.allFinite() || !problem_.assembleStructure(problemWorkspace_, u, ws_, B_, Jc_)) return Factorization::Refused;
  V_ = Matrix::Zero(n_, m_ + 1);
  W_.resize(n_, m_ + 1);
  D_ = Matrix::Zero(m_ + 1, m_ + 1);
  V_.leftCols(m_) = B_;
  W_.leftCols(m_) = Jc_.transpose();
  W_.col(m_) = c.head(n_);
  D_.topRightCorner(m_, 1) = -problem_.leg().direction;
  D_.bottomRows(1) = c.tail(m_ + 1).transpose();
  return eliminate([&] { return dense_->factor(u, s, c); });
}

Factorization TaskPathBorderedSolver::factorGeneral(ConstVectorRef u, double s, ConstMatrixRef B, ConstMatrixRef C,
                                                    ConstMatrixRef D, bool transposed) {
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  usingDense_ = false;
  const int k = int(B.cols()), p = m_ + k, N = n_ + m_;
  if (k < 1 || p > ChainStructure::kMaxBorder || B.rows() != N || C.rows() != N || C.cols() != k || D.rows() != k ||
      D.cols() != k || !B.allFinite() || !C.allFinite() || !D.allFinite())
    return Factorization::Refused;
  if (!problem_.assembleStructure(problemWorkspace_, u, ws_, B_, Jc_)) return Factorization::Refused;
  // F_u = [[H, B], [J_c, 0]]; F_uᵀ = [[H, J_cᵀ], [Bᵀ, 0]] (H symmetric)
  V_.resize(n_, p);
  W_.resize(n_, p);
  D_ = Matrix::Zero(p, p);
  V_.leftCols(m_) = transposed ? Matrix(Jc_.transpose()) : B_;
  W_.leftCols(m_) = transposed ? B_ : Matrix(Jc_.transpose());
  V_.rightCols(k) = B.topRows(n_);
  W_.rightCols(k) = C.topRows(n_);
  D_.topRightCorner(m_, k) = B.bottomRows(m_);
  D_.bottomLeftCorner(k, m_) = C.bottomRows(m_).transpose();
  D_.bottomRightCorner(k, k) = D;
  return eliminate([&] { return dense_->factorGeneral(u, s, B, C, D, transposed); });
}

bool TaskPathBorderedSolver::solve(ConstVectorRef b, VectorRef x) {
  if (sign_ == 0) return false;
  if (usingDense_) return dense_->solve(b, x);
  const int p = int(V_.cols());
  if (!solveFactoredBordered(ws_, V_, W_, D_, b.head(n_), b.tail(p), x_, y_)) return false;
  x.head(n_) = x_;
  x.tail(p) = y_;
  return true;
}

}  // namespace buckle::mechanics
