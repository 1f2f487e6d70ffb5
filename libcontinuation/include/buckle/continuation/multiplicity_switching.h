// Branch switching at branch points of multiplicity m ≥ 2 (m eigenvalues cross zero together, e.g.
// the unloaded straight chain with vanishing joint stiffness, κ = 0, where m = n − 1).
//
// At such a point x₀ the kernel of F_x = [F_u, F_λ] is (m+1)-dimensional: the parent tangent t and
// φ₁ … φ_m; the left kernel is m-dimensional (ψ₁ … ψ_m). The branches through x₀ have tangents in
// the kernel that solve the algebraic bifurcation equation (Lyapunov–Schmidt, Golubitsky–Schaeffer):
//  - quadratic:  ψ_jᵀ F_xx[d, d] = 0, j = 1 … m, d = K z (K = [t φ₁ … φ_m]), |z| = 1; the parent's t
//                is one root, the others are the children;
//  - cubic, when the quadratic form vanishes on span φ (a symmetry q → −q makes F odd in the
//    kernel directions): along x = x₀ + εΦβ + ε²(τ t + w₂) + O(ε³),
//                τ (Bβ)_j + ψ_jᵀ(F_xx[Φβ, w₂] + ⅙ F_xxx[Φβ, Φβ, Φβ]) = 0,   |β| = 1,
//    B_ji = ψ_jᵀ F_xx[φ_i, t], w₂ = −F_x⁺ ½F_xx[Φβ, Φβ] (⊥ kernel).
// Either is a small polynomial system on the sphere, solved by Newton from many starts (a Fibonacci
// lattice on the half-sphere; roots identified up to sign). Each root d is a solution direction:
// two half-branches (±d), traced by switchBranch. The count predicted (two per direction) and the
// count found (children that left the point along their own direction) go into the special point.
// The kernel comes from a dense SVD of F_x up to N = 400, above from bordered solves
// (structuredMultipleKernel), and the second derivatives as O(N) products there
// (Problem::secondDerivativeApply) instead of N×(N+1) matrices.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/tracer.h"

#include <string>
#include <vector>

namespace buckle::continuation {

/// Solution directions of the reduced bifurcation equation at a point of multiplicity m.
struct ReducedBifurcation {
  int kernelDimension = 0;          ///< m: dimension of ker F_u-part (dim ker F_x − 1)
  int order = 0;                    ///< 2 (quadratic) or 3 (cubic) equation solved
  std::vector<Vector> directions;   ///< unit (N+1) tangents of the children (the parent excluded), problem units
  std::vector<double> curvatures;   ///< cubic: τ along each direction (parameter offset ε²τ·t), else 0
  std::string note;                 ///< how it was obtained, or why it failed
};

/// Up to this N a point of multiplicity m ≥ 2 gets its kernel from one dense SVD of F_x (the
/// locator's verification that ker F_x is (m+1)-dimensional, and the reduced equation below):
/// such points are rare, and the SVD also shows the kernel's dimension. Simple points switch to
/// O(N) algebra far earlier (TracerOptions::maxDenseLocationDimension).
constexpr int kMaxDenseMultiplePointDimension = 400;

/// The m-dimensional reduced bifurcation equation at bp (u, λ, tangent set) and all its solution
/// directions. False (with note) when the kernel is not (m+1)-dimensional to `kernelTolerance`
/// (relative to the largest singular value, or to the problem's unit above the crossover) or no
/// direction is found. Above N = maxDenseDimension the kernels come from structuredMultipleKernel
/// instead of a dense SVD (through the problem's structured solver when it takes m + 1 borders,
/// else dense LU).
bool reducedBifurcationDirections(const BoundProblem &problem, const SpecialPoint &bp, int multiplicity,
                                  ReducedBifurcation &out, double kernelTolerance = 1e-7,
                                  int maxDenseDimension = kMaxDenseMultiplePointDimension);

/// The kernel of F_x = [F_u, F_λ] at a point of multiplicity m without a dense SVD: K ((N+1)×(m+1))
/// and Psi (N×m), orthonormal, from bordered solves with m + 1 borders through `solver`
/// (BorderedSolver::factorGeneral, O(N) for a structured problem; needs maxGeneralBorder() ≥ m + 1):
/// G = [[F_x, B], [Cᵀ, 0]] is regular when B spans a complement of range F_x and C is transversal to
/// ker F_x, and then G [V; Γ] = [0; I] gives F_x V = −BΓ with Γ = 0 exactly at the point: V spans the
/// kernel (Gᵀ likewise the left kernel). A first pass with fixed generic borders, a second with
/// the first's kernels as borders (then G is as well conditioned as the point allows); solves
/// refined on the problem's own products (RefinedBorderedSystem). `residual` receives
/// max(‖F_x K‖, ‖Psiᵀ F_x‖) column-wise. False with `why` when a factorization fails.
bool structuredMultipleKernel(const BoundProblem &problem, BorderedSolver &solver, ConstVectorRef u, double lambda,
                              int m, Matrix &K, Matrix &Psi, double &residual, std::string *why = nullptr);

/// Children of the multiple point bp, both sides of every direction, traced with `tracer`; sets
/// bp.branchesPredicted (2 per direction) and bp.branchesFound (children that left bp along their
/// own predicted direction, closer to it than to any other). `how` says what was done.
std::vector<Branch> switchMultiple(Tracer &tracer, SpecialPoint &bp, const BranchSwitchingOptions &options,
                                   std::string *how = nullptr);

}  // namespace buckle::continuation
