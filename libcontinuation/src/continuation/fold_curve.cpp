#include "buckle/continuation/fold_curve.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace buckle::continuation {

FoldCurveProblem::FoldCurveProblem(TwoParameterProblem &problem, const Vector &c)
    : problem_(problem),
      inner_(problem),
      n_(problem.dimension()),
      c_(c),
      Fu_(n_, n_),
      dFu_(n_, n_),
      Flambda_(n_),
      dFlambda_(n_),
      Fmu_(n_),
      FuMuV_(n_),
      Fv_(n_) {
  if (c.size() != n_)
    throw std::invalid_argument("fold curve: normalisation vector of size " + std::to_string(c.size()) +
                                " for a problem of dimension " + std::to_string(n_));
}

Vector FoldCurveProblem::start(const Problem &problem, ConstVectorRef u, double lambda, ConstVectorRef v, Vector &c) {
  const int n = problem.dimension();
  const ProblemScales s = problem.scales();
  // v of unit length in the scaled variables ṽ = D_u⁻¹ v, and c = D_u⁻² v so that cᵀv = ‖ṽ‖² = 1.
  Vector vs = v.cwiseQuotient(s.unknowns);
  vs /= vs.norm();
  const Vector vu = vs.cwiseProduct(s.unknowns);
  c = vs.cwiseQuotient(s.unknowns);
  Vector U(2 * n + 1);
  U << u, lambda, vu;
  return U;
}

bool FoldCurveProblem::residual(ProblemWorkspace &, ConstVectorRef U, double mu, VectorRef G) const {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const auto v = U.tail(n_);
  if (!inner_.residual(u, U[n_], G.head(n_))) return false;
  if (!inner_.jacobian(u, U[n_], Fu_, Flambda_)) return false;
  G.segment(n_, n_).noalias() = Fu_ * v;
  G[2 * n_] = c_.dot(v) - 1.0;
  return true;
}

bool FoldCurveProblem::jacobian(ProblemWorkspace &, ConstVectorRef U, double mu, MatrixRef GU, VectorRef Gmu) const {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  const auto v = U.tail(n_);
  if (!inner_.jacobian(u, lambda, Fu_, Flambda_)) return false;
  // F_uu[v, ·] and F_uλ v: the derivative of [F_u, F_λ] in the direction (v, 0)
  if (!inner_.jacobianDirectionalDerivative(u, lambda, v, 0.0, dFu_, dFlambda_)) return false;
  if (!problem_.secondParameterDerivatives(inner_.workspace(), u, lambda, v, Fmu_, FuMuV_)) return false;
  GU.setZero();
  GU.topLeftCorner(n_, n_) = Fu_;
  GU.block(0, n_, n_, 1) = Flambda_;
  GU.block(n_, 0, n_, n_) = dFu_;
  GU.block(n_, n_, n_, 1) = dFlambda_;
  GU.block(n_, n_ + 1, n_, n_) = Fu_;
  GU.block(2 * n_, n_ + 1, 1, n_) = c_.transpose();
  Gmu.head(n_) = Fmu_;
  Gmu.segment(n_, n_) = FuMuV_;
  Gmu[2 * n_] = 0.0;
  return true;
}

ProblemScales FoldCurveProblem::scales() const {
  const ProblemScales s = problem_.scales();
  ProblemScales out;
  out.unknowns.resize(2 * n_ + 1);
  out.unknowns << s.unknowns, s.parameter, s.unknowns;
  out.residuals.resize(2 * n_ + 1);
  out.residuals << s.residuals, s.residuals, 1.0;
  out.parameter = problem_.secondParameterScale();
  return out;
}

double FoldCurveProblem::boundary(ProblemWorkspace &, int k, ConstVectorRef U, double mu) const {
  // μ outside the domain: not a boundary crossing (residual() refuses the point anyway)
  if (!problem_.setSecondParameter(mu)) return 1.0;
  return inner_.boundary(k, U.head(n_), U[n_]);
}

