// Newton corrector for the Keller pseudo-arclength system, on KINSOL.
//
// With x = (u, λ) ∈ R^{N+1}, a predictor x̂ and a unit tangent t, the corrector solves
//     G(x) = [ F(u, λ) ; tᵀ(x − x̂) ] = 0,
// whose Jacobian [[F_u, F_λ], [tᵀ]] is regular at regular points and at simple folds (Keller
// 1977), so the same code walks around turning points. Exact Newton (Jacobian refreshed at
// every iterate, dense LU): continuation steps are short, so the quadratic convergence
// region is where we live and the iteration count is a reliable step-size signal.
//
// Linear algebra: KINSOL's matrix-based interface with a custom SUNLinearSolver of type DIRECT
// and an empty custom SUNMatrix (nothing for KINSOL to zero or copy), so Newton stays KINSOL's
// and each step costs what the problem allows. By default the Keller matrix is written by the
// Jacobian callback into a DenseLU with SUNDIALS' own rounding (dense_lu.h), factored in the
// solver's setup() and applied in its solve(): the same iterates, bit for bit, as KINSOL's
// SUNLinSol_Dense, without its per-call SUNMatrix/N_Vector overhead (≈ 3 k instructions per
// Newton iteration at N+1 = 4). Given a BorderedSolver (a problem's structured one,
// bordered_solver.h), the Jacobian callback instead factors the bordered matrix through that
// solver at the current iterate, O(n) for the chain instead of O(n³).
//
// One KINSOL instance, N_Vector, SUNMatrix and linear solver are created per Corrector and
// reused for every solve; a solve only copies the new predictor/tangent into storage the
// callbacks read, so the hot loop allocates nothing. A point refused by the problem
// (residual() == false) is a recoverable failure: KINSOL halves its Newton step, and if the
// predictor itself is refused the solve fails with KIN_FIRST_SYSFUNC_ERR.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/internal/dense_lu.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/internal/sundials_raii.h"
#include "buckle/continuation/tracer_options.h"

#include <array>
#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace buckle::continuation {

/// Why and how a corrector solve ended.
struct CorrectorSummary {
  bool converged = false;
  int flag = 0;                   ///< KINSOL return flag
  const char *flagName = "";      ///< kinsolFlagName(flag)
  int iterations = 0;             ///< Newton iterations (KINGetNumNonlinSolvIters)
  int residualEvaluations = 0;
  double residualNorm = 0.0;      ///< ‖G‖₂ at the returned point (KINGetFuncNorm)
  double lastStepNorm = 0.0;      ///< ‖Δx‖₂ of the last Newton step
  double contraction = 0.0;       ///< largest ‖Δx_{k+1}‖/‖Δx_k‖ seen (0: fewer than two steps)
  bool refusedPoint = false;      ///< the problem refused at least one iterate
  std::string message;            ///< KINSOL's own message when it reported an error
};

class Corrector {
 public:
  /// `structured`: optional solver for the bordered Jacobian (not owned; must outlive the
  /// Corrector); null: dense LU.
  explicit Corrector(const BoundProblem &problem, const CorrectorOptions &options = CorrectorOptions(),
                     BorderedSolver *structured = nullptr);
  Corrector(const Corrector &) = delete;
  Corrector &operator=(const Corrector &) = delete;

  int dimension() const { return n_; }
  const CorrectorOptions &options() const { return options_; }
  /// Tolerances may change between solves (the locator tightens them); no reallocation.
  void setOptions(const CorrectorOptions &options);

  /// Keller system: F(x) = 0, tangentᵀ(x − predictor) = 0, starting at the predictor.
  /// predictor, tangent and x have size N+1; x receives the last iterate even on failure.
  CorrectorSummary correct(ConstVectorRef predictor, ConstVectorRef tangent, VectorRef x);

  /// F(u, λ) = 0 at fixed λ (start-point polishing, landing on a λ value): the bordered
  /// system with tangent e_λ, so the same KINSOL instance serves. u has size N.
  CorrectorSummary solveAtFixedParameter(ConstVectorRef u0, double lambda, VectorRef u);

  /// Keeps coordinate `index` of x at predictor[index] (a face of a box, or λ).
  CorrectorSummary solveWithFixedCoordinate(ConstVectorRef predictor, int index, VectorRef x);

 private:
  static int systemFunction(N_Vector x, N_Vector g, void *self);
  static int jacobianFunction(N_Vector x, N_Vector g, SUNMatrix J, void *self, N_Vector, N_Vector);
  static void errorHandler(int code, const char *module, const char *function, char *message, void *self);
  static int linearSetup(SUNLinearSolver solver, SUNMatrix);
  static int linearSolve(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype);
  int evaluate(const double *x, double *g);
  int evaluateJacobian(const double *x);
  int factorStructured(const double *x);
  void applyOptions();
  /// KINSOL's full-Newton iteration (KIN_NONE, direct linear solver, every setting of ours)
  /// reproduced operation for operation on the corrector's own vectors, for the common outcomes
  /// only: converged, or the initial guess already a solution. Anything else (a refused point, a
  /// failed factorization or solve, a step at the maximum length, the step tolerance, the
  /// iteration limit) returns false and correct() runs KINSOL itself from the same predictor.
  bool leanNewton(CorrectorSummary &summary);

  BoundProblem problem_;
  BorderedSolver *structured_ = nullptr;
  std::optional<DenseLU> dense_;  // the Keller matrix and its factors when structured_ is null
  CorrectorOptions options_;
  int n_;
  bool writesAll_;  // Problem::jacobianWritesAllEntries(): the Keller matrix is not cleared first
  Vector predictor_, tangent_, lastIterate_;
  Vector unit_;  // e_k for the fixed-coordinate solves
  Vector iterate_, residual_, step_, trial_, trialResidual_;  // leanNewton()'s uu, fval, pp, unew
  std::vector<double> stepNorms_;  // capacity fixed at construction
  bool haveLastIterate_ = false;
  bool refused_ = false;
  int evaluations_ = 0;
  std::array<char, 256> lastError_{};
  // An exception thrown by the problem inside a KINSOL callback must not unwind through KINSOL's
  // C frames: the callback stores it, fails the solve, and correct() rethrows it.
  std::exception_ptr pending_;

  // Declaration order is release order reversed: KINSOL memory goes first, context last.
  SunContextPtr context_;
  NVectorPtr x_, scale_;
  SunMatrixPtr jacobian_;
  SunLinearSolverPtr linearSolver_;
  KinsolMemoryPtr kinsol_;
};

}  // namespace buckle::continuation
