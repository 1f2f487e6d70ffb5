// The O(n) bordered solver of ContactProblem (contact.h): locked joints eliminated, held
// coordinates and contact gaps bordered on the reduced chain structure, and each self contact's
// rank-2 term R E Rᵀ (self_contact.h, selfCouplingColumns) as two more border columns z = E Rᵀx:
// [[H, R], [Rᵀ, −E]] has the Schur complement H + R E Rᵀ and det(−E) = −1 a contact.
#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/contact.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;
using continuation::Factorization;
using continuation::VectorRef;

namespace {

/// out(t, ·) += sign · Σ_s h[max(s, t)] M(s, ·) over the source joints s (rows of M) and the
/// target joints t (rows of out), both ascending and disjoint: the coupling of locked and free
/// joints through −K_g (eq 27: an entry depends on max(i, j) only), in O((|S| + |T|)·k) as
/// h[t]·Σ_{s<t} M_s + Σ_{s>t} h[s]·M_s.
void addMaxCoupling(const Vector& h, const std::vector<int>& sources, continuation::ConstMatrixRef M,
                    const std::vector<int>& targets, double sign, continuation::MatrixRef out) {
  // fixed capacity: no heap allocation, also where the corrector's solves call this
  using Row = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, ChainStructure::kMaxBorder>;
  const Eigen::Index k = M.cols();
  if (k > ChainStructure::kMaxBorder) throw std::invalid_argument("addMaxCoupling: more columns than kMaxBorder");
  Row below = Row::Zero(k), weightedAbove = Row::Zero(k);
  for (size_t s = 0; s < sources.size(); ++s) weightedAbove += h[sources[s]] * M.row(Eigen::Index(s));
  size_t s = 0;
  for (size_t t = 0; t < targets.size(); ++t) {
    for (; s < sources.size() && sources[s] < targets[t]; ++s) {
      below += M.row(Eigen::Index(s));
      weightedAbove -= h[sources[s]] * M.row(Eigen::Index(s));
    }
    out.row(Eigen::Index(t)) += sign * (h[targets[t]] * below + weightedAbove);
  }
}

/// A(c) = [[F_u, F_λ], [cᵀ]] of ContactProblem in O(n): the locked rows give x_L = −b_L; the rest
/// is the reduced chain's bordered system (chain_solver.h's borders on the free joints: the held
/// rows, the gap rows −∇g, then F_λ | c, then the self contacts' z) with the known x_L moved to the
/// right-hand side (z's rows R_Fᵀx_F − E z = −R_Lᵀx_L). det A = (−1)^(|L| + s) det(reduced)
/// (expansion along the locked rows; det(−E)).
class ReducedChainSolver final : public continuation::BorderedSolver {
 public:
  static constexpr int kDenseFallback = 400;

  ReducedChainSolver(const ContactProblem& problem, continuation::ProblemWorkspace& problemWorkspace)
      : problem_(problem),
        problemWorkspace_(problemWorkspace),
        n_(problem.base().segments()),
        m_(problem.base().heldCount()),
        w_(problem.contacts().gapCount()),
        z_(2 * problem.contacts().selfCount()),
        p_(m_ + w_ + 1 + z_),
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
    std::sort(lockedIndex_.begin(), lockedIndex_.end());  // addMaxCoupling's order
    denseAllowed_ = n_ + m_ + w_ <= kDenseFallback || p_ > ChainStructure::kMaxBorder;
    selfSign_ = problem.contacts().selfCount() % 2 == 0 ? 1 : -1;
  }

