#include "buckle/mechanics/contact.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

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

void ContactSet::touch(const WallVertex& vertex) {
  auto it = std::lower_bound(wall_.begin(), wall_.end(), vertex);
  if (it == wall_.end() || *it != vertex) wall_.insert(it, vertex);
}

void ContactSet::leave(const WallVertex& vertex) { wall_.erase(std::remove(wall_.begin(), wall_.end(), vertex), wall_.end()); }

bool ContactSet::touching(const WallVertex& vertex) const {
  return std::binary_search(wall_.begin(), wall_.end(), vertex);
}

std::string ContactSet::wallLabel() const {
  std::string s;
  for (const WallVertex& v : wall_) s += (s.empty() ? "" : " ") + v.label();
  return s;
}

void ContactSet::hold(const SelfContact& c) {
  auto it = std::lower_bound(self_.begin(), self_.end(), c);
  if (it == self_.end() || *it != c) self_.insert(it, c);
}

void ContactSet::separate(const SelfContact& c) { self_.erase(std::remove(self_.begin(), self_.end(), c), self_.end()); }

bool ContactSet::holding(const SelfContact& c) const { return std::binary_search(self_.begin(), self_.end(), c); }

std::string ContactSet::selfLabel() const {
  std::string s;
  for (const SelfContact& c : self_) s += (s.empty() ? "" : "; ") + c.label();
  return s;
}

void ContactSet::check(int segments) const {
  for (const WallVertex& v : wall_) checkWallVertex(v, segments);
  for (const SelfContact& c : self_) checkSelfContact(c, segments);
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

}  // namespace

void reduceToFreeJoints(const ChainStructure& full, const std::vector<int>& free, VectorRef kf, VectorRef hf,
                        ChainStructure& reduced) {
  for (size_t a = 0; a < free.size(); ++a) {
    kf[Eigen::Index(a)] = full.kappa[free[a]];
    hf[Eigen::Index(a)] = full.h[free[a]];
  }
  assemble(kf, hf, reduced);
}

// ---- ContactProblem ---------------------------------------------------------------------------

ContactProblem::ContactProblem(const EquilibriumProblem& base, ContactSet locked, double maxCompression)
    : base_(base),
      locked_((locked.check(base.segments()), std::move(locked))),
      maxCompression_(maxCompression),
      free_(freeJointsOf(locked_, base.segments())),
      held_(base.endCondition().heldIndices()) {
  for (const SelfContact& c : locked_.self()) selfAtCorner_.push_back(heldAtCorner(base.chain(), c, locked_.self()));
  if (!(maxCompression > 0.0))
    throw std::invalid_argument("contact: the bound of the contact torque must be positive, got " +
                                std::to_string(maxCompression));
}

ContactProblem::Workspace::Workspace(const ContactProblem& problem)
    : base(problem.base_.createWorkspace()),
      full(problem.base_.segments()),
      reduced(std::max(1, int(problem.free_.size()))),
      J(3, problem.base_.segments()),
      Jf(3, Eigen::Index(problem.free_.size())),
      heldRows(Eigen::Index(problem.held_.size() + size_t(problem.locked_.gapCount())),
               Eigen::Index(problem.free_.size())),
      kf(problem.free_.size()),
      hf(problem.free_.size()),
      residual(problem.base_.dimension()),
      wallGrad(problem.base_.segments(), problem.locked_.gapCount()),
      wallGen(problem.base_.segments(), problem.locked_.gapCount()),
      wallX(problem.locked_.gapCount()),
      selfCoupling(problem.base_.segments(), problem.locked_.selfCount()),
      selfWeights(problem.base_.segments(), problem.locked_.selfCount()),
      selfColumns(problem.base_.segments(), 2 * problem.locked_.selfCount()),
      selfColumnsFree(Eigen::Index(problem.free_.size()), 2 * problem.locked_.selfCount()),
      selfSigns(2 * problem.locked_.selfCount()),
      selfAlong(problem.locked_.selfCount()),
      selfEdgeLength(problem.locked_.selfCount()),
      slopeFree(problem.free_.size()),
      slopeHv(problem.free_.size()),
      slopeFull(Vector::Zero(problem.base_.segments())),
      guess(ChainStructure::kMaxBorder) {
  reduced.typicalScale = problem.base_.stiffnessUnit() * problem.base_.lengthUnit() * problem.base_.lengthUnit();
  full.typicalScale = reduced.typicalScale;
}

std::unique_ptr<ProblemWorkspace> ContactProblem::createWorkspace() const { return std::make_unique<Workspace>(*this); }

