#include "buckle/continuation/internal/structured_refinement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace buckle::continuation {

namespace {

// Columns made orthonormal in order (Gram–Schmidt twice); false if one is (numerically) dependent.
bool orthonormalize(Matrix &K) {
  for (Eigen::Index j = 0; j < K.cols(); ++j) {
    const double before = K.col(j).norm();
    for (int pass = 0; pass < 2; ++pass)
      for (Eigen::Index i = 0; i < j; ++i) K.col(j) -= K.col(i).dot(K.col(j)) * K.col(i);
    const double after = K.col(j).norm();
    if (!(after > 1e-10 * before) || !std::isfinite(after)) return false;
    K.col(j) /= after;
  }
  return true;
}

// A fixed start vector for inverse iteration with no special relation to any problem.
Vector startVector(Eigen::Index size) {
  Vector z(size);
  for (Eigen::Index i = 0; i < size; ++i) z[i] = std::sin(0.7 * double(i) + 0.3) + 0.5;
  return z.normalized();
}

std::string format(const char *pattern, double value) {
  char buffer[120];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

constexpr int kInverseIterations = 4;
constexpr int kRefinementSteps = 3;

}  // namespace

RefinedBorderedSystem::RefinedBorderedSystem(const BoundProblem &problem, BorderedSolver &solver)
    : problem_(problem),
      solver_(solver),
      n_(problem.dimension()),
      ex_(Vector::Zero(problem.dimension() + 1)),
      prod_(Vector::Zero(problem.dimension() + 1)) {}

bool RefinedBorderedSystem::factor(ConstVectorRef u, double lambda, const Matrix &B, const Matrix &C, const Matrix &D,
                                   bool transposed) {
  u_ = u;
  lambda_ = lambda;
  B_ = B;
  C_ = C;
  D_ = D;
  transposed_ = transposed;
  return solver_.factorGeneral(u, lambda, B, C, D, transposed) == Factorization::Regular;
}

bool RefinedBorderedSystem::applyG(const Vector &x, Vector &y) {
  const int n = n_;
  const Eigen::Index k = B_.cols();
  if (transposed_) {
    if (!problem_.jacobianTransposeApply(u_, lambda_, x.head(n), prod_)) return false;
  } else {
    ex_.head(n) = x.head(n);
    ex_[n] = 0.0;
    if (!problem_.jacobianApply(u_, lambda_, ex_, prod_.head(n))) return false;
  }
  y.resize(n + k);
  y.head(n) = prod_.head(n);
  y.head(n).noalias() += B_ * x.tail(k);
  y.tail(k).noalias() = C_.transpose() * x.head(n);
  y.tail(k).noalias() += D_ * x.tail(k);
  return y.allFinite();
}

bool RefinedBorderedSystem::solve(const Vector &b, Vector &x) {
  x.resize(b.size());
  if (!solver_.solve(b, x)) return false;
  // Iterative refinement on the exactly evaluated residual: the solution converges to what the
  // problem's own products define, whatever the accuracy of the structured solve. A fixed number
  // of steps, not "while ‖b − Gx‖ decreases": rows of very different natural size (a held end
  // position sums n lever arms) put rounding noise into the norm that hides the progress of the
  // rows that matter.
  dx_.resize(b.size());
  for (int it = 0; it < kRefinementSteps; ++it) {
    if (!applyG(x, Gx_)) return false;
    r_ = b - Gx_;
    if (!solver_.solve(r_, dx_)) return false;
    x += dx_;
    if (dx_.norm() <= 4.0 * std::numeric_limits<double>::epsilon() * x.norm()) break;
  }
  return x.allFinite();
}

StructuredRefinement::StructuredRefinement(const BoundProblem &problem, BorderedSolver &solver, double tolerance,
                                           int maxIterations)
    : problem_(problem),
      solver_(solver),
      system_(problem, solver),
      tolerance_(tolerance),
      maxIterations_(maxIterations),
      n_(problem.dimension()),
      ex_(Vector::Zero(problem.dimension() + 1)) {}

bool StructuredRefinement::parameterDerivative(ConstVectorRef u, double lambda, Vector &Fl) {
  ex_.setZero();
  ex_[n_] = 1.0;
  Fl.resize(n_);
  return problem_.jacobianApply(u, lambda, ex_, Fl);
}

namespace {
// Where a refinement started: a failed refinement puts the point back, so the caller keeps the
// point it had located; and Newton may not wander farther from it than the step.
struct StartPoint {
  StartPoint(const Vector &u, double lambda) : u0(u), lambda0(lambda) {}
  double distance(const Vector &u, double lambda) const { return std::hypot((u - u0).norm(), lambda - lambda0); }
  StructuredRefinementResult restore(Vector &u, double &lambda, StructuredRefinementResult &result,
                                     const std::string &why) const {
    result.message = why;
    result.converged = false;
    u = u0;
    lambda = lambda0;
    return result;
  }
  const Vector u0;
  const double lambda0;
};
}  // namespace

StructuredRefinementResult StructuredRefinement::fold(Vector &u, double &lambda, ConstVectorRef tangent, Vector &v,
                                                      double maxDistance) {
  StructuredRefinementResult result;
  const int n = n_;
  const StartPoint start(u, lambda);
  auto fail = [&](const std::string &why) { return start.restore(u, lambda, result, why); };
  if (tangent.size() != n + 1 || !(tangent.head(n).norm() > 0.0)) return fail("no tangent to start from");
  Vector b = tangent.head(n).normalized(), c = b;
  Matrix Bm(n, 1), Cm(n, 1), Dm = Matrix::Zero(1, 1);
  Vector rhs = Vector::Zero(n + 1), z, y, d, F(n), Fl, gx(n + 1), ev = Vector::Zero(n + 1);
  rhs[n] = 1.0;
  bool met = false;
  double metStep = 0.0;
  for (int it = 0; it <= maxIterations_; ++it) {
    // g and v from [[F_u, b], [cᵀ, 0]] [v; g] = [0; 1]; w from the transposed matrix.
    Bm.col(0) = b;
    Cm.col(0) = c;
    if (!factor(u, lambda, Bm, Cm, Dm, false) || !refinedSolve(rhs, z)) return fail("singular fold bordered matrix");
    Bm.col(0) = c;
    Cm.col(0) = b;
    if (!factor(u, lambda, Bm, Cm, Dm, true) || !refinedSolve(rhs, y)) return fail("singular fold bordered matrix");
    const double g = z[n];
    if (!problem_.residual(u, lambda, F)) return fail("the problem refused an iterate");
    ev.head(n) = z.head(n);
    if (!problem_.secondDerivativeTransposeApply(u, lambda, ev, y.head(n), gx)) return fail("second derivatives unavailable");
    gx = -gx;  // g_x = −wᵀF_xx[(v, 0), ·]
    if (!parameterDerivative(u, lambda, Fl)) return fail("the problem refused an iterate");
    result.testValue = g;
    result.residualNorm = std::hypot(F.norm(), g);
    const double vNorm = z.head(n).norm(), wNorm = y.head(n).norm();
    if (!(vNorm > 0.0) || !(wNorm > 0.0)) return fail("vanishing null vector");
    v = z.head(n) / vNorm;
    // Newton on (F, g): [[F_u, F_λ], [g_uᵀ, g_λ]].
    Bm.col(0) = Fl;
    Cm.col(0) = gx.head(n);
    Dm(0, 0) = gx[n];
    Vector rhsNewton(n + 1);
    rhsNewton << -F, -g;
    const bool solved = factor(u, lambda, Bm, Cm, Dm, false) && refinedSolve(rhsNewton, d);
    Dm(0, 0) = 0.0;
    if (!solved) return fail("singular fold Newton matrix");
    const double step = std::abs(d[n]);
    if (met && step > metStep) break;  // the polishing step only adds noise: keep the point
    u += d.head(n);
    lambda += d[n];
    ++result.iterations;
    result.lastDLambda = step;
    if (start.distance(u, lambda) > maxDistance) return fail("Newton iterate left the step");
    b = y.head(n) / wNorm;
    c = v;
    if (met) break;
    const double tol = tolerance_ * std::max(1.0, std::abs(lambda));
    if (step <= tol && d.cwiseAbs().maxCoeff() <= std::max(tol, 1e-10)) {
      met = true;  // one more step: Newton's error is now far below the step just taken
      metStep = step;
    }
  }
  if (!met) return fail("no convergence: last |dlambda| = " + format("%.3g", result.lastDLambda));
  result.converged = true;
  return result;
}

bool StructuredRefinement::approximateKernel(ConstVectorRef u, double lambda, ConstVectorRef tangent, Matrix &kernel,
                                             Vector &psi) {
  const int n = n_;
  if (tangent.size() != n + 1 || !(tangent.norm() > 0.0)) return false;
  const Vector t = tangent.normalized();
  Vector Fl;
  if (!parameterDerivative(u, lambda, Fl)) return false;
  Matrix Bm(n, 1), Cm(n, 1), Dm(1, 1);
  // A(t) = [[F_u, F_λ], [tᵀ]]: nearly singular at a branch point, its near-null vector is the
  // kernel direction of F_x orthogonal to t; inverse iteration converges to it at the rate
  // (distance to the point) / (distance to the next singular point).
  Bm.col(0) = Fl;
  Cm.col(0) = t.head(n);
  Dm(0, 0) = t[n];
  if (solver_.factorGeneral(u, lambda, Bm, Cm, Dm, false) != Factorization::Regular) return false;
  Vector z = startVector(n + 1), next(n + 1);
  for (int it = 0; it < kInverseIterations; ++it) {
    if (!solver_.solve(z, next) || !(next.norm() > 0.0)) return false;
    z = next.normalized();
  }
  // Aᵀ = [[F_uᵀ, t_u], [F_λᵀ, t_λ]]: its near-null vector is (ψ, ~0).
  Bm.col(0) = t.head(n);
  Cm.col(0) = Fl;
  if (solver_.factorGeneral(u, lambda, Bm, Cm, Dm, true) != Factorization::Regular) return false;
  Vector y = startVector(n + 1);
  for (int it = 0; it < kInverseIterations; ++it) {
    if (!solver_.solve(y, next) || !(next.norm() > 0.0)) return false;
    y = next.normalized();
  }
  kernel.resize(n + 1, 2);
  kernel.col(0) = t;
  kernel.col(1) = z;
  if (!orthonormalize(kernel)) return false;
  psi = y.head(n);
  const double psiNorm = psi.norm();
  if (!(psiNorm > 0.0)) return false;
  psi /= psiNorm;
  return true;
}

StructuredRefinementResult StructuredRefinement::branchPoint(Vector &u, double &lambda, ConstVectorRef tangent,
                                                             Matrix &kernel, Vector &psi, double maxDistance) {
  StructuredRefinementResult result;
  const int n = n_;
  const StartPoint start(u, lambda);
  auto fail = [&](const std::string &why) { return start.restore(u, lambda, result, why); };
  Matrix K;
  Vector psiHat;
  if (!approximateKernel(u, lambda, tangent, K, psiHat)) return fail("no approximate kernel (inverse iteration)");
  double beta = 0.0;
  Matrix Bm(n, 2), Cm(n, 2), Dm(2, 2), Ct(n, 2), Dt(2, 2);
  Vector F(n), Fl, z0, z1, y, d, r0(n + 1), r1(n + 1), xi(n + 1);
  Vector e0 = Vector::Zero(n + 2), e1 = Vector::Zero(n + 2);
  e0[n] = 1.0;
  e1[n + 1] = 1.0;
  bool met = false;
  double metStep = 0.0;
  for (int it = 0; it <= maxIterations_; ++it) {
    if (!parameterDerivative(u, lambda, Fl)) return fail("the problem refused an iterate");
    // M = [[F_u, F_λ, ψ̂], [K_uᵀ, K_λ, 0]]: M [ξ_i; h_i] = [0; e_i], Mᵀ [w; ·] = e_{N+2}.
    Bm.col(0) = Fl;
    Bm.col(1) = psiHat;
    Cm = K.topRows(n);
    Dm << K(n, 0), 0.0, K(n, 1), 0.0;
    if (!factor(u, lambda, Bm, Cm, Dm, false) || !refinedSolve(e0, z0) || !refinedSolve(e1, z1))
      return fail("singular branch-point bordered matrix");
    Dt = Dm.transpose();
    if (!factor(u, lambda, Cm, Bm, Dt, true) || !refinedSolve(e1, y))
      return fail("singular branch-point bordered matrix");
    const auto w = y.head(n);
    if (!problem_.residual(u, lambda, F)) return fail("the problem refused an iterate");
    F += beta * psiHat;
    const double h0 = z0[n + 1], h1 = z1[n + 1];
    // h_i,x = −wᵀF_xx[ξ_i, ·]
    xi = z0.head(n + 1);
    if (!problem_.secondDerivativeTransposeApply(u, lambda, xi, w, r0)) return fail("second derivatives unavailable");
    xi = z1.head(n + 1);
    if (!problem_.secondDerivativeTransposeApply(u, lambda, xi, w, r1)) return fail("second derivatives unavailable");
    result.testValue = std::hypot(h0, h1);
    result.residualNorm = std::hypot(F.norm(), result.testValue);
    // Null vectors at this iterate (the borders of the next one).
    Matrix Knew(n + 1, 2);
    Knew.col(0) = z0.head(n + 1);
    Knew.col(1) = z1.head(n + 1);
    const double wNorm = w.norm();
    if (!orthonormalize(Knew) || !(wNorm > 0.0)) return fail("degenerate null vectors");
    kernel = Knew;
    psi = w / wNorm;
    // Newton on (F + βψ̂, h): [[F_u, F_λ, ψ̂], [h_x,u ᵀ, h_x,λ, 0]].
    Ct.col(0) = -r0.head(n);
    Ct.col(1) = -r1.head(n);
    Dt << -r0[n], 0.0, -r1[n], 0.0;
    Vector rhs(n + 2);
    rhs << -F, -h0, -h1;
    if (!factor(u, lambda, Bm, Ct, Dt, false) || !refinedSolve(rhs, d)) return fail("singular Moore-type Newton matrix");
    const double step = std::abs(d[n]);
    if (met && step > metStep) break;
    u += d.head(n);
    lambda += d[n];
    beta += d[n + 1];
    ++result.iterations;
    result.lastDLambda = step;
    if (start.distance(u, lambda) > maxDistance) return fail("Newton iterate left the step");
    K = Knew;
    psiHat = psi;
    if (met) break;
    const double tol = tolerance_ * std::max(1.0, std::abs(lambda));
    if (step <= tol && d.head(n + 1).cwiseAbs().maxCoeff() <= std::max(tol, 1e-10)) {
      met = true;
      metStep = step;
    }
  }
  if (!met) return fail("no convergence: last |dlambda| = " + format("%.3g", result.lastDLambda));
  result.converged = true;
  return result;
}

}  // namespace buckle::continuation
