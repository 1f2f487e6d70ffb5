// Root finding used to locate points along a continuation step (locator.h), kept apart from
// what is located:
//  - IllinoisBracket: the scalar Illinois iteration (regula falsi whose stale end has its value
//    halved, so both ends keep moving; superlinear, never leaves the bracket);
//  - augmentedNewton: Newton on a square augmented system whose regular solution is the point
//    (fold and Moore systems), with a trust distance and a convergence test on the λ unknown.
#pragma once

#include "buckle/continuation/problem.h"

#include <functional>
#include <string>

namespace buckle::continuation {

/// True when a and b are on the same side of zero (zero counts as negative).
bool sameSign(double a, double b);

/// A bracket [left, right] of a scalar function with fLeft·fRight < 0.
struct IllinoisBracket {
  double left = 0.0, right = 0.0;
  double fLeft = 0.0, fRight = 0.0;  ///< function values, the stale end's halved
  int lastSide = 0;                  ///< which end update() replaced last: -1 left, +1 right, 0 none

  double midpoint() const { return 0.5 * (left + right); }
  double width() const { return right - left; }
  /// The regula falsi point, or the midpoint when that is not strictly inside the bracket.
  double next() const;
  /// Replaces the end whose value has the sign of f by (s, f); when the same end is replaced
  /// twice in a row, the other end's value is halved (Illinois). Returns the side replaced
  /// (-1 left, +1 right).
  int update(double s, double f);
  /// The same with the side given by the caller (-1 left, +1 right), for functions whose sign
  /// is less reliable than another test of which side the root is on (e.g. an eigenvalue count).
  int replace(int side, double s, double f);
};

/// Newton on a square augmented system z ↦ R(z) with Jacobian J(z); the λ unknown sits at
/// lambdaIndex. Stops when the whole update is below tolerance·max(1,|λ|) or after maxIterations;
/// converged iff the last |Δλ| met the tolerance. Reports the last |Δλ| and ‖R‖₂ at the end.
struct AugmentedNewtonResult {
  bool converged = false;
  int iterations = 0;
  double lastDLambda = 0.0;
  double residualNorm = 0.0;
  std::string message;
};
using AugmentedSystem = std::function<bool(const Vector &z, Vector &R, Matrix *J)>;
/// An iterate farther than maxDistance from the start is a failure and z is restored.
AugmentedNewtonResult augmentedNewton(const AugmentedSystem &system, Vector &z, int lambdaIndex, double tolerance,
                                      int maxIterations, double maxDistance);

/// The unit right singular vector of A's smallest singular value (up to sign) by inverse
/// iteration on AᵀA from `start`, with one LU of A (partial pivoting): v ← A⁻¹A⁻ᵀv, normalized.
/// For a square A that is nearly singular in one direction only — the Jacobian F_u at a fold
/// located by the secant — it is what an SVD returns, for O(n³/3) flops instead of the SVD's
/// bidiagonalization and V. False, and v not to be used, unless the smallest singular value is
/// isolated as the LU shows it: A's LU exactly singular or not finite, U's smallest pivot not
/// 100 times below the next one (two small singular values: a fold beside a crossing branch),
/// or the iterates' change not below 32·eps·√n within 4 iterations (a ratio σ_n/σ_{n−1} that is
/// not small); the caller then takes the SVD.
bool smallestSingularVector(const Matrix &A, ConstVectorRef start, Vector &v);

}  // namespace buckle::continuation