  Factorization factor(ConstVectorRef u, double lambda, ConstVectorRef c) override {
    sign_ = 0;
    logAbs_ = -std::numeric_limits<double>::infinity();
    usingDense_ = false;
    general_ = false;
    if (!c.allFinite() || !problem_.assembleFull(problemWorkspace_, u, lambda, full_, J_))
      return Factorization::Refused;
    if (p_ > ChainStructure::kMaxBorder) {  // more borders than the chain structure holds
      usingDense_ = true;
      const Factorization f = dense()->factor(u, lambda, c);
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
    const int nf = int(free_.size()), last = m_ + w_;
    const Matrix& R = ContactProblem::selfColumns(problemWorkspace_);
    const Vector& E = ContactProblem::selfSigns(problemWorkspace_);
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
      for (int k = 0; k < z_; ++k) V_(a, last + 1 + k) = W_(a, last + 1 + k) = R(i, k);
    }
    for (int k = 0; k < m_; ++k) D_(k, last) = dir[held_[size_t(k)]];
    for (int k = 0; k < last; ++k) D_(last, k) = c[n_ + k];
    D_(last, last) = c[n_ + last];
    for (int k = 0; k < z_; ++k) D_(last + 1 + k, last + 1 + k) = -E[k];
    const int lockedSign = (lockedIndex_.size() % 2 == 0 ? 1 : -1) * selfSign_;
    if (factorBordered(ws_, V_, W_, D_)) {
      sign_ = lockedSign * ws_.borderedDetSign;
      logAbs_ = ws_.borderedLogAbsDet;
      return Factorization::Regular;
    }
    if (!dense()) return Factorization::Singular;
    usingDense_ = true;
    const Factorization f = dense_->factor(u, lambda, c);
    sign_ = dense_->determinantSign();
    logAbs_ = dense_->logAbsDeterminant();
    return f;
  }

  bool solve(ConstVectorRef b, VectorRef x) override {
    if (sign_ == 0) return false;
    if (usingDense_) return dense_->solve(b, x);
    if (general_) return solveGeneral(b, x);
    // x_L = −b_L, then the free rows, held rows and the border row with x_L moved right:
    // free a: H_aL x_L = −Σ_i h_max(a,i) x_i (a ≠ i).
    const int nf = int(free_.size()), q = m_ + w_ + 1;
    const Matrix& grad = grad_;
    const Matrix& R = ContactProblem::selfColumns(problemWorkspace_);
    for (int a = 0; a < nf; ++a) f_[a] = b[free_[size_t(a)]];
    g_.head(q) = b.segment(n_, q);
    g_.tail(z_).setZero();
    xL_.resize(Eigen::Index(lockedIndex_.size()), 1);
    for (size_t l = 0; l < lockedIndex_.size(); ++l) xL_(Eigen::Index(l), 0) = -b[lockedIndex_[l]];
    addMaxCoupling(full_.h, lockedIndex_, xL_, free_, 1.0, f_);
    for (int i : lockedIndex_) {
      const double xi = -b[i];
      x[i] = xi;
      for (int k = 0; k < m_; ++k) g_[k] += J_(held_[size_t(k)], i) * xi;
      for (int k = 0; k < w_; ++k) g_[m_ + k] += grad(i, k) * xi;
      g_[q - 1] -= c_[i] * xi;
      for (int k = 0; k < z_; ++k) g_[q + k] -= R(i, k) * xi;
    }
    if (!solveFactoredBordered(ws_, V_, W_, D_, f_, g_, x_, y_)) return false;
    for (int a = 0; a < nf; ++a) x[free_[size_t(a)]] = x_[a];
    x.tail(q) = y_.head(q);
    return true;
  }

  int determinantSign() const override { return sign_; }
  double logAbsDeterminant() const override { return logAbs_; }

  int maxGeneralBorder() const override { return std::max(0, ChainStructure::kMaxBorder - m_ - w_ - z_); }

