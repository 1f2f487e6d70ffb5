// Rule (c) of a task path (task_path.h): the most stable configuration the task allows, as the
// optimality system of max μ_min(H) continued along the path, and its start by continuation in
// the objective's weight θ from the chain's own inputs.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/task_path.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::MatrixRef;
using continuation::ProblemWorkspace;
using continuation::VectorRef;
using continuation::workspaceAs;

bool TaskPathProblem::mostStableResidual(ProblemWorkspace& ws, ConstVectorRef u, double s, double theta,
                                         VectorRef F) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) return false;
  const int P = n_, A = n_ + mIn_, Bt = 2 * n_ + mIn_, V = 2 * n_ + mIn_ + m_, M = 3 * n_ + mIn_ + m_;
  const auto p = u.segment(P, mIn_);
  const auto alpha = u.segment(A, n_);
  const auto beta = u.segment(Bt, m_);
  const auto v = u.segment(V, n_);
  const double mu = u[M];
  const auto hessianTimes = [&](ConstVectorRef w) {  // H w = K_q w − K_g w (eq 27)
    maxIndexProduct(d.h, w, d.work);
    return Vector(d.stiff.cwiseProduct(w) - d.work);
  };
  // ∇_q μ = A(v) v, ∇_p μ = (∂²K_q/∂p)[v, v] (header)
  Vector diagA, genA;
  hessianDerivative(ws, v, 0.0, 0.0, diagA, genA);
  Vector gradQ(n_);
  maxIndexProduct(genA, v, gradQ);
  gradQ += diagA.cwiseProduct(v);
  Matrix E2;
  inputColumns(d.e2, E2);
  const Vector gradP = E2.transpose() * v.cwiseAbs2();

  Vector Rq = -theta * gradQ + hessianTimes(alpha);
  for (int k = 0; k < m_; ++k) Rq += beta[k] * d.J.row(setup_.coordinates[size_t(k)]).transpose();
  F.segment(0, n_) = Rq;
  const double torque = stiffnessUnit_ * lengthUnit_ * lengthUnit_, b2 = lengthUnit_ * lengthUnit_;
  for (int j = 0; j < mIn_; ++j)
    F[P + j] = (1.0 - theta) * torque * setup_.inputs[size_t(j)].weight * (p[j] - p0_[j]) / b2 - theta * gradP[j] +
               d.B.col(j).dot(alpha);
  F.segment(A, n_) = d.grad - d.J.transpose() * setup_.payload - d.tau;  // g (eq 9, eq B2)
  const Vector t = target(s);
  for (int k = 0; k < m_; ++k) F[Bt + k] = d.data.pose[setup_.coordinates[size_t(k)]] - t[k];
  F.segment(V, n_) = hessianTimes(v) - mu * v;
  F[M] = 0.5 * (v.squaredNorm() - 1.0);
  return F.allFinite();
}

bool TaskPathProblem::mostStableJacobian(ProblemWorkspace& ws, ConstVectorRef u, double s, double theta, MatrixRef Fu,
                                         VectorRef Fparameter, bool parameterIsTheta) const {
  const continuation::ProblemScales sc = scales();
  Vector x = u, Fp(dim_), Fm(dim_);
  for (int j = 0; j < dim_; ++j) {
    const double h = 1e-6 * std::max(std::abs(u[j]), sc.unknowns[j]);
    x[j] = u[j] + h;
    if (!mostStableResidual(ws, x, s, theta, Fp)) return false;
    x[j] = u[j] - h;
    if (!mostStableResidual(ws, x, s, theta, Fm)) return false;
    x[j] = u[j];
    Fu.col(j) = (Fp - Fm) / (2.0 * h);
  }
  // the residual is affine in s and in θ: one difference is exact
  const double h = parameterIsTheta ? 1.0 : std::max(std::abs(s), lengthUnit_);
  if (!mostStableResidual(ws, u, parameterIsTheta ? s : s + h, parameterIsTheta ? theta + h : theta, Fp) ||
      !mostStableResidual(ws, u, s, theta, Fm))
    return false;
  Fparameter = (Fp - Fm) / h;
  return Fu.allFinite();
}

double TaskPathProblem::coalescenceGap(ProblemWorkspace& ws, ConstVectorRef u) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u) || n_ < 2) return 1.0;
  assemble(d.stiff, d.h, d.structure);
  Vector lowest(2);
  lowestEigenvalues(d.structure, false, 2, lowest, 1e-13, nullptr);
  const double mu = u[dim_ - 1];
  // the tracked μ is the lowest while the gap to the other one is positive; past a crossing the
  // lowest is another mode and the gap is negative
  const double other = std::abs(mu - lowest[0]) <= std::abs(mu - lowest[1]) ? lowest[1] : lowest[0];
  return (other - mu) / d.structure.typicalScale;
}