bool FoldCurveProblem::cuspTest(ConstVectorRef U, double mu, double &value) const {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  const Vector v = U.tail(n_);
  if (!inner_.jacobian(u, lambda, Fu_, Flambda_)) return false;
  if (!inner_.jacobianDirectionalDerivative(u, lambda, v, 0.0, dFu_, dFlambda_)) return false;
  // ψ: [[F_uᵀ, c], [vᵀ, 0]] [ψ; s] = [0; 1] (s = 0 exactly on the curve)
  Matrix A = Matrix::Zero(n_ + 1, n_ + 1);
  A.topLeftCorner(n_, n_) = Fu_.transpose();
  A.block(0, n_, n_, 1) = c_;
  A.block(n_, 0, 1, n_) = v.transpose();
  lu_.compute(A);
  if (!(std::abs(lu_.determinant()) > 0.0)) return false;
  Vector rhs = Vector::Zero(n_ + 1);
  rhs[n_] = 1.0;
  const Vector psi = lu_.solve(rhs).head(n_);
  Fv_.noalias() = dFu_ * v;  // F_uu[v, v]
  const ProblemScales s = problem_.scales();
  // ψᵀF_uu[v, v] is the same in scaled and user variables; the norms are the scaled ones.
  const double norm = psi.cwiseProduct(s.residuals).norm() * v.cwiseQuotient(s.unknowns).squaredNorm();
  value = psi.dot(Fv_) / norm;
  return std::isfinite(value);
}

// ---- the minimally augmented system -------------------------------------------------------

MinimalFoldCurveProblem::MinimalFoldCurveProblem(TwoParameterProblem &problem, ConstVectorRef u, double lambda,
                                                 ConstVectorRef v)
    : problem_(problem),
      inner_(problem),
      n_(problem.dimension()),
      v_(n_),
      w_(n_),
      gx_(n_ + 1),
      Fmu_(n_),
      FuMuV_(n_),
      Flambda_(n_),
      ex_(Vector::Zero(n_ + 1)),
      Bm_(n_, 1),
      Cm_(n_, 1),
      Dm_(Matrix::Zero(1, 1)),
      rhs_(Vector::Zero(n_ + 1)),
      z_(n_ + 1),
      y_(n_ + 1) {
  if (u.size() != n_ || v.size() != n_)
    throw std::invalid_argument("fold curve: state of size " + std::to_string(u.size()) + " and null vector of size " +
                                std::to_string(v.size()) + " for a problem of dimension " + std::to_string(n_));
  solver_ = inner_.makeStructuredSolver();
  if (!solver_ || solver_->maxGeneralBorder() < 1)
    throw std::invalid_argument("fold curve: the minimally augmented system needs a structured solver with general borders");
  system_ = std::make_unique<RefinedBorderedSystem>(inner_, *solver_);
  rhs_[n_] = 1.0;
  // c from v; b from v as well (exact for a symmetric F_u), then from the left null vector of
  // the first solve (one step of inverse iteration).
  const Vector v0 = v;
  setBorders(v0, v0);
  const Vector U = start(u, lambda);
  if (!adaptBorders(U, problem_.secondParameter()))
    throw std::invalid_argument("fold curve: singular bordered matrix at the start (not a simple fold?)");
  b0_ = b_;
  c0_ = c_;
}

void MinimalFoldCurveProblem::resetBorders() {
  b_ = b0_;
  c_ = c0_;
  cached_ = cachedGradient_ = false;
}

Vector MinimalFoldCurveProblem::start(ConstVectorRef u, double lambda) {
  Vector U(u.size() + 1);
  U << u, lambda;
  return U;
}

void MinimalFoldCurveProblem::setBorders(const Vector &v, const Vector &w) {
  const ProblemScales s = problem_.scales();
  const Vector vs = v.cwiseQuotient(s.unknowns);
  const Vector ws = w.cwiseProduct(s.residuals);
  c_ = (vs / vs.norm()).cwiseQuotient(s.unknowns);
  b_ = (ws / ws.norm()).cwiseProduct(s.residuals);
  cached_ = cachedGradient_ = false;
}

