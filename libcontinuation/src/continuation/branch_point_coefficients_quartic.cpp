#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "buckle/continuation/branch_point_coefficients.h"
#include "buckle/continuation/corrector.h"
#include "buckle/continuation/scaled_problem.h"

namespace buckle::continuation {

namespace {

bool failExpansion(std::string *why, const std::string &reason) {
  if (why) *why = reason;
  return false;
}

/// The exact solution of the 3×3 power fit y_k = Σ_j coef_j (k h)^{p_j}, k = 1, 2, 3, and the
/// 1-norms of the rows of its inverse (how a rounding of y reaches each coefficient).
void powerFit(const double y[3], double h, const int powers[3], Eigen::Vector3d &coef, Eigen::Vector3d &gain) {
  Eigen::Matrix3d A;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) A(k, j) = std::pow((k + 1) * h, powers[j]);
  const Eigen::Matrix3d inverse = A.inverse();
  coef = inverse * Eigen::Vector3d(y[0], y[1], y[2]);
  gain = inverse.cwiseAbs().rowwise().sum();
}

}  // namespace

bool childBranchExpansion(const BoundProblem &problem, ConstVectorRef u0, double lambdaC,
                          const BranchPointCoefficients &g, ConstVectorRef c, ChildBranchExpansion &out,
                          std::string *why, double amplitude) {
  const int n = problem.dimension();
  if (u0.size() != n || c.size() != n || g.v.size() != n || g.u2.size() != n)
    return failExpansion(why, "child expansion: u0, c and the coefficients' vectors must have the problem's dimension");
  const ProblemScales scales = problem.scales();
  const UnitScaling units(scales);
  const BoundScaledProblem scaledProblem(problem, units);
  const BoundProblem &scaled = scaledProblem.bound();
  std::unique_ptr<BorderedSolver> structured;
  if (n > kDenseCoefficientDimension) structured = scaled.makeStructuredSolver();
  CorrectorOptions options;
  options.tolerance = 1e-13;
  options.maxIterations = 30;
  Corrector corrector(scaled, options, structured.get());
  const double vScaled = g.v.cwiseQuotient(scales.unknowns).norm();
  if (!(vScaled > 0.0)) return failExpansion(why, "child expansion: the null vector vanishes");
  const double h = amplitude > 0.0 ? amplitude : 0.05 / vScaled;
  // the hyperplane cᵀ(u − u0) = ξ in the scaled unknowns: normal (c ⊙ D_u, 0)
  Vector normal = Vector::Zero(n + 1);
  normal.head(n) = c.cwiseProduct(scales.unknowns);
  normal /= normal.norm();
  Vector predictor(n + 1), x(n + 1);
  const double lambdaScale = std::max(scales.parameter, std::abs(lambdaC));
  double worstResidual = 0.0;
  // λ at ξ, the child's point on the hyperplane of that amplitude
  auto lambdaAt = [&](double xi, double &lambda) {
    predictor.head(n) = (u0 + xi * g.v + xi * xi * g.u2).cwiseQuotient(scales.unknowns);
    predictor[n] = (lambdaC + g.a * xi + g.b * xi * xi) / scales.parameter;
    const CorrectorSummary summary = corrector.correct(predictor, normal, x);
    if (!summary.converged) return false;
    // the corrected point must have kept its amplitude (Newton stays on the hyperplane)
    const double reached = c.dot(x.head(n).cwiseProduct(scales.unknowns) - u0);
    if (!(std::abs(reached - xi) <= 1e-8 * std::abs(xi))) return false;
    worstResidual = std::max(worstResidual, summary.residualNorm);
    lambda = x[n] * scales.parameter;
    return std::isfinite(lambda);
  };
  Eigen::Vector3d even[2], odd[2], evenGain, oddGain;
  const int evenPowers[3] = {2, 4, 6}, oddPowers[3] = {1, 3, 5};
  for (int fit = 0; fit < 2; ++fit) {
    const double step = fit == 0 ? h : 0.5 * h;
    double e[3], o[3];
    for (int k = 0; k < 3; ++k) {
      double plus = 0.0, minus = 0.0;
      if (!lambdaAt((k + 1) * step, plus) || !lambdaAt(-(k + 1) * step, minus))
        return failExpansion(why, "child expansion: no point of the child at amplitude " + std::to_string((k + 1) * step) +
                             " (the corrector did not converge on its hyperplane)");
      e[k] = 0.5 * (plus + minus) - lambdaC;
      o[k] = 0.5 * (plus - minus);
    }
    powerFit(e, step, evenPowers, even[fit], evenGain);
    powerFit(o, step, oddPowers, odd[fit], oddGain);
  }
  // λ's rounding at each point: its own unit roundoff plus the residual left, both in λ's scale
  const double eps = std::numeric_limits<double>::epsilon();
  const double lambdaRounding = (16.0 * eps + worstResidual) * lambdaScale;
  out.amplitude = h;
  out.c1 = odd[0][0];
  out.c3 = odd[0][1];
  out.c2 = even[0][0];
  out.c4 = even[0][1];
  // the h/2 fit's gains are the larger (the rows of the inverse grow like h^-p)
  out.c2Accuracy = std::abs(even[0][0] - even[1][0]) + evenGain[0] * lambdaRounding;
  out.c4Accuracy = std::abs(even[0][1] - even[1][1]) + evenGain[1] * lambdaRounding;
  return std::isfinite(out.c4) && std::isfinite(out.c4Accuracy);
}

}  // namespace buckle::continuation
