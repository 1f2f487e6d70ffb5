// A one-parameter nonlinear system F(u, λ) = 0 as the continuation core sees it.
//
// The core knows nothing about what the unknowns mean. A problem is a tiny
// interface (in the spirit of Ceres' CostFunction / tiny_solver): a residual,
// its exact Jacobian F_u and parameter derivative F_λ (a problem with the residual alone
// derives from NumericDiffProblem, numeric_diff.h, which differences both; checkDerivatives,
// derivative_check.h, checks hand-written ones), and optionally
//   - a symmetric stability operator H with constraint rows C: the state is
//     stable when H is positive definite on ker C (mechanics: the Hessian of the
//     total potential, C = rows of the held end coordinates; a gradient system
//     derives from GradientProblem, gradient_problem.h, and gets H = ±F_u);
//   - directional second derivatives (used to locate folds and branch points;
//     the default takes central differences of the analytic Jacobian);
//   - boundaries g_k(u, λ) > 0 (joint limits, a box): the tracer stops exactly on
//     g_k = 0;
//   - typical scales of the unknowns, the residual rows, λ and the stability operator
//     (ProblemScales). The tracer works in u/scale, λ/scale, F/scale (scaled_problem.h), so
//     its tolerances, step sizes and thresholds mean the same in any system of units.
// A problem refuses a point outside its domain by returning false, never by
// throwing; the corrector then treats the step as failed and halves it.
//
// Evaluations write into caller-owned storage (Eigen::Ref), so the hot loop of
// the tracer maps SUNDIALS buffers directly and allocates nothing.
//
// A problem is a read-only model (Pinocchio's Model, Ceres' const CostFunction::Evaluate): every
// evaluation is const and writes its scratch and caches into a ProblemWorkspace (Pinocchio's
// Data) that the caller owns, made by createWorkspace() once per computation. One problem can
// therefore be traced from several threads at once, each with its own workspace; a workspace is
// never shared between threads. BoundProblem (bound_problem.h) carries the pair.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>

namespace buckle::continuation {

class BorderedSolver;

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;
using VectorRef = Eigen::Ref<Eigen::VectorXd>;
using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;

/// Inertia and lowest spectrum of the stability operator on ker C.
struct StabilityInfo {
  int negative = -1;          ///< number of negative eigenvalues (-1: not computed)
  int zero = 0;               ///< eigenvalues with |μ| <= tolerance·‖H‖ (reported, not counted as negative)
  double smallest = 0.0;      ///< smallest eigenvalue (0 when no eigenvalue was asked for)
  Vector lowest;              ///< the lowest eigenvalues asked for, ascending (may be empty)
  bool valid() const { return negative >= 0; }
  bool stable() const { return negative == 0 && zero == 0; }
};

/// Typical magnitudes of a problem's quantities, all positive and finite: what "1" is for the
/// continuation core. A diagonal change of variables ũ = u/unknowns, λ̃ = λ/parameter,
/// F̃ = F/residuals (and H̃ = H/stability) makes the scaled problem O(1) (AUTO's THU/THL weights
/// for the arclength, KINSOL's uscale/fscale for the Newton norm).
struct ProblemScales {
  Vector unknowns;         ///< size N: typical |u_i|
  Vector residuals;        ///< size N: typical |F_i| (the size of the terms that balance in row i)
  double parameter = 1.0;  ///< typical |λ|
  double stability = 1.0;  ///< typical eigenvalue of the stability operator

  /// All ones for dimension n.
  static ProblemScales ones(int n);
  /// True when every scale is exactly 1 (the change of variables is the identity).
  bool identity() const;
  /// Empty string when valid for dimension n, else what is wrong.
  std::string check(int n) const;
};

/// Mutable state of one computation on a Problem: the scratch of the defaults below, and in a
/// derived type (Problem::createWorkspace) the problem's own caches and warm starts. Everything
/// cached in it is a pure function of the points evaluated, so results do not depend on which
/// workspace evaluates them beyond warm-started iterations.
struct ProblemWorkspace {
  virtual ~ProblemWorkspace();
  Matrix stabilityH, stabilityC;  // the default stability()
  Matrix applyFu;                 // the dense product defaults
  Matrix secondFu;                // the dense secondDerivativeApply()
  Vector secondFl;
};

[[noreturn]] void throwForeignWorkspace();

/// `ws` as the problem's own workspace type W (what its createWorkspace() made). Throws
/// std::invalid_argument when ws was made by another kind of problem (a programming error).
template <class W>
W &workspaceAs(ProblemWorkspace &ws) {
  auto *w = dynamic_cast<W *>(&ws);
  if (!w) throwForeignWorkspace();
  return *w;
}
template <class W>
const W &workspaceAs(const ProblemWorkspace &ws) {
  return workspaceAs<W>(const_cast<ProblemWorkspace &>(ws));
}

class Problem {
 public:
  virtual ~Problem() = default;