continuation::ProblemScales TaskPathProblem::mostStableScales(continuation::ProblemScales s) const {
  const double b = lengthUnit_, torque = stiffnessUnit_ * b * b;
  const int P = n_, A = n_ + mIn_, Bt = 2 * n_ + mIn_, V = 2 * n_ + mIn_ + m_, M = 3 * n_ + mIn_ + m_;
  s.unknowns.segment(P, mIn_).setConstant(b);
  s.unknowns.segment(A, n_).setConstant(1.0);  // α: H α balances torques
  for (int k = 0; k < m_; ++k) s.unknowns[Bt + k] = setup_.coordinates[size_t(k)] < 2 ? torque / b : torque;  // β
  s.unknowns.segment(V, n_).setConstant(1.0);  // v: unit
  s.unknowns[M] = torque;                      // μ
  s.residuals.segment(0, n_).setConstant(torque);
  s.residuals.segment(P, mIn_).setConstant(torque / b);
  s.residuals.segment(A, n_).setConstant(torque);
  for (int k = 0; k < m_; ++k) s.residuals[Bt + k] = setup_.coordinates[size_t(k)] < 2 ? b : 1.0;
  s.residuals.segment(V, n_).setConstant(torque);
  s.residuals[M] = 1.0;
  return s;
}

/// Rule (c)'s start: the optimality system at the leg's start s₀ with the objective's weight θ as
/// the continuation parameter (task_path.h).
class MostStableHomotopy final : public continuation::Problem {
 public:
  MostStableHomotopy(const TaskPathProblem& problem, double s0) : problem_(problem), s0_(s0) {}
  std::unique_ptr<ProblemWorkspace> createWorkspace() const override { return problem_.createWorkspace(); }
  int dimension() const override { return problem_.dimension(); }
  bool residual(ProblemWorkspace& ws, ConstVectorRef u, double theta, VectorRef F) const override {
    return problem_.mostStableResidual(ws, u, s0_, theta, F);
  }
  bool jacobian(ProblemWorkspace& ws, ConstVectorRef u, double theta, MatrixRef Fu, VectorRef Ftheta) const override {
    return problem_.mostStableJacobian(ws, u, s0_, theta, Fu, Ftheta, true);
  }
  bool jacobianWritesAllEntries() const override { return true; }
  continuation::ProblemScales scales() const override {
    continuation::ProblemScales s = problem_.scales();
    s.parameter = 1.0;
    return s;
  }

 private:
  const TaskPathProblem& problem_;
  double s0_;
};

Vector TaskPathProblem::startPoint(ProblemWorkspace& ws, ConstVectorRef q0,
                                   const continuation::TracerOptions& options) const {
  Vector u = pack(q0, p0_);
  if (setup_.rule != TaskRule::MostStable) return u;
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) throw std::runtime_error("rule most_stable: the start is outside the model's domain");
  Matrix H(n_, n_);
  for (int i = 0; i < n_; ++i)
    for (int j = 0; j < n_; ++j) H(i, j) = -d.h[std::max(i, j)];
  H.diagonal() += d.stiff;
  const Eigen::SelfAdjointEigenSolver<Matrix> eig(H);
  const double torque = stiffnessUnit_ * lengthUnit_ * lengthUnit_;
  if (n_ > 1 && eig.eigenvalues()[1] - eig.eigenvalues()[0] <= 1e-9 * torque)
    throw std::runtime_error("rule most_stable: the smallest eigenvalue of K_q - K_g at the start is not simple "
                             "(two modes equally weak), so the optimum is not smooth there");
  const int V = 2 * n_ + mIn_ + m_;
  u.segment(V, n_) = eig.eigenvectors().col(0);
  u[dim_ - 1] = eig.eigenvalues()[0];
  const MostStableHomotopy homotopy(*this, leg_.s0);
  continuation::TracerOptions o = options;
  o.lambdaMin = -0.5;
  o.lambdaMax = 1.0;
  o.boxLower.resize(0);
  o.boxUpper.resize(0);
  o.detection.branchPoints = false;
  o.detection.stability = false;
  o.detection.boundaries = false;
  o.linearAlgebra = continuation::TracerOptions::LinearAlgebra::Dense;
  o.onStep = nullptr;
  o.onLocated = nullptr;
  const continuation::Branch b =
      continuation::trace(homotopy, u, 0.0, continuation::InitialDirection::increasingLambda(), o);
  if (b.points.empty() || b.stopReason != continuation::StopReason::LambdaRange ||
      std::abs(b.points.back().lambda - 1.0) > 1e-9)
    throw std::runtime_error("rule most_stable: the most stable configuration at the start pose could not be reached "
                             "from the chain's own inputs by continuation in the objective's weight (" +
                             std::string(continuation::toString(b.stopReason)) +
                             (b.stopMessage.empty() ? "" : ": " + b.stopMessage) + ")");
  return b.points.back().u;
}

}  // namespace buckle::mechanics
