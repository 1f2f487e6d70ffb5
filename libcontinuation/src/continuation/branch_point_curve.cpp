#include "buckle/continuation/branch_point_curve.h"

#include <stdexcept>
#include <string>

namespace buckle::continuation {

BranchPointCurveProblem::BranchPointCurveProblem(TwoParameterProblem &problem, const Vector &u0, const Vector &c)
    : problem_(problem),
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

bool BranchPointCurveProblem::residual(ConstVectorRef W, double mu, VectorRef G) {
  if (!problem_.setSecondParameter(mu)) return false;
  if (!problem_.jacobian(u0_, W[n_], Fu_, Flambda_)) return false;
  const auto w = W.head(n_);
  G.head(n_).noalias() = Fu_ * w;
  G[n_] = c_.dot(w) - 1.0;
  return true;
}

bool BranchPointCurveProblem::jacobian(ConstVectorRef W, double mu, MatrixRef GW, VectorRef Gmu) {
  if (!problem_.setSecondParameter(mu)) return false;
  const double lambda = W[n_];
  const auto w = W.head(n_);
  if (!problem_.jacobian(u0_, lambda, Fu_, Flambda_)) return false;
  if (!problem_.jacobianDirectionalDerivative(u0_, lambda, w, 0.0, dFu_, dFlambda_)) return false;
  if (!problem_.secondParameterDerivatives(u0_, lambda, w, Fmu_, FuMuW_)) return false;
  GW.topLeftCorner(n_, n_) = Fu_;
  GW.block(0, n_, n_, 1) = dFlambda_;  // F_λu w = F_uλ w
  GW.block(n_, 0, 1, n_) = c_.transpose();
  GW(n_, n_) = 0.0;
  Gmu.head(n_) = FuMuW_;
  Gmu[n_] = 0.0;
  return true;
}

ProblemScales BranchPointCurveProblem::scales() const {
  const ProblemScales s = problem_.scales();
  ProblemScales out;
  out.unknowns.resize(n_ + 1);
  out.unknowns << s.unknowns, s.parameter;
  out.residuals.resize(n_ + 1);
  out.residuals << s.residuals, 1.0;
  out.parameter = problem_.secondParameterScale();
  return out;
}

}  // namespace buckle::continuation
