// Loads on the chain's body, not at its end: the links' weight and point forces at the joints
// (issue 31, "Gravity and distributed loads"; docs/mechanics.md, "Weight and point loads").
//
// Every such load is a force f_a applied at a point x_a fixed on a link. Link i (1 … n, between
// joint i and i+1, chain.h) carries its weight m_i g at its centre of mass, d_i along the link,
// and the point loads given at joint i (at distance 0). The forces are affine in the path
// parameter: g(λ) = g⁰ + λ g', f_a(λ) = f_a⁰ + λ f_a', so the weight is a path parameter ("how
// heavy can the chain be") as an end load is. Their potential is
//     V(q, λ) = −Σ_a f_a(λ)·x_a(q).                                                        (B1)
// Turning joint j rotates every point beyond it about the joint's position p_j (R(x, y) = (−y, x)),
// so with the torques τ_j = Σ_{a beyond j} (x_a − p_j) × f_a (a × b = a_x b_y − a_y b_x)
//     ∂V/∂q_j = −τ_j,                                                                       (B2)
//     ∂²V/∂q_j∂q_k = γ_max(j,k),  γ_m = Σ_{a beyond m} f_a·(x_a − p_m)                     (B3)
// (gravity.h, eq G3): the pattern of K_g (eq 27), each force acting like an end force at its own
// point. The Hessian of E − F·p + V is K_q − K_g with the generator h − γ, so the O(n) chain
// structure (chain_structure.h) holds unchanged. Per link, with the link direction u_i, the
// resultant F_i = Σ f_a and the first moment D_i = Σ d_a f_a, and r_i = p_i − p_end = −(C_i, S_i)
// from the tail sums of forwardKinematics (no large absolute positions enter):
//     γ_m = Σ_{i≥m} (u_i·D_i + F_i·r_i) − (Σ_{i≥m} F_i)·r_m,
//     τ_m = Σ_{i≥m} (u_i × D_i + r_i × F_i) − r_m × Σ_{i≥m} F_i,                          (B4)
// O(n) suffix sums. Along a direction (dq, dλ), with Θ_m = Σ_{j≤m} dq_j, every x_a − p_m rotates
// by Θ_m and the joints between m and a's link turn x_a alone:
//     dγ_m = γ'_m dλ + Θ_m τ_m + Σ_{j>m} τ_j dq_j                                          (B5)
// (γ' the generator of the rates f'), the third derivatives of V in O(n).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

/// A force at joint `joint` (1 … n: the joint of q_joint, the start of link `joint`).
struct PointLoad {
  int joint = 1;
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  ///< at λ = 0
  Eigen::Vector2d rate = Eigen::Vector2d::Zero();   ///< d force / dλ
};

/// The body loads of one chain: weight (masses and the gravitational acceleration) and point
/// loads, each affine in λ. Empty masses: weightless.
struct BodyLoads {
  Vector mass;    ///< m_i of links 1 … n (size n, or empty)
  Vector centre;  ///< d_i, the centre of mass of link i from joint i along the link (size of mass)
  Eigen::Vector2d gravity = Eigen::Vector2d::Zero();      ///< g at λ = 0
  Eigen::Vector2d gravityRate = Eigen::Vector2d::Zero();  ///< dg/dλ
  std::vector<PointLoad> points;

  /// The links of `inertia` (masses and centres; InertiaData::IsValid) under g(λ) = g + λ rate.
  static BodyLoads weight(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& gravity,
                          const Eigen::Vector2d& gravityRate);
  /// Any force or rate not zero.
  bool active() const;
  /// The loads at λ, as constants: g(λ) and f_a(λ), rates zero (a state at fixed λ, e.g. the
  /// dynamics of a jump, dynamics.h).
  BodyLoads atParameter(double lambda) const;
  /// Throws std::invalid_argument naming the bad value (sizes, finiteness, m ≥ 0, d in [0, ℓ],
  /// joints in 1 … n).
  void check(const Chain& chain) const;
};

/// `inertia` with a point mass `mass` ≥ 0 at the chain's end added to the end link: its mass,
/// centre of mass and centroidal inertia (parallel axes). Throws std::invalid_argument when the
/// inertia does not fit the chain or the mass is negative.
InertiaData withPayload(const Chain& chain, InertiaData inertia, double mass);

/// H += Γ with Γ(i, j) = γ_max(i,j) (eq B3): the body loads' share of a dense Hessian. An empty γ
/// adds nothing; otherwise throws std::invalid_argument unless γ has one entry per row of H.
void addBodyLoadHessian(const Vector& gamma, MatrixRef H);

/// The terms (B2)–(B5) at one configuration: a workspace sized once for a chain, filled by
/// update() from forwardKinematics' data (no heap allocation after construction).
class BodyLoadTerms {
 public:
  BodyLoadTerms() = default;
  /// Throws std::invalid_argument as BodyLoads::check.
  BodyLoadTerms(const Chain& chain, const BodyLoads& loads);

  bool active() const { return active_; }
  int size() const { return int(tau0_.size()); }

  /// The torques and generators of the constant and rate parts at the configuration of `data`
  /// (forwardKinematics at q). O(n).
  void update(const ChainData& data);
  /// τ(λ) = τ⁰ + λ τ' (eq B2: ∂V/∂q = −τ) and γ(λ) (eq B3) at the last update().
  void torques(double lambda, VectorRef tau) const { tau = tau0_ + lambda * tau1_; }
  void generator(double lambda, VectorRef gamma) const { gamma = gamma0_ + lambda * gamma1_; }
  double gammaAt(int m, double lambda) const { return gamma0_[m] + lambda * gamma1_[m]; }
  /// τ' and γ' (the λ derivatives; ∂²V/∂q∂λ = −τ').
  const Vector& rateTorques() const { return tau1_; }
  const Vector& rateGenerator() const { return gamma1_; }
  /// Σ_i |F'_i|: how fast the resultants grow with λ (EquilibriumProblem::scales()).
  double rateForce() const;
  /// dγ along (dq, dλ) at (the last update(), λ), eq (B5). O(n); dgamma may not alias dq.
  void generatorDerivative(double lambda, ConstVectorRef dq, double dlambda, VectorRef dgamma) const;
  /// V(q, λ) (eq B1) at the configuration of `data`.
  double potential(const ChainData& data, double lambda) const;

 private:
  bool active_ = false;
  Eigen::Matrix2Xd force0_, force1_, moment0_, moment1_;  // F_i and D_i of the constant and rate parts
  Vector tau0_, tau1_, gamma0_, gamma1_;
  Eigen::Matrix2Xd dir_, rel_;  // u_i and r_i of the last update()
};

}  // namespace buckle::mechanics
