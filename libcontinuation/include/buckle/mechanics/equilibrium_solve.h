// Newton's method for a continuation::Problem at a fixed parameter λ (dense LU of the exact
// Jacobian, step halving when a trial point leaves the domain or does not reduce ‖F‖).
// Used to compute equilibria of the chain at a given load (EquilibriumProblem).
#pragma once

#include <Eigen/Core>

#include "buckle/continuation/problem.h"

namespace buckle::mechanics {

struct NewtonOptions {
  int maxIterations = 60;
  /// Converged when ‖F‖∞ <= tolerance·max(1, ‖F(u0)‖∞) or the Newton step ‖δu‖∞ <= stepTolerance,
  /// both measured in the problem's scales (F_i / residual scale, δu_i / unknown scale:
  /// Problem::scales()), so the same in any units.
  double tolerance = 1e-13;
  double stepTolerance = 1e-15;
  int maxHalvings = 40;
};

struct NewtonResult {
  Eigen::VectorXd u;          ///< last iterate
  bool converged = false;
  int iterations = 0;
  double residualNorm = 0.0;  ///< ‖F(u)‖∞ at the last iterate, in the problem's scales
};

/// Solves F(u, λ) = 0 from u0. Never throws for a failed solve (converged = false).
NewtonResult solveEquilibrium(continuation::Problem& problem, const Eigen::Ref<const Eigen::VectorXd>& u0,
                              double lambda, const NewtonOptions& options = {});

}  // namespace buckle::mechanics
