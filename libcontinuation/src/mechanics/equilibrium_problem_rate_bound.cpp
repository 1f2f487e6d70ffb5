// How fast the stability operator's eigenvalues move along a tangent, from the q-cache in O(n)
// (equilibrium_problem.h): EquilibriumProblem::stabilityRateBound (a bound on every one) and
// stabilitySlopes (the rates of a few, from their eigenvectors).
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "buckle/mechanics/equilibrium_problem.h"
#include "held_multipliers.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;
using continuation::VectorRef;

namespace {
// Below this chain length differencing two dense spectra (equilibrium_problem.cpp's small dense
// route) costs less than the structure's set-up and an inverse iteration per value: whole race
// runs (benchmarks/race_auto.sh) cross over between n = 4 and 6.
constexpr int kStructuredSlopesFrom = 5;

// The Gram matrix C Cᵀ of the m ≤ 3 held rows (the first m rows of `rows`), padded with
// `padding` on the unused diagonal.
Eigen::Matrix3d heldGram(const continuation::Matrix& rows, int m, double padding) {
  Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
  for (int k = 0; k < m; ++k)
    for (int l = 0; l <= k; ++l) G(k, l) = G(l, k) = rows.row(k).dot(rows.row(l));
  for (int k = m; k < 3; ++k) G(k, k) = padding;
  return G;
}
}  // namespace

void EquilibriumProblem::stabilityRates(Workspace& d, const ConstVectorRef& u, double lambda, const ConstVectorRef& du,
                                        double dlambda) const {
  const int n = chain_.size();
  const int m = heldCount();
  const Wrench W = wrench(u, lambda);
  Wrench dW = dlambda * direction_;  // loads move with λ, reactions with their unknowns
  for (int k = 0; k < m; ++k) dW[held_[size_t(k)]] = du[n + k];
  if (d.bodyTerms.active()) bodyGeneratorDerivative(d, du.head(n), lambda, dlambda);  // dγ (eq B5)
  // H = K_q − K_g with K_g(i, j) = h_max(i,j), h = −F_x C − F_y S (eq 27), so along (du, dλ)
  // dH = diag(E‴_i du_i) − [dh_max(i,j)] with dh = −dF_x C − F_x dC − dF_y S − F_y dS, and the
  // tail sums move with θ̇_p = Σ_{i≤p} du_i: dS_j = Σ_{p≥j} ℓ_p cos θ_p θ̇_p, dC_j = −Σ_{p≥j} ℓ_p
  // sin θ_p θ̇_p, where ℓ_p cos θ_p = C_p − C_{p+1}, ℓ_p sin θ_p = S_p − S_{p+1} (chain.h).
  double thetaDot = du.head(n).sum(), dS = 0.0, dC = 0.0;
  for (int p = n - 1; p >= 0; --p) {
    const double cNext = p + 1 < n ? d.data.C[p + 1] : 0.0, sNext = p + 1 < n ? d.data.S[p + 1] : 0.0;
    dS += (d.data.C[p] - cNext) * thetaDot;
    dC -= (d.data.S[p] - sNext) * thetaDot;
    thetaDot -= du[p];
    double dh = -dW[0] * d.data.C[p] - W[0] * dC - dW[1] * d.data.S[p] - W[1] * dS;
    if (d.bodyTerms.active()) dh -= d.bodyWork[p];  // the body loads' generator h − γ (eq B3)
    const double dControl = control_.active() ? d.controlStiff[p] * dlambda : 0.0;  // ∂K_q/∂λ dλ
    d.rateKappa[p] = d.stiffRate[p] * du[p] + dControl;
    d.rateGenerator[p] = dh;
    d.rateS[p] = dS;
    d.rateC[p] = dC;
  }
}

bool EquilibriumProblem::stabilityRateBound(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                            double dlambda, double& bound) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !std::isfinite(dlambda) || !du.allFinite() || !prepare(d, u, lambda)) return false;
  const int m = heldCount();
  for (int k = 0; k < m; ++k) d.heldRows.row(k) = d.J.row(held_[size_t(k)]);
  return rateBoundOn(d, u, lambda, du, dlambda, nullptr, d.heldRows, bound);
}

bool EquilibriumProblem::stabilityRateBoundOn(ProblemWorkspace& ws, ConstVectorRef u, double lambda,
                                              ConstVectorRef du, double dlambda, const std::vector<int>& free,
                                              const continuation::Matrix& heldRows, double& bound) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !std::isfinite(dlambda) || !du.allFinite() || !prepare(d, u, lambda)) return false;
  return rateBoundOn(d, u, lambda, du, dlambda, &free, heldRows, bound);
}

