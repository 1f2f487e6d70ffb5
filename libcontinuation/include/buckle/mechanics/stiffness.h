// Cartesian stiffness of the end position by the virtual joint method (eq 21–29).
//
// At an equilibrium q under the total end wrench F = (Fx, Fy, Me) (given loads and the
// reactions of held coordinates), a small change δF of the position force moves the end by
// δp = C_F δF; K_F = C_F⁻¹. Joint increments obey (K_q − K_g(F)) δq = Jᵀ δF (eq 28), with the
// end rotation either free (δMe = 0) or held (δφ = 0, Me a Lagrange multiplier). Hence
//   rotation free:  C_F = J_p (K_q − K_g)⁻¹ J_pᵀ                             (eq 29; F = 0: eq 21)
//   rotation held:  C_F = J_p P J_pᵀ, P the inverse of K_q − K_g on ker J_φ.
// Both are evaluated through bordered (KKT) solves, never by inverting K_q − K_g itself:
//   C_F from [[K_q − K_g, J_φᵀ], [J_φ, 0]] X = [J_pᵀ; 0] (no border when the rotation is free),
//   which is regular whenever K_q − K_g is regular on ker J_φ — in particular where K_q − K_g
//   alone is singular but the held rotation removes the singular direction;
//   where that fails (a force-control limit / bifurcation point: infinite compliance), K_F from
//   the position-held system [[K_q − K_g, J_hᵀ], [J_h, 0]] (J_h = J_p, or (J_p; J_φ)), whose
//   inverse has −K_F as the position block of its multiplier corner and stays finite there.
// A singular C_F (a direction the joints cannot move the end in, e.g. x at the straight
// configuration) is reported as `rigid` with K_F NaN; a singular K_F as `singular` with C_F NaN.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "buckle/mechanics/chain.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

struct CartesianStiffness {
  Eigen::Matrix2d stiffness = Eigen::Matrix2d::Zero();   ///< K_F: δF = K_F δp (rows/cols x, y)
  Eigen::Matrix2d compliance = Eigen::Matrix2d::Zero();  ///< C_F = K_F⁻¹ (NaN when K_F is singular)
  /// Rounding bound of each entry of C_F (ε κ |J_i| |X_j| of the bordered solve); an entry of
  /// C_F below its bound is reported as exactly 0 (a rigid direction, or a pole of 1/C_ii).
  Eigen::Matrix2d complianceAccuracy = Eigen::Matrix2d::Zero();
  /// Rotation free and C_F defined (NaN otherwise): the end's rotational compliance
  /// C_φφ = J_φ (K_q − K_g)⁻¹ J_φᵀ (δφ per δMe with the end forces unchanged, on the joint
  /// constraints), its rounding bound as complianceAccuracy's, and the end's rotational stiffness
  /// K_φ = 1/C_φφ (inf where C_φφ is 0 to its bound: a rotation the joints cannot make).
  double rotationalCompliance = std::numeric_limits<double>::quiet_NaN();
  double rotationalComplianceAccuracy = std::numeric_limits<double>::quiet_NaN();
  double rotationalStiffness = std::numeric_limits<double>::quiet_NaN();
  bool rotationHeld = false;
  /// K_F is singular: infinite compliance in some direction (C_F NaN). Set where K_q − K_g is
  /// singular on ker J_φ (force-control limit / bifurcation point); K_F is then still given.
  bool singular = false;
  /// C_F is singular: infinite stiffness in some direction (K_F NaN), e.g. the axial direction
  /// of the straight chain, whose end cannot move along x to first order.
  bool rigid = false;
  /// Both C_F and K_F defined, K_F symmetric positive definite.
  bool positiveDefinite = false;
  /// Number of negative eigenvalues of K_q − K_g on ker J_φ (rotation held) or on the whole
  /// space (rotation free): the equilibrium is stable under force control iff this is 0 and
  /// `singular` is false.
  int negativeDirections = 0;
  /// Smallest eigenvalue of K_q − K_g on that space.
  double smallestEigenvalue = 0.0;
};

