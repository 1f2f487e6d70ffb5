#include "buckle/continuation/derivative_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

namespace buckle::continuation {

std::string DerivativeCheckOptions::validate(int n) const {
  if (!(relativePrecision > 0.0 && relativePrecision < 1.0)) return "relativePrecision must lie in (0, 1)";
  if (direction.size() != 0 && direction.size() != n + 1)
    return "direction must be empty or have size N + 1 = " + std::to_string(n + 1);
  if (secondDirection.size() != 0 && secondDirection.size() != n + 1)
    return "secondDirection must be empty or have size N + 1 = " + std::to_string(n + 1);
  if (!direction.allFinite() || !secondDirection.allFinite()) return "directions must be finite";
  return steps.validate("steps.");
}

const DerivativeComparison *DerivativeCheck::find(const std::string &name) const {
  for (const DerivativeComparison &c : comparisons)
    if (c.name == name) return &c;
  return nullptr;
}

namespace {

// The problem's scales, or ones when it offers invalid ones.
struct Scaling {
  Vector row;     // D_F (size N)
  Vector column;  // D_u and λ₀ (size N+1)
};

Scaling scalingOf(const ProblemScales &s) {
  const Eigen::Index n = s.unknowns.size();
  Scaling out;
  out.row = s.residuals;
  out.column.resize(n + 1);
  out.column << s.unknowns, s.parameter;
  return out;
}

// A fixed pseudo-random vector (splitmix64: the same on every platform) whose components have
// magnitudes in [0.5, 1] and alternating signs.
Vector fixedDirection(Eigen::Index size, std::uint64_t seed) {
  Vector x(size);
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    std::uint64_t z = (seed += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    const double r = double(z >> 11) * 0x1.0p-53;  // [0, 1)
    x[j] = (j % 2 == 0 ? 1.0 : -1.0) * (0.5 + 0.5 * r);
  }
  return x;
}

// Denominator for a row whose own size is `own`: the row's size, else the largest over all rows,
// else 1 (the typical size in the scaled variables).
double denominator(double own, double largest) { return own > 0.0 ? own : largest > 0.0 ? largest : 1.0; }

// Exact A and numeric B (N×(N+1)), compared in the scaled variables over columns [begin, end),
// entry (i, j) relative to the largest scaled entry of row i of A and B (all columns).
DerivativeComparison compareMatrices(const std::string &name, const Matrix &A, const Matrix &B,
                                     const Scaling &scaling, Eigen::Index begin, Eigen::Index end) {
  DerivativeComparison c{name};
  c.evaluated = true;
  const Matrix At = scaling.row.cwiseInverse().asDiagonal() * A * scaling.column.asDiagonal();
  const Matrix Bt = scaling.row.cwiseInverse().asDiagonal() * B * scaling.column.asDiagonal();
  const Vector rowSize = At.cwiseAbs().cwiseMax(Bt.cwiseAbs()).rowwise().maxCoeff();
  const double largest = rowSize.size() ? rowSize.maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    for (Eigen::Index j = begin; j < end; ++j) {
      const double e = std::abs(At(i, j) - Bt(i, j)) / denominator(rowSize[i], largest);
      if (c.row < 0 || e > c.maxRelativeError) {
        c.maxRelativeError = e;
        c.row = int(i);
        c.column = int(j);
        c.exact = A(i, j);
        c.numeric = B(i, j);
      }
    }
  }
  return c;
}

// Exact y against reference r = Ax (terms t_i = Σ_j |A_ij x_j|), component i relative to t_i;
// `scale` maps component i to the scaled variables (the ratio is scale-free, the fallback
// denominator for an all-zero row is not).
DerivativeComparison compareProducts(const std::string &name, const Vector &y, const Vector &r, const Vector &t,
                                     const Vector &scale) {
  DerivativeComparison c{name};
  c.evaluated = true;
  const Vector ts = t.cwiseProduct(scale);
  const double largest = ts.size() ? ts.maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    const double e = std::abs(y[i] - r[i]) * scale[i] / denominator(ts[i], largest);
    if (c.row < 0 || e > c.maxRelativeError) {
      c.maxRelativeError = e;
      c.row = int(i);
      c.exact = y[i];
      c.numeric = r[i];
    }
  }
  return c;
}

