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
// Two routes, the same results (to rounding; tests/mechanics/test_vibration_structured.cpp):
//  - dense, O(n³): Z by the Householder reflectors of a rank-revealing QR of C_hᵀ, Cholesky
//    ZᵀMZ = LLᵀ, the standard form L⁻¹ZᵀHZL⁻ᵀ reduced to tridiagonal, its eigenvalues by implicit
//    QL and only the k wanted vectors by inverse iteration on the tridiagonal mapped back.
//  - structured, O(n) per frequency (pencil_structure.h): locked joints are removed by restriction
//    to the free joints (the restricted H and M keep their chain form: K_g(i, j) = h_max(i,j) on
//    the free joints, the links between two free joints one rigid body), held end rows by
//    bordering (r ≤ 3); each ω² isolated by the pencil's counts and polished on its determinant
//    (warm-started by the previous call's values), each shape by inverse iteration with the same
//    O(n) solves at a shift just below ω², moved while the LDLᵀ meets a tiny pivot.
// The route is chosen by size (structured from kStructuredFrom joints; below, dense is faster:
// benchmarks/RESULTS.md) unless set by setRoute(); VibrationModes::route names the one used.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

/// Which algorithm computes the modes (the header comment).
enum class VibrationRoute { Automatic, Dense, Structured };

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
  /// The route that computed the modes (Dense or Structured).
  VibrationRoute route = VibrationRoute::Dense;
  /// Empty, or why the structured route handed (part of) the work to the dense one.
  std::string fallback;
};

/// The signed frequency of ω²: √ω² when ω² ≥ 0, −√−ω² (minus the growth rate) when unstable.
double signedFrequency(double omegaSquared);

/// Modes of one chain with given masses; reusable across the points of a branch (not
/// thread-safe: one per thread).
class VibrationAnalysis {
 public:
  /// Throws std::invalid_argument when the inertia data do not fit the chain (InertiaData::IsValid).
  VibrationAnalysis(const Chain& chain, const InertiaData& inertia);

  /// Chains of at least this many joints take the structured route under VibrationRoute::Automatic.
  static constexpr int kStructuredFrom = 64;
  /// Force a route (tests, benchmarks); Automatic (the default) chooses by size.
  void setRoute(VibrationRoute route) { route_ = route; }

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
  /// The same on a contact stretch: the joints of `contacts` locked, each of its vertices on
  /// the base wall held there (x_v = 0, friction-free) and each of its self contacts closed
  /// (g = 0) by its force: `forces` the wall forces (order of contacts.wall()) then the self
  /// contacts' (order of contacts.self()), ContactProblem::contactForces's layout. The rows ∇x_v,
  /// ∇g join C_h and the forces' −Σ μ ∂²x_v, −Σ μ ∂²g join H (wall_contact.h, self_contact.h), so
  /// (V1) is the linearisation about the constrained equilibrium while every contact stays
  /// closed. A held self contact's Hessian has a rank-2 part outside the chain structure: such a
  /// point takes the dense route (VibrationModes::fallback says so when the structured was due).
  /// Throws std::invalid_argument when `forces` has not one force per contact or a contact is not
  /// one of the chain's.
  VibrationModes modes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held, const ContactSet& contacts,
                       ConstVectorRef forces, int count, bool shapes = true, const Vector& bodyGenerator = Vector());

  /// Joint-space mass matrix M(q) (dense, n×n).
  void massMatrix(ConstVectorRef q, MatrixRef M);
  /// C_h at q: the held rows of the end Jacobian (eq 11), then e_iᵀ of every locked joint.
  Matrix constraintRows(ConstVectorRef q, const std::vector<int>& held, const std::vector<int>& lockedJoints) const;

 private:
  struct Structured;  // the O(n) route's workspace (vibration_structured.cpp)
  struct StructuredDeleter {  // (defined where Structured is complete)
    void operator()(Structured* p) const;
  };
  // Throws std::invalid_argument for a q, count or generator that does not fit the chain.
  void checkArguments(ConstVectorRef q, int count, const Vector& bodyGenerator) const;
  // Both routes take the contact rows (wall then self, below C_h's rows; empty: none) beside the
  // held and locked ones; the contact forces' generator terms are already in bodyGenerator. The
  // self contacts' rank-2 term (`coupling`, n×n; empty: none) sends the point to the dense route.
  // couplingColumns, couplingSigns: the self contacts' rank-2 terms as R E Rᵀ (selfConstraintTerms)
  VibrationModes route(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                       const std::vector<int>& lockedJoints, const Matrix& wallRows, int count, bool shapes,
                       const Vector& bodyGenerator, const Matrix& couplingColumns = Matrix(),
                       const Vector& couplingSigns = Vector());
  VibrationModes denseModes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                            const std::vector<int>& lockedJoints, const Matrix& wallRows, int count, bool shapes,
                            const Vector& bodyGenerator, const Matrix& couplingColumns, const Vector& couplingSigns);
  VibrationModes structuredModes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                 const std::vector<int>& lockedJoints, const Matrix& wallRows, int count, bool shapes,
                                 const Vector& bodyGenerator, const Matrix& couplingColumns, const Vector& couplingSigns);

  Chain chain_;
  InertiaData inertia_;
  InertialModel model_;  // M(q) (its massMatrix(); the end condition plays no part there)
  VibrationRoute route_ = VibrationRoute::Automatic;
  std::unique_ptr<Structured, StructuredDeleter> structured_;  // built on first use
};

}  // namespace buckle::mechanics
