#include "buckle/mechanics/contact.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::MatrixRef;
using continuation::VectorRef;

const char* toString(LimitSide side) { return side == LimitSide::Upper ? "upper" : "lower"; }

// ---- ContactSet ---------------------------------------------------------------------------

void ContactSet::lock(int joint, LimitSide side) {
  if (joint < 0) throw std::invalid_argument("contact: joint index must be >= 0, got " + std::to_string(joint));
  auto it = std::lower_bound(joints_.begin(), joints_.end(), joint,
                             [](const LockedJoint& l, int j) { return l.joint < j; });
  if (it != joints_.end() && it->joint == joint)
    it->side = side;
  else
    joints_.insert(it, LockedJoint{joint, side});
}

void ContactSet::release(int joint) {
  joints_.erase(std::remove_if(joints_.begin(), joints_.end(), [joint](const LockedJoint& l) { return l.joint == joint; }),
                joints_.end());
}

bool ContactSet::locked(int joint) const {
  return std::any_of(joints_.begin(), joints_.end(), [joint](const LockedJoint& l) { return l.joint == joint; });
}

LimitSide ContactSet::side(int joint) const {
  for (const LockedJoint& l : joints_)
    if (l.joint == joint) return l.side;
  return LimitSide::Upper;
}

std::string ContactSet::label() const {
  std::string s;
  for (const LockedJoint& l : joints_) {
    if (!s.empty()) s += ' ';
    s += std::to_string(l.joint + 1) + (l.side == LimitSide::Upper ? "U" : "L");
  }
  return s;
}

void ContactSet::check(int segments) const {
  for (const LockedJoint& l : joints_)
    if (l.joint >= segments)
      throw std::invalid_argument("contact: locked joint " + std::to_string(l.joint + 1) + " does not exist (the chain has " +
                                  std::to_string(segments) + " joints)");
}

double limitAngle(const Chain& chain, int joint, LimitSide side) {
  return side == LimitSide::Upper ? chain.upperLimits()[joint] : chain.lowerLimits()[joint];
}

LockedJoint limitOfBoundary(int k, int segments) {
  return k < segments ? LockedJoint{k, LimitSide::Upper} : LockedJoint{k - segments, LimitSide::Lower};
}

const ContactSet& lockedAt(const std::vector<ContactStretch>& stretches, int index) {
  static const ContactSet none;
  const ContactSet* at = &none;
  for (const ContactStretch& s : stretches)
    if (s.firstPoint <= index) at = &s.locked;
  return *at;
}

ContactSet jointsAtLimits(const Chain& chain, ConstVectorRef q, double tolerance) {
  ContactSet s;
  for (int i = 0; i < chain.size(); ++i) {
    if (std::abs(chain.upperLimits()[i] - q[i]) <= tolerance)
      s.lock(i, LimitSide::Upper);
    else if (std::abs(q[i] - chain.lowerLimits()[i]) <= tolerance)
      s.lock(i, LimitSide::Lower);
  }
  return s;
}

// ---- the reduced structure ------------------------------------------------------------------

