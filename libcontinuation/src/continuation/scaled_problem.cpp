#include "buckle/continuation/scaled_problem.h"

#include <cmath>

namespace buckle::continuation {

namespace {

// v / ‖v‖, zero left alone.
void normalize(VectorRef v) {
  const double norm = v.norm();
  if (norm > 0.0 && std::isfinite(norm)) v /= norm;
}

// Columns normalised; with two or more columns Gram–Schmidt keeps the first one's direction
// (the traced branch's tangent at a branch point) and makes the basis orthonormal again.
void orthonormalizeColumns(Matrix &K) {
  for (Eigen::Index j = 0; j < K.cols(); ++j) {
    for (Eigen::Index i = 0; i < j; ++i) K.col(j) -= K.col(i).dot(K.col(j)) * K.col(i);
    normalize(K.col(j));
  }
}

}  // namespace

UnitScaling::UnitScaling(const ProblemScales &scales)
    : scales_(scales), n_(static_cast<int>(scales.unknowns.size())), identity_(scales.identity()) {
  stateScales_.resize(n_ + 1);
  stateScales_.head(n_) = scales_.unknowns;
  stateScales_[n_] = scales_.parameter;
}

Vector UnitScaling::directionToScaled(ConstVectorRef t) const {
  if (identity_ || t.size() != n_ + 1) return t;
  Vector s = t.cwiseQuotient(stateScales_);
  normalize(s);
  return s;
}

Vector UnitScaling::directionToUser(ConstVectorRef t) const {
  if (identity_ || t.size() != n_ + 1) return t;
  Vector s = t.cwiseProduct(stateScales_);
  normalize(s);
  return s;
}

void UnitScaling::toScaled(ContinuationPoint &p) const {
  if (identity_) return;
  if (p.u.size() == n_) p.u = p.u.cwiseQuotient(scales_.unknowns);
  p.lambda /= scales_.parameter;
  if (p.tangent.size() == n_ + 1) p.tangent = directionToScaled(p.tangent);
  p.stability.lowest /= scales_.stability;
  p.stability.smallest /= scales_.stability;
  for (int k = 0; k < 2; ++k) {
    p.spectrum.values[k] /= scales_.stability;
    p.spectrum.slopes[k] /= scales_.stability;
  }
  p.spectrum.rateBound /= scales_.stability;
}

void UnitScaling::toUser(ContinuationPoint &p) const {
  if (identity_) return;
  if (p.u.size() == n_) p.u = p.u.cwiseProduct(scales_.unknowns);
  p.lambda *= scales_.parameter;
  if (p.tangent.size() == n_ + 1) p.tangent = directionToUser(p.tangent);
  p.stability.lowest *= scales_.stability;
  p.stability.smallest *= scales_.stability;
  for (int k = 0; k < 2; ++k) {
    p.spectrum.values[k] *= scales_.stability;
    p.spectrum.slopes[k] *= scales_.stability;
  }
  p.spectrum.rateBound *= scales_.stability;
}

void UnitScaling::toScaled(SpecialPoint &p) const {
  if (identity_) return;
  if (p.u.size() == n_) p.u = p.u.cwiseQuotient(scales_.unknowns);
  p.lambda /= scales_.parameter;
  p.lambdaAccuracy /= scales_.parameter;
  if (p.tangent.size() == n_ + 1) p.tangent = directionToScaled(p.tangent);
  // Kernel vectors of F_x map like directions (F̃_x = D_F⁻¹ F_x S), left null vectors like
  // rows (ψ̃ ∝ D_F ψ).
  if (p.nullVectors.rows() == n_ + 1) {
    p.nullVectors.array().colwise() /= stateScales_.array();
    orthonormalizeColumns(p.nullVectors);
  } else if (p.nullVectors.rows() == n_) {
    p.nullVectors.array().colwise() /= scales_.unknowns.array();
    orthonormalizeColumns(p.nullVectors);
  }
  if (p.leftNullVector.size() == n_) {
    p.leftNullVector = p.leftNullVector.cwiseProduct(scales_.residuals);
    normalize(p.leftNullVector);
  }
}

void UnitScaling::toUser(SpecialPoint &p) const {
  if (identity_) return;
  if (p.u.size() == n_) p.u = p.u.cwiseProduct(scales_.unknowns);
  p.lambda *= scales_.parameter;
  p.lambdaAccuracy *= scales_.parameter;
  if (p.tangent.size() == n_ + 1) p.tangent = directionToUser(p.tangent);
  // Columns only normalised: orthogonality is a property of the scaled basis, which toScaled()
  // restores.
  if (p.nullVectors.rows() == n_ + 1) {
    p.nullVectors.array().colwise() *= stateScales_.array();
    for (Eigen::Index j = 0; j < p.nullVectors.cols(); ++j) normalize(p.nullVectors.col(j));
  } else if (p.nullVectors.rows() == n_) {
    p.nullVectors.array().colwise() *= scales_.unknowns.array();
    for (Eigen::Index j = 0; j < p.nullVectors.cols(); ++j) normalize(p.nullVectors.col(j));
  }
  if (p.leftNullVector.size() == n_) {
    p.leftNullVector = p.leftNullVector.cwiseQuotient(scales_.residuals);
    normalize(p.leftNullVector);
  }
}

void UnitScaling::toScaled(Branch &b) const {
  if (identity_) return;
  for (ContinuationPoint &p : b.points) toScaled(p);
  for (SpecialPoint &p : b.specialPoints) toScaled(p);
}

void UnitScaling::toUser(Branch &b) const {
  if (identity_) return;
  for (ContinuationPoint &p : b.points) toUser(p);
  for (SpecialPoint &p : b.specialPoints) toUser(p);
}

ScaledProblem::ScaledProblem(const Problem &problem, const UnitScaling &units)
    : problem_(problem), units_(units), n_(problem.dimension()) {}

ScaledProblem::Workspace::Workspace(const BoundProblem &problem, int n)
    : inner(problem), u(Vector::Zero(n)), du(Vector::Zero(n)) {}

std::unique_ptr<ProblemWorkspace> ScaledProblem::createWorkspace() const {
  return std::make_unique<Workspace>(BoundProblem(problem_), n_);
}

std::unique_ptr<ProblemWorkspace> ScaledProblem::workspaceOn(const BoundProblem &problem) const {
  if (&problem.problem() != &problem_) throwForeignWorkspace();
  return std::make_unique<Workspace>(problem, n_);
}

const Vector &ScaledProblem::user(Workspace &sw, ConstVectorRef u) const {
  sw.u = u.cwiseProduct(units_.scales().unknowns);
  return sw.u;
}

void ScaledProblem::scaleJacobian(MatrixRef Fu, VectorRef Flambda) const {
  const ProblemScales &s = units_.scales();
  Fu.array().colwise() /= s.residuals.array();
  Fu.array().rowwise() *= s.unknowns.transpose().array();
  Flambda.array() *= s.parameter / s.residuals.array();
}

bool ScaledProblem::residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  if (!sw.inner.residual(user(sw, u), lambda * units_.parameter(), F)) return false;
  F.array() /= units_.scales().residuals.array();
  return true;
}

