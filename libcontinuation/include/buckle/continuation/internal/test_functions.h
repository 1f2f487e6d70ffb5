// Test functions: scalar quantities along a branch whose sign changes bracket special points.
//
//   fold          λ-component of the tangent (t_λ = 0 exactly at a simple fold);
//   branch point  det [[F_u, F_λ], [tᵀ]] (regular at folds, simple zero at simple BPs), and the
//                 inertia of the stability operator, which also sees even crossings (a double
//                 zero, two BPs inside one step) that leave the determinant sign unchanged;
//   location      the minimally augmented ψ (Govaerts 2000), a well-scaled smooth stand-in for
//                 the determinant, whose magnitude is ~ the smallest singular value.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"

#include <Eigen/LU>
#include <string>

namespace buckle::continuation {

/// Completes a point whose u and λ are set: tangent (oriented by a reference direction), the
/// fold and determinant tests, and the stability inertia (plus `lowestEigenvalues` lowest
/// eigenvalues). The bordered solves go through `solver` (dense or the problem's structured
/// one; not owned). Workspaces are sized once.
class PointEvaluator {
 public:
  PointEvaluator(const BoundProblem &problem, BorderedSolver &solver, bool computeStability, int lowestEigenvalues = 3);

  /// Tangent from [[F_u, F_λ], [referenceᵀ]] t = e_{N+1}, normalised, so tᵀreference > 0.
  /// False when the problem refuses the point or the bordered matrix is exactly singular; in
  /// the singular case (lastWasSingular()) the point still gets determinantSign = 0, the
  /// normalised reference as tangent and its stability, so test functions stay evaluable.
  /// The stability with the evaluator's lowest eigenvalues, or its inertia alone (inertiaOnly:
  /// the locator's samples, whose tests read the counts).
  bool complete(ContinuationPoint &point, ConstVectorRef reference, bool inertiaOnly = false);
  bool lastWasSingular() const { return singular_; }

  /// Writes [[F_u, F_λ], [tᵀ]] into A ((N+1)×(N+1)).
  bool borderedJacobian(ConstVectorRef u, double lambda, ConstVectorRef t, MatrixRef A);

  bool stabilityEnabled() const { return stability_; }
  const BoundProblem &problem() { return problem_; }

 private:
  BoundProblem problem_;
  BorderedSolver &solver_;
  int n_;
  bool stability_;
  int lowestEigenvalues_;
  bool singular_ = false;
  Vector rhs_, solution_;
};

/// ψ from [[A, b], [cᵀ, 0]] [v; ψ] = [0; 1]. b and c are frozen at a reference matrix (its
/// left/right singular vectors of the smallest singular value), so ψ is a smooth function
/// along the step with a simple zero where A is singular.
class MinimallyAugmentedTest {
 public:
  void initialize(const Matrix &referenceA);
  /// ψ for A; v (size of A) receives the approximate null vector when non-null.
  bool evaluate(const Matrix &A, double &psi, Vector *v = nullptr);

 private:
  Vector b_, c_;
  Matrix augmented_;
  Vector rhs_, solution_;
};

/// What changed between two consecutive points.
struct IntervalCrossings {
  bool fold = false;               ///< foldBetween: t_λ changed sign, confirmed by the determinants
  bool determinantChange = false;  ///< bordered determinant changed sign
  int inertiaChange = -1;          ///< |Δ negative eigenvalues|; -1 when not known at both ends
  int branchPointCrossings = 0;    ///< eigenvalue crossings not explained by the fold
};

/// A fold between a and b: t_λ changed sign and the change is not rounding noise. By Cramer's
/// rule t_λ = det F_u / det [[F_u, F_λ], [tᵀ]] (the bordered matrix with the point's own tangent,
/// whose sign is determinantSign), so t_λ changes sign exactly when one of det F_u and the
/// bordered determinant does: at a simple fold det F_u does, at a simple BP the bordered one.
/// Where both ends carry the stability inertia ν, whose parity follows sign det F_u (for the
/// KKT form F_u = [[H, Cᵀ], [C, 0]] of a gradient problem, or H = ±F_u), a t_λ sign change that
/// neither the parity of Δν nor the determinant confirms is noise: on a branch traced in steps
/// far below its λ scale (the children of a branch point at n = 10 000) t_λ ~ λ''·s lies below
/// the rounding of the tangent's λ component, and its sign is arbitrary. Without the inertia
/// (or with a singular end) the sign change alone decides, as before.
bool foldBetween(const ContinuationPoint &a, const ContinuationPoint &b);

IntervalCrossings classifyInterval(const ContinuationPoint &a, const ContinuationPoint &b, bool detectFolds,
                                   bool detectBranchPoints);

/// Smallest singular value of F_x = [F_u, F_λ] and its right/left singular vectors: an
/// orthonormal basis of the (approximate) kernel from a dense SVD. Allocates; used at special
/// points only.
struct KernelInfo {
  Vector singularValues;  ///< ascending, size N+1; [0] = 0 is the structural extra kernel direction
  Matrix right;           ///< columns: right singular vectors, same order ((N+1)×(N+1))
  Matrix left;            ///< columns: left singular vectors; left.col(k) pairs with singularValues[k + 1]
};
bool jacobianKernel(const BoundProblem &problem, ConstVectorRef u, double lambda, KernelInfo &info);

/// Tangents of the two branches crossing at a simple branch point: the real roots d ∈ span(k₁, k₂)
/// (an orthonormal basis of ker F_x) of the algebraic bifurcation equation ψᵀF_xx[d, d] = 0,
/// ψ the left null vector. Second derivatives from Problem::jacobianDirectionalDerivative.
/// False (with the reason) when they are unavailable, the quadratic form vanishes, or its roots
/// are complex (an isolated point, no crossing branches).
bool bifurcationDirections(const BoundProblem &problem, ConstVectorRef u, double lambda, ConstVectorRef psi,
                           ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2, std::string *why = nullptr);
/// The same from O(N) products (Problem::secondDerivativeTransposeApply), with no N×N matrix:
/// for problems above the dense crossover.
bool bifurcationDirectionsApplied(const BoundProblem &problem, ConstVectorRef u, double lambda, ConstVectorRef psi,
                                  ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2,
                                  std::string *why = nullptr);

}  // namespace buckle::continuation
