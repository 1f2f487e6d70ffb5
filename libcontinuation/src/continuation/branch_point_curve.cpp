#include "buckle/continuation/branch_point_curve.h"

#include <stdexcept>
#include <string>

namespace buckle::continuation {

BranchPointCurveProblem::BranchPointCurveProblem(TwoParameterProblem &problem, const Vector &u0, const Vector &c)
    : problem_(problem),
      inner_(problem),
      n_(problem.dimension()),
      u0_(u0),
      c_(c),
      Fu_(n_, n_),
      dFu_(n_, n_),
      Flambda_(n_),
      dFlambda_(n_),
      Fmu_(n_),
      FuMuW_(n_) {
  if (u0.size() != n_ || c.size() != n_)
    throw std::invalid_argument("branch-point curve: trivial solution of size " + std::to_string(u0.size()) +
                                " and normalisation of size " + std::to_string(c.size()) +
                                " for a problem of dimension " + std::to_string(n_));
}

Vector BranchPointCurveProblem::start(const Problem &problem, double lambda, ConstVectorRef w, Vector &c) {
  const int n = problem.dimension();
  const ProblemScales s = problem.scales();
  Vector ws = w.cwiseQuotient(s.unknowns);
  ws /= ws.norm();
  c = ws.cwiseQuotient(s.unknowns);
  Vector W(n + 1);
  W << ws.cwiseProduct(s.unknowns), lambda;
  return W;
}

bool BranchPointCurveProblem::residual(ProblemWorkspace &, ConstVectorRef W, double mu, VectorRef G) const {
  if (!problem_.setSecondParameter(mu)) return false;
  if (structured_) {
    x_.resize(n_ + 1);
    x_ << W.head(n_), 0.0;
    if (!inner_.jacobianApply(u0_, W[n_], x_, G.head(n_))) return false;
    G[n_] = c_.dot(W.head(n_)) - 1.0;
    return true;
  }
  if (!inner_.jacobian(u0_, W[n_], Fu_, Flambda_)) return false;
  const auto w = W.head(n_);
  G.head(n_).noalias() = Fu_ * w;
  G[n_] = c_.dot(w) - 1.0;
  return true;
}

bool BranchPointCurveProblem::jacobian(ProblemWorkspace &, ConstVectorRef W, double mu, MatrixRef GW,
                                       VectorRef Gmu) const {
  if (!problem_.setSecondParameter(mu)) return false;
  const double lambda = W[n_];
  const auto w = W.head(n_);
  if (!inner_.jacobian(u0_, lambda, Fu_, Flambda_)) return false;
  if (!inner_.jacobianDirectionalDerivative(u0_, lambda, w, 0.0, dFu_, dFlambda_)) return false;
  if (!problem_.secondParameterDerivatives(inner_.workspace(), u0_, lambda, w, Fmu_, FuMuW_)) return false;
  GW.topLeftCorner(n_, n_) = Fu_;
  GW.block(0, n_, n_, 1) = dFlambda_;  // F_λu w = F_uλ w
  GW.block(n_, 0, 1, n_) = c_.transpose();
  GW(n_, n_) = 0.0;
  Gmu.head(n_) = FuMuW_;
  Gmu[n_] = 0.0;
  return true;
}

ProblemScales BranchPointCurveProblem::scales() const {
  return stateAndParameterScales(problem_);
}

namespace {

// The tracer's A(c̃) = [[F_u, F_uλ w, F_uμ w], [cᵀ, 0, 0], [c̃_wᵀ, c̃_λ, c̃_μ]] as
// G = [[F_u, B], [Cᵀ, D]] with B = [F_uλ w, F_uμ w], C = [c, c̃_w], D = [[0, 0], [c̃_λ, c̃_μ]]:
// same rows, same columns. F_u is singular on the curve, so G is solved through
// [[F_u, b], [cᵀ, 0]] (DeflatedBorderedSolve) with b the normalisation's null vector seen in the
// residual rows (D_F² D_u² c: the left null vector when F_u is symmetric).
class BranchPointCurveSolver final : public BorderedSolver {
 public:
  BranchPointCurveSolver(TwoParameterProblem &problem, const BoundProblem &inner, const Vector &u0, const Vector &c,
                         std::unique_ptr<BorderedSolver> base)
      : problem_(problem),
        inner_(inner),
        n_(problem.dimension()),
        u0_(u0),
        c_(c),
        base_(std::move(base)),
        deflated_(*base_, n_),
        B_(n_, 2),
        C_(n_, 2),
        D_(Matrix::Zero(2, 2)),
        Fmu_(n_) {
    C_.col(0) = c;
    const ProblemScales s = problem.scales();
    b_ = c.cwiseProduct(s.unknowns.cwiseProduct(s.unknowns)).cwiseProduct(s.residuals.cwiseProduct(s.residuals));
    b_ /= b_.cwiseQuotient(s.residuals).norm();
  }

  Factorization factor(ConstVectorRef W, double mu, ConstVectorRef cc) override {
    if (!problem_.setSecondParameter(mu) || !cc.allFinite()) return Factorization::Refused;
    const auto w = W.head(n_);
    const double lambda = W[n_];
    if (!problem_.parameterJacobianApply(inner_.workspace(), u0_, lambda, w, B_.col(0))) return Factorization::Refused;
    if (!problem_.secondParameterDerivatives(inner_.workspace(), u0_, lambda, w, Fmu_, B_.col(1)))
      return Factorization::Refused;
    C_.col(1) = cc.head(n_);
    D_(1, 0) = cc[n_];
    D_(1, 1) = cc[n_ + 1];
    return deflated_.factor(u0_, lambda, b_, c_, B_, C_, D_);
  }
  bool solve(ConstVectorRef b, VectorRef x) override { return deflated_.solve(b, x); }
  int determinantSign() const override { return deflated_.determinantSign(); }
  double logAbsDeterminant() const override { return deflated_.logAbsDeterminant(); }

 private:
  TwoParameterProblem &problem_;
  BoundProblem inner_;
  int n_;
  Vector u0_, c_, b_;
  std::unique_ptr<BorderedSolver> base_;
  DeflatedBorderedSolve deflated_;
  Matrix B_, C_, D_;
  Vector Fmu_;
};

}  // namespace

std::unique_ptr<BorderedSolver> BranchPointCurveProblem::makeStructuredSolver(ProblemWorkspace &) const {
  if (!structured_) return nullptr;
  std::unique_ptr<BorderedSolver> base = inner_.makeStructuredSolver();
  if (!base || base->maxGeneralBorder() < 1) return nullptr;
  return std::make_unique<BranchPointCurveSolver>(problem_, inner_, u0_, c_, std::move(base));
}

}  // namespace buckle::continuation
