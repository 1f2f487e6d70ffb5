#include "buckle/mechanics/task_path.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/task_path_kkt_solver.h"
#include "buckle/mechanics/task_path_solver.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;
using continuation::MatrixRef;
using continuation::VectorRef;

std::string taskInputName(const TaskInput& input) {
  const std::string base = controlInputName(input.input);
  return input.segment < 0 ? base : base + "[" + std::to_string(input.segment + 1) + "]";
}

void TaskSetup::validate(int segments) const {
  if (coordinates.empty() || coordinates.size() > 3)
    throw std::invalid_argument("task path: 1 to 3 task coordinates expected, got " + std::to_string(coordinates.size()));
  for (size_t k = 0; k < coordinates.size(); ++k) {
    if (coordinates[k] < 0 || coordinates[k] > 2) throw std::invalid_argument("task path: coordinate out of range");
    if (k > 0 && coordinates[k] <= coordinates[k - 1])
      throw std::invalid_argument("task path: coordinates must be distinct and in the order x, y, phi");
  }
  const size_t m = coordinates.size();
  if (rule == TaskRule::Chosen && inputs.size() != m)
    throw std::invalid_argument("task path: the rule \"chosen\" needs as many inputs as task coordinates (" +
                                std::to_string(m) + "), got " + std::to_string(inputs.size()));
  if (rule != TaskRule::Chosen && inputs.size() < m)
    throw std::invalid_argument(std::string("task path: the rule \"") +
                                (rule == TaskRule::MinimumChange ? "min_change" : "most_stable") +
                                "\" needs at least as many inputs as task coordinates (" + std::to_string(m) + "), got " +
                                std::to_string(inputs.size()));
  for (const TaskInput& in : inputs) {
    if (in.segment < -1 || in.segment >= segments)
      throw std::invalid_argument("task path: input " + taskInputName(in) + ": segment out of range 1.." +
                                  std::to_string(segments));
    if (!(in.weight > 0.0) || !std::isfinite(in.weight))
      throw std::invalid_argument("task path: input " + taskInputName(in) + ": weight must be > 0 and finite");
    if (!(in.lower < in.upper)) throw std::invalid_argument("task path: input " + taskInputName(in) + ": lower bound not below upper");
  }
  if (!payload.allFinite()) throw std::invalid_argument("task path: payload not finite");
}

TaskPathProblem::TaskPathProblem(const Chain& chain, const TaskSetup& setup)
    : chain_(chain),
      setup_(setup),
      n_(chain.size()),
      m_(int(setup.coordinates.size())),
      mIn_(int(setup.inputs.size())),
      dim_(0) {
  setup_.validate(n_);
  setup_.body = setup_.body.atParameter(0.0);
  body_ = BodyLoadTerms(chain_, setup_.body);  // throws as BodyLoads::check
  dim_ = setup_.rule == TaskRule::Chosen ? n_ + mIn_
         : setup_.rule == TaskRule::MinimumChange ? 2 * n_ + mIn_ + m_
                                                  : 3 * n_ + mIn_ + m_ + 1;
  p0_.resize(mIn_);
  for (int j = 0; j < mIn_; ++j) {
    const TaskInput& in = setup_.inputs[size_t(j)];
    rates_.push_back(ControlDirection::named(n_, in.input, in.segment).rates);
    p0_[j] = controlInputValue(chain_, in.input, in.segment);
  }
  L1_.resize(n_);
  L2_.resize(n_);
  domainUpper_.resize(n_);
  domainLower_.resize(n_);
  double b = 0.0, k = 0.0;
  for (int i = 0; i < n_; ++i) {
    const Segment& s = chain_.segment(i);
    L1_[i] = s.parameters().L1_0;
    L2_[i] = s.parameters().L2_0;
    domainUpper_[i] = s.geometricUpperLimit() + EquilibriumProblem::kGeometricOvershoot;
    domainLower_[i] = s.geometricLowerLimit() - EquilibriumProblem::kGeometricOvershoot;
    b += 0.5 * (s.parameters().b1 + s.parameters().b2);
    k += 0.5 * (s.parameters().k1 + s.parameters().k2);
  }
  lengthUnit_ = b / n_;
  stiffnessUnit_ = k / n_;
  leg_.start = Vector::Zero(m_);
  leg_.direction = Vector::Zero(m_);
}

