// The weight of the links as a potential term (issue 31, "Gravity"): a building block, not yet
// part of EquilibriumProblem (docs/mechanics.md, "Gravity").
//
// With link masses m_i at their centres of mass r_i (InertiaData, dynamics.h: link i between
// joint i and i+1, the centre at d_i along it) and the gravitational acceleration g (a vector in
// the scene's units, e.g. (0, −9.81) m/s²),
//     V(q) = −Σ_i m_i g·r_i(q).                                                           (G1)
// Turning joint j rotates every link beyond it about the joint's position p_j, so with
// R(x, y) = (−y, x), W_j = Σ_{i≥j} m_i and C_j = Σ_{i≥j} m_i r_i (suffix sums, O(n)):
//     ∂V/∂q_j = −g·R(C_j − W_j p_j),                                                      (G2)
//     ∂²V/∂q_j∂q_k = γ_max(j,k),   γ_m = g·(C_m − W_m p_m),                                (G3)
// the pattern of K_g (eq 27): each link's weight acts like an end force m_i g applied at r_i.
// The Hessian of E − F·p + V is therefore K_q − K_g with the load generator h_m − γ_m, and the
// O(n) chain structure (chain_structure.h) holds unchanged.
#pragma once

#include <Eigen/Core>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics {

class GravityPotential {
 public:
  /// Throws std::invalid_argument when the inertia data do not fit the chain or g is not finite.
  GravityPotential(const Chain& chain, const InertiaData& inertia, const Eigen::Vector2d& acceleration);

  const Eigen::Vector2d& acceleration() const { return g_; }

  /// Centres of mass r_i of the n links (2×n).
  Eigen::Matrix2Xd centresOfMass(ConstVectorRef q) const;
  /// V(q), eq (G1).
  double value(ConstVectorRef q) const;
  /// ∂V/∂q (size n), eq (G2), O(n).
  void gradient(ConstVectorRef q, VectorRef grad) const;
  /// γ (size n) of eq (G3): ∂²V/∂q_j∂q_k = γ_max(j,k); gravity's share of the load generator h of
  /// eq 27 is −γ. O(n).
  void hessianGenerator(ConstVectorRef q, VectorRef gamma) const;
  /// Dense ∂²V/∂q² (n×n).
  void hessian(ConstVectorRef q, MatrixRef G) const;

 private:
  /// Joint positions p_j (2×n, column j the joint of q_j) and v_j = C_j − W_j p_j (2×n).
  void moments(ConstVectorRef q, Eigen::Matrix2Xd& v) const;

  Chain chain_;
  Vector mass_, com_;  // m_i and d_i
  Eigen::Vector2d g_;
};

}  // namespace buckle::mechanics
