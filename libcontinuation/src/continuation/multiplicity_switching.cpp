#include "buckle/continuation/multiplicity_switching.h"

#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/internal/structured_refinement.h"

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
  BoundProblem problem;
  int n;
  // D(x0)[v] = d/dε F_x(x0 + εv) (N×(N+1)) at the point (u, λ).
  bool operator()(ConstVectorRef u, double lambda, ConstVectorRef v, Matrix &D) const {
    D.resize(n, n + 1);
    return problem.jacobianDirectionalDerivative(u, lambda, v.head(n), v[n], D.leftCols(n), D.col(n)) &&
           D.allFinite();
  }
};

// The reduced bifurcation equation of a multiple branch point (Lyapunov–Schmidt on ker F_x), in
// stages that share the kernels: the kernels ker F_x and ker F_xᵀ, the basis [t φ₁ … φ_m] with the
// parent's tangent first, the quadratic coefficients A_j = ψ_jᵀ F_xx[k_a, k_b], and the roots of
// the quadratic equation on the sphere or, where it vanishes on span φ, of the cubic one.
class ReducedEquation {
 public:
  ReducedEquation(const BoundProblem &problem, const SpecialPoint &bp, int m, ReducedBifurcation &out)
      : problem_(problem), bp_(bp), n_(problem.dimension()), m_(m), r_(n_ - m), D_{problem, n_}, out_(out) {}

  bool solve(double kernelTolerance, int maxDenseDimension) {
    out_ = ReducedBifurcation();
    out_.kernelDimension = m_;
    if (m_ < 1 || m_ > n_ || bp_.u.size() != n_) return fail("multiplicity out of range");
    const bool kernels = n_ > maxDenseDimension ? structuredKernels(kernelTolerance) : denseKernels(kernelTolerance);
    if (!kernels || !basis() || !quadraticCoefficients()) return false;
    if (qphi_ > 1e-6 * qmax_) {
      solveQuadratic();
    } else if (!solveCubic()) {
      return false;
    }
    if (out_.directions.empty())
      return fail(out_.order == 2 ? "quadratic bifurcation equation: no real root besides the parent"
                                  : "cubic bifurcation equation: no real root");
    out_.note = std::string(out_.order == 2 ? "quadratic" : "cubic") + " reduced bifurcation equation, m = " +
                std::to_string(m_) + ": " + std::to_string(out_.directions.size()) + " solution directions";
    return true;
  }

 private:
  bool fail(const std::string &why) {
    out_.note = why;
    return false;
  }

  // Above the dense crossover the kernels come from bordered solves (structuredMultipleKernel, no
  // SVD; the problem's structured solver when it takes m + 1 borders, else dense LU of the
  // (N+m+1)² bordered matrix, e.g. for the κ = 0 chain's m = n − 1), and F_x⁺ from the bordered
  // system [[F_x, Ψ], [Kᵀ, 0]].
  bool structuredKernels(double kernelTolerance) {
    const int n = n_, m = m_;
    solver_ = problem_.makeStructuredSolver();
    if (!solver_ || solver_->maxGeneralBorder() < m + 1) solver_ = std::make_unique<DenseBorderedSolver>(problem_);
    double residual = 0.0;
    std::string why;
    if (!structuredMultipleKernel(problem_, *solver_, bp_.u, bp_.lambda, m, kernel_, Psi_, residual, &why))
      return fail("kernel of F_x is not " + std::to_string(m + 1) + "-dimensional (" + why + ")");
    // the residual against the problem's unit, as the SVD's ratios (F_x may vanish)
    if (residual > kernelTolerance) {
      char text[160];
      std::snprintf(text, sizeof text, "kernel of F_x is not %d-dimensional (residual %.3g)", m + 1, residual);
      return fail(text);
    }
    bordered_ = std::make_unique<RefinedBorderedSystem>(problem_, *solver_);
    Vector Fl(n), el = Vector::Zero(n + 1);
    el[n] = 1.0;
    if (!problem_.jacobianApply(bp_.u, bp_.lambda, el, Fl)) return false;
    Matrix Bp(n, m + 1), Dp = Matrix::Zero(m + 1, m + 1);
    Bp.col(0) = Fl;
    Bp.rightCols(m) = Psi_;
    Dp.col(0) = kernel_.row(n).transpose();
    if (!bordered_->factor(bp_.u, bp_.lambda, Bp, kernel_.topRows(n), Dp, false))
      return fail("bordered system [[F_x, Psi], [K^T, 0]] singular");
    return true;
  }

