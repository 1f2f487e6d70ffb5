#include "buckle/continuation/problem.h"
#include "buckle/continuation/bound_problem.h"

#include "buckle/continuation/bordered_solver.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace buckle::continuation {

ProblemScales ProblemScales::ones(int n) {
  ProblemScales s;
  s.unknowns = Vector::Ones(std::max(0, n));
  s.residuals = Vector::Ones(std::max(0, n));
  return s;
}

bool ProblemScales::identity() const {
  return parameter == 1.0 && stability == 1.0 && (unknowns.array() == 1.0).all() && (residuals.array() == 1.0).all();
}

std::string ProblemScales::check(int n) const {
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  if (unknowns.size() != n || residuals.size() != n)
    return "scales of the unknowns and residuals must have size N = " + std::to_string(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!positive(unknowns[i])) return "scale of unknown " + std::to_string(i) + " must be positive and finite";
    if (!positive(residuals[i])) return "scale of residual row " + std::to_string(i) + " must be positive and finite";
  }
  if (!positive(parameter)) return "parameter scale must be positive and finite";
  if (!positive(stability)) return "stability scale must be positive and finite";
  return "";
}

namespace {

// Central-difference step along (du, dλ), 0 for a zero direction. Scaled to the point so that
// the O(h²) truncation and O(ε/h) rounding errors balance (h ~ ε^{1/3}); Newton on the augmented
// systems only needs an approximate Jacobian, the located point's accuracy is set by the exact
// residuals. Norms in the problem's own scales, so that "1" is a typical size in every unit system.
double differenceStep(const Problem &problem, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda) {
  const ProblemScales s = problem.scales();
  const bool weighted = s.check(problem.dimension()).empty();
  const double uNorm = weighted ? u.cwiseQuotient(s.unknowns).norm() : u.norm();
  const double lNorm = weighted ? std::abs(lambda) / s.parameter : std::abs(lambda);
  const double scale = std::max({1.0, uNorm, lNorm});
  const double dirNorm = weighted ? std::hypot(du.cwiseQuotient(s.unknowns).norm(), dlambda / s.parameter)
                                  : std::sqrt(du.squaredNorm() + dlambda * dlambda);
  return dirNorm == 0.0 ? 0.0 : 6e-6 * scale / dirNorm;
}

}  // namespace

ProblemWorkspace::~ProblemWorkspace() = default;

std::unique_ptr<BorderedSolver> BoundProblem::makeStructuredSolver() const {
  return problem_->makeStructuredSolver(*ws_);
}

void throwForeignWorkspace() {
  throw std::invalid_argument("a ProblemWorkspace evaluated by a problem that did not make it (createWorkspace)");
}

std::unique_ptr<ProblemWorkspace> Problem::createWorkspace() const { return std::make_unique<ProblemWorkspace>(); }

bool Problem::jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                            double dlambda, MatrixRef dFu, VectorRef dFlambda) const {
  const int n = dimension();
  const double h = differenceStep(*this, u, lambda, du, dlambda);
  if (h == 0.0) {
    dFu.setZero();
    dFlambda.setZero();
    return true;
  }
  Vector up = u + h * du, um = u - h * du;
  Matrix Jp(n, n), Jm(n, n);
  Vector lp(n), lm(n);
  if (!jacobian(ws, up, lambda + h * dlambda, Jp, lp)) return false;
  if (!jacobian(ws, um, lambda - h * dlambda, Jm, lm)) return false;
  dFu = (Jp - Jm) / (2.0 * h);
  dFlambda = (lp - lm) / (2.0 * h);
  return true;
}

bool Problem::jacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                            VectorRef y) const {
  const int n = dimension();
  ws.applyFu.resize(n, n + 1);
  if (!jacobian(ws, u, lambda, ws.applyFu.leftCols(n), ws.applyFu.col(n))) return false;
  y.noalias() = ws.applyFu * x;
  return true;
}

bool Problem::jacobianTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                                     VectorRef y) const {
  const int n = dimension();
  ws.applyFu.resize(n, n + 1);
  if (!jacobian(ws, u, lambda, ws.applyFu.leftCols(n), ws.applyFu.col(n))) return false;
  y.noalias() = ws.applyFu.transpose() * w;
  return true;
}

