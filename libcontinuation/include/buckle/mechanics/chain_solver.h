// The chain's bordered Jacobian solved in O(n) (docs/mechanics.md, "The O(n) chain structure").
//
// With u = (q, r) (joint angles, reactions of the m held coordinates) the bordered Jacobian is
//     A(c) = [[H, −J_hᵀ, F_λ,q], [−J_h, 0, F_λ,r], [c_qᵀ, c_rᵀ, c_λ]],   H = K_q − K_g = U T Uᵀ,
// i.e. H bordered by p = m + 1 columns: V = [−J_hᵀ, F_λ,q], W = [−J_hᵀ, c_q] and the p×p corner
// D = [[0, F_λ,r], [c_rᵀ, c_λ]]. Block elimination through the tridiagonal T
// (factorBordered / solveFactoredBordered) costs O(n·p) and gives det A = det T · det S.
//
// Block elimination needs H itself regular. Where it is singular (the straight chain at a
// critical load of the *unconstrained* problem, F = 0 with κ = 0, or a fold of a load-controlled
// problem hit exactly) the solver falls back to a dense LU of the same matrix when
// n + m ≤ kDenseFallback, and reports the factorization singular above that, so the tracer
// halves its step. Det signs agree between the two routes (same matrix).
#pragma once

#include <memory>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

class EquilibriumProblem;

class ChainBorderedSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;

  /// `problem` must outlive the solver.
  /// On `problem` evaluated in `problemWorkspace` (its workspace, outliving the solver).
  ChainBorderedSolver(const EquilibriumProblem& problem, continuation::ProblemWorkspace& problemWorkspace);

  continuation::Factorization factor(continuation::ConstVectorRef u, double lambda,
                                     continuation::ConstVectorRef c) override;
  bool solve(continuation::ConstVectorRef b, continuation::VectorRef x) override;
  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }

  /// General borders (the locator's fold and branch-point systems): with B = [B_q; B_r],
  /// C = [C_q; C_r] split at the n joint rows, G = [[H, V], [Wᵀ, D_G]] with
  /// V = [−J_hᵀ, B_q], W = [−J_hᵀ, C_q], D_G = [[0, B_r], [C_rᵀ, D]]: the same block elimination
  /// with p = m + k ≤ kMaxBorder. F_u is symmetric, so `transposed` changes nothing.
  int maxGeneralBorder() const override { return ChainStructure::kMaxBorder - m_; }
  continuation::Factorization factorGeneral(continuation::ConstVectorRef u, double lambda,
                                            continuation::ConstMatrixRef B, continuation::ConstMatrixRef C,
                                            continuation::ConstMatrixRef D, bool transposed) override;

  /// The last factor() went through the dense fallback.
  bool usedDenseFallback() const { return dense_ != nullptr && usingDense_; }

 private:
  /// The dense fallback (created on first use; null above kDenseFallback).
  continuation::DenseBorderedSolver* dense();

  const EquilibriumProblem& problem_;
  continuation::ProblemWorkspace& problemWorkspace_;
  int n_, m_, p_;
  std::vector<int> held_, loaded_;
  ChainStructure ws_;
  Matrix J_, V_, W_, D_;
  Vector x_, y_;
  Matrix Vg_, Wg_, Dg_;  // borders of the last factorGeneral()
  Vector yg_;
  bool general_ = false;  // solve() uses the general borders
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool denseAllowed_ = false;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace buckle::mechanics
