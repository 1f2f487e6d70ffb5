// Stiffness extrema along an equilibrium branch, located: quasi-buckling (paper §III, Fig 10).
//
// A measure m of the loaded stiffness K_F (eq 29) — K_xx, K_yy or the smallest eigenvalue of
// K_F — has a local minimum along a branch x(s) = (u(s), λ(s)) where g(s) = dm/ds = 0. g is
// exact: dm/ds = m'(K_F)·dK_F with dK_F the directional derivative of K_F along the branch
// tangent (loadedStiffnessDerivative, stiffness.h), the tangent from the bordered system
// [[F_u, F_λ], [nᵀ]] t = e. Between two branch points a, b where g changes sign the branch is
// parametrised by the hyperplanes nᵀ(x − a − τ(b − a)) = 0, n = b − a (in the problem's units,
// scaled_problem.h); each evaluation of g(τ) is a point corrected onto the branch (Corrector on
// that Keller system), and the root of g is found by Brent's safeguarded secant/bisection, so
// the result depends on neither the points' spacing nor the units, only on where g vanishes.
#pragma once

#include <Eigen/Core>
#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

/// Which stiffness a KMIN event watches.
enum class StiffnessMeasure {
  Kxx,             ///< K_F(0, 0): stiffness along x (Fig 10a)
  Kyy,             ///< K_F(1, 1): stiffness along y (Fig 10b)
  MinEigenvalue,   ///< the smallest eigenvalue of K_F: the softest direction of the end
};

/// "Kxx", "Kyy", "Kmin" (the scene spelling).
const char* toString(StiffnessMeasure measure);
/// Inverse of stiffnessMeasureName; false for an unknown name.
bool parseStiffnessMeasure(const std::string& name, StiffnessMeasure& measure);

/// The measure of K (symmetric 2×2).
double stiffnessMeasure(const Eigen::Matrix2d& K, StiffnessMeasure measure);
/// Its derivative along dK: dK(0,0), dK(1,1), or vᵀ dK v with v the unit eigenvector of the
/// smallest eigenvalue (simple eigenvalue).
double stiffnessMeasureDerivative(const Eigen::Matrix2d& K, const Eigen::Matrix2d& dK, StiffnessMeasure measure);

/// The measure at an equilibrium (u, λ) of `problem` and its exact rate along (du, dλ).
struct StiffnessRate {
  bool valid = false;   ///< false: K_F or C_F singular there (no measure / derivative)
  double value = 0.0;
  double rate = 0.0;
  Eigen::Matrix2d K = Eigen::Matrix2d::Zero();
};
StiffnessRate stiffnessRate(const EquilibriumProblem& problem, continuation::ConstVectorRef u, double lambda,
                            continuation::ConstVectorRef du, double dlambda, StiffnessMeasure measure);

struct StiffnessExtremumOptions {
  /// Stop when the bracket of τ (the fraction of the way from a to b) is this small relative to
  /// one; below rounding, Brent stops on its own.
  double tolerance = 1e-15;
  int maxEvaluations = 100;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

struct StiffnessExtremum {
  bool located = false;
  Vector u;                   ///< unknowns of the problem at the minimum
  double lambda = 0.0;
  double value = 0.0;         ///< the measure there
  double rate = 0.0;          ///< dm/ds there, per unit of the bracket's hyperplane parameter
  Eigen::Matrix2d K = Eigen::Matrix2d::Zero();
  double accuracy = 0.0;      ///< |Δλ| between the last two iterates bracketing the root
  double residual = 0.0;      ///< corrector residual (scaled ‖G‖) at the returned point
  int evaluations = 0;
  std::string message;        ///< why not located
};

/// Locates the minimum of `measure` between two points a, b of a branch of `problem` (their u,
/// λ; tangents are not used) where dm/ds < 0 at a and > 0 at b (along a → b). Never throws for a
/// numerical condition: located = false with a message instead.
StiffnessExtremum locateStiffnessMinimum(EquilibriumProblem& problem, const continuation::ContinuationPoint& a,
                                         const continuation::ContinuationPoint& b, StiffnessMeasure measure,
                                         const StiffnessExtremumOptions& options = {});

}  // namespace buckle::mechanics