  /// G = [[F_u, B], [Cᵀ, D]] (or F_uᵀ) by the same reduction (derivation in docs/mechanics.md,
  /// "Contact at the joints", Structure): the locked rows give x_L, the reduced chain's borders
  /// are the held and gap columns, B | C with the locked joints' coupling folded in, and z.
  Factorization factorGeneral(ConstVectorRef u, double lambda, continuation::ConstMatrixRef B,
                              continuation::ConstMatrixRef C, continuation::ConstMatrixRef D, bool transposed) override {
    sign_ = 0;
    logAbs_ = -std::numeric_limits<double>::infinity();
    usingDense_ = false;
    general_ = true;
    transposed_ = transposed;
    const int k = int(B.cols()), N = n_ + m_ + w_, o = m_ + w_, p = o + k + z_;
    if (k < 1 || B.rows() != N || C.rows() != N || C.cols() != k || D.rows() != k || D.cols() != k ||
        !B.allFinite() || !C.allFinite() || !D.allFinite())
      return Factorization::Refused;
    if (p > ChainStructure::kMaxBorder) return denseGeneral(u, lambda, B, C, D, transposed);
    if (!problem_.assembleFull(problemWorkspace_, u, lambda, full_, J_)) return Factorization::Refused;
    reduceToFreeJoints(full_, free_, kf_, hf_, ws_);
    grad_ = ContactProblem::wallGradients(problemWorkspace_);
    const Matrix& R = ContactProblem::selfColumns(problemWorkspace_);
    const Vector& E = ContactProblem::selfSigns(problemWorkspace_);
    const int nf = int(free_.size()), nl = int(lockedIndex_.size());
    BL_.resize(nl, k);
    CL_.resize(nl, k);
    RL_.resize(nl, z_);
    for (int l = 0; l < nl; ++l) {
      const int i = lockedIndex_[size_t(l)];
      BL_.row(l) = B.row(i), CL_.row(l) = C.row(i), RL_.row(l) = R.row(i);
    }
    Vg_.resize(nf, p);
    Wg_.resize(nf, p);
    Dg_ = Matrix::Zero(p, p);
    for (int a = 0; a < nf; ++a) {
      const int i = free_[size_t(a)];
      for (int h = 0; h < m_; ++h) Vg_(a, h) = Wg_(a, h) = -J_(held_[size_t(h)], i);
      for (int v = 0; v < w_; ++v) Vg_(a, m_ + v) = Wg_(a, m_ + v) = -grad_(i, v);
      Vg_.row(a).segment(o, k) = B.row(i);
      Wg_.row(a).segment(o, k) = C.row(i);
      Vg_.row(a).tail(z_) = Wg_.row(a).tail(z_) = R.row(i);
    }
    // P_L = [−J_h,Lᵀ | −∇x_v,L]: the locked joints' entries of the held and wall columns
    PL_.resize(nl, o);
    for (int l = 0; l < nl; ++l) {
      const int i = lockedIndex_[size_t(l)];
      for (int h = 0; h < m_; ++h) PL_(l, h) = -J_(held_[size_t(h)], i);
      for (int v = 0; v < w_; ++v) PL_(l, m_ + v) = -grad_(i, v);
    }
    Dg_.block(0, o, o, k) = B.middleRows(n_, o);
    Dg_.block(o, 0, k, o) = C.middleRows(n_, o).transpose();
    Dg_.block(o, o, k, k) = D + CL_.transpose() * BL_;
    for (int j = 0; j < z_; ++j) Dg_(o + k + j, o + k + j) = -E[j];
    if (!transposed) {
      // x_L = B_L y − b_L into the free rows (H_FL B_L), the held and gap rows (P_Lᵀ B_L), z's rows
      addMaxCoupling(full_.h, lockedIndex_, BL_, free_, -1.0, Vg_.middleCols(o, k));
      Dg_.block(0, o, o, k) += PL_.transpose() * BL_;
      Dg_.block(o + k, o, z_, k) = RL_.transpose() * BL_;
    } else {
      // x_L = H_LF x_F + P_L z_g + R_L z + B_L y − b_L into the border rows
      addMaxCoupling(full_.h, lockedIndex_, CL_, free_, -1.0, Wg_.middleCols(o, k));
      Dg_.block(o, 0, k, o) += CL_.transpose() * PL_;
      Dg_.block(o, o + k, k, z_) = CL_.transpose() * RL_;
    }
    const int lockedSign = (nl % 2 == 0 ? 1 : -1) * selfSign_;
    if (factorBordered(ws_, Vg_, Wg_, Dg_)) {
      sign_ = lockedSign * ws_.borderedDetSign;
      logAbs_ = ws_.borderedLogAbsDet;
      return Factorization::Regular;
    }
    return dense() ? denseGeneral(u, lambda, B, C, D, transposed) : Factorization::Singular;
  }

