// The continuation core works in the problem's own units: a diagonal change of variables.
//
// With the scales of Problem::scales() (D_u for the unknowns, D_F for the residual rows, λ₀ for
// the parameter, μ₀ for the stability operator) the tracer solves
//     F̃(ũ, λ̃) = D_F⁻¹ F(D_u ũ, λ₀ λ̃) = 0,
// whose unknowns, parameter and rows are all O(1). Then one Euclidean arclength over (ũ, λ̃) is
// AUTO's weighted arclength (THU/THL = 1/scale²), KINSOL's ‖G̃‖∞ is the residual relative to the
// terms that balance in each row (uscale = 1/D_u, fscale = 1/D_F), the step sizes are
// dimensionless, and every threshold of the core (start kernel, inertia floor, Moore and
// bordered solves, bifurcation directions, location target λ₀·locationTolerance) means the same
// in every unit system. Results go back to the user's units through UnitScaling.
//
// The identity scaling (every scale 1, the default of Problem) costs nothing: the tracer then
// uses the problem directly.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"

#include <memory>

namespace buckle::continuation {

/// Conversions between the user's units and the scaled variables of a ProblemScales.
/// Points: u, λ, the tangent (renormalised: a unit vector in each system), the recorded
/// eigenvalues. Special points also: null vectors (renormalised, a kernel basis re-orthonormalised
/// in the scaled system), the left null vector, lambdaAccuracy. Arclength, step sizes,
/// residual norms and the fold / branch-point test-function values stay in the scaled
/// (dimensionless) variables in both systems.
class UnitScaling {
 public:
  UnitScaling() = default;
  explicit UnitScaling(const ProblemScales &scales);

  bool identity() const { return identity_; }
  const ProblemScales &scales() const { return scales_; }
  double parameter() const { return scales_.parameter; }
  /// Scale of coordinate i of x = (u, λ) (i = N: λ).
  double state(int i) const { return i < n_ ? scales_.unknowns[i] : scales_.parameter; }

  void toScaled(ContinuationPoint &p) const;
  void toUser(ContinuationPoint &p) const;
  void toScaled(SpecialPoint &p) const;
  void toUser(SpecialPoint &p) const;
  void toScaled(Branch &b) const;
  void toUser(Branch &b) const;
  SpecialPoint scaled(const SpecialPoint &p) const {
    SpecialPoint q = p;
    toScaled(q);
    return q;
  }
  /// A direction in x = (u, λ), as a unit vector in the other system (zero stays zero).
  Vector directionToScaled(ConstVectorRef t) const;
  Vector directionToUser(ConstVectorRef t) const;

 private:
  ProblemScales scales_;
  Vector stateScales_;  // (D_u, λ₀)
  int n_ = 0;
  bool identity_ = true;
};

/// Converts a branch to the scaled variables for the lifetime of the guard (RAII), back after.
class ScopedScaling {
 public:
  ScopedScaling(const UnitScaling &units, Branch &branch) : units_(units), branch_(branch) { units_.toScaled(branch_); }
  ~ScopedScaling() { units_.toUser(branch_); }
  ScopedScaling(const ScopedScaling &) = delete;
  ScopedScaling &operator=(const ScopedScaling &) = delete;

 private:
  const UnitScaling &units_;
  Branch &branch_;
};

/// F̃(ũ, λ̃) of the header comment, on a problem that outlives it. Its own scales() are ones.
class ScaledProblem final : public Problem {
 public:
  ScaledProblem(const Problem &problem, const UnitScaling &units);

  /// The inner problem's workspace (bound) and the change of variables' scratch.
  struct Workspace : ProblemWorkspace {
    Workspace(const BoundProblem &problem, int n);
    BoundProblem inner;
    Vector u, du;
    Vector x, w, z;  // (D_u, λ₀)·x̃, w̃/D_F and (D_u, λ₀)·z̃ of the products
  };
  /// A new workspace of the problem.
  std::unique_ptr<ProblemWorkspace> createWorkspace() const override;
  /// A workspace that evaluates the problem in `problem`'s workspace (problem.problem() must be
  /// the problem this one scales): the tracer's caller keeps its caches and warm starts.
  std::unique_ptr<ProblemWorkspace> workspaceOn(const BoundProblem &problem) const;

  const UnitScaling &units() const { return units_; }