  // At or below the crossover: the full SVD, σ descending (n values); ker F_x = the last m + 1
  // right vectors, the left kernel the last m left vectors. The kernel must be exactly
  // (m+1)-dimensional to the tolerance.
  bool denseKernels(double kernelTolerance) {
    Matrix Fx = Matrix::Zero(n_, n_ + 1);
    if (!problem_.jacobian(bp_.u, bp_.lambda, Fx.leftCols(n_), Fx.col(n_)))
      return fail("the problem refused the Jacobian at the point");
    svd_.compute(Fx, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vector &sigma = svd_.singularValues();
    // relative to the problem's unit (it works in scaled variables): F_x may vanish at the point
    const double top = std::max(sigma[0], 1.0);
    if (sigma[r_] > kernelTolerance * top || (r_ > 0 && sigma[r_ - 1] <= kernelTolerance * top)) {
      char text[160];
      std::snprintf(text, sizeof text, "kernel of F_x is not %d-dimensional (sigma ratios %.3g, %.3g)", m_ + 1,
                    sigma[r_] / top, r_ > 0 ? sigma[r_ - 1] / top : 0.0);
      return fail(text);
    }
    kernel_ = svd_.matrixV().rightCols(m_ + 1);
    Psi_ = svd_.matrixU().rightCols(m_);
    return true;
  }

  // Basis [t φ₁ … φ_m]: the parent's tangent projected onto the kernel, then the complement.
  bool basis() {
    const int n = n_, m = m_;
    K_.resize(n + 1, m + 1);
    Vector t = bp_.tangent.size() == n + 1 ? Vector(kernel_ * (kernel_.transpose() * bp_.tangent)) : Vector(kernel_.col(0));
    if (t.norm() < 1e-8) t = kernel_.col(0);
    K_.col(0) = t.normalized();
    int filled = 1;
    for (int k = 0; k <= m && filled <= m; ++k) {
      Vector w = kernel_.col(k);
      for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j < filled; ++j) w -= K_.col(j).dot(w) * K_.col(j);
      if (w.norm() > 1e-6) K_.col(filled++) = w.normalized();
    }
    if (filled != m + 1) return fail("could not complete the kernel basis");
    return true;
  }

  // x = F_x⁺ b on the complement of the kernel: from the SVD's r largest singular values, or the
  // bordered system [[F_x, Ψ], [Kᵀ, 0]] [x; g] = [b; 0] (x ⊥ ker F_x, F_x x = b − ΨΨᵀb).
  Vector pseudoSolve(const Vector &b) const {
    if (bordered_) {
      Vector rhs = Vector::Zero(n_ + m_ + 1), x(n_ + m_ + 1);
      rhs.head(n_) = b;
      if (!bordered_->solve(rhs, x)) return Vector::Constant(n_ + 1, std::numeric_limits<double>::quiet_NaN());
      return x.head(n_ + 1);
    }
    const Vector &sigma = svd_.singularValues();
    Vector c = svd_.matrixU().leftCols(r_).transpose() * b;
    for (int i = 0; i < r_; ++i) c[i] /= sigma[i];  // σ_i > kernelTolerance·top here
    return svd_.matrixV().leftCols(r_) * c;
  }