DerivativeComparison refused(const std::string &name) {
  DerivativeComparison c{name};
  c.maxRelativeError = std::numeric_limits<double>::infinity();
  return c;
}

// [F_u F_λ] from problem.jacobian(), cleared first (a problem may write its nonzeros only).
bool exactJacobian(const BoundProblem &problem, ConstVectorRef u, double lambda, Matrix &J) {
  const int n = problem.dimension();
  J = Matrix::Zero(n, n + 1);
  return problem.jacobian(u, lambda, J.leftCols(n), J.col(n)) && J.allFinite();
}

// d/dε [F_u F_λ](z + εx) by central differences of the exact jacobian(); the step is relative
// to the point in the scaled variables, like Problem's default.
bool differencedSecondDerivative(const BoundProblem &problem, const Scaling &scaling, double relativeStep,
                                 ConstVectorRef u, double lambda, const Vector &x, Matrix &dF) {
  const int n = problem.dimension();
  Vector z(n + 1);
  z << u, lambda;
  const double size = std::max(1.0, z.cwiseQuotient(scaling.column).lpNorm<Eigen::Infinity>());
  const double h = relativeStep * size / x.cwiseQuotient(scaling.column).norm();
  Matrix Jp, Jm;
  const Vector zp = z + h * x, zm = z - h * x;
  if (!exactJacobian(problem, zp.head(n), zp[n], Jp) || !exactJacobian(problem, zm.head(n), zm[n], Jm)) return false;
  dF = (Jp - Jm) / (2.0 * h);
  return dF.allFinite();
}

void compareProductsOfJacobian(const BoundProblem &problem, ConstVectorRef u, double lambda, const Matrix &J,
                               const Vector &x, const Vector &w, const Scaling &scaling, DerivativeCheck &check) {
  const int n = problem.dimension();
  Vector y(n), yt(n + 1);
  if (problem.jacobianApply(u, lambda, x, y) && y.allFinite())
    check.comparisons.push_back(compareProducts("jacobianApply", y, J * x, J.cwiseAbs() * x.cwiseAbs(),
                                                scaling.row.cwiseInverse()));
  else
    check.comparisons.push_back(refused("jacobianApply"));
  if (problem.jacobianTransposeApply(u, lambda, w, yt) && yt.allFinite())
    check.comparisons.push_back(compareProducts("jacobianTransposeApply", yt, J.transpose() * w,
                                                J.cwiseAbs().transpose() * w.cwiseAbs(), scaling.column));
  else
    check.comparisons.push_back(refused("jacobianTransposeApply"));
}

void compareSecondDerivatives(const BoundProblem &problem, ConstVectorRef u, double lambda, const Vector &x,
                              const Vector &z, const Vector &w, const Scaling &scaling,
                              const DerivativeCheckOptions &options, DerivativeCheck &check) {
  const int n = problem.dimension();
  Matrix dFnumeric;
  const char *names[] = {"jacobianDirectionalDerivative", "secondDerivativeApply", "secondDerivativeTransposeApply"};
  if (!differencedSecondDerivative(problem, scaling, options.steps.secondRelativeStep, u, lambda, x, dFnumeric)) {
    for (const char *name : names) check.comparisons.push_back(refused(name));
    return;
  }
  Matrix dF = Matrix::Zero(n, n + 1);
  if (problem.jacobianDirectionalDerivative(u, lambda, x.head(n), x[n], dF.leftCols(n), dF.col(n)) && dF.allFinite())
    check.comparisons.push_back(compareMatrices(names[0], dF, dFnumeric, scaling, 0, n + 1));
  else
    check.comparisons.push_back(refused(names[0]));
  Vector y(n), yt(n + 1);
  if (problem.secondDerivativeApply(u, lambda, x, z, y) && y.allFinite())
    check.comparisons.push_back(compareProducts(names[1], y, dFnumeric * z, dFnumeric.cwiseAbs() * z.cwiseAbs(),
                                                scaling.row.cwiseInverse()));
  else
    check.comparisons.push_back(refused(names[1]));
  if (problem.secondDerivativeTransposeApply(u, lambda, x, w, yt) && yt.allFinite())
    check.comparisons.push_back(compareProducts(names[2], yt, dFnumeric.transpose() * w,
                                                dFnumeric.cwiseAbs().transpose() * w.cwiseAbs(), scaling.column));
  else
    check.comparisons.push_back(refused(names[2]));
}