namespace {

std::vector<int> freeJointsOf(const ContactSet& locked, int n) {
  std::vector<int> f;
  for (int i = 0; i < n; ++i)
    if (!locked.locked(i)) f.push_back(i);
  return f;
}

// K_q − K_g on the free joints F keeps the generator form κ_a δ_ab − h_max(a,b) (eq 27) with κ_F
// and h_F (the order of the indices is kept), so its T is assembled from those.
void reduceStructure(const ChainStructure& full, const std::vector<int>& free, VectorRef kf, VectorRef hf,
                     ChainStructure& reduced) {
  for (size_t a = 0; a < free.size(); ++a) {
    kf[Eigen::Index(a)] = full.kappa[free[a]];
    hf[Eigen::Index(a)] = full.h[free[a]];
  }
  assemble(kf, hf, reduced);
}

// Inertia and lowest eigenvalues of the reduced H on ker of the held rows (as
// EquilibriumProblem::stability, on the reduced structure).
void reducedStability(ChainStructure& ws, const Matrix& heldRows, int lowestCount, Vector& lastLowest,
                      continuation::StabilityInfo& info) {
  const int wanted = std::max(0, std::min(lowestCount, EquilibriumProblem::kMaxLowest));
  if (ws.n <= kSmallDense && wanted > 0) {
    Eigen::Matrix<double, EquilibriumProblem::kMaxLowest, 1> low;
    int found = 0;
    const Inertia in = smallDenseInertia(ws, heldRows, wanted, low.head(wanted), found);
    info.negative = in.negative;
    info.zero = in.zero;
    info.lowest = low.head(found);
  } else {
    const Inertia in = constrainedInertia(ws, heldRows);
    info.negative = in.negative;
    info.zero = in.zero;
    info.lowest.resize(std::min(wanted, in.size()));
    if (info.lowest.size() > 0) {
      lowestEigenvalues(ws, ws.rank > 0, int(info.lowest.size()), info.lowest, 1e-13,
                        lastLowest.size() == info.lowest.size() ? &lastLowest : nullptr);
      lastLowest = info.lowest;
    }
  }
  info.smallest = info.lowest.size() > 0 ? info.lowest[0] : 0.0;
}

/// A(c) = [[F_u, F_λ], [cᵀ]] of ContactProblem in O(n): the locked rows give x_L = −b_L; the rest
/// is the reduced chain's bordered system (chain_solver.h's borders on the free joints) with the
/// known x_L moved to the right-hand side. det A = (−1)^|L| det(reduced) (expansion along the
/// locked rows).
class ReducedChainSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;

  explicit ReducedChainSolver(ContactProblem& problem)
      : problem_(problem),
        n_(problem.base().segments()),
        m_(problem.base().heldCount()),
        free_(problem.freeJoints()),
        held_(problem.base().endCondition().heldIndices()),
        loaded_(problem.base().endCondition().loadedIndices()),
        full_(problem.base().segments()),
        ws_(int(problem.freeJoints().size())),
        J_(3, problem.base().segments()),
        kf_(problem.freeJoints().size()),
        hf_(problem.freeJoints().size()),
        V_(Matrix::Zero(Eigen::Index(problem.freeJoints().size()), m_ + 1)),
        W_(Matrix::Zero(Eigen::Index(problem.freeJoints().size()), m_ + 1)),
        D_(Matrix::Zero(m_ + 1, m_ + 1)),
        c_(Vector::Zero(n_ + m_ + 1)),
        f_(problem.freeJoints().size()),
        g_(m_ + 1),
        x_(problem.freeJoints().size()),
        y_(m_ + 1) {
    for (const LockedJoint& l : problem.contacts().joints()) lockedIndex_.push_back(l.joint);
    if (n_ + m_ <= kDenseFallback) dense_ = std::make_unique<continuation::DenseBorderedSolver>(problem);
  }

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override {
    sign_ = 0;
    logAbs_ = -std::numeric_limits<double>::infinity();
    usingDense_ = false;
    if (!c.allFinite() || !problem_.base().assembleStructure(u, lambda, full_, J_)) return Factorization::Refused;
    c_ = c;
    reduceStructure(full_, free_, kf_, hf_, ws_);
    const Eigen::Vector3d& dir = problem_.base().direction();
    const int nf = int(free_.size());
    D_.setZero();
    for (int a = 0; a < nf; ++a) {
      const int i = free_[size_t(a)];
      double fl = 0.0;
      for (int cc : loaded_) fl -= J_(cc, i) * dir[cc];
      if (problem_.base().hasBodyLoads()) fl -= problem_.base().bodyRateTorques()[i];  // eq (B2)
      V_(a, m_) = fl;
      W_(a, m_) = c[i];
      for (int k = 0; k < m_; ++k) V_(a, k) = W_(a, k) = -J_(held_[size_t(k)], i);
    }
    for (int k = 0; k < m_; ++k) {
      D_(k, m_) = dir[held_[size_t(k)]];
      D_(m_, k) = c[n_ + k];
    }
    D_(m_, m_) = c[n_ + m_];
    const int lockedSign = lockedIndex_.size() % 2 == 0 ? 1 : -1;
    if (factorBordered(ws_, V_, W_, D_)) {
      sign_ = lockedSign * ws_.borderedDetSign;
      logAbs_ = ws_.borderedLogAbsDet;
      return Factorization::Regular;
    }
    if (!dense_) return Factorization::Singular;
    usingDense_ = true;
    const Factorization f = dense_->factor(u, lambda, c);
    sign_ = dense_->determinantSign();
    logAbs_ = dense_->logAbsDeterminant();
    return f;
  }

