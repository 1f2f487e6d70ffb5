// How much a small imperfection lowers the critical load of a branch point (Koiter 1945;
// Thompson & Hunt ch. 3): the knockdown |Δλ| of the limit point that replaces the branch point
// on the imperfect chain's path, from the Koiter coefficients (koiter.h) and the imperfection's
// first-order coupling e = ψᵀF_ε (ψᵀv = 1).
//
// The imperfection ε is a change of one prescribed end value (end.value[c] += ε: a transverse
// force or an end moment on a loaded coordinate, an eccentric displacement on a held one). The
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
  int coordinate = -1;       ///< the end coordinate perturbed: 0 x, 1 y, 2 φ
  std::string name;          ///< "Fx", "Fy", "Me" (a load) or "x", "y", "phi" (a held coordinate)
  double coupling = std::numeric_limits<double>::quiet_NaN();  ///< e = ψᵀF_ε per unit ε
  /// |Δλ| = prefactor·|ε|^exponent: ½ (asymmetric), ⅔ (subcritical); 0 with prefactor 0 when
  /// there is no limit point (supercritical, or no first-order coupling).
  double exponent = 0.0;
  double prefactor = 0.0;
  /// The sign of ε that has a limit point: +1 / −1 (asymmetric), 0 for both (subcritical) or
  /// none (exponent 0).
  int sign = 0;
  std::string error;         ///< why not valid
};

/// The knockdown of the branch point bp (coefficients k, valid) of `problem` for an imperfection
/// of end coordinate c (0 x, 1 y, 2 φ). The coupling counts as zero when |ψᵀF_ε| is below
/// 1e-10·|ψ||F_ε| (an imperfection orthogonal to the mode, e.g. a symmetric one for an
/// antisymmetric mode). Never throws.
ImperfectionSensitivity imperfectionSensitivity(const EquilibriumProblem& problem, const continuation::SpecialPoint& bp,
                                                const KoiterCoefficients& k, int c);

/// The predicted knockdown |Δλ| for an imperfection of size ε (0 when that sign has no limit point).
double knockdown(const ImperfectionSensitivity& s, double epsilon);

}  // namespace buckle::mechanics
