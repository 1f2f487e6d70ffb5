#include "buckle/continuation/multiplicity_switching.h"

#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/structured_refinement.h"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>

namespace buckle::continuation {

namespace {

// Deterministic start points on the unit sphere of R^d (normalised Gaussian vectors from a
// fixed-seed generator: the roots found do not depend on the run).
std::vector<Vector> sphereStarts(int d, int count) {
  std::vector<Vector> starts;
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto uniform = [&state]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (double((state >> 11) & ((1ull << 53) - 1)) + 0.5) / double(1ull << 53);
  };
  const double pi = std::acos(-1.0);
  for (int k = 0; k < count; ++k) {
    Vector z(d);
    for (int i = 0; i < d; ++i) z[i] = std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * pi * uniform());
    if (z.norm() > 0.0) starts.push_back(z.normalized());
  }
  return starts;
}

// Newton on R(y) = 0 (square system) with the Jacobian from `system`; true when ‖R‖ ≤ tolerance.
template <class System>
bool newton(const System &system, Vector &y, double tolerance) {
  Vector R;
  Matrix J;
  for (int it = 0; it < 60; ++it) {
    system(y, R, J);
    if (!R.allFinite()) return false;
    if (R.norm() <= tolerance) return true;
    const Vector step = J.fullPivLu().solve(R);
    if (!step.allFinite()) return false;
    y -= step;
  }
  system(y, R, J);
  return R.norm() <= tolerance;
}

// Adds z unless ±z is already there.
bool addUpToSign(std::vector<Vector> &roots, const Vector &z) {
  for (const Vector &r : roots)
    if (std::abs(r.dot(z)) >= 1.0 - 1e-6) return false;
  roots.push_back(z);
  return true;
}

struct SecondDerivative {
  Problem &problem;
  int n;
  // D(x0)[v] = d/dε F_x(x0 + εv) (N×(N+1)) at the point (u, λ).
  bool operator()(ConstVectorRef u, double lambda, ConstVectorRef v, Matrix &D) const {
    D.resize(n, n + 1);
    return problem.jacobianDirectionalDerivative(u, lambda, v.head(n), v[n], D.leftCols(n), D.col(n)) &&
           D.allFinite();
  }
};

