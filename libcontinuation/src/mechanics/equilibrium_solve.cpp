#include "buckle/mechanics/equilibrium_solve.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace buckle::mechanics {

NewtonResult solveEquilibrium(continuation::Problem& problem, const Eigen::Ref<const Eigen::VectorXd>& u0,
                              double lambda, const NewtonOptions& options) {
  const int N = problem.dimension();
  NewtonResult r;
  r.u = u0;
  Eigen::VectorXd F(N), Ftrial(N), Flambda(N), du(N), trial(N);
  Eigen::MatrixXd Fu(N, N);
  // Norms in the problem's own scales (Problem::scales()): the tolerances are relative, the
  // same for the same chain in any units.
  const continuation::ProblemScales scales = problem.scales();
  const bool scaled = scales.check(N).empty();
  const Eigen::VectorXd rowScale = scaled ? scales.residuals : Eigen::VectorXd::Ones(N);
  const Eigen::VectorXd unknownScale = scaled ? scales.unknowns : Eigen::VectorXd::Ones(N);
  auto residualNorm = [&](const Eigen::VectorXd& v) { return v.size() ? v.cwiseQuotient(rowScale).lpNorm<Eigen::Infinity>() : 0.0; };
  if (!problem.residual(r.u, lambda, F)) {
    r.residualNorm = std::numeric_limits<double>::infinity();
    return r;
  }
  double norm = residualNorm(F);
  const double target = options.tolerance * std::max(1.0, norm);
  r.residualNorm = norm;
  for (int it = 0; it < options.maxIterations; ++it) {
    if (norm <= target) {
      r.converged = true;
      return r;
    }
    r.iterations = it + 1;
    if (!problem.jacobian(r.u, lambda, Fu, Flambda)) return r;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(Fu);
    du = lu.solve(-F);
    if (!du.allFinite()) return r;
    double t = 1.0;
    bool accepted = false;
    for (int h = 0; h <= options.maxHalvings; ++h, t *= 0.5) {
      trial = r.u + t * du;
      if (problem.residual(trial, lambda, Ftrial)) {
        const double trialNorm = residualNorm(Ftrial);
        // Full steps are always taken near the solution (quadratic convergence), damped ones
        // only if they reduce the residual.
        if (std::isfinite(trialNorm) && (trialNorm < norm || (h == 0 && trialNorm <= 2 * norm && norm < 1e-6))) {
          accepted = true;
          break;
        }
      }
    }
    if (!accepted) return r;
    r.u = trial;
    F = Ftrial;
    norm = residualNorm(F);
    r.residualNorm = norm;
    if (t == 1.0 && du.cwiseQuotient(unknownScale).lpNorm<Eigen::Infinity>() <=
                        options.stepTolerance * std::max(1.0, r.u.cwiseQuotient(unknownScale).lpNorm<Eigen::Infinity>())) {
      r.converged = true;
      return r;
    }
  }
  r.converged = norm <= target;
  return r;
}

}  // namespace buckle::mechanics