TaskPathProblem::Workspace::Workspace(const TaskPathProblem& problem)
    : data(problem.chain_),
      J(3, problem.n_),
      grad(problem.n_),
      stiff(problem.n_),
      third(problem.n_),
      e1(problem.n_, 2),
      e2(problem.n_, 2),
      h(problem.n_),
      work(problem.n_),
      body(problem.body_),
      tau(Vector::Zero(problem.n_)),
      B(problem.n_, problem.mIn_),
      structure(problem.n_) {
  structure.typicalScale = problem.stiffnessUnit_ * problem.lengthUnit_ * problem.lengthUnit_;
}

std::unique_ptr<ProblemWorkspace> TaskPathProblem::createWorkspace() const {
  return std::make_unique<Workspace>(*this);
}

Vector TaskPathProblem::pack(ConstVectorRef q, ConstVectorRef p) const {
  Vector u = Vector::Zero(dim_);
  u.head(n_) = q;
  u.segment(n_, mIn_) = p;
  return u;
}

Eigen::MatrixX2d TaskPathProblem::freeLengthChange(ConstVectorRef p) const {
  Eigen::MatrixX2d d = Eigen::MatrixX2d::Zero(n_, 2);
  for (int j = 0; j < mIn_; ++j) d += (p[j] - p0_[j]) * rates_[size_t(j)];
  return d;
}

Chain TaskPathProblem::chainAt(ConstVectorRef p) const {
  ControlDirection d;
  d.rates = freeLengthChange(p);
  return chainWithControls(chain_, d, 1.0);
}

bool TaskPathProblem::prepare(ProblemWorkspace& ws, ConstVectorRef u) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (u.size() != dim_ || !u.allFinite()) return false;
  // the cache depends on (q, p) only; the tracer evaluates F, F_u and the boundaries at one point
  if (d.cacheValid && std::memcmp(d.cachedKey.data(), u.data(), sizeof(double) * size_t(n_ + mIn_)) == 0) return true;
  d.cacheValid = false;
  const auto q = u.head(n_);
  const Eigen::MatrixX2d dL = freeLengthChange(u.segment(n_, mIn_));
  for (int i = 0; i < n_; ++i) {
    if (!(q[i] <= domainUpper_[i] && q[i] >= domainLower_[i])) return false;
    const double L1 = L1_[i] + dL(i, 0), L2 = L2_[i] + dL(i, 1);
    // the spring model holds for any free length; a little past zero is let through so that the
    // tracer can locate the free-length boundary (L⁰ = 0) from both sides
    const double margin = EquilibriumProblem::kGeometricOvershoot * lengthUnit_;
    if (!(L1 > -margin && L2 > -margin)) return false;
    const Segment& seg = chain_.segment(i);
    const double sh = std::sin(0.5 * q[i]), ch = std::cos(0.5 * q[i]);
    Jet3 rate;
    const Jet3 e = seg.energyJet(q[i], sh, ch, L1, L2, 0.0, 0.0, rate);
    d.grad[i] = e.d1;
    d.stiff[i] = e.d2;
    d.third[i] = e.d3;
    // ∂E^(j)/∂L⁰_s = −k_s L_s^(j) (segment.h)
    const Jet3 s1 = seg.spring1(q[i]), s2 = seg.spring2(q[i]);
    d.e1(i, 0) = -seg.parameters().k1 * s1.d1;
    d.e1(i, 1) = -seg.parameters().k2 * s2.d1;
    d.e2(i, 0) = -seg.parameters().k1 * s1.d2;
    d.e2(i, 1) = -seg.parameters().k2 * s2.d2;
  }
  forwardKinematics(chain_, q, d.data);
  endJacobian(d.data, d.J);
  loadHessianGenerator(d.data, setup_.payload, d.h);
  if (d.body.active()) {  // the generator h − γ and ∂V/∂q = −τ (eq B2, B3)
    d.body.update(d.data);
    d.body.torques(0.0, d.tau);
    d.body.generator(0.0, d.work);
    d.h -= d.work;
  }
  inputColumns(d.e1, d.B);
  d.cachedKey = u.head(n_ + mIn_);
  d.cacheValid = true;
  return true;
}

void TaskPathProblem::inputColumns(const Eigen::MatrixX2d& e, Matrix& out) const {
  out.resize(n_, mIn_);
  for (int j = 0; j < mIn_; ++j)
    out.col(j) = rates_[size_t(j)].col(0).cwiseProduct(e.col(0)) + rates_[size_t(j)].col(1).cwiseProduct(e.col(1));
}