bool solveReduced(Problem &problem, const SpecialPoint &bp, int m, ReducedBifurcation &out, double kernelTolerance,
                  int maxDenseDimension) {
  const int n = problem.dimension();
  out = ReducedBifurcation();
  out.kernelDimension = m;
  if (m < 1 || m > n || bp.u.size() != n) {
    out.note = "multiplicity out of range";
    return false;
  }
  Matrix kernel, Psi;
  // Above the dense crossover the kernels come from bordered solves (structuredMultipleKernel, no
  // SVD; the problem's structured solver when it takes m + 1 borders, else dense LU of the
  // (N+m+1)² bordered matrix, e.g. for the κ = 0 chain's m = n − 1), and F_x⁺ from the bordered
  // system [[F_x, Ψ], [Kᵀ, 0]]; at or below it the full SVD.
  std::unique_ptr<BorderedSolver> solver;
  std::unique_ptr<RefinedBorderedSystem> bordered;
  Eigen::BDCSVD<Matrix> svd;
  int r = n - m;  // rank
  if (n > maxDenseDimension) {
    solver = problem.makeStructuredSolver();
    if (!solver || solver->maxGeneralBorder() < m + 1) solver = std::make_unique<DenseBorderedSolver>(problem);
    double residual = 0.0;
    std::string why;
    if (!structuredMultipleKernel(problem, *solver, bp.u, bp.lambda, m, kernel, Psi, residual, &why)) {
      out.note = "kernel of F_x is not " + std::to_string(m + 1) + "-dimensional (" + why + ")";
      return false;
    }
    // the residual against the problem's unit, as the SVD's ratios below (F_x may vanish)
    if (residual > kernelTolerance) {
      char text[160];
      std::snprintf(text, sizeof text, "kernel of F_x is not %d-dimensional (residual %.3g)", m + 1, residual);
      out.note = text;
      return false;
    }
    bordered = std::make_unique<RefinedBorderedSystem>(problem, *solver);
    Vector Fl(n), el = Vector::Zero(n + 1);
    el[n] = 1.0;
    if (!problem.jacobianApply(bp.u, bp.lambda, el, Fl)) return false;
    Matrix Bp(n, m + 1), Dp = Matrix::Zero(m + 1, m + 1);
    Bp.col(0) = Fl;
    Bp.rightCols(m) = Psi;
    Dp.col(0) = kernel.row(n).transpose();
    if (!bordered->factor(bp.u, bp.lambda, Bp, kernel.topRows(n), Dp, false)) {
      out.note = "bordered system [[F_x, Psi], [K^T, 0]] singular";
      return false;
    }
  } else {
    Matrix Fx = Matrix::Zero(n, n + 1);
    if (!problem.jacobian(bp.u, bp.lambda, Fx.leftCols(n), Fx.col(n))) {
      out.note = "the problem refused the Jacobian at the point";
      return false;
    }
    // Full SVD: σ descending (n values); ker F_x = the last m + 1 right vectors, the left kernel the
    // last m left vectors. The kernel must be exactly (m+1)-dimensional to the tolerance.
    svd.compute(Fx, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vector &sigma = svd.singularValues();
    // relative to the problem's unit (it works in scaled variables): F_x may vanish at the point
    const double top = std::max(sigma[0], 1.0);
    if (sigma[r] > kernelTolerance * top || (r > 0 && sigma[r - 1] <= kernelTolerance * top)) {
      char text[160];
      std::snprintf(text, sizeof text, "kernel of F_x is not %d-dimensional (sigma ratios %.3g, %.3g)", m + 1,
                    sigma[r] / top, r > 0 ? sigma[r - 1] / top : 0.0);
      out.note = text;
      return false;
    }
    kernel = svd.matrixV().rightCols(m + 1);
    Psi = svd.matrixU().rightCols(m);
  }
  // Basis [t φ₁ … φ_m]: the parent's tangent projected onto the kernel, then the complement.
  Matrix K(n + 1, m + 1);
  Vector t = bp.tangent.size() == n + 1 ? Vector(kernel * (kernel.transpose() * bp.tangent)) : Vector(kernel.col(0));
  if (t.norm() < 1e-8) t = kernel.col(0);
  K.col(0) = t.normalized();
  int filled = 1;
  for (int k = 0; k <= m && filled <= m; ++k) {
    Vector w = kernel.col(k);
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < filled; ++j) w -= K.col(j).dot(w) * K.col(j);
    if (w.norm() > 1e-6) K.col(filled++) = w.normalized();
  }
  if (filled != m + 1) {
    out.note = "could not complete the kernel basis";
    return false;
  }
  // x = F_x⁺ b on the complement of the kernel: from the SVD's r largest singular values, or the
  // bordered system [[F_x, Ψ], [Kᵀ, 0]] [x; g] = [b; 0] (x ⊥ ker F_x, F_x x = b − ΨΨᵀb).
  auto pseudoSolve = [&](const Vector &b) -> Vector {
    if (bordered) {
      Vector rhs = Vector::Zero(n + m + 1), x(n + m + 1);
      rhs.head(n) = b;
      if (!bordered->solve(rhs, x)) return Vector::Constant(n + 1, std::numeric_limits<double>::quiet_NaN());
      return x.head(n + 1);
    }
    const Vector &sigma = svd.singularValues();
    Vector c = svd.matrixU().leftCols(r).transpose() * b;
    for (int i = 0; i < r; ++i) c[i] /= sigma[i];  // σ_i > kernelTolerance·top here
    return svd.matrixV().leftCols(r) * c;
  };

  // F_xx[k_a, z] at (u, λ): the matrices D_a = F_xx[k_a, ·] (N×(N+1)) at or below the crossover
  // (as before), O(N) products (Problem::secondDerivativeApply) above it.
  const SecondDerivative D{problem, n};
  std::vector<Matrix> Dk(size_t(bordered ? 0 : m + 1));
  for (size_t a = 0; a < Dk.size(); ++a)
    if (!D(bp.u, bp.lambda, K.col(Eigen::Index(a)), Dk[a])) {
      out.note = "second derivatives unavailable";
      return false;
    }
  bool secondOk = true;
  auto secondAt = [&](ConstVectorRef u, double lambda, int a, const Vector &z) -> Vector {
    Vector y(n);
    secondOk = problem.secondDerivativeApply(u, lambda, K.col(a), z, y) && secondOk;
    return y;
  };
  auto second = [&](int a, const Vector &z) -> Vector {
    if (!bordered) return Dk[size_t(a)] * z;
    return secondAt(bp.u, bp.lambda, a, z);
  };
  // A_j(a, b) = ψ_jᵀ F_xx[k_a, k_b], symmetrised (the default second derivatives are differences).
  std::vector<Matrix> A(size_t(m), Matrix::Zero(m + 1, m + 1));
  double qmax = 0.0, qphi = 0.0;
  for (int a = 0; a <= m; ++a)
    for (int b = 0; b <= m; ++b) {
      const Vector y = second(a, K.col(b));
      for (int j = 0; j < m; ++j) A[size_t(j)](a, b) = Psi.col(j).dot(y);
    }
  if (!secondOk) {
    out.note = "second derivatives unavailable";
    return false;
  }
  for (int j = 0; j < m; ++j) {
    A[size_t(j)] = (0.5 * (A[size_t(j)] + A[size_t(j)].transpose())).eval();
    qmax = std::max(qmax, A[size_t(j)].cwiseAbs().maxCoeff());
    qphi = std::max(qphi, A[size_t(j)].bottomRightCorner(m, m).cwiseAbs().maxCoeff());
  }
  if (!(qmax > 0.0)) {
    out.note = "degenerate bifurcation equation (vanishing second derivatives)";
    return false;
  }
  std::vector<Vector> roots;
  if (qphi > 1e-6 * qmax) {
    // Quadratic equation on the sphere S^m: zᵀA_j z = 0, |z|² = 1.
    out.order = 2;
    const auto system = [&](const Vector &z, Vector &R, Matrix &J) {
      R.resize(m + 1);
      J.resize(m + 1, m + 1);
      for (int j = 0; j < m; ++j) {
        R[j] = z.dot(A[size_t(j)] * z) / qmax;
        J.row(j) = 2.0 * (A[size_t(j)] * z).transpose() / qmax;
      }
      R[m] = z.squaredNorm() - 1.0;
      J.row(m) = 2.0 * z.transpose();
    };
    for (Vector z : sphereStarts(m + 1, 64 * (m + 1))) {
      if (!newton(system, z, 1e-12)) continue;
      z.normalize();
      if (std::abs(z[0]) >= 1.0 - 1e-6) continue;  // the parent branch
      if (addUpToSign(roots, z)) {
        out.directions.push_back(K * z);
        out.curvatures.push_back(0.0);
      }
    }
  } else {
    // Cubic: the quadratic form vanishes on span φ. Tensor of the cubic term, from the
    // bilinear correction w₂ and a central difference of the second derivative along φ_c.
    out.order = 3;
    const Matrix B = [&] {
      Matrix b(m, m);
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) b(j, i) = A[size_t(j)](i + 1, 0);
      return b;
    }();
    const double h = 1e-3;
    std::vector<Matrix> W(size_t(m * m));  // W_bc = −F_x⁺ ½F_xx[φ_b, φ_c]
    for (int b = 0; b < m; ++b)
      for (int c = 0; c < m; ++c)
        W[size_t(b * m + c)] = -pseudoSolve(0.25 * (second(b + 1, K.col(c + 1)) + second(c + 1, K.col(b + 1))));
    // T[j][(a·m + b)·m + c] = ψ_jᵀ(F_xx[φ_a, W_bc] + ⅙F_xxx[φ_a, φ_b, φ_c])
    std::vector<double> T(size_t(m * m * m * m), 0.0);
    Matrix Dp, Dm;
    for (int c = 0; c < m; ++c) {
      const Vector shift = h * K.col(c + 1);
      const Vector up = bp.u + shift.head(n), um = bp.u - shift.head(n);
      for (int a = 0; a < m; ++a) {
        if (!bordered &&
            (!D(up, bp.lambda + shift[n], K.col(a + 1), Dp) || !D(um, bp.lambda - shift[n], K.col(a + 1), Dm))) {
          out.note = "third derivatives unavailable";
          return false;
        }
        for (int b = 0; b < m; ++b) {
          // F_xxx[φ_a, φ_b, φ_c] by a central difference along φ_c
          const Vector third = bordered ? Vector((secondAt(up, bp.lambda + shift[n], a + 1, K.col(b + 1)) -
                                                  secondAt(um, bp.lambda - shift[n], a + 1, K.col(b + 1))) /
                                                 (2.0 * h))
                                        : Vector((Dp - Dm) / (2.0 * h) * K.col(b + 1));
          const Vector secondTerm = second(a + 1, W[size_t(b * m + c)]);
          for (int j = 0; j < m; ++j)
            T[size_t(j * m * m * m + (a * m + b) * m + c)] = Psi.col(j).dot(secondTerm + third / 6.0);
        }
        if (!secondOk) {
          out.note = "third derivatives unavailable";
          return false;
        }
      }
    }
    double cscale = 0.0;
    for (double v : T) cscale = std::max(cscale, std::abs(v));
    const double bscale = B.cwiseAbs().maxCoeff();
    if (!(cscale > 0.0) || !(bscale > 0.0)) {
      out.note = "degenerate cubic bifurcation equation";
      return false;
    }
    auto cubic = [&](const Vector &beta, Vector &g, Matrix &dg) {
      g = Vector::Zero(m);
      dg = Matrix::Zero(m, m);
      for (int j = 0; j < m; ++j)
        for (int a = 0; a < m; ++a)
          for (int b = 0; b < m; ++b)
            for (int c = 0; c < m; ++c) {
              const double t = T[size_t(j * m * m * m + (a * m + b) * m + c)];
              g[j] += t * beta[a] * beta[b] * beta[c];
              dg(j, a) += t * beta[b] * beta[c];
              dg(j, b) += t * beta[a] * beta[c];
              dg(j, c) += t * beta[a] * beta[b];
            }
    };
    // Unknowns y = (β, τ): τBβ + g(β) = 0, |β|² = 1 (rows scaled by the cubic's size).
    const auto system = [&](const Vector &y, Vector &R, Matrix &J) {
      const Vector beta = y.head(m);
      const double tau = y[m];
      Vector g;
      Matrix dg;
      cubic(beta, g, dg);
      R.resize(m + 1);
      J.resize(m + 1, m + 1);
      R.head(m) = (tau * (B * beta) + g) / cscale;
      J.topLeftCorner(m, m) = (tau * B + dg) / cscale;
      J.col(m).head(m) = B * beta / cscale;
      R[m] = beta.squaredNorm() - 1.0;
      J.row(m).head(m) = 2.0 * beta.transpose();
      J(m, m) = 0.0;
    };
    for (const Vector &beta0 : sphereStarts(m, 64 * m)) {
      Vector g;
      Matrix dg;
      cubic(beta0, g, dg);
      const Vector Bb = B * beta0;
      Vector y(m + 1);
      y << beta0, (Bb.squaredNorm() > 0.0 ? -Bb.dot(g) / Bb.squaredNorm() : 0.0);
      if (!newton(system, y, 1e-12)) continue;
      const Vector beta = y.head(m).normalized();
      if (addUpToSign(roots, beta)) {
        out.directions.push_back((K.rightCols(m) * beta).normalized());
        out.curvatures.push_back(y[m]);
      }
    }
  }
  if (out.directions.empty()) {
    out.note = out.order == 2 ? "quadratic bifurcation equation: no real root besides the parent"
                              : "cubic bifurcation equation: no real root";
    return false;
  }
  out.note = std::string(out.order == 2 ? "quadratic" : "cubic") + " reduced bifurcation equation, m = " +
             std::to_string(m) + ": " + std::to_string(out.directions.size()) + " solution directions";
  return true;
}

}  // namespace

