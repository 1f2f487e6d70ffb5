#include "buckle/continuation/internal/test_functions.h"

#include <Eigen/SVD>
#include <cmath>
#include <algorithm>
#include <cstdlib>
#include <limits>

namespace buckle::continuation {

PointEvaluator::PointEvaluator(const BoundProblem &problem, BorderedSolver &solver, bool computeStability,
                               int lowestEigenvalues)
    : problem_(problem),
      solver_(solver),
      n_(problem.dimension()),
      stability_(computeStability && problem.hasStabilityOperator()),
      lowestEigenvalues_(lowestEigenvalues),
      rhs_(Vector::Zero(n_ + 1)),
      solution_(Vector::Zero(n_ + 1)) {
  rhs_[n_] = 1.0;
}

bool PointEvaluator::borderedJacobian(ConstVectorRef u, double lambda, ConstVectorRef t, MatrixRef A) {
  A.setZero();
  if (!problem_.jacobian(u, lambda, A.topLeftCorner(n_, n_), A.col(n_).head(n_))) return false;
  A.row(n_) = t.transpose();
  return A.allFinite();
}

bool PointEvaluator::complete(ContinuationPoint &point, ConstVectorRef reference, bool inertiaOnly) {
  singular_ = false;
  const Factorization f = solver_.factor(point.u, point.lambda, reference);
  if (f == Factorization::Refused) return false;
  singular_ = f == Factorization::Singular;
  if (stability_) {
    if (!problem_.stability(point.u, point.lambda, inertiaOnly ? 0 : lowestEigenvalues_, point.stability))
      point.stability = StabilityInfo();
  } else {
    point.stability = StabilityInfo();
  }
  if (!singular_) {
    const double norm = solver_.solve(rhs_, solution_) ? solution_.norm() : 0.0;
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      singular_ = true;
    } else {
      point.tangent = solution_ / norm;
      // det with the point's own tangent as last row: det_ref = (refᵀt)·det_t, refᵀt = 1/‖y‖ > 0.
      point.determinantSign = solver_.determinantSign();
      point.logAbsDeterminant = solver_.logAbsDeterminant() + std::log(norm);
    }
  }
  if (singular_) {
    point.tangent = reference.normalized();
    point.determinantSign = 0;
    point.logAbsDeterminant = -std::numeric_limits<double>::infinity();
  }
  point.foldTest = point.tangent[n_];
  return !singular_;
}

void MinimallyAugmentedTest::initialize(const Matrix &referenceA) {
  const Eigen::Index m = referenceA.rows();
  Eigen::BDCSVD<Matrix> svd(referenceA, Eigen::ComputeFullU | Eigen::ComputeFullV);
  b_ = svd.matrixU().col(m - 1);
  c_ = svd.matrixV().col(m - 1);
  augmented_ = Matrix::Zero(m + 1, m + 1);
  rhs_ = Vector::Zero(m + 1);
  rhs_[m] = 1.0;
  solution_ = Vector::Zero(m + 1);
}

bool MinimallyAugmentedTest::evaluate(const Matrix &A, double &psi, Vector *v) {
  const Eigen::Index m = A.rows();
  if (b_.size() != m) return false;
  augmented_.topLeftCorner(m, m) = A;
  augmented_.col(m).head(m) = b_;
  augmented_.row(m).head(m) = c_.transpose();
  augmented_(m, m) = 0.0;
  // Bordered by the reference's singular vectors, the matrix is regular near the reference
  // (Govaerts 2000): partial pivoting suffices, and a breakdown shows as a non-finite solution.
  Eigen::PartialPivLU<Matrix> lu(augmented_);
  solution_ = lu.solve(rhs_);
  if (!solution_.allFinite()) return false;
  psi = solution_[m];
  if (v) *v = solution_.head(m);
  return true;
}

bool foldBetween(const ContinuationPoint &a, const ContinuationPoint &b) {
  if ((a.foldTest >= 0.0) == (b.foldTest >= 0.0)) return false;
  if (!a.stability.valid() || !b.stability.valid() || a.determinantSign == 0 || b.determinantSign == 0) return true;
  // sign t_λ = sign det F_u · sign det[[F_u, F_λ], [tᵀ]]: t_λ flips iff exactly one of them does.
  const bool fuFlips = std::abs(b.stability.negative - a.stability.negative) % 2 == 1;
  const bool borderedFlips = a.determinantSign * b.determinantSign < 0;
  return fuFlips != borderedFlips;
}

