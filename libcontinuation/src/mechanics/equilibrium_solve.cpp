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
  if (!problem.residual(r.u, lambda, F)) {
    r.residualNorm = std::numeric_limits<double>::infinity();
    return r;
  }
  double norm = F.size() ? F.lpNorm<Eigen::Infinity>() : 0.0;
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
        const double trialNorm = Ftrial.lpNorm<Eigen::Infinity>();
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
    norm = F.lpNorm<Eigen::Infinity>();
    r.residualNorm = norm;
    if (t == 1.0 && du.lpNorm<Eigen::Infinity>() <= options.stepTolerance * std::max(1.0, r.u.lpNorm<Eigen::Infinity>())) {
      r.converged = true;
      return r;
    }
  }
  r.converged = norm <= target;
  return r;
}

}  // namespace buckle::mechanics