bool ContactProblem::wallKinematics(ProblemWorkspace& ws, ConstVectorRef q) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int w = locked_.wallCount();
  if (locked_.gapCount() == 0) return true;
  if (!q.allFinite()) return false;
  const Eigen::Matrix2Xd P = jointPositions(base_.chain(), q);
  for (int k = 0; k < w; ++k) {
    const WallVertex& v = locked_.wall()[size_t(k)];
    const Eigen::Vector2d x = wallVertexPoint(base_.chain(), q, P, v);
    d.wallX[k] = x.x();
    wallVertexDerivatives(P, x, v, d.wallGrad.col(k), d.wallGen.col(k));
  }
  for (int k = 0; k < locked_.selfCount(); ++k) {
    const SelfContact& c = locked_.self()[size_t(k)];
    const SelfContactGap g = selfContactGap(base_.chain(), q, P, c);
    d.wallX[w + k] = g.gap;
    d.selfAlong[k] = g.along;
    d.selfEdgeLength[k] = g.edgeLength;
    selfContactDerivatives(P, c, g, d.wallGrad.col(w + k), d.wallGen.col(w + k), d.selfCoupling.col(k),
                           d.selfWeights.col(k));
  }
  return true;
}

namespace {

// −μ ∂²g of every bordered contact added to the n×n block H (self_contact.h: the generator form,
// and the self contacts' rank-2 term).
void addContactHessians(const ContactSet& contacts, const ContactProblem::Workspace& d, ConstVectorRef mu,
                        MatrixRef H) {
  const int w = contacts.wallCount(), n = int(H.rows());
  for (int k = 0; k < w; ++k) {  // −μ ∂²x_v = μ g_max(j,l) (wall_contact.h)
    const int last = contacts.wall()[size_t(k)].lastJoint();
    for (int j = 0; j <= last; ++j)
      for (int l = 0; l <= last; ++l) H(j, l) += mu[k] * d.wallGen(std::max(j, l), k);
  }
  for (int k = 0; k < contacts.selfCount(); ++k) {
    const auto c = d.selfCoupling.col(k), wt = d.selfWeights.col(k);
    for (int j = 0; j < n; ++j)
      for (int l = 0; l < n; ++l)
        H(j, l) += mu[w + k] * (d.wallGen(std::max(j, l), w + k) - c[j] * wt[l] - wt[j] * c[l]);
  }
}

}  // namespace

bool ContactProblem::baseRowsWithWall(ProblemWorkspace& ws, ConstVectorRef u, double lambda, VectorRef F) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), n = base_.segments(), w = locked_.gapCount();
  if (!base_.residual(*d.base, u.head(N), lambda, F)) return false;
  if (w == 0) return true;
  if (!wallKinematics(ws, u.head(n))) return false;
  F.head(n).noalias() -= d.wallGrad * u.segment(N, w);  // −Σ μ ∇g (wall_contact.h, self_contact.h)
  return true;
}

Vector ContactProblem::wallForces(ProblemWorkspace& ws, ConstVectorRef u, double lambda) const {
  return contactForces(ws, u, lambda).head(locked_.wallCount());
}

Vector ContactProblem::selfForces(ProblemWorkspace& ws, ConstVectorRef u, double lambda) const {
  return contactForces(ws, u, lambda).tail(locked_.selfCount());
}

Vector ContactProblem::contactForces(ProblemWorkspace& ws, ConstVectorRef u, double lambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), w = locked_.gapCount();
  Vector mu = Vector::Constant(w, std::numeric_limits<double>::quiet_NaN());
  if (w == 0 || !base_.residual(*d.base, u.head(N), lambda, d.residual) ||
      !wallKinematics(ws, u.head(base_.segments())))
    return mu;
  // the free joints' rows: R_F = G_Fᵀ μ (the locked rows carry the joints' own contact torques)
  Matrix A(Eigen::Index(free_.size()), w);
  Vector b(Eigen::Index(free_.size()));
  for (size_t a = 0; a < free_.size(); ++a) {
    A.row(Eigen::Index(a)) = d.wallGrad.row(free_[a]);
    b[Eigen::Index(a)] = d.residual[free_[a]];
  }
  if (free_.empty()) return mu;
  mu = A.colPivHouseholderQr().solve(b);
  return mu;
}

Vector ContactProblem::withWallForces(ProblemWorkspace& ws, ConstVectorRef u, double lambda) const {
  const int N = base_.dimension();
  Vector full(dimension());
  full.head(N) = u.head(N);
  full.tail(locked_.gapCount()) = contactForces(ws, u, lambda);
  return full;
}