  bool solve(ConstVectorRef b, VectorRef x) override {
    if (sign_ == 0) return false;
    if (usingDense_) return dense_->solve(b, x);
    // x_L = −b_L, then the free rows, held rows and the border row with x_L moved right:
    // free a: H_aL x_L = −Σ_i h_max(a,i) x_i (a ≠ i).
    const int nf = int(free_.size());
    for (int a = 0; a < nf; ++a) f_[a] = b[free_[size_t(a)]];
    for (int k = 0; k < m_; ++k) g_[k] = b[n_ + k];
    g_[m_] = b[n_ + m_];
    for (int i : lockedIndex_) {
      const double xi = -b[i];
      x[i] = xi;
      for (int a = 0; a < nf; ++a) f_[a] += full_.h[std::max(free_[size_t(a)], i)] * xi;
      for (int k = 0; k < m_; ++k) g_[k] += J_(held_[size_t(k)], i) * xi;
      g_[m_] -= c_[i] * xi;
    }
    if (!solveFactoredBordered(ws_, V_, W_, D_, f_, g_, x_, y_)) return false;
    for (int a = 0; a < nf; ++a) x[free_[size_t(a)]] = x_[a];
    x.tail(m_ + 1) = y_;
    return true;
  }

  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }

 private:
  ContactProblem& problem_;
  int n_, m_;
  std::vector<int> free_, held_, loaded_, lockedIndex_;
  ChainStructure full_, ws_;
  Matrix J_;
  Vector kf_, hf_;
  Matrix V_, W_, D_;
  Vector c_, f_, g_, x_, y_;
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace

// ---- ContactProblem ---------------------------------------------------------------------------

ContactProblem::ContactProblem(EquilibriumProblem& base, ContactSet locked, double maxCompression)
    : base_(base),
      locked_((locked.check(base.segments()), std::move(locked))),
      maxCompression_(maxCompression),
      free_(freeJointsOf(locked_, base.segments())),
      held_(base.endCondition().heldIndices()),
      full_(base.segments()),
      reduced_(std::max(1, int(free_.size()))),
      J_(3, base.segments()),
      Jf_(3, Eigen::Index(free_.size())),
      heldRows_(Eigen::Index(held_.size()), Eigen::Index(free_.size())),
      kf_(free_.size()),
      hf_(free_.size()),
      residual_(base.dimension()) {
  if (!(maxCompression > 0.0))
    throw std::invalid_argument("contact: the bound of the contact torque must be positive, got " +
                                std::to_string(maxCompression));
  reduced_.typicalScale = base.stiffnessUnit() * base.lengthUnit() * base.lengthUnit();
  full_.typicalScale = reduced_.typicalScale;
}

double ContactProblem::contactTorque(ConstVectorRef u, double lambda, int joint) {
  if (!base_.residual(u, lambda, residual_)) return std::numeric_limits<double>::quiet_NaN();
  return residual_[joint];
}

double ContactProblem::compression(ConstVectorRef u, double lambda, int joint) {
  return -double(int(locked_.side(joint))) * contactTorque(u, lambda, joint);
}

bool ContactProblem::residual(ConstVectorRef u, double lambda, VectorRef F) {
  if (!base_.residual(u, lambda, F)) return false;
  for (const LockedJoint& l : locked_.joints()) F[l.joint] = limitAngle(base_.chain(), l.joint, l.side) - u[l.joint];
  return true;
}

bool ContactProblem::jacobian(ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Flambda) {
  if (!base_.jacobian(u, lambda, Fu, Flambda)) return false;
  for (const LockedJoint& l : locked_.joints()) {
    Fu.row(l.joint).setZero();
    Fu(l.joint, l.joint) = -1.0;
    Flambda[l.joint] = 0.0;
  }
  return true;
}

bool ContactProblem::jacobianDirectionalDerivative(ConstVectorRef u, double lambda, ConstVectorRef du,
                                                   double dlambda, MatrixRef dFu, VectorRef dFlambda) {
  if (!base_.jacobianDirectionalDerivative(u, lambda, du, dlambda, dFu, dFlambda)) return false;
  for (const LockedJoint& l : locked_.joints()) {  // the locked rows are linear
    dFu.row(l.joint).setZero();
    dFlambda[l.joint] = 0.0;
  }
  return true;
}