bool TaskPathProblem::residual(ProblemWorkspace& ws, ConstVectorRef u, double s, VectorRef F) const {
  if (setup_.rule == TaskRule::MostStable) return mostStableResidual(ws, u, s, 1.0, F);
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) return false;
  const Vector t = target(s);
  const Vector g = d.grad - d.J.transpose() * setup_.payload - d.tau;  // eq 9, eq B2 (τ = 0 without body loads)
  if (setup_.rule == TaskRule::Chosen) {
    F.head(n_) = g;
    for (int k = 0; k < m_; ++k) F[n_ + k] = d.data.pose[setup_.coordinates[size_t(k)]] - t[k];
    return true;
  }
  const auto p = u.segment(n_, mIn_);
  const auto mu = u.segment(n_ + mIn_, n_);
  const auto nu = u.segment(2 * n_ + mIn_, m_);
  // R_q = H μ + J_cᵀ ν, H μ = K_q μ − K_g μ (K_g(i, j) = h_max(i,j), eq 27)
  maxIndexProduct(d.h, mu, d.work);
  Vector Rq = d.stiff.cwiseProduct(mu) - d.work;
  for (int k = 0; k < m_; ++k) Rq += nu[k] * d.J.row(setup_.coordinates[size_t(k)]).transpose();
  F.head(n_) = Rq;
  const double b2 = lengthUnit_ * lengthUnit_;
  for (int j = 0; j < mIn_; ++j)
    F[n_ + j] = setup_.inputs[size_t(j)].weight * (p[j] - p0_[j]) / b2 + d.B.col(j).dot(mu);
  F.segment(n_ + mIn_, n_) = g;
  for (int k = 0; k < m_; ++k) F[2 * n_ + mIn_ + k] = d.data.pose[setup_.coordinates[size_t(k)]] - t[k];
  return true;
}

bool TaskPathProblem::jacobian(ProblemWorkspace& ws, ConstVectorRef u, double s, MatrixRef Fu, VectorRef Fs) const {
  if (setup_.rule == TaskRule::MostStable) return mostStableJacobian(ws, u, s, 1.0, Fu, Fs, false);
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) return false;
  Fu.setZero();
  Fs.setZero();
  // H = K_q − K_g, K_g(i, j) = h_max(i,j) (eq 27)
  Matrix H(n_, n_);
  for (int i = 0; i < n_; ++i)
    for (int j = 0; j < n_; ++j) H(i, j) = -d.h[std::max(i, j)];
  H.diagonal() += d.stiff;
  const int tRow = setup_.rule == TaskRule::Chosen ? n_ : 2 * n_ + mIn_;
  for (int k = 0; k < m_; ++k) Fs[tRow + k] = -leg_.direction[k];
  if (setup_.rule == TaskRule::Chosen) {
    Fu.topLeftCorner(n_, n_) = H;
    Fu.topRightCorner(n_, mIn_) = d.B;
    for (int k = 0; k < m_; ++k) Fu.row(n_ + k).head(n_) = d.J.row(setup_.coordinates[size_t(k)]);
    return true;
  }
  Vector diagA, genA;
  Matrix D;
  optimalityBlocks(ws, u, diagA, genA, D);
  const int P = n_, M = n_ + mIn_, N = 2 * n_ + mIn_;
  for (int i = 0; i < n_; ++i)
    for (int j = 0; j < n_; ++j) Fu(i, j) = genA[std::max(i, j)];
  Fu.topLeftCorner(n_, n_).diagonal() += diagA;
  Fu.block(0, P, n_, mIn_) = D;
  Fu.block(P, 0, mIn_, n_) = D.transpose();
  Fu.block(0, M, n_, n_) = H;
  Fu.block(M, 0, n_, n_) = H;
  for (int j = 0; j < mIn_; ++j) Fu(P + j, P + j) = setup_.inputs[size_t(j)].weight / (lengthUnit_ * lengthUnit_);
  Fu.block(P, M, mIn_, n_) = d.B.transpose();
  Fu.block(M, P, n_, mIn_) = d.B;
  for (int k = 0; k < m_; ++k) {
    const auto row = d.J.row(setup_.coordinates[size_t(k)]);
    Fu.block(0, N + k, n_, 1) = row.transpose();
    Fu.block(N + k, 0, 1, n_) = row;
  }
  return true;
}