bool ScaledProblem::jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu,
                             VectorRef Flambda) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  if (!sw.inner.jacobian(user(sw, u), lambda * units_.parameter(), Fu, Flambda)) return false;
  scaleJacobian(Fu, Flambda);
  return true;
}

bool ScaledProblem::jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda,
                                                  ConstVectorRef du, double dlambda, MatrixRef dFu,
                                                  VectorRef dFlambda) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  sw.du = du.cwiseProduct(units_.scales().unknowns);
  const double lp = units_.parameter();
  if (!sw.inner.jacobianDirectionalDerivative(user(sw, u), lambda * lp, sw.du, dlambda * lp, dFu, dFlambda))
    return false;
  scaleJacobian(dFu, dFlambda);
  return true;
}

bool ScaledProblem::jacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                  VectorRef y) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  // F̃_x x̃ = D_F⁻¹ F_x S x̃, S = diag(D_u, λ₀).
  sw.x.resize(n_ + 1);
  sw.x.head(n_) = x.head(n_).cwiseProduct(units_.scales().unknowns);
  sw.x[n_] = x[n_] * units_.parameter();
  if (!sw.inner.jacobianApply(user(sw, u), lambda * units_.parameter(), sw.x, y)) return false;
  y.array() /= units_.scales().residuals.array();
  return true;
}