bool ContactProblem::stabilityOperator(ConstVectorRef u, double lambda, Matrix& H, Matrix& C) {
  Matrix Ch;
  if (!base_.stabilityOperator(u, lambda, H, Ch)) return false;
  const int n = base_.segments();
  C = Matrix::Zero(Ch.rows() + locked_.count(), n);
  C.topRows(Ch.rows()) = Ch;
  for (int k = 0; k < locked_.count(); ++k) C(Ch.rows() + k, locked_.joints()[size_t(k)].joint) = 1.0;
  return true;
}

bool ContactProblem::assembleReduced(ConstVectorRef u, double lambda, ChainStructure& ws, MatrixRef Jf) {
  if (free_.empty() || !base_.assembleStructure(u, lambda, full_, J_)) return false;
  reduceStructure(full_, free_, kf_, hf_, ws);
  for (size_t a = 0; a < free_.size(); ++a) Jf.col(Eigen::Index(a)) = J_.col(free_[a]);
  return true;
}

bool ContactProblem::stability(ConstVectorRef u, double lambda, int lowestCount, continuation::StabilityInfo& info) {
  if (free_.empty()) {  // every joint locked: nothing can move
    if (!residual(u, lambda, residual_)) return false;
    info = continuation::StabilityInfo();
    info.negative = 0;
    return true;
  }
  if (!assembleReduced(u, lambda, reduced_, Jf_)) return false;
  for (size_t k = 0; k < held_.size(); ++k) heldRows_.row(Eigen::Index(k)) = Jf_.row(held_[k]);
  reducedStability(reduced_, heldRows_, lowestCount, lastLowest_, info);
  return true;
}

std::unique_ptr<continuation::BorderedSolver> ContactProblem::makeStructuredSolver() {
  if (free_.empty()) return std::make_unique<continuation::DenseBorderedSolver>(*this);
  return std::make_unique<ReducedChainSolver>(*this);
}

continuation::ProblemScales ContactProblem::scales() const {
  continuation::ProblemScales s = base_.scales();
  for (const LockedJoint& l : locked_.joints()) s.residuals[l.joint] = 1.0;  // q̄ − q: an angle
  return s;
}

// Boundaries: the joints' 2n (a locked joint's own limit is its contact release), the base
// problem's path range (EquilibriumOptions::heldRange), then the locked joints' torque bounds.
int ContactProblem::boundaryCount() const {
  return 2 * base_.segments() + base_.rangeBoundaryCount() + (std::isfinite(maxCompression_) ? locked_.count() : 0);
}

double ContactProblem::boundary(int k, ConstVectorRef u, double lambda) {
  const int n = base_.segments();
  const int range = base_.rangeBoundaryCount();
  if (k >= 2 * n + range)
    return maxCompression_ - compression(u, lambda, locked_.joints()[size_t(k - 2 * n - range)].joint);
  if (k >= 2 * n) return base_.boundary(base_.rangeBoundaryBegin() + k - 2 * n, u, lambda);
  const LockedJoint b = limitOfBoundary(k, base_.segments());
  if (locked_.locked(b.joint) && locked_.side(b.joint) == b.side) return compression(u, lambda, b.joint);
  return base_.boundary(k, u, lambda);
}

std::string ContactProblem::boundaryName(int k) const {
  const int n = base_.segments();
  const int range = base_.rangeBoundaryCount();
  if (k >= 2 * n + range) {
    std::ostringstream os;
    os << "joint " << locked_.joints()[size_t(k - 2 * n - range)].joint + 1 << " contact torque reached its bound "
       << maxCompression_ << " (the locked chain is pressed far beyond what its springs carry)";
    return os.str();
  }
  if (k >= 2 * n) return base_.boundaryName(base_.rangeBoundaryBegin() + k - 2 * n);
  const LockedJoint b = limitOfBoundary(k, base_.segments());
  if (locked_.locked(b.joint) && locked_.side(b.joint) == b.side)
    return "joint " + std::to_string(b.joint + 1) + " " + toString(b.side) + " contact released (contact torque -> 0)";
  return base_.boundaryName(k);
}

