// Switching at branch points of multiplicity m ≥ 2 (multiplicity_switching.h), on gradient
// systems whose branches are known in closed form.
#include "buckle/continuation/multiplicity_switching.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/internal/test_functions.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

namespace {

/// F = −∇V, V = −λ|u|²/2 + Σu_i⁴/4 + (c/2)Σ_{i<j} u_i²u_j², H = ∇²V: on u = 0 all m eigenvalues
/// are −λ, an m-fold branch point at λ = 0. The branches are u = s·e with e a vector of 0, ±1
/// entries (k nonzero ones): λ = s²(1 + c(k − 1)). Lines through 0: 2 for m = 2 per k ∈ {1, 2}
/// (4 in all), 3 + 6 + 4 = 13 for m = 3: the cubic reduced equation has its Bézout number of roots.
class CoupledPitchforks : public Problem {
 public:
  CoupledPitchforks(int m, double c) : m_(m), c_(c) {}
  int dimension() const override { return m_; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    const double s = u.squaredNorm();
    for (int i = 0; i < m_; ++i) F[i] = lambda * u[i] - u[i] * u[i] * u[i] - c_ * u[i] * (s - u[i] * u[i]);
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    const double s = u.squaredNorm();
    for (int i = 0; i < m_; ++i) {
      for (int j = 0; j < m_; ++j) Fu(i, j) = i == j ? 0.0 : -2.0 * c_ * u[i] * u[j];
      Fu(i, i) = lambda - 3.0 * u[i] * u[i] - c_ * (s - u[i] * u[i]);
    }
    Fl = u;
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return toys::negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  int m_;
  double c_;
};

TracerOptions options() {
  TracerOptions o;
  o.lambdaMin = -1.0;
  o.lambdaMax = 1.0;
  o.step.maxStep = 0.05;
  o.maxPoints = 40;
  return o;
}

// The m-fold branch point of CoupledPitchforks as the tracer locates it on the trivial branch
// (exactly one BP expected there).
SpecialPoint locatedMultiplePoint(CoupledPitchforks &problem, int m) {
  const Branch trivial = trace(problem, Vector::Zero(m), -0.37, InitialDirection::increasingLambda(), options());
  const auto bps = trivial.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  return *bps[0];
}

}  // namespace

TEST_CASE("an m-fold branch point is located once, refined, and its reduced equation solved") {
  for (int m : {2, 3}) {
    INFO("m = " << m);
    CoupledPitchforks problem(m, 0.4);
    const SpecialPoint bp = locatedMultiplePoint(problem, m);
    CHECK(bp.multiplicity == m);
    CHECK(std::abs(bp.lambda) <= 1e-12);  // closed form: λ = 0
    CHECK(bp.refined);
    ReducedBifurcation rb;
    const bool solved = reducedBifurcationDirections(problem, bp, m, rb);
    INFO(rb.note);
    REQUIRE(solved);
    CHECK(rb.order == 3);  // odd in u: the quadratic part vanishes on the kernel
    CHECK(int(rb.directions.size()) == (m == 2 ? 4 : 13));
    // each direction is a line of 0, ±1 entries (closed form), with λ curvature τ = 1 + c(k − 1)
    for (size_t d = 0; d < rb.directions.size(); ++d) {
      const Vector e = rb.directions[d].head(m);
      const double largest = e.cwiseAbs().maxCoeff();
      int k = 0;
      for (int i = 0; i < m; ++i) {
        const double r = std::abs(e[i]) / largest;
        CHECK((r <= 1e-6 || std::abs(r - 1.0) <= 1e-6));
        if (r > 0.5) ++k;
      }
      CHECK(std::abs(rb.directions[d][m]) <= 1e-8);  // along the trivial branch's normal: λ' = 0
      // x = εΦβ + ε²τ·t: |u|² = ε², u_i² = ε²/k on the k nonzero entries, so τ = λ/ε² = (1 + c(k − 1))/k
      CHECK(rb.curvatures[d] == Approx((1.0 + 0.4 * (k - 1)) / k).epsilon(1e-5));
    }
  }
}

TEST_CASE("traceTree switches an m-fold point along every direction: predicted = found") {
  for (int m : {2, 3}) {
    INFO("m = " << m);
    CoupledPitchforks problem(m, 0.4);
    TracerOptions o = options();
    o.maxPoints = 15;
    const BranchTree tree = traceTree(problem, Vector::Zero(m), -0.37, InitialDirection::increasingLambda(), o, 1);
    const auto bps = tree.branches.at(0).specialPointsOfType(SpecialPointType::BranchPoint);
    REQUIRE(bps.size() == 1);
    const int lines = m == 2 ? 4 : 13;
    CHECK(bps[0]->branchesPredicted == 2 * lines);
    CHECK(bps[0]->branchesFound == 2 * lines);
    REQUIRE(int(tree.branches.size()) == 1 + 2 * lines);
    // every child lies on its closed-form branch λ = u_i²(1 + c(k − 1)) (u_i a nonzero entry)
    for (size_t b = 1; b < tree.branches.size(); ++b) {
      const Branch &child = tree.branches[b];
      REQUIRE(child.points.size() >= 3);
      const ContinuationPoint &p = child.points.back();
      const double largest = p.u.cwiseAbs().maxCoeff();
      int k = 0;
      for (int i = 0; i < m; ++i)
        if (std::abs(p.u[i]) > 0.5 * largest) ++k;
      CHECK(p.lambda == Approx(largest * largest * (1.0 + 0.4 * (k - 1))).epsilon(1e-8));
    }
  }
}

namespace {
/// Two identical uncoupled chains, F = λu − Tu − u³ with T = blockdiag(T₁, T₁), T₁ = tridiag(−1, 2, −1)
/// of size n/2 (H = −F_u = T − λ + 3u²): on u = 0 every eigenvalue of T₁ is a double branch point;
/// the first at λ* = 2 − 2cos(π/(n/2 + 1)) with ker F_u = span{(φ, 0), (0, φ)}, φ_i = sin(iπ/(n/2 + 1)).
class TwinChains : public Problem {
 public:
  explicit TwinChains(int n) : n_(n) {}
  int dimension() const override { return n_; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    const int h = n_ / 2;
    for (int i = 0; i < n_; ++i) {
      const int j = i % h;
      const double left = j > 0 ? u[i - 1] : 0.0, right = j + 1 < h ? u[i + 1] : 0.0;
      F[i] = lambda * u[i] - (2.0 * u[i] - left - right) - u[i] * u[i] * u[i];
    }
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    const int h = n_ / 2;
    Fu.setZero();
    for (int i = 0; i < n_; ++i) {
      const int j = i % h;
      Fu(i, i) = lambda - 2.0 - 3.0 * u[i] * u[i];
      if (j > 0) Fu(i, i - 1) = 1.0;
      if (j + 1 < h) Fu(i, i + 1) = 1.0;
    }
    Fl = u;
    return true;
  }
  double firstBranchPoint() const { return 2.0 - 2.0 * std::cos(std::acos(-1.0) / (n_ / 2 + 1)); }

