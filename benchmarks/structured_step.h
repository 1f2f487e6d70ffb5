// A pseudo-arclength continuation step done entirely with the O(n) chain structure, for the
// scaling benchmark (what a structured linear solver in the core would cost per step).
//
// Per step: tangent predictor; Newton on the Keller system
//     [[H, −J_hᵀ, F_λ,q], [−J_h, 0, F_λ,r], [t_qᵀ, t_rᵀ, t_λ]] δ = −[F; tᵀ(x − x̂)]
// by solveBordered() (H = U T Uᵀ, border p = m + 1); the new tangent from the same bordered
// matrix with the old tangent as last row; and the test functions: the inertia of H on ker J_h
// (two O(n) counts) and the fold test t_λ. Everything is O(n); nothing allocates per step.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>

#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::bench {

class StructuredStepper {
 public:
  explicit StructuredStepper(mechanics::EquilibriumProblem& problem)
      : p_(problem),
        n_(problem.segments()),
        m_(problem.heldCount()),
        N_(n_ + m_),
        ws_(n_),
        data_(problem.chain()),
        J_(3, n_),
        F_(N_),
        V_(n_, m_ + 1),
        W_(n_, m_ + 1),
        D_(m_ + 1, m_ + 1),
        Ch_(m_, n_),
        xq_(n_),
        yb_(m_ + 1),
        g_(m_ + 1),
        x_(N_ + 1),
        xhat_(N_ + 1),
        t_(N_ + 1),
        held_(problem.endCondition().heldIndices()),
        loaded_(problem.endCondition().loadedIndices()) {}

  /// Start on (u, λ) with tangent t (N+1, unit).
  void start(const Eigen::VectorXd& u, double lambda, const Eigen::VectorXd& t) {
    x_.head(N_) = u;
    x_[N_] = lambda;
    t_ = t;
  }

  const Eigen::VectorXd& x() const { return x_; }
  const Eigen::VectorXd& tangent() const { return t_; }
  const mechanics::Inertia& inertia() const { return inertia_; }
  int lastIterations() const { return iterations_; }

  /// One step of length ds; false if Newton failed (the state is then unchanged).
  bool step(double ds, double tol = 1e-10, int maxIt = 8) {
    xhat_ = x_ + ds * t_;
    Eigen::VectorXd& x = xq_store();
    x = xhat_;
    iterations_ = 0;
    bool ok = false;
    for (int it = 0; it < maxIt; ++it) {
      if (!p_.residual(x.head(N_), x[N_], F_)) return false;
      const double arc = t_.dot(x - xhat_);
      const double res = std::max(F_.lpNorm<Eigen::Infinity>(), std::abs(arc));
      if (res <= tol && it > 0) {
        ok = true;
        break;
      }
      if (!linearize(x, t_)) return false;
      // right-hand sides −F (top n), −F (held rows) and −arc
      for (int k = 0; k < m_; ++k) g_[k] = -F_[n_ + k];
      g_[m_] = -arc;
      fq_ = -F_.head(n_);
      if (!mechanics::solveBordered(ws_, V_, W_, D_, fq_, g_, xq_, yb_)) return false;
      x.head(n_) += xq_;
      x.segment(n_, m_) += yb_.head(m_);
      x[N_] += yb_[m_];
      ++iterations_;
    }
    if (!ok) return false;
    // New tangent: [[F_u, F_λ], [t_oldᵀ]] t = e_{N+1} at the converged point.
    if (!linearize(x, t_)) return false;
    fq_.setZero();
    g_.setZero();
    g_[m_] = 1.0;
    if (!mechanics::solveBordered(ws_, V_, W_, D_, fq_, g_, xq_, yb_)) return false;
    tnew_.resize(N_ + 1);
    tnew_.head(n_) = xq_;
    tnew_.segment(n_, m_) = yb_.head(m_);
    tnew_[N_] = yb_[m_];
    tnew_.normalize();
    t_ = tnew_;
    x_ = x;
    // Test functions: inertia on ker J_h (T already assembled at x) and the fold test t_λ.
    inertia_ = mechanics::constrainedInertia(ws_, Ch_);
    foldTest_ = t_[N_];
    return true;
  }

  double foldTest() const { return foldTest_; }

 private:
  Eigen::VectorXd& xq_store() {
    work_.resize(N_ + 1);
    return work_;
  }

  /// Assemble T, the borders V = [−J_hᵀ, F_λ,q], W = [−J_hᵀ, t_q], D = [[0, F_λ,r], [t_rᵀ, t_λ]].
  bool linearize(const Eigen::VectorXd& x, const Eigen::VectorXd& t) {
    const auto q = x.head(n_);
    mechanics::forwardKinematics(p_.chain(), q, data_);
    mechanics::endJacobian(data_, J_);
    mechanics::assemble(p_.chain(), data_, q, p_.wrench(x.head(N_), x[N_]), ws_);
    const Eigen::Vector3d dir = p_.direction();
    V_.col(m_).setZero();
    for (int c : loaded_) V_.col(m_) -= J_.row(c).transpose() * dir[c];
    D_.setZero();
    for (int k = 0; k < m_; ++k) {
      Ch_.row(k) = J_.row(held_[size_t(k)]);
      V_.col(k) = -J_.row(held_[size_t(k)]).transpose();
      W_.col(k) = V_.col(k);
      D_(k, m_) = dir[held_[size_t(k)]];
      D_(m_, k) = t[n_ + k];
    }
    W_.col(m_) = t.head(n_);
    D_(m_, m_) = t[N_];
    return true;
  }

  mechanics::EquilibriumProblem& p_;
  int n_, m_, N_;
  mechanics::ChainStructure ws_;
  mechanics::ChainData data_;
  Eigen::MatrixXd J_;
  Eigen::VectorXd F_;
  Eigen::MatrixXd V_, W_, D_, Ch_;
  Eigen::VectorXd xq_, yb_, g_, fq_, x_, xhat_, t_, tnew_, work_;
  std::vector<int> held_, loaded_;
  mechanics::Inertia inertia_;
  double foldTest_ = 0.0;
  int iterations_ = 0;
};

}  // namespace buckle::bench