std::string describe(const DerivativeComparison &c, double precision) {
  char text[320];
  if (!c.evaluated) {
    std::snprintf(text, sizeof text, "%s: the problem refused the evaluation (or a perturbed point)", c.name.c_str());
  } else if (c.column >= 0) {
    std::snprintf(text, sizeof text,
                  "%s: entry (%d, %d) is %.10g but finite differences give %.10g (relative error %.3g > %.3g)",
                  c.name.c_str(), c.row, c.column, c.exact, c.numeric, c.maxRelativeError, precision);
  } else {
    std::snprintf(text, sizeof text,
                  "%s: component %d is %.10g but finite differences give %.10g (relative error %.3g > %.3g)",
                  c.name.c_str(), c.row, c.exact, c.numeric, c.maxRelativeError, precision);
  }
  return text;
}

}  // namespace

DerivativeCheck checkDerivatives(const BoundProblem &problem, ConstVectorRef u, double lambda,
                                 const DerivativeCheckOptions &options) {
  DerivativeCheck check;
  const int n = problem.dimension();
  if (n <= 0 || u.size() != n) {
    check.message = "u must have size N = " + std::to_string(n) + " (N > 0)";
    return check;
  }
  if (const std::string why = options.validate(n); !why.empty()) {
    check.message = "DerivativeCheckOptions: " + why;
    return check;
  }
  ProblemScales s = problem.scales();
  if (!s.check(n).empty()) s = ProblemScales::ones(n);
  const Scaling scaling = scalingOf(s);
  // x, z in the problem's units are D_x times O(1) vectors; w weighs the rows of F, and in the
  // scaled variables F̃_xᵀw̃ = D_x F_xᵀ D_F⁻¹ w̃, so w = D_F⁻¹ times an O(1) vector.
  const Vector x = options.direction.size() ? options.direction
                                            : Vector(fixedDirection(n + 1, 1).cwiseProduct(scaling.column));
  const Vector z = options.secondDirection.size() ? options.secondDirection
                                                  : Vector(fixedDirection(n + 1, 2).cwiseProduct(scaling.column));
  const Vector w = fixedDirection(n, 3).cwiseQuotient(scaling.row);

  Vector work(n), Fplus(n), Fminus(n);
  check.numericJacobian.resize(n, n + 1);
  const bool exact = exactJacobian(problem, u, lambda, check.jacobian);
  const bool numeric = differenceJacobian(problem, s, options.steps.relativeStep, u, lambda,
                                          check.numericJacobian.leftCols(n), check.numericJacobian.col(n), work,
                                          Fplus, Fminus);
  if (exact && numeric) {
    check.comparisons.push_back(compareMatrices("F_u", check.jacobian, check.numericJacobian, scaling, 0, n));
    check.comparisons.push_back(compareMatrices("F_lambda", check.jacobian, check.numericJacobian, scaling, n, n + 1));
    compareProductsOfJacobian(problem, u, lambda, check.jacobian, x, w, scaling, check);
    compareSecondDerivatives(problem, u, lambda, x, z, w, scaling, options, check);
  } else {
    check.comparisons.push_back(refused("F_u"));
    check.comparisons.push_back(refused("F_lambda"));
  }

  // A refused comparison carries an infinite error, so it is the worst.
  const DerivativeComparison *worst = nullptr;
  for (const DerivativeComparison &c : check.comparisons)
    if (!worst || c.maxRelativeError > worst->maxRelativeError) worst = &c;
  check.maxRelativeError = worst->maxRelativeError;
  check.success = check.maxRelativeError <= options.relativePrecision;
  if (!check.success && worst) check.message = describe(*worst, options.relativePrecision);
  return check;
}

}  // namespace buckle::continuation
