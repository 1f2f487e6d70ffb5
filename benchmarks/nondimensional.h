// An independent check of the core's own unit handling (benchmarks/hard_cases.cpp, "nondim"
// rows): the chain traced in nondimensional variables built from outside, by hand. The core
// itself does the same change of variables from EquilibriumProblem::scales()
// (continuation/scaled_problem.h); this view's scales() are the default ones, so the tracer
// does not scale again, and both paths must agree:
//   angles q as they are; reactions r̃ = r / F₀; λ̃ = λ / λ₀;
//   torque rows / (k₀ L₀²), held-position rows / L₀, held-angle rows as they are;
//   the stability operator H / (k₀ L₀²), its constraint rows like the held rows.
// Located values come back in physical units as λ = λ₀ λ̃, r = F₀ r̃. With a unit length L₀ and
// stiffness k₀ (force per length): F₀ = k₀ L₀, torque k₀ L₀².
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::bench {

/// A system of units relative to the paper's (lengths ×length, spring stiffnesses ×stiffness).
struct UnitScale {
  double length = 1.0;
  double stiffness = 1.0;
  double force() const { return stiffness * length; }            ///< loads and reactions
  double torque() const { return stiffness * length * length; }  ///< joint torques, K_q
};

/// The chain's own units: mean triangle half-length b and mean spring stiffness k. What a user
/// who does not know "the" unit system of a model should pass to NondimensionalProblem.
inline UnitScale typicalUnits(const mechanics::Chain& chain) {
  double b = 0.0, k = 0.0;
  for (int i = 0; i < chain.size(); ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    b += 0.5 * (p.b1 + p.b2);
    k += 0.5 * (p.k1 + p.k2);
  }
  return UnitScale{b / chain.size(), k / chain.size()};
}

/// EquilibriumProblem seen in nondimensional variables (header comment). The load-path
/// direction is assumed to be a force (λ₀ = F₀) unless `lambdaScale` says otherwise.
class NondimensionalProblem final : public continuation::Problem {
 public:
  NondimensionalProblem(const mechanics::EquilibriumProblem& problem, UnitScale scale, double lambdaScale = 0.0)
      : p_(problem),
        lambdaScale_(lambdaScale > 0.0 ? lambdaScale : scale.force()),
        torque_(scale.torque()),
        uScale_(Eigen::VectorXd::Ones(problem.dimension())),
        rowScale_(Eigen::VectorXd::Constant(problem.dimension(), scale.torque())) {
    const std::vector<int> held = problem.endCondition().heldIndices();
    constraintScale_.resize(Eigen::Index(held.size()));
    for (size_t c = 0; c < held.size(); ++c) {
      const bool angle = held[c] == 2;
      const Eigen::Index i = problem.segments() + Eigen::Index(c);
      uScale_[i] = angle ? scale.torque() : scale.force();
      rowScale_[i] = angle ? 1.0 : scale.length;
      constraintScale_[Eigen::Index(c)] = rowScale_[i];
    }
  }

  /// The equilibrium problem's workspace and the physical unknowns of the last evaluation.
  struct Workspace : continuation::ProblemWorkspace {
    std::unique_ptr<continuation::ProblemWorkspace> inner;
    Eigen::VectorXd u;
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override {
    auto w = std::make_unique<Workspace>();
    w->inner = p_.createWorkspace();
    w->u.resize(p_.dimension());
    return w;
  }

  double lambdaScale() const { return lambdaScale_; }
  /// Physical unknowns of nondimensional ones.
  Eigen::VectorXd physical(continuation::ConstVectorRef u) const { return u.cwiseProduct(uScale_); }
  Eigen::VectorXd nondimensional(continuation::ConstVectorRef u) const { return u.cwiseQuotient(uScale_); }

  int dimension() const override { return p_.dimension(); }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::VectorRef F) const override {
    Workspace& w = continuation::workspaceAs<Workspace>(ws);
    w.u = u.cwiseProduct(uScale_);
    if (!p_.residual(*w.inner, w.u, lambda * lambdaScale_, F)) return false;
    F.array() /= rowScale_.array();
    return true;
  }
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::MatrixRef Fu, continuation::VectorRef Flambda) const override {
    Workspace& w = continuation::workspaceAs<Workspace>(ws);
    w.u = u.cwiseProduct(uScale_);
    if (!p_.jacobian(*w.inner, w.u, lambda * lambdaScale_, Fu, Flambda)) return false;
    scaleJacobian(Fu, Flambda);
    return true;
  }
  bool jacobianDirectionalDerivative(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                                     continuation::ConstVectorRef du, double dlambda, continuation::MatrixRef dFu,
                                     continuation::VectorRef dFlambda) const override {
    Workspace& w = continuation::workspaceAs<Workspace>(ws);
    w.u = u.cwiseProduct(uScale_);
    const Eigen::VectorXd duPhysical = du.cwiseProduct(uScale_);
    if (!p_.jacobianDirectionalDerivative(*w.inner, w.u, lambda * lambdaScale_, duPhysical, dlambda * lambdaScale_, dFu,
                                          dFlambda))
      return false;
    scaleJacobian(dFu, dFlambda);
    return true;
  }

  // Stability: H and C rescaled; the inertia is then the default dense one of Problem (n small).
  bool hasStabilityOperator() const override { return p_.hasStabilityOperator(); }
  bool stabilityOperator(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                         continuation::Matrix& H, continuation::Matrix& C) const override {
    Workspace& w = continuation::workspaceAs<Workspace>(ws);
    w.u = u.cwiseProduct(uScale_);
    if (!p_.stabilityOperator(*w.inner, w.u, lambda * lambdaScale_, H, C)) return false;
    H /= torque_;
    if (C.rows() == constraintScale_.size()) C.array().colwise() /= constraintScale_.array();
    return true;
  }

  // Boundaries are joint-angle limits: unit-free.
  int boundaryCount() const override { return p_.boundaryCount(); }
  double boundary(continuation::ProblemWorkspace& ws, int k, continuation::ConstVectorRef u,
                  double lambda) const override {
    Workspace& w = continuation::workspaceAs<Workspace>(ws);
    w.u = u.cwiseProduct(uScale_);
    return p_.boundary(*w.inner, k, w.u, lambda * lambdaScale_);
  }
  std::string boundaryName(int k) const override { return p_.boundaryName(k); }

 private:
  void scaleJacobian(continuation::MatrixRef Fu, continuation::VectorRef Flambda) const {
    Fu.array().colwise() /= rowScale_.array();
    Fu.array().rowwise() *= uScale_.transpose().array();
    Flambda.array() *= lambdaScale_ / rowScale_.array();
  }

  const mechanics::EquilibriumProblem& p_;
  double lambdaScale_, torque_;
  Eigen::VectorXd uScale_, rowScale_, constraintScale_;
};

}  // namespace buckle::bench
