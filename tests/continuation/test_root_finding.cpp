#include "buckle/continuation/root_finding.h"

#include <catch2/catch.hpp>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

TEST_CASE("Illinois bracket halves the stale end's value after two updates on one side", "[root_finding]") {
  IllinoisBracket bracket;
  bracket.left = 0.0;
  bracket.right = 1.0;
  bracket.fLeft = -1.0;
  bracket.fRight = 1.0;
  CHECK(bracket.next() == 0.5);  // the secant through (0, -1) and (1, 1)
  CHECK(bracket.update(0.2, -0.5) == -1);
  CHECK(bracket.left == 0.2);
  CHECK(bracket.fRight == 1.0);  // first time on this side: no halving
  CHECK(bracket.update(0.3, -0.25) == -1);
  CHECK(bracket.fRight == 0.5);  // the right end went stale: its value halved
  CHECK(bracket.update(0.9, 0.125) == 1);
  CHECK(bracket.right == 0.9);
  CHECK(bracket.fLeft == -0.25);  // a side change halves nothing
  CHECK(bracket.width() == 0.9 - 0.3);
}

TEST_CASE("Illinois bracket falls back to the midpoint when the secant point is not inside", "[root_finding]") {
  IllinoisBracket bracket;
  bracket.left = 1.0;
  bracket.right = 3.0;
  bracket.fLeft = -2.0;
  bracket.fRight = -2.0;  // equal values: the secant is undefined
  CHECK(bracket.next() == 2.0);
}

TEST_CASE("Illinois iteration finds the cube root of 2 superlinearly", "[root_finding]") {
  // f(x) = x^3 - 2 on [0, 2]: root 2^(1/3). Plain regula falsi keeps the convex function's
  // right end for ever (linear convergence); bisection needs ~50 halvings for 1e-15.
  const auto f = [](double x) { return x * x * x - 2.0; };
  IllinoisBracket bracket;
  bracket.left = 0.0;
  bracket.right = 2.0;
  bracket.fLeft = f(0.0);
  bracket.fRight = f(2.0);
  const double root = std::cbrt(2.0);
  double x = 0.0;
  int evaluations = 0;
  while (bracket.width() > 1e-12 * root && evaluations < 60) {
    x = bracket.next();
    const double fx = f(x);
    ++evaluations;
    if (fx == 0.0) break;
    bracket.update(x, fx);
    CHECK(bracket.left <= root * (1.0 + 1e-15));  // the root stays bracketed (to rounding of f)
    CHECK(bracket.right >= root * (1.0 - 1e-15));
  }
  CHECK(std::abs(x - root) <= 1e-12 * root);
  CHECK(evaluations < 20);
}

TEST_CASE("Augmented Newton reaches the exact root and reports the last update", "[root_finding]") {
  // z = (x, λ): x² − 2 = 0, λ − x = 0  →  λ = √2.
  const AugmentedSystem system = [](const Vector &z, Vector &R, Matrix *J) {
    R.resize(2);
    R << z[0] * z[0] - 2.0, z[1] - z[0];
    if (J) *J << 2.0 * z[0], 0.0, -1.0, 1.0;
    return true;
  };
  Vector z(2);
  z << 1.5, 1.4;
  const AugmentedNewtonResult result = augmentedNewton(system, z, 1, 1e-12, 20, 10.0);
  CHECK(result.converged);
  CHECK(std::abs(z[1] - std::sqrt(2.0)) < 1e-14);
  CHECK(result.lastDLambda <= 1e-12 * std::sqrt(2.0));
  CHECK(result.residualNorm < 1e-14);
  CHECK(result.iterations >= 3);

  Vector far(2);
  far << 1.5, 1.4;
  const AugmentedNewtonResult limited = augmentedNewton(system, far, 1, 1e-12, 20, 1e-3);
  CHECK_FALSE(limited.converged);
  CHECK_THAT(limited.message, Contains("left the step"));
  CHECK(far[0] == 1.5);  // restored
}

