#include "buckle/continuation/fold_curve.h"

#include <cmath>
#include <stdexcept>

namespace buckle::continuation {

FoldCurveProblem::FoldCurveProblem(TwoParameterProblem &problem, const Vector &c)
    : problem_(problem),
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

bool FoldCurveProblem::residual(ConstVectorRef U, double mu, VectorRef G) {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const auto v = U.tail(n_);
  if (!problem_.residual(u, U[n_], G.head(n_))) return false;
  if (!problem_.jacobian(u, U[n_], Fu_, Flambda_)) return false;
  G.segment(n_, n_).noalias() = Fu_ * v;
  G[2 * n_] = c_.dot(v) - 1.0;
  return true;
}

bool FoldCurveProblem::jacobian(ConstVectorRef U, double mu, MatrixRef GU, VectorRef Gmu) {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  const auto v = U.tail(n_);
  if (!problem_.jacobian(u, lambda, Fu_, Flambda_)) return false;
  // F_uu[v, ·] and F_uλ v: the derivative of [F_u, F_λ] in the direction (v, 0)
  if (!problem_.jacobianDirectionalDerivative(u, lambda, v, 0.0, dFu_, dFlambda_)) return false;
  if (!problem_.secondParameterDerivatives(u, lambda, v, Fmu_, FuMuV_)) return false;
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

double FoldCurveProblem::boundary(int k, ConstVectorRef U, double mu) {
  // μ outside the domain: not a boundary crossing (residual() refuses the point anyway)
  if (!problem_.setSecondParameter(mu)) return 1.0;
  return problem_.boundary(k, U.head(n_), U[n_]);
}

bool FoldCurveProblem::cuspTest(ConstVectorRef U, double mu, double &value) {
  if (!problem_.setSecondParameter(mu)) return false;
  const auto u = U.head(n_);
  const double lambda = U[n_];
  const Vector v = U.tail(n_);
  if (!problem_.jacobian(u, lambda, Fu_, Flambda_)) return false;
  if (!problem_.jacobianDirectionalDerivative(u, lambda, v, 0.0, dFu_, dFlambda_)) return false;
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

}  // namespace buckle::continuation