namespace {

// Orthonormal columns spanning those of X (modified Gram–Schmidt, twice).
Matrix orthonormalColumns(const Matrix &X) {
  Matrix Q = X;
  for (Eigen::Index j = 0; j < Q.cols(); ++j) {
    for (int pass = 0; pass < 2; ++pass)
      for (Eigen::Index i = 0; i < j; ++i) Q.col(j) -= Q.col(i).dot(Q.col(j)) * Q.col(i);
    Q.col(j).normalize();
  }
  return Q;
}

}  // namespace

bool structuredMultipleKernel(Problem &problem, BorderedSolver &solver, ConstVectorRef u, double lambda, int m,
                              Matrix &K, Matrix &Psi, double &residual, std::string *why) {
  const int n = problem.dimension();
  const int k = m + 1;
  if (m < 1 || m > n || solver.maxGeneralBorder() < k) {
    if (why) *why = "multiplicity out of range for the solver's borders";
    return false;
  }
  Vector Fl(n);
  {
    Vector el = Vector::Zero(n + 1);
    el[n] = 1.0;
    if (!problem.jacobianApply(u, lambda, el, Fl)) {
      if (why) *why = "the problem refused the Jacobian at the point";
      return false;
    }
  }
  // Generic first borders: the deterministic sphere points of the root search, one per column.
  const std::vector<Vector> right = sphereStarts(n + 1, k), left = sphereStarts(n, m + 7);
  Matrix C(n + 1, k), B(n, m);
  for (int j = 0; j < k; ++j) C.col(j) = right[size_t(j)];
  for (int j = 0; j < m; ++j) B.col(j) = left[size_t(j + 7)];
  RefinedBorderedSystem system(problem, solver);
  Matrix V(n + 1, k), W(n, m);
  for (int pass = 0; pass < 2; ++pass) {
    // Right: [[F_u, [F_λ B]], [C_uᵀ, [C_λ 0]]] [x; (v_λ, γ)] = [0; e_i].
    Matrix Bp(n, k), Dp = Matrix::Zero(k, k);
    Bp.col(0) = Fl;
    Bp.rightCols(m) = B;
    Dp.col(0) = C.row(n).transpose();
    const Matrix Cu = C.topRows(n);
    if (!system.factor(u, lambda, Bp, Cu, Dp, false)) {
      if (why) *why = "bordered kernel system singular";
      return false;
    }
    Vector rhs = Vector::Zero(n + k), x(n + k);
    for (int i = 0; i < k; ++i) {
      rhs.setZero();
      rhs[n + i] = 1.0;
      if (!system.solve(rhs, x)) {
        if (why) *why = "bordered kernel solve failed";
        return false;
      }
      V.col(i).head(n) = x.head(n);
      V(n, i) = x[n];
    }
    // Left: the transpose, [[F_uᵀ, C_u], [[F_λ B]ᵀ, [C_λ 0]ᵀ]] [ψ; h] = [0; (0, e_j)].
    if (!system.factor(u, lambda, Cu, Bp, Dp.transpose(), true)) {
      if (why) *why = "transposed bordered kernel system singular";
      return false;
    }
    for (int j = 0; j < m; ++j) {
      rhs.setZero();
      rhs[n + 1 + j] = 1.0;
      if (!system.solve(rhs, x)) {
        if (why) *why = "transposed bordered kernel solve failed";
        return false;
      }
      W.col(j) = x.head(n);
    }
    C = orthonormalColumns(V);
    B = orthonormalColumns(W);
  }
  K = C;
  Psi = B;
  residual = 0.0;
  Vector y(n), z(n + 1);
  for (int i = 0; i < k; ++i) {
    if (!problem.jacobianApply(u, lambda, K.col(i), y)) return false;
    residual = std::max(residual, y.norm());
  }
  for (int j = 0; j < m; ++j) {
    if (!problem.jacobianTransposeApply(u, lambda, Psi.col(j), z)) return false;
    residual = std::max(residual, z.norm());
  }
  return true;
}