void TaskPathProblem::optimalityBlocks(ProblemWorkspace& ws, ConstVectorRef u, Vector& diagA, Vector& genA,
                                       Matrix& D) const {
  const auto mu = u.segment(n_ + mIn_, n_);
  const auto nu = u.segment(2 * n_ + mIn_, m_);
  double nx = 0.0, ny = 0.0;
  for (int k = 0; k < m_; ++k) {
    if (setup_.coordinates[size_t(k)] == 0) nx = nu[k];
    if (setup_.coordinates[size_t(k)] == 1) ny = nu[k];
  }
  hessianDerivative(ws, mu, nx, ny, diagA, genA);
  inputColumns(workspaceAs<Workspace>(ws).e2, D);
  D = mu.asDiagonal() * D;
}

void TaskPathProblem::hessianDerivative(ProblemWorkspace& ws, ConstVectorRef w, double nx, double ny, Vector& diagA,
                                        Vector& genA) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  // A = diag(E‴ ⊙ w) − K_a + K_b (header): one generator genA_m = b_m − a_m of a max-index matrix
  const Wrench& F = setup_.payload;
  genA.resize(n_);
  double prefix = 0.0, tail = 0.0;
  for (int m = 0; m < n_; ++m) prefix += w[m], d.work[m] = prefix;  // Σ_{j≤m} w_j
  for (int m = n_ - 1; m >= 0; --m) {
    const double rho = F[0] * d.data.S[m] - F[1] * d.data.C[m] - d.tau[m];  // ρ_m (header, eq B5)
    const double a = rho * d.work[m] + tail;
    tail += rho * w[m];
    genA[m] = -nx * d.data.C[m] - ny * d.data.S[m] - a;
  }
  diagA = d.third.cwiseProduct(w);
}

bool TaskPathProblem::assembleOptimality(ProblemWorkspace& ws, ConstVectorRef u, ChainStructure& structure,
                                         OptimalityBlocks& blocks) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (setup_.rule != TaskRule::MinimumChange || !prepare(ws, u)) return false;
  structure.typicalScale = d.structure.typicalScale;
  assemble(d.stiff, d.h, structure);
  optimalityBlocks(ws, u, blocks.diagA, blocks.genA, blocks.D);
  blocks.B = d.B;
  blocks.Jc.resize(m_, n_);
  for (int k = 0; k < m_; ++k) blocks.Jc.row(k) = d.J.row(setup_.coordinates[size_t(k)]);
  blocks.weights.resize(mIn_);
  for (int j = 0; j < mIn_; ++j) blocks.weights[j] = setup_.inputs[size_t(j)].weight / (lengthUnit_ * lengthUnit_);
  return true;
}

bool TaskPathProblem::assembleStructure(ProblemWorkspace& ws, ConstVectorRef u, ChainStructure& structure, Matrix& B,
                                        Matrix& Jc) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) return false;
  structure.typicalScale = d.structure.typicalScale;
  assemble(d.stiff, d.h, structure);
  B = d.B;
  Jc.resize(m_, n_);
  for (int k = 0; k < m_; ++k) Jc.row(k) = d.J.row(setup_.coordinates[size_t(k)]);
  return true;
}

bool TaskPathProblem::fixedInputStability(ProblemWorkspace& ws, ConstVectorRef u, Inertia& inertia,
                                          double& smallest) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(ws, u)) return false;
  assemble(d.stiff, d.h, d.structure);
  inertia = hessianInertia(d.structure);
  // warm start from the last point's value (the path moves continuously)
  Vector out(1);
  lowestEigenvalues(d.structure, false, 1, out, 1e-13, d.lastSmallest.size() ? &d.lastSmallest : nullptr);
  smallest = out[0];
  d.lastSmallest = out;
  return true;
}

