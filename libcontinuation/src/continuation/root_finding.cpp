#include "buckle/continuation/root_finding.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace buckle::continuation {

bool sameSign(double a, double b) { return (a > 0.0) == (b > 0.0); }

double IllinoisBracket::next() const {
  const double s = (left * fRight - right * fLeft) / (fRight - fLeft);
  return s > left && s < right ? s : midpoint();
}

int IllinoisBracket::update(double s, double f) { return replace(sameSign(f, fLeft) ? -1 : 1, s, f); }

int IllinoisBracket::replace(int side, double s, double f) {
  if (side < 0) {
    left = s;
    fLeft = f;
    if (lastSide == -1) fRight *= 0.5;
    lastSide = -1;
  } else {
    right = s;
    fRight = f;
    if (lastSide == 1) fLeft *= 0.5;
    lastSide = 1;
  }
  return lastSide;
}

AugmentedNewtonResult augmentedNewton(const AugmentedSystem &system, Vector &z, int lambdaIndex, double tolerance,
                                      int maxIterations, double maxDistance) {
  AugmentedNewtonResult result;
  const Eigen::Index m = z.size();
  const Vector z0 = z;
  Vector R(m), delta(m);
  Matrix J(m, m);
  double lastUpdate = std::numeric_limits<double>::infinity();
  for (int it = 0; it < maxIterations; ++it) {
    if (!system(z, R, &J)) {
      result.message = "the problem refused an iterate";
      break;
    }
    // Partial pivoting (blocked, several times faster than full pivoting at the (2N+1)² fold
    // system of a 50-segment chain); singular as FullPivLU::isInvertible judges it: a pivot below
    // eps·m times the largest.
    Eigen::PartialPivLU<Matrix> lu(J);
    const auto pivots = lu.matrixLU().diagonal().cwiseAbs();
    if (!(pivots.minCoeff() > std::numeric_limits<double>::epsilon() * double(m) * pivots.maxCoeff())) {
      result.message = "singular augmented Jacobian";
      break;
    }
    delta = -lu.solve(R);
    if (!delta.allFinite()) {
      result.message = "non-finite Newton update";
      break;
    }
    z += delta;
    ++result.iterations;
    result.lastDLambda = std::abs(delta[lambdaIndex]);
    lastUpdate = delta.cwiseAbs().maxCoeff();
    if ((z - z0).norm() > maxDistance) {
      result.message = "Newton iterate left the step";
      break;
    }
    if (lastUpdate <= tolerance * std::max(1.0, std::abs(z[lambdaIndex]))) break;
  }
  if (!result.message.empty()) {
    z = z0;
    return result;
  }
  if (system(z, R, nullptr)) result.residualNorm = R.norm();
  const double tol = tolerance * std::max(1.0, std::abs(z[lambdaIndex]));
  // λ must meet the target; the other unknowns (null vectors) only need to have settled.
  result.converged = result.lastDLambda <= tol && lastUpdate <= 1e-6;
  if (!result.converged) {
    char message[80];
    std::snprintf(message, sizeof message, "no convergence: last |dlambda| = %.3g", result.lastDLambda);
    result.message = message;
  }
  return result;
}

bool smallestSingularVector(const Matrix &A, ConstVectorRef start, Vector &v) {
  const Eigen::Index n = A.rows();
  if (n < 2 || A.cols() != n || start.size() != n || !A.allFinite()) return false;
  const double startNorm = start.norm();
  if (!(startNorm > 0.0) || !std::isfinite(startNorm)) return false;
  const Eigen::PartialPivLU<Matrix> lu(A);
  // Isolation as the pivots show it: one pivot far below all the others.
  double smallest = std::numeric_limits<double>::infinity(), next = smallest;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double p = std::abs(lu.matrixLU()(k, k));
    if (!std::isfinite(p)) return false;
    if (p < smallest) {
      next = smallest;
      smallest = p;
    } else if (p < next) {
      next = p;
    }
  }
  if (!(smallest > 0.0) || !(next >= 100.0 * smallest)) return false;
  const double tolerance = 32.0 * std::numeric_limits<double>::epsilon() * std::sqrt(double(n));
  v = start / startNorm;
  Vector y(n), z(n);
  for (int iteration = 0; iteration < 4; ++iteration) {
    y = lu.transpose().solve(v);  // A⁻ᵀ v
    z = lu.solve(y);              // (AᵀA)⁻¹ v
    const double norm = z.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return false;
    z /= norm;
    if (z.dot(v) < 0.0) z = -z;
    const double change = (z - v).norm();
    v = z;
    if (change <= tolerance) return true;
  }
  return false;
}

}  // namespace buckle::continuation
