// The optimality (KKT) system of rule (b) of a task path (task_path.h) solved by block
// elimination through the chain's Hessian H, O(n·(m_in + m)) per factorisation.
//
// Ordering the unknowns as big = (q, μ) and small = (p, ν, and the border's columns), the
// Jacobian's big block is K = [[A, H], [H, 0]] (rows R_q, R_μ), whose inverse needs H alone:
//     K⁻¹ = [[0, H⁻¹], [H⁻¹, −H⁻¹ A H⁻¹]],   det K = (−1)ⁿ det(H)²,
// i.e. two O(n) solves through the tridiagonal T (H = U T Uᵀ, chain_structure.h) and one O(n)
// product with A (a diagonal plus a max-index matrix, task_path.h). The small unknowns border K
// with V = [[D, J_cᵀ, B_x,q], [B, 0, B_x,μ]] and the Schur complement S = D_s − Wᵀ K⁻¹ V
// (size m_in + m + k) is factorised densely; det = (−1)ⁿ det(H)² det S. One step of iterative
// refinement with the exact O(n) products. H must be regular: it is on the stable part of a path,
// which ends where H becomes singular (the stability boundary); there, and wherever T's
// factorisation is near singular, the solver falls back to dense LU for N ≤ kDenseFallback.
// F_u is symmetric, so the transposed general borders are the same system.
#pragma once

#include <Eigen/LU>
#include <memory>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

class TaskPathProblem;

class TaskPathKktSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;
  /// The largest Schur complement (m_in + m + border) taken; more inputs are solved densely.
  static constexpr int kMaxSmall = 64;
  /// `problem` (rule (b)) must outlive the solver.
  /// On `problem` evaluated in `problemWorkspace` (its workspace, outliving the solver).
  TaskPathKktSolver(const TaskPathProblem& problem, continuation::ProblemWorkspace& problemWorkspace);

  continuation::Factorization factor(continuation::ConstVectorRef u, double s, continuation::ConstVectorRef c) override;
  bool solve(continuation::ConstVectorRef b, continuation::VectorRef x) override;
  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }
  int maxGeneralBorder() const override { return 2; }
  continuation::Factorization factorGeneral(continuation::ConstVectorRef u, double s, continuation::ConstMatrixRef B,
                                            continuation::ConstMatrixRef C, continuation::ConstMatrixRef D,
                                            bool transposed) override;

 private:
  /// The bordered system with extra columns Bx, rows Cx (N×k) and corner Dx (k×k).
  continuation::Factorization eliminate(continuation::ConstVectorRef u, continuation::ConstMatrixRef Bx,
                                        continuation::ConstMatrixRef Cx, continuation::ConstMatrixRef Dx);
  /// [x_q; x_μ] = K⁻¹ [f_q; f_μ] (after the factorisation of T).
  void solveK(const Eigen::Ref<const Vector>& f, Eigen::Ref<Vector> x);
  /// y = K x (exact, O(n)).
  void applyK(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);

  const TaskPathProblem& problem_;
  continuation::ProblemWorkspace& problemWorkspace_;
  int n_, mIn_, m_, N_;
  ChainStructure ws_;
  Vector diagA_, genA_, wdiag_;
  Matrix B_, D_, Jc_;
  Matrix V_, W_, X_, Ds_;       // borders of K, K⁻¹V, the small corner
  Eigen::PartialPivLU<Matrix> schur_;
  Vector work1_, work2_, big_, small_, resBig_, resSmall_;
  int k_ = 0;
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace buckle::mechanics