  // F_xx[k_a, z] at (u, λ): the matrices D_a = F_xx[k_a, ·] (N×(N+1)) at or below the crossover,
  // O(N) products (Problem::secondDerivativeApply) above it.
  Vector secondAt(ConstVectorRef u, double lambda, int a, const Vector &z) {
    Vector y(n_);
    secondOk_ = problem_.secondDerivativeApply(u, lambda, K_.col(a), z, y) && secondOk_;
    return y;
  }
  Vector second(int a, const Vector &z) {
    if (!bordered_) return Dk_[size_t(a)] * z;
    return secondAt(bp_.u, bp_.lambda, a, z);
  }

  // A_j(a, b) = ψ_jᵀ F_xx[k_a, k_b], symmetrised (the default second derivatives are differences).
  bool quadraticCoefficients() {
    const int m = m_;
    Dk_.resize(size_t(bordered_ ? 0 : m + 1));
    for (size_t a = 0; a < Dk_.size(); ++a)
      if (!D_(bp_.u, bp_.lambda, K_.col(Eigen::Index(a)), Dk_[a])) return fail("second derivatives unavailable");
    A_.assign(size_t(m), Matrix::Zero(m + 1, m + 1));
    for (int a = 0; a <= m; ++a)
      for (int b = 0; b <= m; ++b) {
        const Vector y = second(a, K_.col(b));
        for (int j = 0; j < m; ++j) A_[size_t(j)](a, b) = Psi_.col(j).dot(y);
      }
    if (!secondOk_) return fail("second derivatives unavailable");
    for (int j = 0; j < m; ++j) {
      A_[size_t(j)] = (0.5 * (A_[size_t(j)] + A_[size_t(j)].transpose())).eval();
      qmax_ = std::max(qmax_, A_[size_t(j)].cwiseAbs().maxCoeff());
      qphi_ = std::max(qphi_, A_[size_t(j)].bottomRightCorner(m, m).cwiseAbs().maxCoeff());
    }
    if (!(qmax_ > 0.0)) return fail("degenerate bifurcation equation (vanishing second derivatives)");
    return true;
  }

  // Quadratic equation on the sphere S^m: zᵀA_j z = 0, |z|² = 1.
  void solveQuadratic() {
    const int m = m_;
    out_.order = 2;
    const auto system = [&](const Vector &z, Vector &R, Matrix &J) {
      R.resize(m + 1);
      J.resize(m + 1, m + 1);
      for (int j = 0; j < m; ++j) {
        R[j] = z.dot(A_[size_t(j)] * z) / qmax_;
        J.row(j) = 2.0 * (A_[size_t(j)] * z).transpose() / qmax_;
      }
      R[m] = z.squaredNorm() - 1.0;
      J.row(m) = 2.0 * z.transpose();
    };
    std::vector<Vector> roots;
    for (Vector z : sphereStarts(m + 1, 64 * (m + 1))) {
      if (!newton(system, z, 1e-12)) continue;
      z.normalize();
      if (std::abs(z[0]) >= 1.0 - 1e-6) continue;  // the parent branch
      if (addUpToSign(roots, z)) {
        out_.directions.push_back(K_ * z);
        out_.curvatures.push_back(0.0);
      }
    }
  }

