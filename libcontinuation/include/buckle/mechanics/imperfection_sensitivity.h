// How much a small imperfection lowers the critical load of a branch point (Koiter 1945;
// Thompson & Hunt ch. 3): the knockdown |Δλ| of the limit point that replaces the branch point
// on the imperfect chain's path, from the Koiter coefficients (koiter.h) and the imperfection's
// first-order coupling e = ψᵀF_ε (ψᵀv = 1).
//
// The imperfection ε is a change of one prescribed end value (end.value[c] += ε: a transverse
// force or an end moment on a loaded coordinate, an eccentric displacement on a held one), or a
// preload asymmetry: the free lengths of one segment's springs (or of every segment's) move
// apart by ε with their mean kept, L1_0 += ε/2, L2_0 −= ε/2 (preloadAsymmetric()); then F_ε is
// the exact ∂²E/∂q_i∂ε of the affected joints (Segment::energyJetParameterDerivative). The
// reduced equation of the imperfect chain near (λc, ξ = 0), with μ = λ − λc,
//     τξ(μ − aξ − bξ²) + εe = 0,   i.e.  μ = aξ + bξ² + K/ξ,  K = −εe/τ,
// has its limit point where dμ/dξ = 0:
//   asymmetric (a ≠ 0):   |Δλ| = 2 √(|a e/τ|) |ε|^{1/2},  for the sign of ε with aK > 0 (the
//                         other sign passes smoothly);
//   symmetric subcritical: |Δλ| = 3 |b|^{1/3} |e/(2τ)|^{2/3} |ε|^{2/3}  (Koiter's 2/3 law), for
//                         both signs;
//   symmetric supercritical: no limit point, the path rises smoothly past λc.
// Leading order in ε: corrections are of relative order |ε|^{1/2} (asymmetric) or |ε|^{1/3}.
#pragma once

#include <limits>
#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/koiter.h"

namespace buckle::mechanics {

struct ImperfectionSensitivity {
  bool valid = false;
  int coordinate = -1;       ///< the end coordinate perturbed: 0 x, 1 y, 2 φ (−1: a preload asymmetry)
  /// A preload asymmetry: the segment (0-based) whose springs' free lengths differ by ε, −1 for
  /// every segment at once (or an end-coordinate imperfection).
  int segment = -1;
  /// "Fx", "Fy", "Me" (a load), "x", "y", "phi" (a held coordinate), "dL0" (a preload asymmetry)
  std::string name;
  double coupling = std::numeric_limits<double>::quiet_NaN();  ///< e = ψᵀF_ε per unit ε
  /// |Δλ| = prefactor·|ε|^exponent: ½ (asymmetric), ⅔ (subcritical); 0 with prefactor 0 when
  /// there is no limit point (supercritical, or no first-order coupling).
  double exponent = 0.0;
  double prefactor = 0.0;
  /// The sign of ε that has a limit point: +1 / −1 (asymmetric), 0 for both (subcritical) or
  /// none (exponent 0).
  int sign = 0;
  std::string message;       ///< why not valid
};

/// The knockdown of the branch point bp (coefficients k, valid) of `problem` for an imperfection
/// of end coordinate c (0 x, 1 y, 2 φ). The coupling counts as zero when |ψᵀF_ε| is below
/// 1e-10·|ψ||F_ε| (an imperfection orthogonal to the mode, e.g. a symmetric one for an
/// antisymmetric mode). Never throws.
ImperfectionSensitivity imperfectionSensitivity(const EquilibriumProblem& problem, const continuation::SpecialPoint& bp,
                                                const KoiterCoefficients& k, int c);

/// The knockdown of bp for a preload asymmetry of size ε (free lengths L1_0 + ε/2, L2_0 − ε/2) in
/// segment `segment` (0-based), or in every segment at once when segment = −1. F_ε exact, O(n).
ImperfectionSensitivity preloadImperfectionSensitivity(const EquilibriumProblem& problem,
                                                       const continuation::SpecialPoint& bp,
                                                       const KoiterCoefficients& k, int segment);

/// The segment whose preload asymmetry couples most strongly to the mode of bp (largest
/// |ψ_i ∂²E_i/∂q_i∂ε|: the largest knockdown of any single segment), −1 if k is not valid. O(n).
int mostSensitivePreloadSegment(const EquilibriumProblem& problem, const continuation::SpecialPoint& bp,
                                const KoiterCoefficients& k);

/// The preload asymmetry of preloadImperfectionSensitivity() applied: a copy of `chain` whose
/// segment `segment` (every segment when −1) has L1_0 + ε/2, L2_0 − ε/2. Throws
/// std::invalid_argument for a segment out of range or a free length that would not be positive.
Chain preloadAsymmetric(const Chain& chain, int segment, double epsilon);

/// The predicted knockdown |Δλ| for an imperfection of size ε (0 when that sign has no limit point).
double knockdown(const ImperfectionSensitivity& s, double epsilon);

}  // namespace buckle::mechanics
