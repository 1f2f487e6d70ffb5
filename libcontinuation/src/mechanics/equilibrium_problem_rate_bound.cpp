// EquilibriumProblem::stabilityRateBound: a bound on how fast the eigenvalues of the stability
// operator move along a tangent, from the q-cache in O(n) (equilibrium_problem.h).
#include <Eigen/Eigenvalues>
#include <cmath>

#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;

bool EquilibriumProblem::stabilityRateBound(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                            double dlambda, double& bound) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !std::isfinite(dlambda) || !du.allFinite() || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  const int m = heldCount();
  const Wrench W = wrench(u, lambda);
  Wrench dW = dlambda * direction_;  // loads move with λ, reactions with their unknowns
  for (int k = 0; k < m; ++k) dW[held_[size_t(k)]] = du[n + k];
  if (d.bodyTerms.active()) bodyGeneratorDerivative(d, du.head(n), lambda, dlambda);  // dγ (eq B5)
  bool heldX = false, heldY = false;
  for (int c : held_) {
    heldX |= c == 0;
    heldY |= c == 1;
  }
  // H = K_q − K_g with K_g(i, j) = h_max(i,j), h = −F_x C − F_y S (eq 27), so along (du, dλ)
  // dH = diag(E‴_i du_i) − [dh_max(i,j)] with dh = −dF_x C − F_x dC − dF_y S − F_y dS, and the
  // tail sums move with θ̇_p = Σ_{i≤p} du_i: dS_j = Σ_{p≥j} ℓ_p cos θ_p θ̇_p, dC_j = −Σ_{p≥j} ℓ_p
  // sin θ_p θ̇_p, where ℓ_p cos θ_p = C_p − C_{p+1}, ℓ_p sin θ_p = S_p − S_{p+1} (chain.h). In the
  // Frobenius norms the entries with max(i, j) = p appear 2p + 1 times (0-based), once on the
  // diagonal. C = J_h has rows (−S, C, 1) of eq 11, so dC has rows (−dS, dC, 0).
  double thetaDot = du.head(n).sum(), dS = 0.0, dC = 0.0;
  double dH2 = 0.0, H2 = 0.0, dC2 = 0.0;
  for (int p = n - 1; p >= 0; --p) {
    const double cNext = p + 1 < n ? d.data.C[p + 1] : 0.0, sNext = p + 1 < n ? d.data.S[p + 1] : 0.0;
    dS += (d.data.C[p] - cNext) * thetaDot;
    dC -= (d.data.S[p] - sNext) * thetaDot;
    thetaDot -= du[p];
    double h = -W[0] * d.data.C[p] - W[1] * d.data.S[p];
    double dh = -dW[0] * d.data.C[p] - W[0] * dC - dW[1] * d.data.S[p] - W[1] * dS;
    if (d.bodyTerms.active()) {  // the body loads' generator h − γ (eq B3) and its rate
      h -= d.bodyTerms.gammaAt(p, lambda);
      dh -= d.bodyWork[p];
    }
    const double dControl = control_.active() ? d.controlStiff[p] * dlambda : 0.0;  // ∂K_q/∂λ dλ
    const double dDiagonal = d.stiffRate[p] * du[p] + dControl - dh, diagonal = d.stiff[p] - h;
    dH2 += dDiagonal * dDiagonal + 2.0 * p * dh * dh;
    H2 += diagonal * diagonal + 2.0 * p * h * h;
    if (heldX) dC2 += dS * dS;
    if (heldY) dC2 += dC * dC;
  }
  bound = std::sqrt(dH2);
  if (m == 0) return std::isfinite(bound);
  // The eigenvector's multiplier: H v + Cᵀζ = μ v, C v = 0 give ζ = −(CCᵀ)⁻¹C H v, so
  // ‖ζ‖ ≤ ‖H‖₂/σ_min(C); and dμ = vᵀ dH v + 2 ζᵀ dC v (differentiate and multiply by vᵀ).
  // σ_min(C)² = the smallest eigenvalue of the Gram matrix CCᵀ (m ≤ 3; the unused diagonal is
  // padded above every eigenvalue of the m×m block, which stays decoupled).
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  for (int k = 0; k < m; ++k)
    for (int l = 0; l <= k; ++l) G(k, l) = G(l, k) = d.J.row(held_[size_t(k)]).dot(d.J.row(held_[size_t(l)]));
  const double trace = G.trace();
  for (int k = m; k < 3; ++k) G(k, k) = 2.0 * trace + 1.0;
  const double sigma2 =
      m == 1 ? G(0, 0) : Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(G, Eigen::EigenvaluesOnly).eigenvalues()[0];
  // Rank-deficient C (e.g. x held on the straight chain): ker C jumps, no finite bound.
  if (!(sigma2 > 1e-12 * trace)) return false;
  bound += 2.0 * std::sqrt(H2) * std::sqrt(dC2 / sigma2);
  return std::isfinite(bound);
}

}  // namespace buckle::mechanics