bool MinimalFoldCurveProblem::evaluate(ConstVectorRef U, double mu) const {
  if (cached_ && mu == cachedMu_ && (U.array() == cachedU_.array()).all()) return true;
  cached_ = cachedGradient_ = false;
  if (!problem_.setSecondParameter(mu) || !U.allFinite()) return false;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  // [[F_u, b], [cᵀ, 0]] [v; g] = [0; 1] and [[F_uᵀ, c], [bᵀ, 0]] [w; s] = [0; 1]
  Bm_.col(0) = b_;
  Cm_.col(0) = c_;
  if (!system_->factor(u, lambda, Bm_, Cm_, Dm_, false) || !system_->solve(rhs_, z_)) return false;
  Bm_.col(0) = c_;
  Cm_.col(0) = b_;
  if (!system_->factor(u, lambda, Bm_, Cm_, Dm_, true) || !system_->solve(rhs_, y_)) return false;
  v_ = z_.head(n_);
  g_ = z_[n_];
  w_ = y_.head(n_);
  cachedU_ = U;
  cachedMu_ = mu;
  cached_ = true;
  return true;
}

bool MinimalFoldCurveProblem::evaluateGradient(ConstVectorRef U, double mu) const {
  if (!evaluate(U, mu)) return false;
  if (cachedGradient_) return true;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  // g_x = −wᵀF_xx[(v, 0), ·], g_μ = −wᵀF_uμ v
  ex_.head(n_) = v_;
  ex_[n_] = 0.0;
  if (!inner_.secondDerivativeTransposeApply(u, lambda, ex_, w_, gx_)) return false;
  gx_ = -gx_;
  if (!problem_.secondParameterDerivatives(inner_.workspace(), u, lambda, v_, Fmu_, FuMuV_)) return false;
  gmu_ = -w_.dot(FuMuV_);
  ex_.setZero();
  ex_[n_] = 1.0;
  if (!inner_.jacobianApply(u, lambda, ex_, Flambda_)) return false;
  cachedGradient_ = gx_.allFinite() && std::isfinite(gmu_);
  return cachedGradient_;
}

bool MinimalFoldCurveProblem::gradient(ConstVectorRef U, double mu, double &g, Vector &gx, double &gmu, Vector &Flambda,
                                       Vector &Fmu) const {
  if (!evaluateGradient(U, mu)) return false;
  g = g_;
  gx = gx_;
  gmu = gmu_;
  Flambda = Flambda_;
  Fmu = Fmu_;
  return true;
}

bool MinimalFoldCurveProblem::residual(ProblemWorkspace &, ConstVectorRef U, double mu, VectorRef G) const {
  if (!evaluate(U, mu)) return false;
  if (!inner_.residual(U.head(n_), U[n_], G.head(n_))) return false;
  G[n_] = g_;
  return true;
}

bool MinimalFoldCurveProblem::jacobian(ProblemWorkspace &, ConstVectorRef U, double mu, MatrixRef GU,
                                       VectorRef Gmu) const {
  if (!evaluateGradient(U, mu)) return false;
  if (!inner_.jacobian(U.head(n_), U[n_], GU.topLeftCorner(n_, n_), GU.col(n_).head(n_))) return false;
  GU.row(n_) = gx_.transpose();
  Gmu.head(n_) = Fmu_;
  Gmu[n_] = gmu_;
  return true;
}

bool MinimalFoldCurveProblem::jacobianApply(ProblemWorkspace &, ConstVectorRef U, double mu, ConstVectorRef x,
                                            VectorRef y) const {
  if (!evaluateGradient(U, mu)) return false;
  if (!inner_.jacobianApply(U.head(n_), U[n_], x.head(n_ + 1), y.head(n_))) return false;
  y.head(n_) += x[n_ + 1] * Fmu_;
  y[n_] = gx_.dot(x.head(n_ + 1)) + gmu_ * x[n_ + 1];
  return y.allFinite();
}

bool MinimalFoldCurveProblem::jacobianTransposeApply(ProblemWorkspace &, ConstVectorRef U, double mu, ConstVectorRef w,
                                                     VectorRef y) const {
  if (!evaluateGradient(U, mu)) return false;
  if (!inner_.jacobianTransposeApply(U.head(n_), U[n_], w.head(n_), y.head(n_ + 1))) return false;
  y.head(n_ + 1) += w[n_] * gx_;
  y[n_ + 1] = Fmu_.dot(w.head(n_)) + gmu_ * w[n_];
  return y.allFinite();
}

ProblemScales MinimalFoldCurveProblem::scales() const {
  return stateAndParameterScales(problem_);
}