double ContactProblem::contactTorque(ProblemWorkspace& ws, ConstVectorRef u, double lambda, int joint) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const bool withForces = u.size() == dimension();
  const Vector full = withForces ? Vector(u) : withWallForces(ws, u, lambda);
  if (!baseRowsWithWall(ws, full, lambda, d.residual)) return std::numeric_limits<double>::quiet_NaN();
  return d.residual[joint];
}

double ContactProblem::compression(ProblemWorkspace& ws, ConstVectorRef u, double lambda, int joint) const {
  return -double(int(locked_.side(joint))) * contactTorque(ws, u, lambda, joint);
}

bool ContactProblem::residual(ProblemWorkspace& ws, ConstVectorRef u, double lambda, VectorRef F) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension();
  if (!baseRowsWithWall(ws, u, lambda, F.head(N))) return false;
  F.tail(locked_.gapCount()) = -d.wallX.head(locked_.gapCount());  // −x_v = 0, −g = 0
  for (const LockedJoint& l : locked_.joints()) F[l.joint] = limitAngle(base_.chain(), l.joint, l.side) - u[l.joint];
  return true;
}

bool ContactProblem::jacobian(ProblemWorkspace& ws, ConstVectorRef u, double lambda, MatrixRef Fu,
                              VectorRef Flambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), n = base_.segments(), w = locked_.gapCount();
  if (!base_.jacobian(*d.base, u.head(N), lambda, Fu.topLeftCorner(N, N), Flambda.head(N))) return false;
  if (w > 0) {
    if (!wallKinematics(ws, u.head(n))) return false;
    Fu.rightCols(w).setZero();
    Fu.bottomRows(w).setZero();
    Flambda.tail(w).setZero();
    addContactHessians(locked_, d, u.segment(N, w), Fu.topLeftCorner(n, n));
    Fu.block(0, N, n, w) = -d.wallGrad;
    Fu.block(N, 0, w, n) = -d.wallGrad.transpose();
  }
  for (const LockedJoint& l : locked_.joints()) {
    Fu.row(l.joint).setZero();
    Fu(l.joint, l.joint) = -1.0;
    Flambda[l.joint] = 0.0;
  }
  return true;
}

bool ContactProblem::jacobianDirectionalDerivative(ProblemWorkspace& ws, ConstVectorRef u, double lambda,
                                                   ConstVectorRef du, double dlambda, MatrixRef dFu,
                                                   VectorRef dFlambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  // With wall vertices or self contacts, the central differences of jacobian() (the locked rows
  // stay linear).
  if (locked_.gapCount() > 0) return Problem::jacobianDirectionalDerivative(ws, u, lambda, du, dlambda, dFu, dFlambda);
  if (!base_.jacobianDirectionalDerivative(*d.base, u, lambda, du, dlambda, dFu, dFlambda)) return false;
  for (const LockedJoint& l : locked_.joints()) {  // the locked rows are linear
    dFu.row(l.joint).setZero();
    dFlambda[l.joint] = 0.0;
  }
  return true;
}

bool ContactProblem::stabilityOperator(ProblemWorkspace& ws, ConstVectorRef u, double lambda, Matrix& H,
                                       Matrix& C) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  Matrix Ch;
  const int N = base_.dimension(), n = base_.segments(), w = locked_.gapCount();
  if (!base_.stabilityOperator(*d.base, u.head(N), lambda, H, Ch) || !wallKinematics(ws, u.head(n))) return false;
  addContactHessians(locked_, d, u.segment(N, w), H);
  C = Matrix::Zero(Ch.rows() + locked_.count() + w, n);
  C.topRows(Ch.rows()) = Ch;
  for (int k = 0; k < locked_.count(); ++k) C(Ch.rows() + k, locked_.joints()[size_t(k)].joint) = 1.0;
  C.bottomRows(w) = d.wallGrad.transpose();
  return true;
}

bool ContactProblem::assembleFull(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ChainStructure& full,
                                  MatrixRef J) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), n = base_.segments(), w = locked_.wallCount();
  if (!base_.assembleStructure(*d.base, u.head(N), lambda, full, J)) return false;
  if (locked_.gapCount() == 0) return true;
  if (!wallKinematics(ws, u.head(n))) return false;
  for (int k = 0; k < w; ++k)  // the generator h gains −μ_v g_v (wall_contact.h)
    for (int m = 0; m <= locked_.wall()[size_t(k)].lastJoint(); ++m) full.h[m] -= u[N + k] * d.wallGen(m, k);
  for (int k = 0; k < locked_.selfCount(); ++k) {  // and −μ γ, the rank-2 rest as R E Rᵀ (self_contact.h)
    const double mu = u[N + w + k];
    for (int m = 0; m < n; ++m) full.h[m] -= mu * d.wallGen(m, w + k);
    const double s = selfCouplingColumns(d.selfCoupling.col(k), d.selfWeights.col(k), mu, d.selfColumns.middleCols(2 * k, 2));
    d.selfSigns[2 * k] = -s;
    d.selfSigns[2 * k + 1] = s;
  }
  assemble(full.kappa, full.h, full);
  return true;
}