struct StiffnessOptions {
  /// Reciprocal condition number below which a matrix is treated as singular.
  double singularTolerance = 1e-12;
  /// Also compute negativeDirections / smallestEigenvalue (a dense eigen-decomposition).
  bool computeInertia = true;
  /// γ of the body loads at q (body_loads.h, eq B3; EquilibriumProblem::bodyLoadGenerator): the
  /// Hessian is K_q − K_g with the generator h − γ. Empty: no body loads.
  Vector bodyGenerator;
  /// dγ along the direction of loadedStiffnessDerivative (eq B5). Empty: none.
  Vector bodyGeneratorRate;

  /// Empty when valid for a chain of `segments`, else what is wrong, the field named by its path.
  std::string validate(int segments, const std::string& prefix = "") const;
  bool IsValid(int segments, std::string* why) const {
    return continuation::reportValidity(validate(segments), why);
  }
};

/// Loaded stiffness K_F at (q, F) (eq 24–29); rotation free or held.
CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld = false,
                                   const StiffnessOptions& options = {});
/// Same, with the joint increments also constrained by E δq = 0 (the rows of `jointConstraints`,
/// n columns; e.g. joints locked at a limit, contact.h): K_q − K_g is then inverted on ker E (and
/// ker J_φ when the rotation is held), and negativeDirections / smallestEigenvalue are on that space.
CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   const Eigen::Ref<const Matrix>& jointConstraints,
                                   const StiffnessOptions& options = {});
/// Same, with the end rotation held iff `end` holds φ (the held x / y only decide which forces
/// are reactions in F, not the definition of K_F).
CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, const EndCondition& end,
                                   const StiffnessOptions& options = {});
/// Derivative of the end Jacobian J (rows (−S_j, C_j, 1), eq 5) along a joint increment dq:
/// dS_j = Σ_{m≥j} ℓ_m cos θ_m θ̇_m, dC_j = −Σ_{m≥j} ℓ_m sin θ_m θ̇_m, θ̇_m = Σ_{i≤m} dq_i; the φ row
/// is constant (zero). `data` from forwardKinematics at q; dJ is 3×n.
void endJacobianDerivative(const Chain& chain, const ChainData& data, ConstVectorRef dq, MatrixRef dJ);

/// K_F of loadedStiffness and its exact directional derivative dK_F along (dq, dF) (the total end
/// wrench moving with the joints, e.g. a tangent of an equilibrium branch). With the bordered
/// form of loadedStiffness, B = [[H, J_φᵀ], [J_φ, 0]], X = B⁻¹[J_pᵀ; 0], C_F = J_p X_q:
///   dC_F = dJ_p X_q + X_qᵀ dJ_pᵀ − X_qᵀ dH X_q   (J_φ = (1 … 1) is constant),
///   dK_F = −K_F dC_F K_F,
/// dH = diag(dK_q) dq − dK_g (eq 27 differentiated: dh_m = −dFx C_m − Fx dC_m − dFy S_m − Fy dS_m).
/// False where C_F or K_F is singular (no derivative there).
bool loadedStiffnessDerivative(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                               ConstVectorRef dq, const Wrench& dF, Eigen::Matrix2d& K, Eigen::Matrix2d& dK,
                               const StiffnessOptions& options = {});

/// K_F and dK_F of loadedStiffnessDerivative in O(n): K_q − K_g through the chain structure
/// (chain_structure.h; the body loads' γ in its generator), X by bordered solves (J_φ the border
/// where the rotation is held) and Xᵀ dH X by prefix sums over dH's generator form. The same values
/// to rounding; false where C_F or K_F is singular to singularTolerance, or K_q − K_g itself to
/// working precision. dK null: K_F alone (dq unused).
bool structuredStiffnessDerivative(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   ConstVectorRef dq, const Wrench& dF, Eigen::Matrix2d& K, Eigen::Matrix2d* dK,
                                   const StiffnessOptions& options = {});
/// Chains of this many segments or more take the O(n) stiffness routes (this one, the branch
/// reports' structuredContactStiffness): below, the dense solves cost less.
constexpr int kStructuredStiffnessFrom = 64;

/// Unloaded stiffness K_F⁰ = (J K_q⁻¹ Jᵀ)⁻¹ (eq 21–23): loadedStiffness with F = 0.
CartesianStiffness unloadedStiffness(const Chain& chain, ConstVectorRef q, bool rotationHeld = false,
                                     const StiffnessOptions& options = {});

}  // namespace buckle::mechanics