bool ScaledProblem::jacobianTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                                           VectorRef y) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  // F̃_xᵀ w̃ = S F_xᵀ D_F⁻¹ w̃.
  sw.w = w.cwiseQuotient(units_.scales().residuals);
  if (!sw.inner.jacobianTransposeApply(user(sw, u), lambda * units_.parameter(), sw.w, y)) return false;
  y.head(n_).array() *= units_.scales().unknowns.array();
  y[n_] *= units_.parameter();
  return true;
}

bool ScaledProblem::secondDerivativeTransposeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda,
                                                   ConstVectorRef x, ConstVectorRef w, VectorRef y) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  // F̃(x̃) = D_F⁻¹ F(S x̃): (F̃_xx[x̃, ·])ᵀ w̃ = S (F_xx[S x̃, ·])ᵀ D_F⁻¹ w̃.
  sw.x.resize(n_ + 1);
  sw.x.head(n_) = x.head(n_).cwiseProduct(units_.scales().unknowns);
  sw.x[n_] = x[n_] * units_.parameter();
  sw.w = w.cwiseQuotient(units_.scales().residuals);
  if (!sw.inner.secondDerivativeTransposeApply(user(sw, u), lambda * units_.parameter(), sw.x, sw.w, y)) return false;
  y.head(n_).array() *= units_.scales().unknowns.array();
  y[n_] *= units_.parameter();
  return true;
}

bool ScaledProblem::secondDerivativeApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                          ConstVectorRef z, VectorRef y) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  // F̃_xx[x̃, z̃] = D_F⁻¹ F_xx[S x̃, S z̃]: the problem's own (exact, O(N)) product.
  sw.x.resize(n_ + 1);
  sw.x.head(n_) = x.head(n_).cwiseProduct(units_.scales().unknowns);
  sw.x[n_] = x[n_] * units_.parameter();
  sw.z.resize(n_ + 1);
  sw.z.head(n_) = z.head(n_).cwiseProduct(units_.scales().unknowns);
  sw.z[n_] = z[n_] * units_.parameter();
  if (!sw.inner.secondDerivativeApply(user(sw, u), lambda * units_.parameter(), sw.x, sw.z, y)) return false;
  y.array() /= units_.scales().residuals.array();
  return true;
}

bool ScaledProblem::stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H,
                                      Matrix &C) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  if (!sw.inner.stabilityOperator(user(sw, u), lambda * units_.parameter(), H, C)) return false;
  H /= units_.scales().stability;
  return true;
}

bool ScaledProblem::stability(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int lowestCount,
                              StabilityInfo &info) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  if (!sw.inner.stability(user(sw, u), lambda * units_.parameter(), lowestCount, info)) return false;
  info.lowest /= units_.scales().stability;
  info.smallest /= units_.scales().stability;
  return true;
}

bool ScaledProblem::stabilityEigenvalues(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int first,
                                         VectorRef values) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  if (!sw.inner.stabilityEigenvalues(user(sw, u), lambda * units_.parameter(), first, values)) return false;
  values /= units_.scales().stability;
  return true;
}

bool ScaledProblem::stabilityRateBound(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                       double dlambda, double &bound) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  sw.du = du.cwiseProduct(units_.scales().unknowns);
  if (!sw.inner.stabilityRateBound(user(sw, u), lambda * units_.parameter(), sw.du, dlambda * units_.parameter(),
                                   bound))
    return false;
  bound /= units_.scales().stability;
  return true;
}

bool ScaledProblem::stabilitySlopes(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                    double dlambda, int first, ConstVectorRef values, VectorRef slopes) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  const double mu0 = units_.scales().stability;
  // The values in the problem's units: a few numbers (a 2-vector), on the stack.
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;
  if (values.size() > SmallVector::MaxRowsAtCompileTime) return false;
  const SmallVector userValues = values * mu0;
  sw.du = du.cwiseProduct(units_.scales().unknowns);
  if (!sw.inner.stabilitySlopes(user(sw, u), lambda * units_.parameter(), sw.du, dlambda * units_.parameter(), first,
                                userValues, slopes))
    return false;
  slopes /= mu0;
  return true;
}