  // The cubic term's tensor T[j][(a·m + b)·m + c] = ψ_jᵀ(F_xx[φ_a, W_bc] + ⅙F_xxx[φ_a, φ_b, φ_c]),
  // from the bilinear correction W_bc = −F_x⁺ ½F_xx[φ_b, φ_c] and a central difference of the
  // second derivative along φ_c.
  bool cubicTensor(std::vector<double> &T) {
    const int n = n_, m = m_;
    const double h = 1e-3;
    std::vector<Matrix> W(size_t(m * m));
    for (int b = 0; b < m; ++b)
      for (int c = 0; c < m; ++c)
        W[size_t(b * m + c)] = -pseudoSolve(0.25 * (second(b + 1, K_.col(c + 1)) + second(c + 1, K_.col(b + 1))));
    T.assign(size_t(m * m * m * m), 0.0);
    Matrix Dp, Dm;
    for (int c = 0; c < m; ++c) {
      const Vector shift = h * K_.col(c + 1);
      const Vector up = bp_.u + shift.head(n), um = bp_.u - shift.head(n);
      for (int a = 0; a < m; ++a) {
        if (!bordered_ &&
            (!D_(up, bp_.lambda + shift[n], K_.col(a + 1), Dp) || !D_(um, bp_.lambda - shift[n], K_.col(a + 1), Dm)))
          return fail("third derivatives unavailable");
        for (int b = 0; b < m; ++b) {
          // F_xxx[φ_a, φ_b, φ_c] by a central difference along φ_c
          const Vector third = bordered_ ? Vector((secondAt(up, bp_.lambda + shift[n], a + 1, K_.col(b + 1)) -
                                                   secondAt(um, bp_.lambda - shift[n], a + 1, K_.col(b + 1))) /
                                                  (2.0 * h))
                                         : Vector((Dp - Dm) / (2.0 * h) * K_.col(b + 1));
          const Vector secondTerm = second(a + 1, W[size_t(b * m + c)]);
          for (int j = 0; j < m; ++j)
            T[size_t(j * m * m * m + (a * m + b) * m + c)] = Psi_.col(j).dot(secondTerm + third / 6.0);
        }
        if (!secondOk_) return fail("third derivatives unavailable");
      }
    }
    return true;
  }

  // Cubic: the quadratic form vanishes on span φ. Unknowns y = (β, τ): τBβ + g(β) = 0, |β|² = 1
  // (rows scaled by the cubic's size), B_ji = A_j(i + 1, 0).
  bool solveCubic() {
    const int m = m_;
    out_.order = 3;
    Matrix B(m, m);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) B(j, i) = A_[size_t(j)](i + 1, 0);
    std::vector<double> T;
    if (!cubicTensor(T)) return false;
    double cscale = 0.0;
    for (double v : T) cscale = std::max(cscale, std::abs(v));
    const double bscale = B.cwiseAbs().maxCoeff();
    if (!(cscale > 0.0) || !(bscale > 0.0)) return fail("degenerate cubic bifurcation equation");
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
    std::vector<Vector> roots;
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
        out_.directions.push_back((K_.rightCols(m) * beta).normalized());
        out_.curvatures.push_back(y[m]);
      }
    }
    return true;
  }

  BoundProblem problem_;
  const SpecialPoint &bp_;
  const int n_, m_, r_;  // dimension, multiplicity, rank of F_x
  const SecondDerivative D_;
  ReducedBifurcation &out_;
  Matrix kernel_, Psi_, K_;  // ker F_x, ker F_xᵀ, the basis [t φ₁ … φ_m]
  std::unique_ptr<BorderedSolver> solver_;
  std::unique_ptr<RefinedBorderedSystem> bordered_;
  Eigen::BDCSVD<Matrix> svd_;
  std::vector<Matrix> Dk_;
  std::vector<Matrix> A_;
  double qmax_ = 0.0, qphi_ = 0.0;
  bool secondOk_ = true;
};

bool solveReduced(const BoundProblem &problem, const SpecialPoint &bp, int m, ReducedBifurcation &out,
                  double kernelTolerance, int maxDenseDimension) {
  return ReducedEquation(problem, bp, m, out).solve(kernelTolerance, maxDenseDimension);
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

bool structuredMultipleKernel(const BoundProblem &problem, BorderedSolver &solver, ConstVectorRef u, double lambda,
                              int m, Matrix &K, Matrix &Psi, double &residual, std::string *why) {
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

bool reducedBifurcationDirections(const BoundProblem &problem, const SpecialPoint &bp, int multiplicity,
                                  ReducedBifurcation &out, double kernelTolerance, int maxDenseDimension) {
  // In the problem's scaled variables (as bifurcatingDirection); directions back in its units.
  const int n = problem.dimension();
  const ProblemScales scales = problem.scales();
  if (!scales.identity() && scales.check(n).empty()) {
    const UnitScaling units(scales);
    const BoundScaledProblem scaledProblem(problem, units);
    const BoundProblem &scaled = scaledProblem.bound();
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
  if (!(first.amplitude > 0.0)) first.amplitude = 0.25 * tracer.options().step.initialStep;
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