bool ContactProblem::assembleReduced(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ChainStructure& structure,
                                     MatrixRef Jf) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (free_.empty() || !assembleFull(ws, u, lambda, d.full, d.J)) return false;
  reduceToFreeJoints(d.full, free_, d.kf, d.hf, structure);
  for (size_t a = 0; a < free_.size(); ++a) Jf.col(Eigen::Index(a)) = d.J.col(free_[a]);
  return true;
}

continuation::ProblemScales ContactProblem::scales() const {
  continuation::ProblemScales s = base_.scales();
  for (const LockedJoint& l : locked_.joints()) s.residuals[l.joint] = 1.0;  // q̄ − q: an angle
  const int N = base_.dimension(), w = locked_.gapCount();
  s.unknowns.conservativeResize(N + w);
  s.residuals.conservativeResize(N + w);
  s.unknowns.tail(w).setConstant(base_.stiffnessUnit() * base_.lengthUnit());  // μ: a force k̄b̄
  s.residuals.tail(w).setConstant(base_.lengthUnit());                          // −x_v, −g: a length b̄
  return s;
}

// Boundaries: the joints' 2n (a locked joint's own limit is its contact release), the base
// problem's path range (EquilibriumOptions::heldRange), the locked joints' torque bounds, the
// wall for the vertices not on it (when the base traces it), the wall vertices' forces.
int ContactProblem::torqueBoundBegin() const { return 2 * base_.segments() + base_.rangeBoundaryCount(); }
int ContactProblem::wallClearanceBoundary() const {
  return base_.wallIsBoundary() ? torqueBoundBegin() + (std::isfinite(maxCompression_) ? locked_.count() : 0) : -1;
}
int ContactProblem::wallReleaseBoundary(int k) const {
  return torqueBoundBegin() + (std::isfinite(maxCompression_) ? locked_.count() : 0) + (base_.wallIsBoundary() ? 1 : 0) +
         k;
}
int ContactProblem::selfClearanceBoundary() const {
  return base_.selfContactIsBoundary() ? wallReleaseBoundary(locked_.wallCount()) : -1;
}
int ContactProblem::selfReleaseBoundary(int k) const {
  return wallReleaseBoundary(locked_.wallCount()) + (base_.selfContactIsBoundary() ? 1 : 0) + k;
}
int ContactProblem::selfEdgeBoundary(int k) const { return selfReleaseBoundary(locked_.selfCount()) + 2 * k; }
int ContactProblem::boundaryCount() const { return selfEdgeBoundary(locked_.selfCount()); }

namespace {

/// Boundary k of `p` (ContactProblem's class comment) with the compression of a locked joint and
/// the force of wall vertex r from the caller: boundary() forms each anew, boundaries() once a point.
template <class Compression, class WallForce>
double boundaryValue(const ContactProblem& p, ContactProblem::Workspace& d, int k, ConstVectorRef u, double lambda,
                     double maxCompression, Compression&& compression, WallForce&& wallForce) {
  const EquilibriumProblem& base = p.base();
  const int n = base.segments(), N = base.dimension();
  if (k == p.wallClearanceBoundary()) return nearestWallVertex(base.chain(), u.head(n), p.contacts().wall()).distance;
  const int w = p.contacts().wallCount();
  if (k >= p.selfEdgeBoundary(0)) {  // t·|e| and (1 − t)·|e|: the vertex over its edge
    if (!p.wallKinematics(d, u.head(n))) return std::numeric_limits<double>::quiet_NaN();
    const int r = (k - p.selfEdgeBoundary(0)) / 2;
    if (p.selfHeldAtCorner(r)) return d.selfEdgeLength[r];
    const double t = (k - p.selfEdgeBoundary(0)) % 2 == 0 ? d.selfAlong[r] : 1.0 - d.selfAlong[r];
    return t * d.selfEdgeLength[r];
  }
  if (k >= p.selfReleaseBoundary(0)) return wallForce(w + k - p.selfReleaseBoundary(0));  // μ ≥ 0
  if (k == p.selfClearanceBoundary()) return selfClearanceApart(base.chain(), u.head(n), p.contacts().self());
  if (k >= p.wallReleaseBoundary(0)) return wallForce(k - p.wallReleaseBoundary(0));  // μ_v ≥ 0
  if (k >= p.torqueBoundBegin())
    return maxCompression - compression(p.contacts().joints()[size_t(k - p.torqueBoundBegin())].joint);
  if (k >= 2 * n) return base.boundary(*d.base, base.rangeBoundaryBegin() + k - 2 * n, u.head(N), lambda);
  const LockedJoint b = limitOfBoundary(k, n);
  if (p.contacts().locked(b.joint) && p.contacts().side(b.joint) == b.side) return compression(b.joint);
  return base.boundary(*d.base, k, u.head(N), lambda);
}

}  // namespace

