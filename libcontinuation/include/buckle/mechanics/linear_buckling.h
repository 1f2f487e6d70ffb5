// Linear buckling of the chain from an unloaded configuration q0 (∂E/∂q(q0) = 0).
//
// Under the end load F = λ·d the Hessian of the total potential is K_q − λ·G with
// G = K_g(d) = d_x ∂²x/∂q² + d_y ∂²y/∂q² (eq 26–27). With the end coordinates in `end` held
// (clamped–pinned: y; free end: none) the critical load factors solve the symmetric generalised
// eigenproblem on ker J_h (Z an orthonormal basis):
//   (Zᵀ K_q Z) w = λ (Zᵀ G Z) w,   mode z = Z w (joint angles).
// For the straight chain under an axial load (J_loadedᵀ d ∈ span J_hᵀ) q0 stays an equilibrium
// for every λ and these are exact bifurcation loads; elsewhere they are the classical linearised
// estimate (pre-buckling rotations neglected). Directions in which G vanishes have λ = ∞ and
// are dropped. If K_q vanishes on ker J_h (κ = 0) every finite critical load is 0 (`degenerate`).
//
// Post-buckling shortening: along q = q0 + ε z the end moves along d by
//   δ(d·p) = ½ ε² zᵀ G z + O(ε³),  reported as shortening = −½ zᵀ G z (> 0 for a compressive
//   buckle); for three segments, δx = μ·b·q2² (eq 18, docs/mechanics.md erratum 3) with
//   μ = shortening/(ℓ0 z2²).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

struct BucklingMode {
  double lambda = 0.0;       ///< critical load factor: the end wrench is λ·d (Fx = λ for d = (1,0,0))
  Eigen::VectorXd mode;      ///< joint-angle mode, unit 2-norm, largest-|·| component positive
  std::string shape;         ///< modeShapeName(mode): "U" / "Z" / "other" for n = 3, "mode k" otherwise
  double shortening = 0.0;   ///< −½ zᵀ G z for the unit mode (see above)
  /// n = 3 only (NaN otherwise): μ of eq 18, shortening / (ℓ0 z2²); ratios α1 = z1/z2, α3 = z3/z2 (eq 15).
  double mu = std::numeric_limits<double>::quiet_NaN();
  double alpha1 = std::numeric_limits<double>::quiet_NaN();
  double alpha3 = std::numeric_limits<double>::quiet_NaN();
};

struct LinearBucklingResult {
  std::vector<BucklingMode> modes;  ///< finite critical loads, ascending |λ| (both signs)
  bool unloadedStable = false;      ///< K_q positive definite on ker J_h (at λ = 0)
  bool degenerate = false;          ///< K_q ≈ 0 on ker J_h: all finite critical loads are 0
  int droppedInfinite = 0;          ///< directions with G z = 0 (λ = ∞), not reported
  int constrainedDimension = 0;     ///< dim ker J_h
};

struct LinearBucklingOptions {
  Eigen::Vector3d direction = Eigen::Vector3d(1.0, 0.0, 0.0);  ///< load direction d (Me part unused)
  int count = -1;                    ///< keep the first `count` modes (−1: all)
  double gradientTolerance = 1e-8;   ///< reject q0 with ‖∂E/∂q‖∞ above this (relative to max K_q)
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// Critical loads and modes at q0 with the coordinates held by `end` (its values are unused).
/// Throws std::invalid_argument when q0 is not an unloaded equilibrium or has the wrong size.
/// Above kStructuredBucklingFrom segments, with options.count > 0 and K_q definite on ker J_h
/// (the stable or the uniformly unstable chain), the modes come from O(n) Sylvester counts on the
/// chain structure that isolate each load, finished by Rayleigh-quotient iteration through the
/// O(n) KKT solve: O(n) per mode instead of the dense O(n³) pencil, to rounding. Otherwise the
/// dense pencil is solved, and refused (std::invalid_argument) above kMaxDensePencil segments.
constexpr int kStructuredBucklingFrom = 64;
constexpr int kMaxDensePencil = 4000;

LinearBucklingResult linearBuckling(const Chain& chain, ConstVectorRef q0, const EndCondition& end,
                                    const LinearBucklingOptions& options = {});

/// Closed forms of the paper for three identical symmetric segments, clamped–pinned (eq 15, 17, 18).
struct AnalyticBuckling3 {
  double kappa = 0.0;                   ///< κ = k (b L0 − 2(b² − a²))
  double lambdaU = 0.0, lambdaZ = 0.0;  ///< (√21 − 14)/10, −(√21 + 14)/10
  double FxU = 0.0, FxZ = 0.0;          ///< λ κ / b (eq 17)
  double alpha1U = 0.0, alpha3U = 0.0;  ///< −(√21 + 11)/20, (√21 − 1)/4
  double alpha1Z = 0.0, alpha3Z = 0.0;  ///< −(−√21 + 11)/20, (−√21 − 1)/4
  double muU = 0.0, muZ = 0.0;          ///< (21 + √21)/20, (21 − √21)/20
};
AnalyticBuckling3 analyticClampedPinned3(double a, double b, double k, double L0);

}  // namespace buckle::mechanics