namespace {

// sign det F_u at a point, by Cramer's rule t_λ = det F_u / det [[F_u, F_λ], [tᵀ]] (0: unknown).
int jacobianDeterminantSign(const ContinuationPoint &p) {
  if (p.determinantSign == 0 || p.foldTest == 0.0) return 0;
  return p.foldTest > 0.0 ? p.determinantSign : -p.determinantSign;
}

// The inertia ν of p for counting the crossings between p and `other`, with an eigenvalue in the
// count's zero band at p (stability.zero: neither negative nor positive) put on the side that
// det F_u takes at p. A step can end where an eigenvalue crosses (a branch point at λ = 0 reached
// in whole steps from λ = −3 lands there to rounding): there ν does not count it as negative, but
// the determinant may already have changed sign, so without this the step ending at p counts the
// crossing from the determinant and the next one counts it again from ν (one branch point located
// twice). The assignment depends on p alone, and the two steps that share p see the same one.
// Along a branch sign det F_u = σ·(−1)^ν with a fixed σ (as in foldBetween: H = ±F_u or the KKT
// form), so ν_p has the parity of ν_other plus one if sign det F_u differs between the two points.
// Only a single zero-band eigenvalue at p facing a clear count at `other` is settled: with several
// the parity does not fix the count (a double zero would be lost), and two ambiguous ends have no
// reference.
int settledNegative(const ContinuationPoint &p, const ContinuationPoint &other) {
  const int nu = p.stability.negative;
  if (p.stability.zero != 1 || other.stability.zero != 0) return nu;
  const int sp = jacobianDeterminantSign(p), so = jacobianDeterminantSign(other);
  if (sp == 0 || so == 0) return nu;
  const bool parityDiffers = (nu - other.stability.negative) % 2 != 0;
  return parityDiffers == (sp != so) ? nu : nu + 1;
}

}  // namespace

namespace {

// Whether the step resolves a turning of λ at all. A fold is a turning point of λ(s); the
// equations fix λ only to the rounding of their λ terms, ε·max(λ₀, |λ|) (λ₀ = 1 in the tracer's
// scaled variables), so if neither the ends' λ nor the tangents' λ components move λ by more than
// that over the step (|λ_b − λ_a| and |t_λ|·ds below it), the sign of t_λ is rounding. This is
// the case on the children of a branch point of the n = 10 000 chain traced in steps of 4e−9
// (λ − λ_c ~ λ_c s², λ_c ~ 1e−7): there t_λ ~ 1e−9 and the crossing eigenvalue of F_u (~λ_c s²,
// far below its rounding) flip together from step to step, det F_u with them, so the parity check
// of foldBetween confirms them; before this, 22 LPs on each child. A real fold in a step of length
// ds moves λ by ~½|λ''|ds², resolved down to steps of ~1e−7 (test_tracer: the cubic's folds in
// steps of 1e−6 still found to 1e−12).
bool turningResolved(const ContinuationPoint &a, const ContinuationPoint &b) {
  const int n = int(a.tangent.size()) - 1;
  if (n < 0 || b.tangent.size() != a.tangent.size() || a.u.size() != n || b.u.size() != n) return true;
  const double ds = std::sqrt((b.u - a.u).squaredNorm() + (b.lambda - a.lambda) * (b.lambda - a.lambda));
  const double motion = std::max({std::abs(b.lambda - a.lambda), std::abs(a.foldTest) * ds, std::abs(b.foldTest) * ds});
  const double resolution = 4.0 * std::numeric_limits<double>::epsilon() * std::max({1.0, std::abs(a.lambda), std::abs(b.lambda)});
  return motion > resolution;
}

}  // namespace

IntervalCrossings classifyInterval(const ContinuationPoint &a, const ContinuationPoint &b, bool detectFolds,
                                   bool detectBranchPoints) {
  IntervalCrossings crossings;
  // An unresolved turning is not reported, but the eigenvalue crossing that came with it is the
  // same rounding, so it still explains one change of the inertia below (no spurious BP instead).
  const bool foldSignChange = foldBetween(a, b);
  crossings.fold = detectFolds && foldSignChange && turningResolved(a, b);
  if (!detectBranchPoints) return crossings;
  crossings.determinantChange = a.determinantSign * b.determinantSign < 0;
  if (a.stability.valid() && b.stability.valid())
    crossings.inertiaChange = std::abs(settledNegative(b, a) - settledNegative(a, b));
  int count = crossings.determinantChange ? 1 : 0;
  // A fold moves one eigenvalue through zero too; only the rest are branch points.
  // (whether or not folds are being reported).
  if (crossings.inertiaChange >= 0) count = std::max(count, crossings.inertiaChange - (foldSignChange ? 1 : 0));
  crossings.branchPointCrossings = count;
  return crossings;
}

