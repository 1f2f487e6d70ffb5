#include "buckle/mechanics/task_path_kkt_solver.h"

#include <cmath>
#include <limits>

#include "buckle/mechanics/task_path.h"

namespace buckle::mechanics {

using continuation::ConstMatrixRef;
using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::VectorRef;

namespace {
// T's factorisation is trusted for the elimination while its smallest pivot is above this
// fraction of its scale (chain_structure.h, minPivotRatio): below it H is numerically singular.
constexpr double kMinPivotRatio = 1e-12;
}  // namespace

TaskPathKktSolver::TaskPathKktSolver(const TaskPathProblem& problem, continuation::ProblemWorkspace& problemWorkspace)
    : problem_(problem),
      problemWorkspace_(problemWorkspace),
      n_(problem.segments()),
      mIn_(problem.inputCount()),
      m_(problem.taskCount()),
      N_(problem.dimension()),
      ws_(problem.segments()),
      work1_(problem.segments()),
      work2_(problem.segments()) {
  if (N_ <= kDenseFallback)
    dense_ = std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(problem, problemWorkspace));
}

// K⁻¹ = [[0, H⁻¹], [H⁻¹, −H⁻¹ A H⁻¹]] (header): x_q = H⁻¹ f_μ, x_μ = H⁻¹ (f_q − A x_q).
void TaskPathKktSolver::solveK(const Eigen::Ref<const Vector>& f, Eigen::Ref<Vector> x) {
  auto xq = x.head(n_);
  auto xm = x.tail(n_);
  applyUInverse(f.tail(n_), xq);
  solveFactored(ws_, xq);
  applyUInverseTranspose(xq, xq);
  maxIndexProduct(genA_, xq, work1_);
  work1_ += diagA_.cwiseProduct(xq);
  applyUInverse(f.head(n_) - work1_, xm);
  solveFactored(ws_, xm);
  applyUInverseTranspose(xm, xm);
}

void TaskPathKktSolver::applyK(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) {
  const auto xq = x.head(n_), xm = x.tail(n_);
  maxIndexProduct(genA_, xq, work1_);
  applyHessian(ws_, xm, work2_);
  y.head(n_) = work1_ + diagA_.cwiseProduct(xq) + work2_;
  applyHessian(ws_, xq, work2_);
  y.tail(n_) = work2_;
}

// Unknown order of the problem: (q [0, n), p [n, n + m_in), μ [n + m_in, 2n + m_in), ν [2n + m_in, N)).
Factorization TaskPathKktSolver::eliminate(ConstVectorRef u, ConstMatrixRef Bx, ConstMatrixRef Cx, ConstMatrixRef Dx) {
  sign_ = 0;
  logAbs_ = -std::numeric_limits<double>::infinity();
  usingDense_ = false;
  k_ = int(Bx.cols());
  TaskPathProblem::OptimalityBlocks blocks;
  if (!problem_.assembleOptimality(problemWorkspace_, u, ws_, blocks)) return Factorization::Refused;
  diagA_ = blocks.diagA;
  genA_ = blocks.genA;
  factorize(ws_, 0.0, true);
  if (ws_.singular || ws_.minPivotRatio < kMinPivotRatio) return Factorization::Singular;
  const int P = n_, M = n_ + mIn_, Nu = 2 * n_ + mIn_, small = mIn_ + m_ + k_;
  V_ = Matrix::Zero(2 * n_, small);
  W_ = Matrix::Zero(2 * n_, small);
  Ds_ = Matrix::Zero(small, small);
  // the inputs: rows R_q carry D, rows R_μ carry B (symmetric: the same as rows R_p)
  V_.block(0, 0, n_, mIn_) = blocks.D;
  V_.block(n_, 0, n_, mIn_) = blocks.B;
  W_.leftCols(mIn_) = V_.leftCols(mIn_);
  // the multipliers ν: rows R_q carry J_cᵀ
  V_.block(0, mIn_, n_, m_) = blocks.Jc.transpose();
  W_.block(0, mIn_, n_, m_) = blocks.Jc.transpose();
  // the border's columns and rows, split into their big (q, μ) and small (p, ν) parts
  const int e = mIn_ + m_;
  V_.block(0, e, n_, k_) = Bx.middleRows(0, n_);
  V_.block(n_, e, n_, k_) = Bx.middleRows(M, n_);
  W_.block(0, e, n_, k_) = Cx.middleRows(0, n_);
  W_.block(n_, e, n_, k_) = Cx.middleRows(M, n_);
  Ds_.topLeftCorner(mIn_, mIn_) = blocks.weights.asDiagonal();
  Ds_.block(0, e, mIn_, k_) = Bx.middleRows(P, mIn_);
  Ds_.block(mIn_, e, m_, k_) = Bx.middleRows(Nu, m_);
  Ds_.block(e, 0, k_, mIn_) = Cx.middleRows(P, mIn_).transpose();
  Ds_.block(e, mIn_, k_, m_) = Cx.middleRows(Nu, m_).transpose();
  Ds_.bottomRightCorner(k_, k_) = Dx;
  X_.resize(2 * n_, small);
  for (int j = 0; j < small; ++j) solveK(V_.col(j), X_.col(j));
  const Matrix S = Ds_ - W_.transpose() * X_;
  schur_.compute(S);
  const double detS = schur_.determinant();
  if (!(std::isfinite(detS) && detS != 0.0) || schur_.rcond() < 1e-14) return Factorization::Singular;
  // det = det K · det S = (−1)ⁿ det(H)² det S (the symmetric permutation to big, small keeps it)
  sign_ = (detS > 0 ? 1 : -1) * (n_ % 2 == 0 ? 1 : -1);
  logAbs_ = 2.0 * ws_.logAbsDet + std::log(std::abs(detS));
  return Factorization::Regular;
}