double TaskPathProblem::boundary(ProblemWorkspace& ws, int k, ConstVectorRef u, double) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (k < n_) return chain_.upperLimits()[k] - u[k];
  if (k < 2 * n_) return u[k - n_] - chain_.lowerLimits()[k - n_];
  if (k < 2 * n_ + 2 * mIn_) {
    const int j = (k - 2 * n_) / 2;
    const TaskInput& in = setup_.inputs[size_t(j)];
    const double p = u[n_ + j];
    // an infinite bound is never reached: a constant positive value in the input's unit
    if ((k - 2 * n_) % 2 == 0) return std::isfinite(in.upper) ? in.upper - p : lengthUnit_;
    return std::isfinite(in.lower) ? p - in.lower : lengthUnit_;
  }
  if (k < 4 * n_ + 2 * mIn_) {  // free lengths L⁰_{i,s}(p) > 0
    const int f = k - 2 * n_ - 2 * mIn_, i = f / 2, spring = f % 2;
    double L = spring == 0 ? L1_[i] : L2_[i];
    for (int j = 0; j < mIn_; ++j) L += (u[n_ + j] - p0_[j]) * rates_[size_t(j)](i, spring);
    return L;
  }
  if (k == 4 * n_ + 2 * mIn_ + 1) return coalescenceGap(ws, u);
  if (!setup_.stabilityBoundary) return 1.0;
  Inertia inertia;
  double smallest = 0.0;
  if (!fixedInputStability(ws, u, inertia, smallest)) return 1.0;
  return smallest / d.structure.typicalScale;
}

TaskPathProblem::BoundaryKind TaskPathProblem::boundaryKind(int k) const {
  if (k < 2 * n_) return BoundaryKind::JointLimit;
  if (k < 4 * n_ + 2 * mIn_) return BoundaryKind::InputBound;
  return k == 4 * n_ + 2 * mIn_ ? BoundaryKind::Stability : BoundaryKind::Coalescence;
}

std::string TaskPathProblem::boundaryName(int k) const {
  if (k < 2 * n_) {
    const int j = k < n_ ? k : k - n_;
    return "joint " + std::to_string(j + 1) + (k < n_ ? " upper" : " lower") + " limit";
  }
  if (k < 2 * n_ + 2 * mIn_) {
    const int j = (k - 2 * n_) / 2;
    return "input " + taskInputName(setup_.inputs[size_t(j)]) + ((k - 2 * n_) % 2 == 0 ? " upper" : " lower") + " bound";
  }
  if (k < 4 * n_ + 2 * mIn_) {
    const int f = k - 2 * n_ - 2 * mIn_;
    return std::string("free length ") + (f % 2 == 0 ? "L1_0" : "L2_0") + " of segment " + std::to_string(f / 2 + 1) +
           " reaches zero (the inputs' admissible range)";
  }
  if (k == 4 * n_ + 2 * mIn_ + 1)
    return "the optimised smallest eigenvalue of K_q - K_g meets the next one (the most stable configuration stops "
           "being smooth: two modes are equally weak)";
  return "loss of stability at fixed inputs (smallest eigenvalue of K_q - K_g crosses zero)";
}

std::unique_ptr<continuation::BorderedSolver> TaskPathProblem::makeStructuredSolver(ProblemWorkspace& ws) const {
  if (setup_.rule == TaskRule::MostStable) return nullptr;  // a dense Jacobian (header)
  if (setup_.rule == TaskRule::MinimumChange)
    return mIn_ + m_ + 2 <= TaskPathKktSolver::kMaxSmall ? std::make_unique<TaskPathKktSolver>(*this, ws) : nullptr;
  if (mIn_ + 3 > ChainStructure::kMaxBorder) return nullptr;
  return std::make_unique<TaskPathBorderedSolver>(*this, ws);
}

continuation::ProblemScales TaskPathProblem::scales() const {
  const double b = lengthUnit_, torque = stiffnessUnit_ * b * b;
  continuation::ProblemScales s = continuation::ProblemScales::ones(dim_);
  s.parameter = b;
  s.stability = torque;
  if (setup_.rule == TaskRule::MostStable) return mostStableScales(s);
  const bool chosen = setup_.rule == TaskRule::Chosen;
  const int gRow = chosen ? 0 : n_ + mIn_, tRow = chosen ? n_ : 2 * n_ + mIn_;
  s.unknowns.segment(n_, mIn_).setConstant(b);
  s.residuals.segment(gRow, n_).setConstant(torque);
  for (int k = 0; k < m_; ++k) s.residuals[tRow + k] = setup_.coordinates[size_t(k)] < 2 ? b : 1.0;
  if (!chosen) {
    s.unknowns.segment(n_ + mIn_, n_).setConstant(1.0 / torque);  // μ
    for (int k = 0; k < m_; ++k) s.unknowns[tRow + k] = setup_.coordinates[size_t(k)] < 2 ? 1.0 / b : 1.0;  // ν
    s.residuals.segment(n_, mIn_).setConstant(1.0 / b);  // R_p
  }
  return s;
}

}  // namespace buckle::mechanics
