// The O(n) bordered solver of ContactProblem (contact.h): locked joints eliminated, held
// coordinates and wall vertices bordered on the reduced chain structure.
#include <algorithm>
#include <limits>
#include <memory>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/contact.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::VectorRef;

namespace {

/// A(c) = [[F_u, F_λ], [cᵀ]] of ContactProblem in O(n): the locked rows give x_L = −b_L; the rest
/// is the reduced chain's bordered system (chain_solver.h's borders on the free joints: the held
/// rows, the wall rows −∇x_v, then F_λ | c) with the known x_L moved to the right-hand side.
/// det A = (−1)^|L| det(reduced) (expansion along the locked rows).
class ReducedChainSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;

  ReducedChainSolver(const ContactProblem& problem, continuation::ProblemWorkspace& problemWorkspace)
      : problem_(problem),
        problemWorkspace_(problemWorkspace),
        n_(problem.base().segments()),
        m_(problem.base().heldCount()),
        w_(problem.contacts().wallCount()),
        p_(m_ + w_ + 1),
        free_(problem.freeJoints()),
        held_(problem.base().endCondition().heldIndices()),
        loaded_(problem.base().endCondition().loadedIndices()),
        full_(problem.base().segments()),
        ws_(int(problem.freeJoints().size())),
        J_(3, problem.base().segments()),
        kf_(problem.freeJoints().size()),
        hf_(problem.freeJoints().size()),
        V_(Matrix::Zero(Eigen::Index(problem.freeJoints().size()), p_)),
        W_(Matrix::Zero(Eigen::Index(problem.freeJoints().size()), p_)),
        D_(Matrix::Zero(p_, p_)),
        c_(Vector::Zero(n_ + p_)),
        f_(problem.freeJoints().size()),
        g_(p_),
        x_(problem.freeJoints().size()),
        y_(p_) {
    for (const LockedJoint& l : problem.contacts().joints()) lockedIndex_.push_back(l.joint);
    if (n_ + m_ + w_ <= kDenseFallback || p_ > ChainStructure::kMaxBorder)
      dense_ =
          std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(problem, problemWorkspace));
  }

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override {
    sign_ = 0;
    logAbs_ = -std::numeric_limits<double>::infinity();
    usingDense_ = false;
    if (!c.allFinite() || !problem_.assembleFull(problemWorkspace_, u, lambda, full_, J_))
      return Factorization::Refused;
    if (p_ > ChainStructure::kMaxBorder) {  // more borders than the chain structure holds
      usingDense_ = true;
      const Factorization f = dense_->factor(u, lambda, c);
      sign_ = dense_->determinantSign();
      logAbs_ = dense_->logAbsDeterminant();
      return f;
    }
    c_ = c;
    reduceToFreeJoints(full_, free_, kf_, hf_, ws_);
    const Eigen::Vector3d& dir = problem_.base().direction();
    grad_ =
        ContactProblem::wallGradients(problemWorkspace_);  // a copy: the problem's is rewritten by the next evaluation
    const Matrix& grad = grad_;
    const int nf = int(free_.size()), last = p_ - 1;
    D_.setZero();
    for (int a = 0; a < nf; ++a) {
      const int i = free_[size_t(a)];
      double fl = 0.0;
      for (int cc : loaded_) fl -= J_(cc, i) * dir[cc];
      if (problem_.base().hasBodyLoads())
        fl -= EquilibriumProblem::bodyRateTorques(
            *workspaceAs<ContactProblem::Workspace>(problemWorkspace_).base)[i];  // eq (B2)
      V_(a, last) = fl;
      W_(a, last) = c[i];
      for (int k = 0; k < m_; ++k) V_(a, k) = W_(a, k) = -J_(held_[size_t(k)], i);
      for (int k = 0; k < w_; ++k) V_(a, m_ + k) = W_(a, m_ + k) = -grad(i, k);  // wall_contact.h
    }
    for (int k = 0; k < m_; ++k) D_(k, last) = dir[held_[size_t(k)]];
    for (int k = 0; k < last; ++k) D_(last, k) = c[n_ + k];
    D_(last, last) = c[n_ + last];
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
    const Matrix& grad = grad_;
    for (int a = 0; a < nf; ++a) f_[a] = b[free_[size_t(a)]];
    g_ = b.segment(n_, p_);
    for (int i : lockedIndex_) {
      const double xi = -b[i];
      x[i] = xi;
      for (int a = 0; a < nf; ++a) f_[a] += full_.h[std::max(free_[size_t(a)], i)] * xi;
      for (int k = 0; k < m_; ++k) g_[k] += J_(held_[size_t(k)], i) * xi;
      for (int k = 0; k < w_; ++k) g_[m_ + k] += grad(i, k) * xi;
      g_[p_ - 1] -= c_[i] * xi;
    }
    if (!solveFactoredBordered(ws_, V_, W_, D_, f_, g_, x_, y_)) return false;
    for (int a = 0; a < nf; ++a) x[free_[size_t(a)]] = x_[a];
    x.tail(p_) = y_;
    return true;
  }

  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }

 private:
  const ContactProblem& problem_;
  continuation::ProblemWorkspace& problemWorkspace_;
  int n_, m_, w_, p_;
  std::vector<int> free_, held_, loaded_, lockedIndex_;
  ChainStructure full_, ws_;
  Matrix J_;
  Vector kf_, hf_;
  Matrix V_, W_, D_;
  Matrix grad_;  // ∇x_v of the wall vertices at the factored point (n×w)
  Vector c_, f_, g_, x_, y_;
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace

std::unique_ptr<continuation::BorderedSolver> ContactProblem::makeStructuredSolver(ProblemWorkspace& ws) const {
  if (free_.empty()) return std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(*this, ws));
  return std::make_unique<ReducedChainSolver>(*this, ws);
}

}  // namespace buckle::mechanics