bool reducedBifurcationDirections(Problem &problem, const SpecialPoint &bp, int multiplicity, ReducedBifurcation &out,
                                  double kernelTolerance, int maxDenseDimension) {
  // In the problem's scaled variables (as bifurcatingDirection); directions back in its units.
  const int n = problem.dimension();
  const ProblemScales scales = problem.scales();
  if (!scales.identity() && scales.check(n).empty()) {
    const UnitScaling units(scales);
    ScaledProblem scaled(problem, units);
    const bool ok = solveReduced(scaled, units.scaled(bp), multiplicity, out, kernelTolerance, maxDenseDimension);
    for (Vector &d : out.directions) d = units.directionToUser(d);
    return ok;
  }
  return solveReduced(problem, bp, multiplicity, out, kernelTolerance, maxDenseDimension);
}

std::vector<Branch> switchMultiple(Tracer &tracer, SpecialPoint &bp, const BranchSwitchingOptions &options,
                                   std::string *how) {
  std::vector<Branch> children;
  ReducedBifurcation rb;
  if (!reducedBifurcationDirections(tracer.problem(), bp, bp.multiplicity, rb)) {
    if (how) *how = rb.note;
    return children;
  }
  const int n = tracer.problem().dimension();
  const UnitScaling &units = tracer.units();
  // The predicted directions, both signs, in the tracer's scaled variables (where they are compared).
  std::vector<Vector> predicted;
  for (const Vector &d : rb.directions) predicted.push_back(units.directionToScaled(d));
  Vector x0(n + 1);
  x0 << bp.u, bp.lambda;
  int found = 0;
  // The first step off a multiple point is a quarter of the usual one: the other solution
  // directions are nearby (the predictor x₀ + h·d is off the child by ~τh²), and a long first step
  // lets the corrector fall onto a neighbouring child.
  BranchSwitchingOptions first = options;
  if (!(first.amplitude > 0.0)) first.amplitude = 0.25 * tracer.options().initialStep;
  for (size_t k = 0; k < rb.directions.size(); ++k) {
    for (int sign : {1, -1}) {
      Branch child = switchBranch(tracer, bp, rb.directions[k], sign, first);
      if (child.stopReason != StopReason::SwitchFailed && child.points.size() >= 2) {
        Vector x1(n + 1);
        x1 << child.points[1].u, child.points[1].lambda;
        const Vector w = units.directionToScaled(x1 - x0);
        // found: the first point left along its own direction, closer to it than to any other
        const double own = sign * w.dot(predicted[k]);
        bool closest = own > 0.0;
        for (size_t j = 0; j < predicted.size() && closest; ++j)
          if (j != k && std::abs(w.dot(predicted[j])) >= own) closest = false;
        if (closest) ++found;
      }
      children.push_back(std::move(child));
    }
  }
  bp.branchesPredicted = 2 * int(rb.directions.size());
  bp.branchesFound = found;
  if (how) *how = rb.note + "; " + std::to_string(found) + " of " + std::to_string(bp.branchesPredicted) +
                  " half-branches found";
  return children;
}

}  // namespace buckle::continuation