std::unique_ptr<BorderedSolver> ScaledProblem::makeStructuredSolver(ProblemWorkspace &ws) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  std::unique_ptr<BorderedSolver> solver = sw.inner.makeStructuredSolver();
  if (!solver) return nullptr;
  return std::make_unique<ScaledBorderedSolver>(std::move(solver), units_);
}

double ScaledProblem::boundary(ProblemWorkspace &ws, int k, ConstVectorRef u, double lambda) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  return sw.inner.boundary(k, user(sw, u), lambda * units_.parameter());
}

void ScaledProblem::boundaries(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef g) const {
  Workspace &sw = workspaceAs<Workspace>(ws);
  sw.inner.boundaries(user(sw, u), lambda * units_.parameter(), g);  // u scaled once, not once per k
}

ScaledBorderedSolver::ScaledBorderedSolver(std::unique_ptr<BorderedSolver> solver, const UnitScaling &units)
    : solver_(std::move(solver)), units_(units) {
  const ProblemScales &s = units_.scales();
  const Eigen::Index n = s.unknowns.size();
  stateScales_.resize(n + 1);
  stateScales_ << s.unknowns, s.parameter;
  rowScales_.resize(n + 1);
  rowScales_ << s.residuals, 1.0;
  u_ = Vector::Zero(n);
  c_ = Vector::Zero(n + 1);
  b_ = Vector::Zero(n + 1);
}

Factorization ScaledBorderedSolver::factor(ConstVectorRef u, double lambda, ConstVectorRef c) {
  general_ = false;
  u_ = u.cwiseProduct(units_.scales().unknowns);
  c_ = c.cwiseQuotient(stateScales_);
  return solver_->factor(u_, lambda * units_.parameter(), c_);
}

Factorization ScaledBorderedSolver::factorGeneral(ConstVectorRef u, double lambda, ConstMatrixRef B, ConstMatrixRef C,
                                                  ConstMatrixRef D, bool transposed) {
  general_ = true;
  const ProblemScales &s = units_.scales();
  u_ = u.cwiseProduct(s.unknowns);
  // Plain: G̃ = diag(D_F⁻¹, I) G diag(D_u, I), so B = D_F B̃, C = D_u⁻¹ C̃, and G̃x̃ = b̃ is
  // G (D_u x̃) = D_F b̃. Transposed: G̃ = diag(D_u, I) G diag(D_F⁻¹, I), so B = D_u⁻¹ B̃,
  // C = D_F C̃, and G (D_F⁻¹ x̃) = D_u⁻¹ b̃.
  const Vector &left = transposed ? s.unknowns : s.residuals;
  const Vector &right = transposed ? s.residuals : s.unknowns;
  inScale_ = transposed ? Vector(left.cwiseInverse()) : left;
  outScale_ = transposed ? right : Vector(right.cwiseInverse());
  const Matrix Bu = transposed ? Matrix(B.array().colwise() / left.array()) : Matrix(B.array().colwise() * left.array());
  const Matrix Cu =
      transposed ? Matrix(C.array().colwise() * right.array()) : Matrix(C.array().colwise() / right.array());
  return solver_->factorGeneral(u_, lambda * units_.parameter(), Bu, Cu, D, transposed);
}

bool ScaledBorderedSolver::solve(ConstVectorRef b, VectorRef x) {
  if (general_) {
    const Eigen::Index n = inScale_.size();
    b_ = b;
    b_.head(n).array() *= inScale_.array();
    if (!solver_->solve(b_, x)) return false;
    x.head(n).array() *= outScale_.array();
    return x.allFinite();
  }
  // Ã x̃ = b̃  ⇔  A (S x̃) = diag(D_F, 1) b̃.
  b_ = b.cwiseProduct(rowScales_);
  if (!solver_->solve(b_, x)) return false;
  x.array() /= stateScales_.array();
  return x.allFinite();
}

}  // namespace buckle::continuation