Factorization TaskPathKktSolver::factor(ConstVectorRef u, double s, ConstVectorRef c) {
  if (!c.allFinite()) return Factorization::Refused;
  // F_s: −d on the rows R_ν; the border row c
  Matrix Bx = Matrix::Zero(N_, 1), Cx = c.head(N_), Dx(1, 1);
  Bx.bottomRows(m_) = -problem_.leg().direction;
  Dx(0, 0) = c[N_];
  const Factorization f = eliminate(u, Bx, Cx, Dx);
  if (f != Factorization::Singular || !dense_) return f;
  usingDense_ = true;
  const Factorization fd = dense_->factor(u, s, c);
  sign_ = dense_->determinantSign();
  logAbs_ = dense_->logAbsDeterminant();
  return fd;
}

Factorization TaskPathKktSolver::factorGeneral(ConstVectorRef u, double s, ConstMatrixRef B, ConstMatrixRef C,
                                               ConstMatrixRef D, bool transposed) {
  const int k = int(B.cols());
  if (k < 1 || k > maxGeneralBorder() || B.rows() != N_ || C.rows() != N_ || C.cols() != k || D.rows() != k ||
      D.cols() != k || !B.allFinite() || !C.allFinite() || !D.allFinite())
    return Factorization::Refused;
  const Factorization f = eliminate(u, B, C, D);  // F_u symmetric: `transposed` changes nothing
  if (f != Factorization::Singular || !dense_) return f;
  usingDense_ = true;
  const Factorization fd = dense_->factorGeneral(u, s, B, C, D, transposed);
  sign_ = dense_->determinantSign();
  return fd;
}

bool TaskPathKktSolver::solve(ConstVectorRef b, VectorRef x) {
  if (sign_ == 0) return false;
  if (usingDense_) return dense_->solve(b, x);
  const int P = n_, M = n_ + mIn_, Nu = 2 * n_ + mIn_, e = mIn_ + m_, small = e + k_;
  // gather into big (q, μ) and small (p, ν, border) parts
  Vector f(2 * n_), g(small);
  f << b.segment(0, n_), b.segment(M, n_);
  g << b.segment(P, mIn_), b.segment(Nu, m_), b.tail(k_);
  Vector xb(2 * n_), y(small);
  const auto eliminateOnce = [&](const Vector& rf, const Vector& rg, Vector& ob, Vector& oy) {
    Vector t(2 * n_);
    solveK(rf, t);
    oy = schur_.solve(rg - W_.transpose() * t);
    ob = t - X_ * oy;
  };
  eliminateOnce(f, g, xb, y);
  // one step of iterative refinement with the exact products
  Vector rf(2 * n_), db, dy;
  applyK(xb, rf);
  rf = f - rf - V_ * y;
  const Vector rg = g - W_.transpose() * xb - Ds_ * y;
  eliminateOnce(rf, rg, db, dy);
  xb += db;
  y += dy;
  x.segment(0, n_) = xb.head(n_);
  x.segment(M, n_) = xb.tail(n_);
  x.segment(P, mIn_) = y.head(mIn_);
  x.segment(Nu, m_) = y.segment(mIn_, m_);
  x.tail(k_) = y.tail(k_);
  return x.allFinite();
}

}  // namespace buckle::mechanics