// ---- constrained equilibrium, stability, stiffness ------------------------------------------

ConstrainedEquilibrium solveConstrainedEquilibrium(EquilibriumProblem& base, const ContactSet& locked,
                                                   ConstVectorRef u0, double lambda, double tolerance,
                                                   int maxIterations) {
  ConstrainedEquilibrium out;
  const int N = base.dimension();
  if (u0.size() != N)
    throw std::invalid_argument("solveConstrainedEquilibrium: u0 must have " + std::to_string(N) + " entries, got " +
                                std::to_string(u0.size()));
  if (!std::isfinite(lambda)) throw std::invalid_argument("solveConstrainedEquilibrium: lambda must be finite");
  ContactProblem problem(base, locked);
  const continuation::ProblemScales s = problem.scales();
  const std::unique_ptr<continuation::BorderedSolver> solver = problem.makeStructuredSolver();
  Vector u = u0, F(N), trial(N), b = Vector::Zero(N + 1), dx(N + 1), c = Vector::Zero(N + 1);
  c[N] = 1.0;  // fixed λ: the border row e_λ
  for (const LockedJoint& l : locked.joints()) u[l.joint] = limitAngle(base.chain(), l.joint, l.side);
  auto scaledNorm = [&](const Vector& r) { return r.cwiseQuotient(s.residuals).cwiseAbs().maxCoeff(); };
  if (!problem.residual(u, lambda, F)) {
    out.message = "the start is outside the model's domain";
    out.u = u;
    return out;
  }
  double norm = scaledNorm(F);
  for (out.iterations = 0; out.iterations < maxIterations && !(norm <= tolerance); ++out.iterations) {
    if (solver->factor(u, lambda, c) != Factorization::Regular) {
      out.message = "singular constrained Jacobian";
      break;
    }
    b.head(N) = F;
    if (!solver->solve(b, dx)) {
      out.message = "singular constrained Jacobian";
      break;
    }
    // Newton step, halved while it leaves the domain or increases the residual.
    double t = 1.0, trialNorm = std::numeric_limits<double>::infinity();
    for (int h = 0; h < 30; ++h, t *= 0.5) {
      trial = u - t * dx.head(N);
      if (problem.residual(trial, lambda, F) && (trialNorm = scaledNorm(F)) < std::max(norm, tolerance) * 2.0) break;
      trialNorm = std::numeric_limits<double>::infinity();
    }
    if (!std::isfinite(trialNorm)) {
      out.message = "the Newton step leaves the model's domain";
      break;
    }
    u = trial;
    norm = trialNorm;
  }
  if (!problem.residual(u, lambda, F)) norm = std::numeric_limits<double>::infinity();
  out.u = u;
  out.residual = norm;
  out.converged = norm <= tolerance;
  if (!out.converged && out.message.empty()) out.message = "no convergence in " + std::to_string(maxIterations) + " iterations";
  out.torques = Vector::Zero(base.segments());
  out.minCompression = std::numeric_limits<double>::infinity();
  Vector Fb(N);
  if (base.residual(u, lambda, Fb)) {
    for (const LockedJoint& l : locked.joints()) {
      out.torques[l.joint] = Fb[l.joint];
      out.minCompression = std::min(out.minCompression, -double(int(l.side)) * Fb[l.joint]);
    }
  }
  return out;
}

continuation::StabilityInfo constrainedStability(EquilibriumProblem& base, const ContactSet& locked, ConstVectorRef u,
                                                 double lambda, int lowestCount) {
  ContactProblem problem(base, locked);
  continuation::StabilityInfo info;
  if (!problem.stability(u, lambda, lowestCount, info)) info.negative = -1;
  return info;
}

CartesianStiffness lockedLoadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, const EndCondition& end,
                                         const ContactSet& locked, const StiffnessOptions& options) {
  if (locked.empty()) return loadedStiffness(chain, q, F, end, options);
  locked.check(chain.size());
  Matrix E = Matrix::Zero(locked.count(), chain.size());  // δq_i = 0 at the locked joints
  for (int k = 0; k < locked.count(); ++k) E(k, locked.joints()[size_t(k)].joint) = 1.0;
  return loadedStiffness(chain, q, F, end.isHeld(EndCoordinate::Phi), E, options);
}

}  // namespace buckle::mechanics