TEST_CASE("Augmented Newton pivots past a zero leading entry and stops on a singular Jacobian", "[root_finding]") {
  // z = (x, λ): λ − 1 = 0, x·λ − 3 = 0 → (3, 1). J = [[0, 1], [λ, x]]: its leading entry is zero at
  // every iterate, so an LU without row exchanges fails at the first pivot; partial pivoting swaps.
  const AugmentedSystem swapped = [](const Vector &z, Vector &R, Matrix *J) {
    R.resize(2);
    R << z[1] - 1.0, z[0] * z[1] - 3.0;
    if (J) *J << 0.0, 1.0, z[1], z[0];
    return true;
  };
  Vector z(2);
  z << 2.0, 1.2;
  const AugmentedNewtonResult result = augmentedNewton(swapped, z, 1, 1e-12, 20, 10.0);
  CHECK(result.converged);
  CHECK(std::abs(z[0] - 3.0) < 1e-13);
  CHECK(std::abs(z[1] - 1.0) < 1e-15);

  // x² − 2 = 0, λ − x² = 0 from x = 0: J = [[2x, 0], [−2x, 1]] has the zero column of x.
  const AugmentedSystem singular = [](const Vector &w, Vector &R, Matrix *J) {
    R.resize(2);
    R << w[0] * w[0] - 2.0, w[1] - w[0] * w[0];
    if (J) *J << 2.0 * w[0], 0.0, -2.0 * w[0], 1.0;
    return true;
  };
  Vector s(2);
  s << 0.0, 0.5;
  const AugmentedNewtonResult failed = augmentedNewton(singular, s, 1, 1e-12, 20, 10.0);
  CHECK_FALSE(failed.converged);
  CHECK_THAT(failed.message, Contains("singular"));
  CHECK(s[0] == 0.0);  // restored
  CHECK(s[1] == 0.5);

  // Nearly singular in relative terms (a pivot 1e-3 eps of the largest): also refused, at any scale.
  for (double scale : {1e-6, 1.0, 1e6}) {
    const AugmentedSystem tiny = [scale](const Vector &w, Vector &R, Matrix *J) {
      R.resize(2);
      R << scale * (w[0] - 1.0), w[1] - 2.0;
      if (J) *J << scale, 0.0, 0.0, 1e-19 * scale;
      return true;
    };
    Vector t(2);
    t << 0.0, 0.0;
    CHECK_THAT(augmentedNewton(tiny, t, 1, 1e-12, 20, 10.0).message, Contains("singular"));
  }
}

namespace {

/// A = Q1 diag(σ) Q2ᵀ with random orthogonal Q1, Q2 (QR of random matrices) and the given σ.
Matrix withSingularValues(const Vector& sigma, unsigned seed, Matrix& V) {
  const Eigen::Index n = sigma.size();
  std::srand(seed);
  const Eigen::HouseholderQR<Matrix> q1(Matrix::Random(n, n)), q2(Matrix::Random(n, n));
  const Matrix U = q1.householderQ() * Matrix::Identity(n, n);
  V = q2.householderQ() * Matrix::Identity(n, n);
  return U * sigma.asDiagonal() * V.transpose();
}

}  // namespace

TEST_CASE("smallestSingularVector is the SVD's right singular vector of an isolated smallest singular value",
          "[root_finding]") {
  // Independent formulations: the constructed V's last column and Eigen's BDCSVD (up to sign),
  // at n = 3 and 51, at scales 1e±6, with the smallest singular value 1e-6 … 1e-12 of the others (the pivot test may refuse 1e-4 at n = 51: the SVD then).
  for (int n : {3, 12, 51})
    for (double scale : {1e-6, 1.0, 1e6})
      for (double gap : {1e-6, 1e-9, 1e-12}) {
        INFO("n = " << n << ", scale " << scale << ", gap " << gap);
        Vector sigma = scale * (Vector::LinSpaced(n, 2.0, 1.0));
        sigma[n - 1] = scale * gap;
        Matrix V;
        const Matrix A = withSingularValues(sigma, unsigned(n * 7 + 1), V);
        const Vector exact = V.col(n - 1);
        // a start as the secant leaves it: the null direction and a few per cent of others
        const Vector start = exact + 0.05 * V.col(0) - 0.03 * V.col(n / 2);
        Vector v;
        REQUIRE(smallestSingularVector(A, start, v));
        const Eigen::BDCSVD<Matrix> svd(A, Eigen::ComputeFullV);
        const Vector reference = svd.matrixV().col(n - 1);
        const double sign = v.dot(reference) < 0.0 ? -1.0 : 1.0;
        CHECK((sign * v - reference).norm() <= 1e-13);
        CHECK(std::min((v - exact).norm(), (v + exact).norm()) <= 1e-12);
        CHECK(std::abs(v.norm() - 1.0) <= 1e-15);
      }
}

TEST_CASE("smallestSingularVector refuses two small singular values, a singular and a non-finite matrix",
          "[root_finding]") {
  const int n = 20;
  Vector sigma = Vector::LinSpaced(n, 2.0, 1.0);
  sigma[n - 1] = 1e-9;
  sigma[n - 2] = 3e-9;  // a fold beside a crossing branch: not isolated
  Matrix V;
  Vector out;
  const Matrix A = withSingularValues(sigma, 5u, V);
  CHECK_FALSE(smallestSingularVector(A, Vector::Ones(n), out));
  Matrix S = Matrix::Identity(n, n);
  S(3, 3) = 0.0;  // exactly singular: the LU has a zero pivot
  CHECK_FALSE(smallestSingularVector(S, Vector::Ones(n), out));
  Matrix N = Matrix::Identity(n, n);
  N(0, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(smallestSingularVector(N, Vector::Ones(n), out));
  CHECK_FALSE(smallestSingularVector(Matrix::Identity(n, n), Vector::Zero(n), out));  // no start
  // one isolated small value, the other σ equal: accepted (only σ_n must be isolated)
  sigma.setOnes();
  sigma[n - 1] = 1e-7;
  const Matrix B = withSingularValues(sigma, 9u, V);
  REQUIRE(smallestSingularVector(B, Vector::Ones(n), out));
  CHECK(std::min((out - V.col(n - 1)).norm(), (out + V.col(n - 1)).norm()) <= 1e-12);
}
