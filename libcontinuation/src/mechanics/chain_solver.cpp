#include "buckle/mechanics/chain_solver.h"

#include <cmath>
#include <limits>

#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::VectorRef;

ChainBorderedSolver::ChainBorderedSolver(const EquilibriumProblem& problem,
                                         continuation::ProblemWorkspace& problemWorkspace)
    : problem_(problem),
      problemWorkspace_(problemWorkspace),
      n_(problem.segments()),
      m_(problem.heldCount()),
      p_(problem.heldCount() + 1),
      held_(problem.endCondition().heldIndices()),
      loaded_(problem.endCondition().loadedIndices()),
      ws_(problem.segments()),
      J_(3, problem.segments()),
      V_(Matrix::Zero(problem.segments(), problem.heldCount() + 1)),
      W_(Matrix::Zero(problem.segments(), problem.heldCount() + 1)),
      D_(Matrix::Zero(problem.heldCount() + 1, problem.heldCount() + 1)),
      x_(Vector::Zero(problem.segments())),
      y_(Vector::Zero(problem.heldCount() + 1)) {
  denseAllowed_ = n_ + m_ <= kDenseFallback;
}

Factorization ChainBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  general_ = false;
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  usingDense_ = false;
  if (!c.allFinite() || !problem_.assembleStructure(problemWorkspace_, u, lambda, ws_, J_))
    return Factorization::Refused;
  // Borders: V = [−J_hᵀ, F_λ,q], W = [−J_hᵀ, c_q], D = [[0, F_λ,r], [c_rᵀ, c_λ]] (see header).
  const Eigen::Vector3d& dir = problem_.direction();
  V_.col(m_).setZero();
  for (int cc : loaded_) V_.col(m_) -= J_.row(cc).transpose() * dir[cc];
  if (problem_.controlled())
    V_.col(m_) += EquilibriumProblem::controlRate(problemWorkspace_);  // moving free lengths (equilibrium_problem.h)
  if (problem_.hasBodyLoads())
    V_.col(m_) -= EquilibriumProblem::bodyRateTorques(problemWorkspace_);  // body loads growing with λ (eq B2)
  D_.setZero();
  for (int k = 0; k < m_; ++k) {
    const int h = held_[size_t(k)];
    V_.col(k) = -J_.row(h).transpose();
    W_.col(k) = V_.col(k);
    D_(k, m_) = dir[h];
    D_(m_, k) = c[n_ + k];
  }
  W_.col(m_) = c.head(n_);
  D_(m_, m_) = c[n_ + m_];
  if (factorBordered(ws_, V_, W_, D_)) {
    sign_ = ws_.borderedDetSign;
    logAbs_ = ws_.borderedLogAbsDet;
    return Factorization::Regular;
  }
  if (!dense()) return Factorization::Singular;
  usingDense_ = true;
  const Factorization f = dense_->factor(u, lambda, c);
  sign_ = dense_->determinantSign();
  logAbs_ = dense_->logAbsDeterminant();
  return f;
}

continuation::DenseBorderedSolver* ChainBorderedSolver::dense() {
  // made where a factorization first needs it: most solvers never do, and an (n + 1)² LU made
  // up front for each costs more than their solves on a short branch
  if (!dense_ && denseAllowed_) dense_ = std::make_unique<continuation::DenseBorderedSolver>(problem_);
  return dense_.get();
}

Factorization ChainBorderedSolver::factorGeneral(ConstVectorRef u, double lambda, continuation::ConstMatrixRef B,
                                                 continuation::ConstMatrixRef C, continuation::ConstMatrixRef D,
                                                 bool transposed) {
  general_ = true;
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  usingDense_ = false;
  const int k = int(B.cols()), p = m_ + k;
  if (k < 1 || p > ChainStructure::kMaxBorder || B.rows() != n_ + m_ || C.rows() != n_ + m_ || C.cols() != k ||
      D.rows() != k || D.cols() != k || !B.allFinite() || !C.allFinite() || !D.allFinite())
    return Factorization::Refused;
  if (!problem_.assembleStructure(problemWorkspace_, u, lambda, ws_, J_)) return Factorization::Refused;
  Vg_.resize(n_, p);
  Wg_.resize(n_, p);
  Dg_ = Matrix::Zero(p, p);
  yg_.resize(p);
  for (int j = 0; j < m_; ++j) {
    Vg_.col(j) = -J_.row(held_[size_t(j)]).transpose();
    Wg_.col(j) = Vg_.col(j);
  }
  Vg_.rightCols(k) = B.topRows(n_);
  Wg_.rightCols(k) = C.topRows(n_);
  Dg_.topRightCorner(m_, k) = B.bottomRows(m_);
  Dg_.bottomLeftCorner(k, m_) = C.bottomRows(m_).transpose();
  Dg_.bottomRightCorner(k, k) = D;
  if (factorBordered(ws_, Vg_, Wg_, Dg_)) {
    sign_ = ws_.borderedDetSign;
    logAbs_ = ws_.borderedLogAbsDet;
    return Factorization::Regular;
  }
  if (!dense()) return Factorization::Singular;
  usingDense_ = true;
  const Factorization f = dense_->factorGeneral(u, lambda, B, C, D, transposed);
  sign_ = dense_->determinantSign();
  return f;
}

bool ChainBorderedSolver::solve(ConstVectorRef b, VectorRef x) {
  if (sign_ == 0) return false;
  if (usingDense_) return dense_->solve(b, x);
  if (general_) {
    const int p = int(Vg_.cols());
    if (!solveFactoredBordered(ws_, Vg_, Wg_, Dg_, b.head(n_), b.tail(p), x_, yg_)) return false;
    x.head(n_) = x_;
    x.tail(p) = yg_;
    return true;
  }
  if (!solveFactoredBordered(ws_, V_, W_, D_, b.head(n_), b.tail(p_), x_, y_)) return false;
  x.head(n_) = x_;
  x.tail(p_) = y_;
  return true;
}

}  // namespace buckle::mechanics
