// Checks a Problem's derivatives against finite differences at one point (in the spirit of
// Ceres' GradientChecker): F_u and F_λ against central differences of residual(), and the
// optional members the core also trusts — the products jacobianApply / jacobianTransposeApply
// against the dense jacobian(), and the second derivative (jacobianDirectionalDerivative,
// secondDerivativeApply, secondDerivativeTransposeApply) against central differences of
// jacobian(). A member the problem does not override is checked too (its default then agrees
// to the differences' accuracy), so one call covers whatever the problem offers.
//
// Errors are relative to the problem's own scale: every quantity is compared in the scaled
// variables of scales() (ũ = u/D_u, λ̃ = λ/λ₀, F̃ = F/D_F, scaled_problem.h), entry (i, j) of a
// matrix relative to the largest entry of its row i of the two matrices compared, entry i of a
// product relative to the size of the terms that sum to it, Σ_j |A_ij x_j|. So a wrong entry is
// found however the units of the problem are chosen, and rows that are all small are not
// dominated by rows that are large.
#pragma once

#include "buckle/continuation/numeric_diff.h"
#include "buckle/continuation/bound_problem.h"

#include <string>
#include <vector>

namespace buckle::continuation {

struct DerivativeCheckOptions {
  /// Largest relative error accepted (the differences' own error is ~1e-10 for F_u, ~1e-8 for
  /// the second derivative, relative to the size of the terms).
  double relativePrecision = 1e-6;
  /// Direction x = (du, dλ) of the second-derivative and product checks (size N+1, in the
  /// problem's units); empty: a fixed pseudo-random direction with every scaled component in
  /// [0.5, 1] in magnitude (no entry of F_xx[x, ·] is missed by a zero component).
  Vector direction;
  /// Second direction z (products F_xx[x, z], F_xᵀw uses its first N entries as w); empty:
  /// another fixed pseudo-random one.
  Vector secondDirection;
  NumericDiffOptions steps;
  /// Empty when valid for dimension n, else which field is wrong.
  std::string validate(int n) const;
  bool IsValid(int n, std::string *why) const { return reportValidity(validate(n), why); }
};

/// One derivative compared: its largest relative error and where.
struct DerivativeComparison {
  std::string name;        ///< "F_u", "F_lambda", "jacobianApply", "F_uu[x]", …
  double maxRelativeError = 0.0;
  int row = -1;            ///< where the largest error is (row of F; −1: nothing compared)
  int column = -1;         ///< its column (N: the F_λ column of an N×(N+1) block; −1 for a vector)
  double exact = 0.0;      ///< the problem's value there, in its units
  double numeric = 0.0;    ///< the finite-difference value there
  bool evaluated = false;  ///< false: the problem (or a perturbed point) refused the evaluation
};

struct DerivativeCheck {
  bool success = false;                     ///< every comparison evaluated and within precision
  double maxRelativeError = 0.0;            ///< the worst over every comparison
  std::vector<DerivativeComparison> comparisons;
  Matrix jacobian;                          ///< the problem's [F_u F_λ] (N×(N+1))
  Matrix numericJacobian;                   ///< its central differences
  std::string message;                      ///< the worst comparison in words ("" when ok)

  /// The comparison named `name`, or null.
  const DerivativeComparison *find(const std::string &name) const;
};

/// Compares the problem's derivatives at (u, λ) with finite differences (see the file comment).
/// Invalid input (sizes, options) gives success = false and the reason in message; nothing is thrown.
DerivativeCheck checkDerivatives(const BoundProblem &problem, ConstVectorRef u, double lambda,
                                 const DerivativeCheckOptions &options = DerivativeCheckOptions());

}  // namespace buckle::continuation