double MinimalFoldCurveProblem::boundary(ProblemWorkspace &, int k, ConstVectorRef U, double mu) const {
  if (!problem_.setSecondParameter(mu)) return 1.0;
  return inner_.boundary(k, U.head(n_), U[n_]);
}

bool MinimalFoldCurveProblem::nullVectors(ConstVectorRef U, double mu, Vector &v, Vector &w) const {
  if (!evaluate(U, mu)) return false;
  v = v_;
  w = w_;
  return true;
}

bool MinimalFoldCurveProblem::adaptBorders(ConstVectorRef U, double mu) {
  if (!evaluate(U, mu)) return false;
  const Vector v = v_, w = w_;
  if (!(v.norm() > 0.0) || !(w.norm() > 0.0)) return false;
  setBorders(v, w);
  return true;
}

bool MinimalFoldCurveProblem::cuspTest(ConstVectorRef U, double mu, double &value) const {
  if (!evaluate(U, mu)) return false;
  ex_.head(n_) = v_;
  ex_[n_] = 0.0;
  Vector second(n_ + 1);
  if (!inner_.secondDerivativeTransposeApply(U.head(n_), U[n_], ex_, w_, second)) return false;
  const ProblemScales s = problem_.scales();
  // ψᵀF_uu[v, v] with ψ = w; the norms are the scaled ones (as FoldCurveProblem::cuspTest)
  const double norm = w_.cwiseProduct(s.residuals).norm() * v_.cwiseQuotient(s.unknowns).squaredNorm();
  value = second.head(n_).dot(v_) / norm;
  return std::isfinite(value);
}

namespace {

// The tracer's A(c̃) = [[F_u, F_λ, F_μ], [g_uᵀ, g_λ, g_μ], [c̃_uᵀ, c̃_λ, c̃_μ]] as the base solver's
// G = [[F_u, B], [Cᵀ, D]] with B = [F_λ, F_μ], C = [g_u, c̃_u], D = [[g_λ, g_μ], [c̃_λ, c̃_μ]]:
// same rows, same columns, solved through the curve's current borders (DeflatedBorderedSolve). Its
// own base solver (the curve problem's is refactored by every residual evaluation).
class MinimalFoldCurveSolver final : public BorderedSolver {
 public:
  MinimalFoldCurveSolver(const MinimalFoldCurveProblem &curve, std::unique_ptr<BorderedSolver> base)
      : curve_(curve),
        n_(curve.base()),
        base_(std::move(base)),
        deflated_(*base_, n_),
        B_(n_, 2),
        C_(n_, 2),
        D_(2, 2),
        gx_(n_ + 1),
        Flambda_(n_),
        Fmu_(n_) {}

  Factorization factor(ConstVectorRef U, double mu, ConstVectorRef cc) override {
    double g = 0.0, gmu = 0.0;
    if (!cc.allFinite() || !curve_.gradient(U, mu, g, gx_, gmu, Flambda_, Fmu_)) return Factorization::Refused;
    B_.col(0) = Flambda_;
    B_.col(1) = Fmu_;
    C_.col(0) = gx_.head(n_);
    C_.col(1) = cc.head(n_);
    D_ << gx_[n_], gmu, cc[n_], cc[n_ + 1];
    return deflated_.factor(U.head(n_), U[n_], curve_.leftBorder(), curve_.rightBorder(), B_, C_, D_);
  }
  bool solve(ConstVectorRef b, VectorRef x) override { return deflated_.solve(b, x); }
  int determinantSign() const override { return deflated_.determinantSign(); }
  double logAbsDeterminant() const override { return deflated_.logAbsDeterminant(); }

 private:
  const MinimalFoldCurveProblem &curve_;
  int n_;
  std::unique_ptr<BorderedSolver> base_;
  DeflatedBorderedSolve deflated_;
  Matrix B_, C_, D_;
  Vector gx_, Flambda_, Fmu_;
};

}  // namespace

std::unique_ptr<BorderedSolver> MinimalFoldCurveProblem::makeStructuredSolver(ProblemWorkspace &) const {
  std::unique_ptr<BorderedSolver> base = inner_.makeStructuredSolver();
  if (!base || base->maxGeneralBorder() < 1) return nullptr;
  return std::make_unique<MinimalFoldCurveSolver>(*this, std::move(base));
}

}  // namespace buckle::continuation