 private:
  int n_;
};

// A bound on the sine of the largest principal angle between the column spans of orthonormal X and
// Y: the Frobenius norm of X's part outside span Y (≥ its 2-norm, the sine itself).
double subspaceAngle(const Matrix &X, const Matrix &Y) { return (X - Y * (Y.transpose() * X)).norm(); }
}  // namespace

TEST_CASE("structuredMultipleKernel: the kernel of a double point at n = 1000 equals the dense SVD's") {
  const int n = 1000;
  TwinChains problem(n);
  const Vector u = Vector::Zero(n);
  const double lambda = problem.firstBranchPoint();
  DenseBorderedSolver solver(problem);
  Matrix K, Psi;
  double residual = 0.0;
  std::string why;
  REQUIRE(structuredMultipleKernel(problem, solver, u, lambda, 2, K, Psi, residual, &why));
  REQUIRE(K.cols() == 3);
  REQUIRE(Psi.cols() == 2);
  CHECK((K.transpose() * K - Matrix::Identity(3, 3)).norm() <= 1e-14);
  CHECK(residual <= 1e-14);  // F_x K and Psiᵀ F_x, against ‖F_x‖ ~ 4
  // The dense route (full SVD of F_x): its three smallest right and two smallest left vectors.
  KernelInfo dense;
  REQUIRE(jacobianKernel(problem, u, lambda, dense));
  CHECK(dense.singularValues[2] <= 1e-13);
  CHECK(dense.singularValues[3] > 1e-6);
  CHECK(subspaceAngle(K, dense.right.leftCols(3)) <= 1e-10);
  CHECK(subspaceAngle(Psi, dense.left.leftCols(2)) <= 1e-10);
  // and the closed form: e_λ and the two copies of φ
  Matrix exact = Matrix::Zero(n + 1, 3);
  for (int i = 0; i < n / 2; ++i)
    exact(i, 0) = exact(n / 2 + i, 1) = std::sin((i + 1) * std::acos(-1.0) / (n / 2 + 1));
  exact.col(0).normalize();
  exact.col(1).normalize();
  exact(n, 2) = 1.0;
  CHECK(subspaceAngle(K, exact) <= 1e-10);
}

TEST_CASE("structuredMultipleKernel: where F_x vanishes (kappa = 0 type) the kernel is everything") {
  // CoupledPitchforks at u = 0, λ = 0: F_u = λI = 0 and F_λ = u = 0, as the κ = 0 chain's F_x at
  // the unloaded straight state: an (m+1)-dimensional kernel in R^(m+1), the left kernel R^m.
  for (int m : {2, 3}) {
    INFO("m = " << m);
    CoupledPitchforks problem(m, 0.4);
    DenseBorderedSolver solver(problem);
    Matrix K, Psi;
    double residual = 1.0;
    REQUIRE(structuredMultipleKernel(problem, solver, Vector::Zero(m), 0.0, m, K, Psi, residual));
    CHECK(residual == 0.0);
    CHECK((K.transpose() * K - Matrix::Identity(m + 1, m + 1)).norm() <= 1e-14);
    CHECK((Psi.transpose() * Psi - Matrix::Identity(m, m)).norm() <= 1e-14);
  }
}

TEST_CASE("reducedBifurcationDirections at n = 1000: the bordered kernels give the dense SVD's directions") {
  // The double point of the twin chains: F odd in u, so the cubic equation; its roots are the
  // lines (φ, 0), (0, φ) and (φ, ±φ) (the uncoupled cubics u_i³ make the diagonals roots too).
  const int n = 1000;
  TwinChains problem(n);
  SpecialPoint bp;
  bp.type = SpecialPointType::BranchPoint;
  bp.multiplicity = 2;
  bp.u = Vector::Zero(n);
  bp.lambda = problem.firstBranchPoint();
  bp.tangent = Vector::Unit(n + 1, n);
  ReducedBifurcation bordered, dense;
  REQUIRE(reducedBifurcationDirections(problem, bp, 2, bordered));
  REQUIRE(reducedBifurcationDirections(problem, bp, 2, dense, 1e-7, n));  // the SVD route
  INFO(bordered.note << " | " << dense.note);
  CHECK(bordered.order == 3);
  CHECK(dense.order == 3);
  REQUIRE(bordered.directions.size() == 4);
  REQUIRE(dense.directions.size() == bordered.directions.size());
  for (size_t d = 0; d < bordered.directions.size(); ++d) {
    double closest = 0.0;
    size_t match = 0;
    for (size_t e = 0; e < dense.directions.size(); ++e)
      if (std::abs(bordered.directions[d].dot(dense.directions[e])) > closest) {
        closest = std::abs(bordered.directions[d].dot(dense.directions[e]));
        match = e;
      }
    CHECK(closest >= 1.0 - 1e-12);
    // τ comes from central differences of the second derivatives (h = 1e−3) along the kernel basis,
    // which differs between the routes (any orthonormal basis of the same kernel): O(h²) apart.
    CHECK(bordered.curvatures[d] == Approx(dense.curvatures[match]).epsilon(1e-6));
  }
}

TEST_CASE("reducedBifurcationDirections where F_x vanishes: the bordered route forced gives the dense one's roots") {
  // CoupledPitchforks' m-fold point (F_x = 0 there, the κ = 0 type): the bordered kernels with the
  // crossover forced to 0 against the SVD route, root by root (4 and 13 lines, closed form).
  for (int m : {2, 3}) {
    INFO("m = " << m);
    CoupledPitchforks problem(m, 0.4);
    const SpecialPoint bp = locatedMultiplePoint(problem, m);
    ReducedBifurcation bordered, dense;
    REQUIRE(reducedBifurcationDirections(problem, bp, m, bordered, 1e-7, 0));
    REQUIRE(reducedBifurcationDirections(problem, bp, m, dense));
    INFO(bordered.note << " | " << dense.note);
    CHECK(bordered.order == dense.order);
    REQUIRE(bordered.directions.size() == size_t(m == 2 ? 4 : 13));
    REQUIRE(dense.directions.size() == bordered.directions.size());
    for (const Vector &d : bordered.directions) {
      double closest = 0.0;
      for (const Vector &e : dense.directions) closest = std::max(closest, std::abs(d.dot(e)));
      CHECK(closest >= 1.0 - 1e-10);
    }
  }
}