double ContactProblem::boundary(ProblemWorkspace& ws, int k, ConstVectorRef u, double lambda) const {
  const int N = base_.dimension();
  return boundaryValue(
      *this, workspaceAs<Workspace>(ws), k, u, lambda, maxCompression_,
      [&](int joint) { return compression(ws, u, lambda, joint); },
      [&](int r) { return u.size() == dimension() ? u[N + r] : contactForces(ws, u, lambda)[r]; });
}

void ContactProblem::boundaries(ProblemWorkspace& ws, ConstVectorRef u, double lambda, VectorRef g) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension();
  const bool withForces = u.size() == dimension();
  // the rows whose locked entries are the contact torques (contactTorque's), and the wall
  // forces, each formed once for the point when first needed
  bool rowsFormed = false, rowsValid = false, forcesFormed = false;
  Vector forces;
  const auto compressionOf = [&](int joint) {
    if (!rowsFormed) {
      rowsFormed = true;
      if (withForces) d.unknowns = u;
      else d.unknowns = withWallForces(ws, u, lambda);
      rowsValid = baseRowsWithWall(ws, d.unknowns, lambda, d.residual);
    }
    const double torque = rowsValid ? d.residual[joint] : std::numeric_limits<double>::quiet_NaN();
    return -double(int(locked_.side(joint))) * torque;
  };
  const auto wallForceOf = [&](int r) {
    if (withForces) return u[N + r];
    if (!forcesFormed) forces = contactForces(ws, u, lambda), forcesFormed = true;
    return forces[r];
  };
  for (int k = 0; k < int(g.size()); ++k)
    g[k] = boundaryValue(*this, d, k, u, lambda, maxCompression_, compressionOf, wallForceOf);
}

std::string ContactProblem::boundaryName(int k) const {
  const int n = base_.segments();
  if (k == wallClearanceBoundary()) return EquilibriumProblem::wallBoundaryName();
  if (k >= selfEdgeBoundary(0)) return selfEdgeName(locked_.self()[size_t((k - selfEdgeBoundary(0)) / 2)]);
  if (k >= selfReleaseBoundary(0)) return selfReleaseName(locked_.self()[size_t(k - selfReleaseBoundary(0))]);
  if (k == selfClearanceBoundary()) return EquilibriumProblem::selfContactBoundaryName();
  if (k >= wallReleaseBoundary(0)) return wallReleaseName(locked_.wall()[size_t(k - wallReleaseBoundary(0))]);
  if (k >= torqueBoundBegin()) {
    std::ostringstream os;
    os << "joint " << locked_.joints()[size_t(k - torqueBoundBegin())].joint + 1 << " contact torque reached its bound "
       << maxCompression_ << " (the locked chain is pressed far beyond what its springs carry)";
    return os.str();
  }
  if (k >= 2 * n) return base_.boundaryName(base_.rangeBoundaryBegin() + k - 2 * n);
  const LockedJoint b = limitOfBoundary(k, base_.segments());
  if (locked_.locked(b.joint) && locked_.side(b.joint) == b.side)
    return "joint " + std::to_string(b.joint + 1) + " " + toString(b.side) + " contact released (contact torque -> 0)";
  return base_.boundaryName(k);
}

std::string selfReleaseName(const SelfContact& c) {
  return "vertex " + c.vertex.label() + " leaves edge " + c.edge.label() + " (self contact force -> 0)";
}

std::string selfEdgeName(const SelfContact& c) {
  return "vertex " + c.vertex.label() + " reaches an end of edge " + c.edge.label();
}

std::string wallReleaseName(const WallVertex& v) {
  return "vertex " + v.label() + " leaves the base wall (wall force -> 0)";
}

}  // namespace buckle::mechanics
