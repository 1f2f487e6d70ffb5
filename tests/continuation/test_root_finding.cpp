#include "buckle/continuation/root_finding.h"

#include <catch2/catch.hpp>

#include <cmath>
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
  CHECK_THAT(limited.failure, Contains("left the step"));
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
  CHECK_THAT(failed.failure, Contains("singular"));
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
    CHECK_THAT(augmentedNewton(tiny, t, 1, 1e-12, 20, 10.0).failure, Contains("singular"));
  }
}
