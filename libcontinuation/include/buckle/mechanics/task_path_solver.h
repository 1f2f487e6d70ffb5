// The bordered Jacobian of a task path under rule (a) (task_path.h) solved in O(n).
//
// With u = (q, p) (joint angles, the m chosen inputs) the tracer's matrix is
//     A(c) = [[H, B, 0], [J_c, 0, −d], [c_qᵀ, c_pᵀ, c_s]],   H = K_q − K_g = U T Uᵀ,
// i.e. H bordered by m + 1 columns: V = [B, 0], W = [J_cᵀ, c_q] and the corner
// D = [[0, −d], [c_pᵀ, c_s]]; block elimination through the tridiagonal T (factorBordered,
// chain_structure.h) costs O(n·(m + 1)) and det A = det T · det S. The locator's general borders
// [[F_u, B_G], [C_Gᵀ, D_G]] add their k columns the same way (F_uᵀ swaps B and J_cᵀ).
// Where H itself is singular (the equilibrium at fixed inputs at its stability limit, which the
// path ends on) the elimination falls back to a dense LU for N ≤ kDenseFallback, as the chain's
// own solver does (chain_solver.h).
#pragma once

#include <memory>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

class TaskPathProblem;

class TaskPathBorderedSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;
  /// `problem` (rule (a), m + 3 ≤ ChainStructure::kMaxBorder) must outlive the solver.
  /// On `problem` evaluated in `problemWorkspace` (its workspace, outliving the solver).
  TaskPathBorderedSolver(const TaskPathProblem& problem, continuation::ProblemWorkspace& problemWorkspace);

  continuation::Factorization factor(continuation::ConstVectorRef u, double s, continuation::ConstVectorRef c) override;
  bool solve(continuation::ConstVectorRef b, continuation::VectorRef x) override;
  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }
  int maxGeneralBorder() const override { return ChainStructure::kMaxBorder - m_; }
  continuation::Factorization factorGeneral(continuation::ConstVectorRef u, double s, continuation::ConstMatrixRef B,
                                            continuation::ConstMatrixRef C, continuation::ConstMatrixRef D,
                                            bool transposed) override;

 private:
  /// Block elimination with the current V_, W_, D_; the dense fallback through `dense` otherwise.
  template <class DenseFactor>
  continuation::Factorization eliminate(DenseFactor dense);

  const TaskPathProblem& problem_;
  continuation::ProblemWorkspace& problemWorkspace_;
  int n_, m_;
  ChainStructure ws_;
  Matrix B_, Jc_, V_, W_, D_;
  Vector x_, y_;
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace buckle::mechanics