  int dimension() const override { return n_; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override;
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Flambda) const override;
  bool jacobianWritesAllEntries() const override { return problem_.jacobianWritesAllEntries(); }
  bool jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                     double dlambda, MatrixRef dFu, VectorRef dFlambda) const override;
  /// The problem's own O(N) products, through the change of variables.
  bool jacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                     VectorRef y) const override;
  bool jacobianTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                              VectorRef y) const override;
  bool secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                      ConstVectorRef w, VectorRef y) const override;
  bool secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x, ConstVectorRef z,
                             VectorRef y) const override;
  bool hasStabilityOperator() const override { return problem_.hasStabilityOperator(); }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override;
  /// The problem's own stability() (its inertia count must be relative to ‖H‖), eigenvalues / μ₀.
  bool stability(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int lowestCount,
                 StabilityInfo &info) const override;
  bool stabilityEigenvalues(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int first,
                            VectorRef values) const override;
  /// The problem's bound along the user direction (D_u du, λ₀ dλ), / μ₀.
  bool stabilityRateBound(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda,
                          double &bound) const override;
  /// The problem's slopes along the user direction (D_u du, λ₀ dλ) of the values × μ₀, / μ₀.
  bool stabilitySlopes(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda,
                       int first, ConstVectorRef values, VectorRef slopes) const override;
  /// The problem's structured solver seen through the change of variables (still O(its cost)).
  std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace &ws) const override;
  int boundaryCount() const override { return problem_.boundaryCount(); }
  double boundary(ProblemWorkspace &ws, int k, ConstVectorRef u, double lambda) const override;
  void boundaries(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef g) const override;
  std::string boundaryName(int k) const override { return problem_.boundaryName(k); }

 private:
  void scaleJacobian(MatrixRef Fu, VectorRef Flambda) const;
  const Vector &user(Workspace &sw, ConstVectorRef u) const;

  const Problem &problem_;
  UnitScaling units_;
  int n_;
};

/// A ScaledProblem over a bound problem, evaluated in that problem's workspace (its caches and
/// warm starts): what the core's computations in the scaled variables work on. Not movable (the
/// handle points at the scaled problem it holds).
class BoundScaledProblem {
 public:
  BoundScaledProblem(const BoundProblem &problem, const UnitScaling &units)
      : scaled_(problem.problem(), units), ws_(scaled_.workspaceOn(problem)), bound_(scaled_, *ws_) {}
  BoundScaledProblem(const BoundScaledProblem &) = delete;
  BoundScaledProblem &operator=(const BoundScaledProblem &) = delete;
  const BoundProblem &bound() const { return bound_; }

 private:
  ScaledProblem scaled_;
  std::unique_ptr<ProblemWorkspace> ws_;
  BoundProblem bound_;
};

/// A problem's BorderedSolver for A(c) seen in the scaled variables:
/// Ã(c̃) = diag(D_F⁻¹, 1) [[F_u, F_λ], [(S⁻¹c̃)ᵀ]] S with S = diag(D_u, λ₀), so factor() hands
/// the border S⁻¹c̃ to the problem's solver and solve() maps right-hand side and solution.
/// det Ã differs from det A by a positive constant: the same signs.
class ScaledBorderedSolver final : public BorderedSolver {
 public:
  ScaledBorderedSolver(std::unique_ptr<BorderedSolver> solver, const UnitScaling &units);

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override;
  bool solve(ConstVectorRef b, VectorRef x) override;
  int determinantSign() const override { return solver_->determinantSign(); }
  double logAbsDeterminant() const override { return solver_->logAbsDeterminant(); }
  /// G̃ = diag(D_F⁻¹, I) G diag(D_u, I) (transposed: diag(D_u, I) G diag(D_F⁻¹, I)): the
  /// problem's solver gets the borders in its units, solve() maps right-hand side and solution.
  int maxGeneralBorder() const override { return solver_->maxGeneralBorder(); }
  Factorization factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C, ConstMatrixRef D,
                              bool transposed) override;

 private:
  std::unique_ptr<BorderedSolver> solver_;
  UnitScaling units_;
  Vector stateScales_, rowScales_;  // S (N+1) and (D_F, 1) (N+1)
  Vector u_, c_, b_;
  // After factorGeneral(): solve() maps b by inScale_ and x by outScale_ on the first N rows.
  bool general_ = false;
  Vector inScale_, outScale_;
};

}  // namespace buckle::continuation
