// Koiter's post-buckling coefficients of a branch point of the chain, on any branch (the straight
// chain's or a bent one's, uniform or not): the generic reduction (branch_point_coefficients.h)
// with the amplitude measured in the chain's own words. ξ = m·(q − q_p(λ)) is the amplitude of
// the unit joint-angle mode m (|m| = 1, its largest component positive) relative to the branch
// being traced (the parent q_p), in radians, so the bifurcated branch is
//     λ(ξ) = λc + aξ + bξ² + O(ξ³)
// in the traced parameter's units (a force, a torque or a coordinate, whatever λ moves).
// Where b is zero to its accuracy (a degenerate pitchfork, e.g. the DP of the design map) the
// next term decides: λ = λc + c₄ξ⁴, from the child branch itself (childBranchExpansion).
//
// Which way it goes: F_u is symmetric (equilibrium_problem.h), so ψ ∝ v and the eigenvalue of
// F_u that vanishes at λc moves like τ(λ − λc) (τ = ψᵀF_xx[e, d], ψᵀv = 1): the parent gains a
// negative eigenvalue on the side −sign(τ). A symmetric point (a = 0 to rounding) is
// supercritical when the bifurcated branch lies on that side (b·τ < 0: it takes over the
// parent's stability, benign buckling), subcritical when it lies on the stable side (b·τ > 0:
// unstable, the chain jumps). a ≠ 0 is an asymmetric (transcritical) point: one half of the
// bifurcated branch is always on the stable side (dangerous, imperfection_sensitivity.h).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/branch_point_coefficients.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

enum class KoiterKind { Supercritical, Subcritical, Asymmetric };

/// "supercritical", "subcritical", "asymmetric".
const char* toString(KoiterKind kind);

struct KoiterCoefficients;
/// The kind as reported: toString(kind), prefixed "degenerate " at a degenerate pitchfork decided
/// by its quartic term, "degenerate (undecided)" when that term is zero to its accuracy too.
std::string postBucklingName(const KoiterCoefficients& k);

struct KoiterCoefficients {
  bool valid = false;
  double lambda = std::numeric_limits<double>::quiet_NaN();  ///< λc, the traced parameter
  double a = std::numeric_limits<double>::quiet_NaN();       ///< dλ/dξ (λ units per rad)
  double b = std::numeric_limits<double>::quiet_NaN();       ///< ½ d²λ/dξ² (λ units per rad²)
  double transversality = std::numeric_limits<double>::quiet_NaN();  ///< τ (file comment)
  /// What |b| may be in error by (BranchPointCoefficients::bAccuracy: its terms' rounding and
  /// the point's location error).
  double bAccuracy = std::numeric_limits<double>::quiet_NaN();
  /// A symmetric point with |b| ≤ bAccuracy: a degenerate pitchfork. The quartic term of the
  /// child, λ = λc + bξ² + c₄ξ⁴ (childBranchExpansion), then decides the kind, by the same rule
  /// with c₄ for b; `decided` false when |c₄| is below its accuracy too (kind then by b's sign).
  /// The traced branch is vertical at the point (it reached the branch point along a bifurcated
  /// branch, at that branch's tip): the coefficients are taken with the other branch through the
  /// point as the parent, the traced one being its child.
  bool parentIsOther = false;
  bool degenerate = false;
  bool decided = true;
  double c4 = std::numeric_limits<double>::quiet_NaN();          ///< λ units per rad⁴
  double c4Accuracy = std::numeric_limits<double>::quiet_NaN();
  KoiterKind kind = KoiterKind::Supercritical;
  Eigen::VectorXd mode;   ///< the unit joint-angle mode m (size n)
  Eigen::VectorXd v;      ///< null vector of F_u (size N), its joint part m
  Eigen::VectorXd psi;    ///< left null vector, ψᵀv = 1
  Eigen::VectorXd parentSlope;  ///< du_p/dλ of the traced branch at the point (size N)
  std::string message;    ///< why not valid
};

/// The coefficients at the branch point bp located on a branch of `problem` (free joints: not in
/// contact), at any chain length: above continuation::kDenseCoefficientDimension unknowns (or
/// with `algebra` Structured) in O(n) through the chain's exact second-derivative products and
/// its bordered solver (branch_point_coefficients.h). The structured solver eliminates through
/// the joint block K_q − K_g, so a chain with no held end coordinate (where that block itself is
/// singular at its branch points) is reported with the solver's reason above the solver's dense
/// fallback size. Never throws: failures are reported in `error`.
KoiterCoefficients koiterCoefficients(EquilibriumProblem& problem, const continuation::SpecialPoint& bp,
                                      continuation::CoefficientAlgebra algebra = continuation::CoefficientAlgebra::Automatic);

}  // namespace buckle::mechanics