bool EquilibriumProblem::rateBoundOn(Workspace& d, const ConstVectorRef& u, double lambda, const ConstVectorRef& du,
                                     double dlambda, const std::vector<int>* free, const continuation::Matrix& heldRows,
                                     double& bound) const {
  const int n = chain_.size();
  const int m = heldCount();
  stabilityRates(d, u, lambda, du, dlambda);
  const Wrench W = wrench(u, lambda);
  bool heldX = false, heldY = false;
  for (int c : held_) {
    heldX |= c == 0;
    heldY |= c == 1;
  }
  // In the Frobenius norms the entries with max(i, j) = p appear 2a + 1 times, a the rank of p
  // among the joints kept (0-based; every joint, or `free`), once on the diagonal. C = J_h has
  // rows (−S, C, 1) of eq 11, so dC has rows (−dS, dC, 0).
  double dH2 = 0.0, H2 = 0.0, dC2 = 0.0;
  int rank = free ? int(free->size()) - 1 : n - 1;
  for (int p = n - 1; p >= 0; --p) {
    if (free && (rank < 0 || (*free)[size_t(rank)] != p)) continue;  // a locked joint: its rows and columns are gone
    double h = -W[0] * d.data.C[p] - W[1] * d.data.S[p];
    if (d.bodyTerms.active()) h -= d.bodyTerms.gammaAt(p, lambda);
    const double dh = d.rateGenerator[p];
    const double dDiagonal = d.rateKappa[p] - dh, diagonal = d.stiff[p] - h;
    dH2 += dDiagonal * dDiagonal + 2.0 * rank * dh * dh;
    H2 += diagonal * diagonal + 2.0 * rank * h * h;
    if (heldX) dC2 += d.rateS[p] * d.rateS[p];
    if (heldY) dC2 += d.rateC[p] * d.rateC[p];
    --rank;
  }
  bound = std::sqrt(dH2);
  if (m == 0) return std::isfinite(bound);
  // The eigenvector's multiplier: H v + Cᵀζ = μ v, C v = 0 give ζ = −(CCᵀ)⁻¹C H v, so
  // ‖ζ‖ ≤ ‖H‖₂/σ_min(C); and dμ = vᵀ dH v + 2 ζᵀ dC v (differentiate and multiply by vᵀ).
  // σ_min(C)² = the smallest eigenvalue of the Gram matrix CCᵀ (m ≤ 3; the unused diagonal is
  // padded above every eigenvalue of the m×m block, which stays decoupled).
  Eigen::Matrix3d G = heldGram(heldRows, m, 0.0);
  const double trace = G.trace();
  for (int k = m; k < 3; ++k) G(k, k) = 2.0 * trace + 1.0;
  const double sigma2 =
      m == 1 ? G(0, 0) : Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(G, Eigen::EigenvaluesOnly).eigenvalues()[0];
  // Rank-deficient C (e.g. x held on the straight chain): ker C jumps, no finite bound.
  if (!(sigma2 > 1e-12 * trace)) return false;
  bound += 2.0 * std::sqrt(H2) * std::sqrt(dC2 / sigma2);
  return std::isfinite(bound);
}

bool EquilibriumProblem::stabilitySlopes(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                         double dlambda, int first, ConstVectorRef values, VectorRef slopes) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int n = chain_.size(), m = heldCount();
  if (!options_.structuredStability || n < kStructuredSlopesFrom || first < 0 || values.size() != slopes.size() ||
      !values.allFinite() || !std::isfinite(lambda) || !std::isfinite(dlambda) || !du.allFinite() ||
      !prepare(d, u, lambda))
    return false;
  assembleFromCache(d, u, lambda, d.structure);
  for (int k = 0; k < m; ++k) d.heldRows.row(k) = d.J.row(held_[size_t(k)]);
  // rank-deficient C: ker C jumps along the tangent (no derivative), as for the bound
  if ((m > 0 ? setConstraints(d.structure, d.heldRows) : (d.structure.rank = 0)) < m) return false;
  stabilityRates(d, u, lambda, du, dlambda);
  Vector& v = d.eigenvector;
  Vector& Hv = d.hessianTimes;
  for (Eigen::Index j = 0; j < values.size(); ++j) {
    Eigen::Vector3d zeta;
    if (!eigenvectorAt(d.structure, m > 0, values[j], v) ||
        !heldMultipliers(d.structure, d.heldRows, m, values[j], v, Hv, zeta))
      return false;
    slopes[j] = rateAlong(d, v, zeta);
  }
  return slopes.allFinite();
}

double EquilibriumProblem::rateAlong(const Workspace& d, const ConstVectorRef& v, const Eigen::Vector3d& zeta) const {
  const int n = chain_.size(), m = heldCount();
  // vᵀ dH v = Σ dκ_p v_p² − Σ_{i,j} dh_max(i,j) v_i v_j, and Σ_{i,j} g_max(i,j) v_i v_j =
  // Σ_p (g_p − g_{p+1}) P_p² with the prefix sums P_p = Σ_{i≤p} v_i (g_n = 0).
  double rate = 0.0, prefix = 0.0;
  for (int p = 0; p < n; ++p) {
    prefix += v[p];
    const double dgNext = p + 1 < n ? d.rateGenerator[p + 1] : 0.0;
    rate += d.rateKappa[p] * v[p] * v[p] - (d.rateGenerator[p] - dgNext) * prefix * prefix;
  }
  // + 2 ζᵀ dC v, dC with rows (−dS, dC, 0) for x, y, φ held (eq 11)
  for (int k = 0; k < m; ++k) {
    const int c = held_[size_t(k)];
    if (c == 2) continue;
    const double dCv = c == 0 ? -d.rateS.dot(v) : d.rateC.dot(v);
    rate += 2.0 * zeta[k] * dCv;
  }
  return rate;
}

bool EquilibriumProblem::eigenvalueRate(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                        double dlambda, ConstVectorRef v, const Eigen::Vector3d& zeta,
                                        double& rate) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (v.size() != chain_.size() || !std::isfinite(lambda) || !std::isfinite(dlambda) || !du.allFinite() ||
      !prepare(d, u, lambda))
    return false;
  stabilityRates(d, u, lambda, du, dlambda);
  rate = rateAlong(d, v, zeta);
  return std::isfinite(rate);
}

}  // namespace buckle::mechanics
