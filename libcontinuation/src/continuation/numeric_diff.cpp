#include "buckle/continuation/numeric_diff.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace buckle::continuation {

std::string NumericDiffOptions::validate(const std::string &prefix) const {
  auto inRange = [](double d) { return d > 0.0 && d <= 0.1; };
  return firstProblem({require(inRange(relativeStep), prefix, "relativeStep", "must lie in (0, 0.1]"),
                       require(inRange(secondRelativeStep), prefix, "secondRelativeStep", "must lie in (0, 0.1]")});
}

bool differenceJacobian(const BoundProblem &problem, const ProblemScales &scales, double relativeStep, ConstVectorRef u,
                        double lambda, MatrixRef Fu, VectorRef Fl, VectorRef work, VectorRef Fplus, VectorRef Fminus) {
  const Eigen::Index n = u.size();
  work = u;
  // Column j = n is F_λ. The step is the representable difference of the two abscissae, so the
  // quotient divides by exactly the distance the residuals were taken apart.
  for (Eigen::Index j = 0; j <= n; ++j) {
    const double x = j < n ? u[j] : lambda;
    const double scale = j < n ? scales.unknowns[j] : scales.parameter;
    const double h = relativeStep * std::max(std::abs(x), scale);
    const double xPlus = x + h, xMinus = x - h;
    bool ok;
    if (j < n) {
      work[j] = xPlus;
      ok = problem.residual(work, lambda, Fplus);
      work[j] = xMinus;
      ok = ok && problem.residual(work, lambda, Fminus);
      work[j] = x;
    } else {
      ok = problem.residual(work, xPlus, Fplus) && problem.residual(work, xMinus, Fminus);
    }
    if (!ok) return false;
    if (j < n) Fu.col(j) = (Fplus - Fminus) / (xPlus - xMinus);
    else Fl = (Fplus - Fminus) / (xPlus - xMinus);
  }
  return Fu.allFinite() && Fl.allFinite();
}

NumericDiffProblem::NumericDiffProblem(const NumericDiffOptions &options) : options_(options) {
  std::string why;
  if (!options_.IsValid(&why)) throw std::invalid_argument("NumericDiffOptions: " + why);
}

const ProblemScales &NumericDiffProblem::cachedScales(Workspace &nd) const {
  const int n = dimension();
  if (!nd.scalesValid || nd.scales.unknowns.size() != n) {
    nd.scales = scales();
    if (!nd.scales.check(n).empty()) nd.scales = ProblemScales::ones(n);
    nd.scalesValid = true;
    nd.work.resize(n);
    nd.Fplus.resize(n);
    nd.Fminus.resize(n);
    nd.corner.resize(n);
    nd.Jplus.resize(n, n + 1);
    nd.Jminus.resize(n, n + 1);
  }
  return nd.scales;
}

double NumericDiffProblem::directionStep(Workspace &nd, ConstVectorRef u, double lambda, ConstVectorRef du,
                                         double dlambda, double relative) const {
  const ProblemScales &s = cachedScales(nd);
  // In the scaled variables (where "1" is a typical size), as Problem's default second derivative.
  const double size = std::max({1.0, u.cwiseQuotient(s.unknowns).lpNorm<Eigen::Infinity>(),
                                std::abs(lambda) / s.parameter});
  const double length = std::hypot(du.cwiseQuotient(s.unknowns).norm(), dlambda / s.parameter);
  return length == 0.0 ? 0.0 : relative * size / length;
}

bool NumericDiffProblem::jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu,
                                  VectorRef Flambda) const {
  Workspace &nd = workspaceAs<Workspace>(ws);
  const ProblemScales &s = cachedScales(nd);
  return differenceJacobian(BoundProblem(*this, ws), s, options_.relativeStep, u, lambda, Fu, Flambda, nd.work,
                            nd.Fplus, nd.Fminus);
}

bool NumericDiffProblem::jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda,
                                                       ConstVectorRef du, double dlambda, MatrixRef dFu,
                                                       VectorRef dFlambda) const {
  Workspace &nd = workspaceAs<Workspace>(ws);
  const ProblemScales &s = cachedScales(nd);
  const double delta = options_.secondRelativeStep;
  const double h = directionStep(nd, u, lambda, du, dlambda, delta);
  if (h == 0.0) {
    dFu.setZero();
    dFlambda.setZero();
    return true;
  }
  // nd.corner holds the shifted u while differenceJacobian perturbs its own copy (nd.work).
  nd.corner = u + h * du;
  if (!differenceJacobian(BoundProblem(*this, ws), s, delta, nd.corner, lambda + h * dlambda,
                          nd.Jplus.leftCols(dimension()), nd.Jplus.col(dimension()), nd.work, nd.Fplus, nd.Fminus))
    return false;
  nd.corner = u - h * du;
  if (!differenceJacobian(BoundProblem(*this, ws), s, delta, nd.corner, lambda - h * dlambda,
                          nd.Jminus.leftCols(dimension()), nd.Jminus.col(dimension()), nd.work, nd.Fplus, nd.Fminus))
    return false;
  const int n = dimension();
  dFu = (nd.Jplus.leftCols(n) - nd.Jminus.leftCols(n)) / (2.0 * h);
  dFlambda = (nd.Jplus.col(n) - nd.Jminus.col(n)) / (2.0 * h);
  return dFu.allFinite() && dFlambda.allFinite();
}

bool NumericDiffProblem::secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                               ConstVectorRef z, VectorRef y) const {
  Workspace &nd = workspaceAs<Workspace>(ws);
  const int n = dimension();
  const double delta = options_.secondRelativeStep;
  const double h = directionStep(nd, u, lambda, x.head(n), x[n], delta);
  const double k = directionStep(nd, u, lambda, z.head(n), z[n], delta);
  if (h == 0.0 || k == 0.0) {
    y.setZero();
    return true;
  }
  // F_xx[x, z] ≈ [F(+h,+k) − F(+h,−k) − F(−h,+k) + F(−h,−k)] / (4hk), truncation O(h² + k²).
  y.setZero();
  for (int a = -1; a <= 1; a += 2) {
    for (int b = -1; b <= 1; b += 2) {
      nd.corner = u + (a * h) * x.head(n) + (b * k) * z.head(n);
      if (!residual(ws, nd.corner, lambda + a * h * x[n] + b * k * z[n], nd.Fplus)) return false;
      y += (a * b) * nd.Fplus;
    }
  }
  y /= 4.0 * h * k;
  return y.allFinite();
}

bool NumericDiffProblem::secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda,
                                                        ConstVectorRef x, ConstVectorRef w, VectorRef y) const {
  Workspace &nd = workspaceAs<Workspace>(ws);
  const int n = dimension();
  cachedScales(nd);
  // nd.Jplus/nd.Jminus are the directional derivative's own workspaces: use a separate block.
  Matrix &dF = nd.second;
  dF.resize(n, n + 1);
  if (!jacobianDirectionalDerivative(ws, u, lambda, x.head(n), x[n], dF.leftCols(n), dF.col(n))) return false;
  y.noalias() = dF.transpose() * w;
  return y.allFinite();
}

}  // namespace buckle::continuation
