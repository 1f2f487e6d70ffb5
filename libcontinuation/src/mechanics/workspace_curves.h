// The bounding curves of a workspace map (workspace_map.h) traced from their starts on the grid.
#pragma once

#include <vector>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/mechanics/workspace_map.h"

namespace buckle::mechanics::detail {

/// The core's corrector in a problem's scaled variables (scaled_problem.h): its tolerances are
/// relative, the same in every unit system.
class ScaledCorrector {
 public:
  explicit ScaledCorrector(const continuation::BoundProblem& problem)
      : units_(problem.problem().scales()), scaled_(problem, units_), corrector_(scaled_.bound()) {}
  /// F(u, λ) = 0 at fixed λ from u0; false when it does not converge.
  bool atFixedParameter(ConstVectorRef u0, double lambda, Vector& u) {
    const Vector& D = units_.scales().unknowns;
    Vector us(u0.size());
    const bool ok = corrector_.solveAtFixedParameter(u0.cwiseQuotient(D), lambda / units_.parameter(), us).converged;
    u = us.cwiseProduct(D);
    return ok;
  }
  /// F = 0 with coordinate `index` of x = (u, λ) kept at x0's; false when it does not converge.
  bool withFixedCoordinate(ConstVectorRef x0, int index, Vector& x) {
    const int N = int(x0.size()) - 1;
    Vector xs(N + 1), scale(N + 1);
    for (int i = 0; i <= N; ++i) scale[i] = units_.state(i);
    const bool ok = corrector_.solveWithFixedCoordinate(x0.cwiseQuotient(scale), index, xs).converged;
    x = xs.cwiseProduct(scale);
    return ok;
  }

 private:
  continuation::UnitScaling units_;
  continuation::BoundScaledProblem scaled_;
  continuation::Corrector corrector_;
};

/// A point on a bounding curve found on the grid: x = (q, u₂, u₁) near the curve, corrected with
/// coordinate `fixed` of x kept (n: u₂ on a row, n + 1: u₁ on a column).
struct CurveStart {
  InputPlaneCurveProblem::Condition condition = InputPlaneCurveProblem::Condition::Fold;
  int boundary = -1;  ///< Limit: the equilibrium problem's boundary index
  std::string name;   ///< the curve's name ("fold", "singular", "joint 2 at q_max")
  Vector x;
  int fixed = 0;
};

/// Traces every start not already on a traced curve of its name (both ways, within the box),
/// at most options.maxCurves per kind, and appends the curves to map.curves.
void traceBoundaryCurves(const InputPlane& plane, const WorkspaceMapOptions& options,
                         const std::vector<CurveStart>& starts, WorkspaceMap& map);

}  // namespace buckle::mechanics::detail
