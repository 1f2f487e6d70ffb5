// Small oscillations of the chain about an equilibrium: natural frequencies and mode shapes.
// Conventions: conventions.h; the inertial model: dynamics.h (D2).
//
// Linearising (D2) about an equilibrium q* at rest (the velocity terms c(q, q̇) are quadratic in
// q̇ and drop out; no damping) under the same end wrench F (given loads and the reactions of the
// held coordinates) gives M(q*) δq̈ + H δq = C_hᵀ δr, C_h δq = 0, with
//     H = K_q − K_g(F)        the stability operator (eq 27, equilibrium_problem.h),
//     M = Tᵀ M_θ T            the joint-space mass matrix (dynamics.h),
//     C_h                     the held rows of the end Jacobian (eq 11) and e_iᵀ of locked joints.
// Modes δq = v e^{iωt} solve the symmetric-definite generalized eigenproblem on ker C_h
//     Zᵀ H Z y = ω² Zᵀ M Z y,  v = Z y,                                                     (V1)
// Z an orthonormal basis of ker C_h. ω² < 0 is an unstable equilibrium (growth rate √−ω²); the
// inertia of (V1) is that of Zᵀ H Z (Sylvester), so the lowest ω² crosses zero exactly where the
// lowest eigenvalue of the stability operator does: at every branch point and fold.
//
// Route (dense, O(n³); n = 1000 takes about a second per point: benchmarks/RESULTS.md):
// Z by the Householder reflectors of a rank-revealing QR of C_hᵀ (ZᵀHZ, ZᵀMZ in O(m n²)),
// Cholesky ZᵀMZ = LLᵀ, the standard form L⁻¹ZᵀHZL⁻ᵀ reduced to tridiagonal, its eigenvalues
// by implicit QL without vectors, and only the k wanted vectors by inverse iteration on the
// tridiagonal (O(n) each) mapped back through the reflectors (O(n²) each). No O(n) route: M is
// dense (a rank-2 semiseparable M_θ) and a shift-invert of H − σM would need its own structured
// factorization.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

/// The lowest modes of (V1) at one equilibrium.
struct VibrationModes {
  /// n − rank(C_h): how many modes the constrained chain has.
  int dimension = 0;
  /// The lowest min(count, dimension) eigenvalues ω² of (V1), ascending, in (time unit)⁻²: the
  /// stiffness unit over the mass unit times length² (rad²/s² with N, m, kg).
  Vector omegaSquared;
  /// Joint-angle mode shapes v (n × omegaSquared.size()), M-orthonormal (vᵀ M v = 1), each
  /// signed so that its largest |component| is positive; empty unless asked for.
  Matrix shapes;
};

/// The signed frequency of ω²: √ω² when ω² ≥ 0, −√−ω² (minus the growth rate) when unstable.
double signedFrequency(double omegaSquared);

/// Modes of one chain with given masses; reusable across the points of a branch (not
/// thread-safe: one per thread).
class VibrationAnalysis {
 public:
  /// Throws std::invalid_argument when the inertia data do not fit the chain (InertiaData::IsValid).
  VibrationAnalysis(const Chain& chain, const InertiaData& inertia);

  const Chain& chain() const { return chain_; }
  const InertiaData& inertia() const { return inertia_; }

  /// The lowest `count` modes at joint angles q under the total end wrench F (loads and
  /// reactions), with the end coordinates `held` (0 x, 1 y, 2 φ) fixed and the joints
  /// `lockedJoints` (0-based) locked. `shapes`: also the mode shapes. Throws
  /// std::invalid_argument for wrong sizes or indices; std::runtime_error if M is not positive
  /// definite on ker C_h to working precision.
  /// `bodyGenerator`: γ of the body loads at q (EquilibriumProblem::bodyLoadGenerator, eq B3),
  /// H = K_q − K_g with the generator h − γ; empty: none.
  VibrationModes modes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                       const std::vector<int>& lockedJoints, int count, bool shapes = true,
                       const Vector& bodyGenerator = Vector());

  /// Joint-space mass matrix M(q) (dense, n×n).
  void massMatrix(ConstVectorRef q, MatrixRef M);
  /// C_h at q: the held rows of the end Jacobian (eq 11), then e_iᵀ of every locked joint.
  Matrix constraintRows(ConstVectorRef q, const std::vector<int>& held, const std::vector<int>& lockedJoints) const;

 private:
  Chain chain_;
  InertiaData inertia_;
  InertialModel model_;  // M(q) (its massMatrix(); the end condition plays no part there)
};

}  // namespace buckle::mechanics