  /// A workspace for evaluations of this problem (ProblemWorkspace; a problem with caches
  /// returns its own derived type, preallocated for its dimension). Default: the base scratch.
  virtual std::unique_ptr<ProblemWorkspace> createWorkspace() const;

  // Every evaluation below is const and takes, first, a workspace this problem's
  // createWorkspace() made (a problem with caches reads it with workspaceAs<its type>).

  /// Number of unknowns N.
  virtual int dimension() const = 0;

  /// F(u, λ) → F (size N). False: (u, λ) is outside the domain.
  virtual bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const = 0;

  /// Exact F_u (N×N, Fu may be a block of a larger matrix) and F_λ (size N).
  virtual bool jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu,
                        VectorRef Flambda) const = 0;
  /// True if jacobian() writes every entry of Fu and Flambda, zeros included. The core then does
  /// not clear them before each call (the default, false: a problem may write its nonzeros only).
  virtual bool jacobianWritesAllEntries() const { return false; }

  /// d/dε [F_u, F_λ](u + ε·du, λ + ε·dlambda) at ε = 0. Default: central
  /// differences of jacobian(); override with the exact second derivative.
  virtual bool jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                             double dlambda, MatrixRef dFu, VectorRef dFlambda) const;

  // ---- optional: O(N) products (special points above the dense crossover) --------------
  // The locator's structured refinements evaluate their residuals with these products, so a
  // problem whose Jacobian has structure should override them with exact O(N) versions in its
  // own coordinates (the attainable accuracy of a refined point is that of these residuals).
  // Defaults: dense, through jacobian() (O(N²) memory and time); the second derivative by
  // central differences of jacobianTransposeApply() (only used in Newton matrices and in the
  // bifurcation equation, never in a residual).
  /// y = F_x x = F_u x_u + F_λ x_λ (x size N+1, y size N).
  virtual bool jacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                             VectorRef y) const;
  /// y = F_xᵀ w (w size N, y size N+1).
  virtual bool jacobianTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                                      VectorRef y) const;
  /// y = (F_xx[x, ·])ᵀ w = d/dε F_x(z + εx)ᵀ w at ε = 0, z = (u, λ) (x size N+1, w size N,
  /// y size N+1): the gradient of wᵀF_x x, i.e. y_j = wᵀF_xx[x, e_j].
  virtual bool secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                              ConstVectorRef w, VectorRef y) const;
  /// y = F_xx[x, z] = d/dε F_x(z0 + εx) z at ε = 0, z0 = (u, λ) (x, z size N+1, y size N): the
  /// second directional derivative as a vector (the post-buckling coefficients,
  /// branch_point_coefficients.h). Default: the matrix of jacobianDirectionalDerivative() times z
  /// (O(N²)); a structured problem overrides it with an exact O(N) product.
  virtual bool secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                     ConstVectorRef z, VectorRef y) const;
  /// F_xx[x, z] by central differences of jacobianApply() along x (the step of the default
  /// jacobianDirectionalDerivative()): O(N) where the products are, for overrides of
  /// secondDerivativeApply() whose exact form is not available for some of their rows.
  bool secondDerivativeApplyByDifferences(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                          ConstVectorRef z, VectorRef y) const;

  // ---- optional: mechanical stability ---------------------------------------------------
  virtual bool hasStabilityOperator() const { return false; }
  /// Symmetric H (n_s×n_s) and constraint rows C (m×n_s, m may be 0); resized by the problem.
  virtual bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const;
  /// Inertia of H on ker C and its `lowestCount` lowest eigenvalues (info.lowest, info.smallest).
  /// lowestCount = 0 asks for the inertia only: that is all the branch-point test needs, and for
  /// structured problems it is much cheaper than isolating eigenvalues (benchmarks/RESULTS.md).
  /// Default: dense eigen-decomposition of Zᵀ H Z (Z a basis of ker C), which gets every
  /// eigenvalue anyway. Problems with structure override this (e.g. an O(n) Sturm count).
  virtual bool stability(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int lowestCount,
                         StabilityInfo &info) const;
  /// Eigenvalues of H on ker C with ascending indices first … first + values.size() − 1 (the
  /// certified counting of spectral_monitor.h follows the two next to zero, indices ν − 1 and ν).
  /// False when the point is refused or an index is out of range. Default: dense
  /// eigen-decomposition of Zᵀ H Z; structured problems override it (e.g. isolation on O(n)
  /// Sturm counts of the shifted operator).
  virtual bool stabilityEigenvalues(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int first,
                                    VectorRef values) const;
  /// An upper bound on |dμ_i/dε| for every eigenvalue μ_i of H on ker C along
  /// (u + ε·du, λ + ε·dlambda) at ε = 0 (Weyl: |dμ_i| ≤ ‖dH‖₂ + 2‖ζ_i‖‖dC‖₂, ζ_i the multiplier of
  /// the eigenvector). Certified counting uses it to skip the eigenvalue slopes on steps where no
  /// eigenvalue can come near zero (spectral_monitor.h). False (the default): no bound offered,
  /// the slopes are measured at every point.
  virtual bool stabilityRateBound(ProblemWorkspace &, ConstVectorRef /*u*/, double /*lambda*/, ConstVectorRef /*du*/,
                                  double /*dlambda*/, double & /*bound*/) const {
    return false;
  }
  /// The rates dμ_i/dε along (u + ε·du, λ + ε·dlambda) at ε = 0 of the eigenvalues of H on ker C
  /// with indices first … first + values.size() − 1, `values` being those eigenvalues at (u, λ) as
  /// stabilityEigenvalues() returned them, into `slopes` (Hellmann–Feynman: dμ = vᵀ dH v + 2 ζᵀ dC v
  /// for the eigenvector v, ‖v‖ = 1, and its multiplier ζ, H v + Cᵀζ = μ v). False (the default):
  /// not offered, and the certified counting differences the eigenvalues along the tangent
  /// instead (spectral_monitor.h), one more eigenvalue search per point.
  virtual bool stabilitySlopes(ProblemWorkspace &, ConstVectorRef /*u*/, double /*lambda*/, ConstVectorRef /*du*/,
                               double /*dlambda*/, int /*first*/, ConstVectorRef /*values*/, VectorRef /*slopes*/) const {
    return false;
  }

  // ---- optional: structured linear algebra ---------------------------------------------
  /// A solver for the bordered Jacobian [[F_u, F_λ], [cᵀ]] that exploits the problem's
  /// structure (bordered_solver.h), or null (the default): the core then uses dense LU.
  virtual std::unique_ptr<BorderedSolver> makeStructuredSolver(ProblemWorkspace &ws) const;

  // ---- optional: domain boundaries ------------------------------------------------------
  virtual int boundaryCount() const { return 0; }
  /// g_k(u, λ): positive inside the admissible set, zero on its boundary.
  virtual double boundary(ProblemWorkspace &, int /*k*/, ConstVectorRef /*u*/, double /*lambda*/) const { return 1.0; }
  /// Every g_k(u, λ), k < g.size() ≤ boundaryCount(), into g: the tracer asks for all of them at
  /// every point. The default calls boundary(k) for each; an override must give the same values
  /// and saves the per-call overhead.
  virtual void boundaries(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef g) const;
  virtual std::string boundaryName(int k) const { return "boundary " + std::to_string(k); }

  // ---- optional: units ------------------------------------------------------------------
  /// Typical scales (ProblemScales). Default: all ones, i.e. the problem is already posed in
  /// O(1) variables. Evaluated once per Tracer.
  virtual ProblemScales scales() const { return ProblemScales::ones(dimension()); }
};

/// Inertia of the symmetric H restricted to ker C (C may have zero rows), by a dense
/// eigen-decomposition. `zeroTolerance` is relative to max(scale, ‖H‖) (‖H‖ the largest
/// |eigenvalue| on ker C, `scale` the typical eigenvalue, ProblemScales::stability), so the count
/// does not depend on the units of H. At most `lowestCount` lowest eigenvalues are kept in
/// info.lowest.
StabilityInfo projectedInertia(const Matrix& H, const Matrix& C, double zeroTolerance = 1e-13, int lowestCount = 3,
                               double scale = 1.0);

}  // namespace buckle::continuation