bool Problem::secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                             ConstVectorRef w, VectorRef y) const {
  const int n = dimension();
  const double h = differenceStep(*this, u, lambda, x.head(n), x[n]);
  if (h == 0.0) {
    y.setZero();
    return true;
  }
  Vector yp(n + 1), ym(n + 1);
  if (!jacobianTransposeApply(ws, u + h * x.head(n), lambda + h * x[n], w, yp)) return false;
  if (!jacobianTransposeApply(ws, u - h * x.head(n), lambda - h * x[n], w, ym)) return false;
  y = (yp - ym) / (2.0 * h);
  return y.allFinite();
}

bool Problem::secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                    ConstVectorRef z, VectorRef y) const {
  const int n = dimension();
  ws.secondFu.resize(n, n);
  ws.secondFl.resize(n);
  if (!jacobianDirectionalDerivative(ws, u, lambda, x.head(n), x[n], ws.secondFu, ws.secondFl)) return false;
  y.noalias() = ws.secondFu * z.head(n);
  y += z[n] * ws.secondFl;
  return y.allFinite();
}

bool Problem::secondDerivativeApplyByDifferences(ProblemWorkspace &ws, ConstVectorRef u, double lambda,
                                                 ConstVectorRef x, ConstVectorRef z, VectorRef y) const {
  const int n = dimension();
  const double h = differenceStep(*this, u, lambda, x.head(n), x[n]);
  if (h == 0.0) {
    y.setZero();
    return true;
  }
  Vector yp(n), ym(n);
  if (!jacobianApply(ws, u + h * x.head(n), lambda + h * x[n], z, yp)) return false;
  if (!jacobianApply(ws, u - h * x.head(n), lambda - h * x[n], z, ym)) return false;
  y = (yp - ym) / (2.0 * h);
  return y.allFinite();
}

std::unique_ptr<BorderedSolver> Problem::makeStructuredSolver(ProblemWorkspace &) const { return nullptr; }

void Problem::boundaries(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef g) const {
  for (Eigen::Index k = 0; k < g.size(); ++k) g[k] = boundary(ws, static_cast<int>(k), u, lambda);
}

bool Problem::stabilityOperator(ProblemWorkspace &, ConstVectorRef, double, Matrix &, Matrix &) const { return false; }

bool Problem::stability(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int lowestCount,
                        StabilityInfo &info) const {
  if (!hasStabilityOperator()) return false;
  if (!stabilityOperator(ws, u, lambda, ws.stabilityH, ws.stabilityC)) return false;
  info = projectedInertia(ws.stabilityH, ws.stabilityC, 1e-13, lowestCount, scales().stability);
  return true;
}

bool Problem::stabilityEigenvalues(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int first,
                                   VectorRef values) const {
  if (!hasStabilityOperator() || first < 0) return false;
  if (!stabilityOperator(ws, u, lambda, ws.stabilityH, ws.stabilityC)) return false;
  const StabilityInfo all =
      projectedInertia(ws.stabilityH, ws.stabilityC, 1e-13, int(ws.stabilityH.rows()), scales().stability);
  if (first + values.size() > all.lowest.size()) return false;
  values = all.lowest.segment(first, values.size());
  return true;
}

StabilityInfo projectedInertia(const Matrix& H, const Matrix& C, double zeroTolerance, int lowestCount, double scale) {
  StabilityInfo info;
  Matrix reduced;
  if (C.rows() == 0) {
    reduced = H;
  } else {
    // Z = last (n − rank C) columns of Q in Cᵀ = Q R: an orthonormal basis of ker C.
    Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
    const Eigen::Index rank = qr.rank();
    const Eigen::Index n = H.rows();
    Matrix Q = qr.householderQ() * Matrix::Identity(n, n);
    Matrix Z = Q.rightCols(n - rank);
    reduced = Z.transpose() * H * Z;
  }
  if (reduced.rows() == 0) {
    info.negative = 0;
    info.smallest = 0.0;
    info.lowest.resize(0);
    return info;
  }
  Eigen::SelfAdjointEigenSolver<Matrix> es(0.5 * (reduced + reduced.transpose()), Eigen::EigenvaluesOnly);
  const Vector& mu = es.eigenvalues();
  const double tol = zeroTolerance * std::max(scale, mu.cwiseAbs().maxCoeff());
  info.negative = 0;
  info.zero = 0;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    if (std::abs(mu[i]) <= tol) ++info.zero;
    else if (mu[i] < 0.0) ++info.negative;
  }
  info.lowest = mu.head(std::min<Eigen::Index>(std::max(0, lowestCount), mu.size()));
  info.smallest = info.lowest.size() ? info.lowest[0] : 0.0;
  return info;
}

}  // namespace buckle::continuation