 private:
  // The dense fallback, made where a factorization first needs it: most solvers never do, and
  // an (n + 1)² LU made up front for each costs more than their solves on a short branch.
  continuation::DenseBorderedSolver* dense() {
    if (!dense_ && denseAllowed_)
      dense_ = std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(problem_, problemWorkspace_));
    return dense_.get();
  }

  Factorization denseGeneral(ConstVectorRef u, double lambda, continuation::ConstMatrixRef B,
                             continuation::ConstMatrixRef C, continuation::ConstMatrixRef D, bool transposed) {
    if (!dense_) return Factorization::Refused;
    usingDense_ = true;
    const Factorization f = dense_->factorGeneral(u, lambda, B, C, D, transposed);
    sign_ = dense_->determinantSign();
    return f;
  }

  bool solveGeneral(ConstVectorRef b, VectorRef x) {
    const int nf = int(free_.size()), nl = int(lockedIndex_.size()), o = m_ + w_, k = int(Vg_.cols()) - o - z_;
    fg_.resize(nf);
    for (int a = 0; a < nf; ++a) fg_[a] = b[free_[size_t(a)]];
    xL_.resize(nl, 1);
    for (int l = 0; l < nl; ++l) xL_(l, 0) = b[lockedIndex_[size_t(l)]];  // b_L
    gg_.resize(o + k + z_);
    gg_.head(o + k) = b.segment(n_, o + k);
    gg_.segment(o, k) += CL_.transpose() * xL_.col(0);
    gg_.tail(z_).setZero();
    if (!transposed_) {
      addMaxCoupling(full_.h, lockedIndex_, xL_, free_, -1.0, fg_);
      gg_.head(o) += PL_.transpose() * xL_.col(0);
      gg_.tail(z_) += RL_.transpose() * xL_.col(0);
    }
    xg_.resize(nf);
    yg_.resize(o + k + z_);
    if (!solveFactoredBordered(ws_, Vg_, Wg_, Dg_, fg_, gg_, xg_, yg_)) return false;
    for (int a = 0; a < nf; ++a) x[free_[size_t(a)]] = xg_[a];
    x.segment(n_, o) = yg_.head(o);
    x.tail(k) = yg_.segment(o, k);
    // the locked unknowns: B_L y − b_L (+ H_LF x_F + P_L z_g + R_L z for the transpose)
    xLocked_.noalias() = BL_ * yg_.segment(o, k);
    xLocked_ -= xL_;
    if (transposed_) {
      xLocked_.noalias() += PL_ * yg_.head(o);
      xLocked_.noalias() += RL_ * yg_.tail(z_);
      addMaxCoupling(full_.h, free_, xg_, lockedIndex_, -1.0, xLocked_);
    }
    for (int l = 0; l < nl; ++l) x[lockedIndex_[size_t(l)]] = xLocked_(l, 0);
    return x.allFinite();
  }

  const ContactProblem& problem_;
  continuation::ProblemWorkspace& problemWorkspace_;
  int n_, m_, w_, z_, p_;  // joints, held rows, gap rows, the self contacts' coupling columns, borders
  int selfSign_ = 1;       // det(−E): (−1)^s
  std::vector<int> free_, held_, loaded_, lockedIndex_;
  ChainStructure full_, ws_;
  Matrix J_;
  Vector kf_, hf_;
  Matrix V_, W_, D_;
  Matrix grad_;  // ∇x_v of the wall vertices at the factored point (n×w)
  Vector c_, f_, g_, x_, y_;
  std::unique_ptr<continuation::DenseBorderedSolver> dense_;
  bool denseAllowed_ = false;
  // factorGeneral(): the reduced borders, the locked rows of B and C, P_L, and solve scratch
  Matrix Vg_, Wg_, Dg_, BL_, CL_, PL_, RL_, xL_, xLocked_;
  Vector fg_, gg_, xg_, yg_;
  bool general_ = false, transposed_ = false;
  bool usingDense_ = false;
  int sign_ = 0;
  double logAbs_ = 0.0;
};

}  // namespace

std::unique_ptr<continuation::BorderedSolver> ContactProblem::makeStructuredSolver(ProblemWorkspace& ws) const {
  // every joint locked: the dense route
  if (free_.empty())
    return std::make_unique<continuation::DenseBorderedSolver>(continuation::BoundProblem(*this, ws));
  return std::make_unique<ReducedChainSolver>(*this, ws);
}

}  // namespace buckle::mechanics