bool jacobianKernel(const BoundProblem &problem, ConstVectorRef u, double lambda, KernelInfo &info) {
  const int n = problem.dimension();
  Matrix Fx = Matrix::Zero(n, n + 1);
  if (!problem.jacobian(u, lambda, Fx.leftCols(n), Fx.col(n))) return false;
  // Full SVD of the N×(N+1) matrix: V has N+1 columns, the last one spans the always-present
  // extra kernel dimension; Eigen orders singular values descending.
  // BDCSVD: divide and conquer, Jacobi below 16×16, so small problems see no difference.
  Eigen::BDCSVD<Matrix> svd(Fx, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vector &sigma = svd.singularValues();
  info.singularValues = Vector::Zero(n + 1);
  info.right.resize(n + 1, n + 1);
  info.left.resize(n, n);
  // Ascending: column k of `right` pairs with singularValues[k]; the (N+1)-th right vector has
  // no singular value (σ = 0 by dimension).
  info.right.col(0) = svd.matrixV().col(n);
  info.singularValues[0] = 0.0;
  for (int k = 0; k < n; ++k) {
    info.singularValues[k + 1] = sigma[n - 1 - k];
    info.right.col(k + 1) = svd.matrixV().col(n - 1 - k);
    info.left.col(k) = svd.matrixU().col(n - 1 - k);
  }
  return true;
}

namespace {
// Real roots d = αk₁ + βk₂ of aα² + 2bαβ + cβ² = 0, normalised.
bool bifurcationRoots(double a, double b, double c, ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2,
                      std::string *why);
}  // namespace

bool bifurcationDirections(const BoundProblem &problem, ConstVectorRef u, double lambda, ConstVectorRef psi,
                           ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2, std::string *why) {
  const int n = problem.dimension();
  Matrix D1(n, n + 1), D2(n, n + 1);
  if (!problem.jacobianDirectionalDerivative(u, lambda, k1.head(n), k1[n], D1.leftCols(n), D1.col(n)) ||
      !problem.jacobianDirectionalDerivative(u, lambda, k2.head(n), k2[n], D2.leftCols(n), D2.col(n))) {
    if (why) *why = "second derivatives unavailable";
    return false;
  }
  // ψᵀF_xx[αk₁ + βk₂, αk₁ + βk₂] = aα² + 2bαβ + cβ²; b symmetrised against finite-difference noise.
  const double a = psi.dot(D1 * k1);
  const double b = 0.5 * (psi.dot(D1 * k2) + psi.dot(D2 * k1));
  const double c = psi.dot(D2 * k2);
  return bifurcationRoots(a, b, c, k1, k2, d1, d2, why);
}

bool bifurcationDirectionsApplied(const BoundProblem &problem, ConstVectorRef u, double lambda, ConstVectorRef psi,
                                  ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2, std::string *why) {
  const int n = problem.dimension();
  Vector y1(n + 1), y2(n + 1);
  // y_i = (F_xx[k_i, ·])ᵀψ, so ψᵀF_xx[k_i, k_j] = y_i · k_j.
  if (!problem.secondDerivativeTransposeApply(u, lambda, k1, psi, y1) ||
      !problem.secondDerivativeTransposeApply(u, lambda, k2, psi, y2)) {
    if (why) *why = "second derivatives unavailable";
    return false;
  }
  const double a = y1.dot(k1);
  const double b = 0.5 * (y1.dot(k2) + y2.dot(k1));
  const double c = y2.dot(k2);
  return bifurcationRoots(a, b, c, k1, k2, d1, d2, why);
}

namespace {

bool bifurcationRoots(double a, double b, double c, ConstVectorRef k1, ConstVectorRef k2, Vector &d1, Vector &d2,
                      std::string *why) {
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (!(scale > 1e-12)) {
    if (why) *why = "degenerate bifurcation equation (vanishing second derivatives)";
    return false;
  }
  const double discriminant = b * b - a * c;
  if (discriminant < -1e-8 * scale * scale) {
    if (why) *why = "bifurcation equation has no real roots (isolated point)";
    return false;
  }
  const double root = std::sqrt(std::max(0.0, discriminant));
  if (std::abs(a) <= 1e-12 * scale && std::abs(c) <= 1e-12 * scale) {
    d1 = k1;
    d2 = k2;
  } else if (std::abs(c) >= std::abs(a)) {
    // β/α = r solves c r² + 2b r + a = 0.
    d1 = k1 + ((-b + root) / c) * k2;
    d2 = k1 + ((-b - root) / c) * k2;
  } else {
    // α/β = r solves a r² + 2b r + c = 0.
    d1 = ((-b + root) / a) * k1 + k2;
    d2 = ((-b - root) / a) * k1 + k2;
  }
  d1.normalize();
  d2.normalize();
  return true;
}

}  // namespace

}  // namespace buckle::continuation
