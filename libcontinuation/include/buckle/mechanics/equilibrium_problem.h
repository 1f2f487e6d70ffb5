// The chain's equilibrium as a continuation problem (the mechanics layer on the generic core).
//
// Unknowns u = (q_1 … q_n, r_1 … r_m): joint angles and the reactions (Lagrange multipliers)
// of the m held end coordinates, in (x, y, φ) order. Parameter λ moves the prescribed loads
// and coordinates along a straight line: value(λ) = end.value + λ·direction.
// Equations (eq 9 / 13 with multipliers):
//   ∂E/∂q − Jᵀ F(u, λ) = 0,           F = given loads on loaded coordinates, r on held ones
//   −(p_c(q) − value_c(λ)) = 0         for every held coordinate c
// so that F_u = [[K_q − K_g(F), −J_hᵀ], [−J_h, 0]] is symmetric (a KKT matrix).
// Stability operator: K_q − K_g(F) on ker J_h.
// With a control direction (control_path.h) λ also moves the springs' free lengths,
// L⁰(λ) = L⁰ + (λ − origin)·rates, so E = Σ ½k(L − L⁰(λ))² depends on λ and
//   F_λ = −J_lᵀ d_l + ∂²E/∂q∂λ,   ∂²E/∂q_i∂λ = −Σ_s k_s r_{i,s} ∂L_s/∂q_i,
//   ∂K_q/∂λ = diag(−Σ_s k_s r_{i,s} ∂²L_s/∂q_i²),  ∂²F/∂λ² = 0 (E is quadratic in L⁰, F linear in it).
// With body loads (body_loads.h: the links' weight and point loads at the joints, affine in λ)
// the potential gains V(q, λ) (eq B1): the q rows gain ∂V/∂q = −τ (eq B2), the generator of
// K_g becomes h − γ (eq B3: the same O(n) structure), F_λ gains −τ', and the second derivatives
// dγ (eq B5). Every route below (dense, structured, stability, rate bound) includes them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/control_path.h"
#include "buckle/mechanics/eigenvalue_memory.h"
#include "buckle/mechanics/end_condition.h"

namespace buckle::mechanics {

struct EquilibriumOptions {
  /// Report the joint limits as boundaries g = q_max − q, q − q_min (the tracer stops on them).
  bool jointLimitsAsBoundaries = true;
  /// stability(): O(n) inertia and lowest eigenvalues through the chain structure
  /// (chain_structure.h); false: the dense default of Problem (kept for cross-checks).
  bool structuredStability = true;
  /// Displacement control of end coordinate `heldRange.coordinate` traced through its reaction
  /// (branch_report.h): the coordinate must stay in the path's range [low, high]. Two more
  /// boundaries after the joint limits, g = pose_c − low and high − pose_c (plus 1e-12 of the
  /// range's scale, equilibrium_problem.cpp), end a branch where the end leaves the range, as the
  /// λ range ends a load path. coordinate −1: none.
  struct CoordinateRange {
    int coordinate = -1;  ///< 0 x, 1 y, 2 φ
    double low = 0.0, high = 0.0;
    bool active() const { return coordinate >= 0; }
  } heldRange{};
  /// The base wall as a boundary (wall_contact.h): one more after heldRange's, g = d_base, the
  /// smallest x over the moving vertices, so the tracer stops where a vertex reaches x = 0 (where
  /// the wall contact begins, contact.h).
  bool wallAsBoundary = false;
  /// Self contact as a boundary (self_contact.h): one more after the wall's, g = d_self
  /// (contact_geometry.h), so the tracer stops where two links' triangles touch (where a self
  /// contact begins, contact.h).
  bool selfContactAsBoundary = false;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

class EquilibriumProblem final : public continuation::Problem {
 public:
  /// `control`: λ moves the free lengths as well (control_path.h; rates n×2 or empty). Throws
  /// std::invalid_argument for non-finite input or rates of the wrong size.
  /// `body`: the weight and point loads on the links (body_loads.h; BodyLoads::check throws).
  EquilibriumProblem(const Chain& chain, const EndCondition& end, const Eigen::Vector3d& direction,
                     EquilibriumOptions options = {}, const ControlDirection& control = {},
                     const BodyLoads& body = {});

  const Chain& chain() const { return chain_; }
  const EndCondition& endCondition() const { return end_; }
  const Eigen::Vector3d& direction() const { return direction_; }
  int segments() const { return chain_.size(); }
  int heldCount() const { return static_cast<int>(held_.size()); }
  /// The control direction (inactive: λ moves the end values alone).
  const ControlDirection& control() const { return control_; }
  bool controlled() const { return control_.active(); }
  /// The chain with its free lengths at λ (chainWithControls; a copy of chain() when no control
  /// path): what the energy, stiffness and dynamics of a point at λ are computed on. Throws
  /// std::invalid_argument when a free length is not positive at λ.
  Chain chainAt(double lambda) const { return chainWithControls(chain_, control_, lambda); }
  /// The caches of one computation (ProblemWorkspace), preallocated for the chain. Every cache is
  /// keyed bitwise on the point it was computed at, so its values are pure functions of the
  /// points evaluated; the eigenvalue searches' warm starts (found) only speed them up.
  struct Workspace : continuation::ProblemWorkspace {
    explicit Workspace(const EquilibriumProblem& problem);
    // prepare()'s q-cache: kinematics, the end Jacobian (3×n), ∂E/∂q and the diagonal of K_q
    // (size n), d³E/dq³ per joint (stabilityRateBound()), sin/cos(q_i/2), for cachedQ (and
    // cachedLambda on a control path); controlGrad, controlStiff: ∂(∂E/∂q)/∂λ, ∂K_q/∂λ there.
    ChainData data;
    Matrix J;
    Vector grad, stiff, stiffRate, cachedQ;
    double cachedLambda = 0.0;
    Vector controlGrad, controlStiff;
    Vector sinHalf, cosHalf;
    bool cacheValid = false;
    Vector work;               // size n
    ChainStructure structure;  // the structured stability()'s
    Matrix heldRows;           // m×n held rows of J
    // The whole small dense spectrum (n ≤ 16) of the last (u, λ) it was computed at, by
    // stability() or stabilityEigenvalues(): the tracer asks stability() for the inertia and then
    // the certified counting's values at the same point (spectral_monitor.h), one eigen-solve serves
    // both. Keyed bitwise on (u, λ) like the q-cache (H depends on r and λ through the wrench).
    Vector spectrumKey;                              // (u, λ) of spectrum (size N + 1)
    Eigen::Matrix<double, kSmallDense, 1> spectrum;  // ascending eigenvalues on ker J_h ...
    int spectrumSize = -1;                           // ... their number (n − rank); −1: none cached
    Inertia spectrumInertia;                         // ... and the inertia that goes with them
    BodyLoadTerms bodyTerms;                         // the body loads' τ and γ at the cached q
    Vector bodyWork;                                 // size n: dγ and other body-load scratch
    EigenvalueMemory found;                          // warm starts of the structured eigenvalue searches (by index)
    Vector guess;  // their guesses (size kMaxBorder once used: no allocation per call)
    // stabilityRates() along a direction (size n each): dκ; the rate of the generator h of
    // K_q − H (eq 27, body loads included); the tail sums' rates dS, dC (the held rows' rates, eq 11).
    Vector rateKappa, rateGenerator, rateS, rateC;
    Vector eigenvector, hessianTimes;  // stabilitySlopes(): v and H v (size n)
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override;

  /// ∂²E/∂q∂λ (size n) at the (q, λ) of the workspace's last evaluation (residual, jacobian,
  /// assembleStructure …): the control part of F_λ. Empty when no control path.
  static const Vector& controlRate(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).controlGrad;
  }
  /// The body loads (weight, point loads) and whether any of them is not zero.
  const BodyLoads& bodyLoads() const { return body_; }
  bool hasBodyLoads() const { return bodyTerms_.active(); }
  /// γ(λ) of the body loads at the joint angles q (eq B3; empty without them): the Hessian of the
  /// total potential is K_q − K_g with the generator h − γ (StiffnessOptions, vibration.h). O(n).
  Vector bodyLoadGenerator(continuation::ConstVectorRef q, double lambda) const;
  /// dγ along (dq, dλ) at (q, λ) (eq B5; empty without body loads). O(n).
  Vector bodyLoadGeneratorRate(continuation::ConstVectorRef q, double lambda, continuation::ConstVectorRef dq,
                               double dlambda) const;
  /// τ' at the q of the last evaluation (eq B2: F_λ gains −τ'), for the structured solvers that
  /// form F_λ themselves; meaningful only with hasBodyLoads().
  static const Vector& bodyRateTorques(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).bodyTerms.rateTorques();
  }
  /// V(q, λ) of the body loads (eq B1; 0 without them).
  double bodyLoadPotential(continuation::ConstVectorRef q, double lambda) const;

  /// Prescribed values (loads or coordinates) at λ.
  Eigen::Vector3d prescribed(double lambda) const { return end_.value + lambda * direction_; }
  /// Total end wrench at (u, λ): given loads and the multipliers. Inline: every residual,
  /// Jacobian and stability evaluation forms it (a call cost more than the three stores).
  Wrench wrench(const continuation::ConstVectorRef& u, double lambda) const {
    Wrench F = prescribed(lambda);
    const int n = chain_.size();
    for (size_t k = 0; k < held_.size(); ++k) F[held_[k]] = u[n + int(k)];
    return F;
  }
  /// Unknown vector for given joint angles, with the multipliers that best satisfy the
  /// equilibrium in the least-squares sense (a starting guess).
  Vector initialGuess(continuation::ConstVectorRef q, double lambda) const;

  int dimension() const override { return chain_.size() + heldCount(); }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::VectorRef F) const override;
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::MatrixRef Fu, continuation::VectorRef Flambda) const override;
  /// Every entry of F_u and F_λ, the zero block of the multipliers included.
  bool jacobianWritesAllEntries() const override { return true; }
  bool jacobianDirectionalDerivative(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                                     continuation::ConstVectorRef du, double dlambda, continuation::MatrixRef dFu,
                                     continuation::VectorRef dFlambda) const override;

  /// O(n) products with F_x = [F_u, F_λ] in the joint coordinates (K_g x by prefix and suffix
  /// sums of h, eq 27): exact to rounding, with no cancellation beyond that of the dense product.
  /// F_u is symmetric, so F_xᵀ w = (F_u w, F_λ·w). The second derivative keeps the default
  /// (central differences of jacobianTransposeApply, O(n)).
  bool jacobianApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                     continuation::ConstVectorRef x, continuation::VectorRef y) const override;
  bool jacobianTransposeApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                              continuation::ConstVectorRef w, continuation::VectorRef y) const override;
  /// Exact F_xx[x, z] in O(n): jacobianDirectionalDerivative() along x applied to z, i.e.
  /// (q rows) E‴ ⊙ x_q ⊙ z_q − K_g(dh_x) z_q − dJ_h[x]ᵀ z_r − Σ_loaded dJ_c[x]ᵀ dir_c z_λ with
  /// dh_x = d h along x (eq 27 differentiated, the wrench moving with x_r and x_λ) and dJ the
  /// derivative of the end Jacobian (stiffness.h); (held rows) −dJ_h[x] z_q.
  bool secondDerivativeApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                             continuation::ConstVectorRef x, continuation::ConstVectorRef z,
                             continuation::VectorRef y) const override;

  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, Matrix& H,
                         Matrix& C) const override;
  /// Inertia of K_q − K_g on ker J_h and its min(lowestCount, kMaxLowest) lowest eigenvalues.
  /// options.structuredStability: the inertia from two O(n) Sturm counts, the eigenvalues by
  /// Newton on the counts' determinant (chain_structure.h); for n <= 16 with eigenvalues wanted,
  /// one heap-free dense solve (faster there: benchmarks/RESULTS.md). Otherwise the dense
  /// Problem::stability().
  static constexpr int kMaxLowest = 4;  // the isolation's fixed-size brackets
  /// How far (rad) past a geometric limit points are still evaluated while the joint limits are
  /// traced as boundaries (inDomain()): a few halvings of a step that crosses a limit.
  static constexpr double kGeometricOvershoot = 0.05;
  bool stability(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, int lowestCount,
                 continuation::StabilityInfo& info) const override;
  /// Eigenvalues by index of K_q − K_g on ker J_h, each isolated on O(n) Sturm counts of the
  /// shifted tridiagonal T − σM (chain_structure.h, eigenvaluesFrom).
  bool stabilityEigenvalues(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                            int first, continuation::VectorRef values) const override;
  /// O(n) factorizations the structured stability() and stabilityEigenvalues() have taken so
  /// far (their cost; eigenvalue_memory.h).
  static long structuredFactorizations(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).structure.factorizations;
  }
  /// ‖dH‖_F + 2‖H‖_F‖dC‖_F/σ_min(C) along (du, dλ), H = K_q − K_g and C = J_h (held rows of
  /// eq 11), in O(n) from the q-cache: an upper bound on every |dμ_i| (Problem). False when C is
  /// rank-deficient (no finite bound) or the point is refused.
  bool stabilityRateBound(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                          continuation::ConstVectorRef du, double dlambda, double& bound) const override;
  /// The same bound for H on the joints `free` (increasing) and ker of `heldRows` (J_h's columns
  /// of those joints, held order): a chain whose other joints are locked (contact.h), whose
  /// locked rows e_iᵀ do not move along the tangent.
  bool stabilityRateBoundOn(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                            continuation::ConstVectorRef du, double dlambda, const std::vector<int>& free,
                            const continuation::Matrix& heldRows, double& bound) const;
  /// dμ of the eigenvalues `values` (indices first …) of K_q − K_g on ker J_h along (du, dλ) by
  /// Hellmann–Feynman (Problem::stabilitySlopes): each eigenvector by inverse iteration on the O(n)
  /// structure (chain_structure.h, eigenvectorAt), dH and dC from the q-cache as for the bound.
  /// O(n) per eigenvalue. False for chains of n ≤ 4 (differencing their small dense spectra costs
  /// less than the structure's set-up), for rank-deficient J_h, and when an eigenvector's residual
  /// shows it was not found.
  bool stabilitySlopes(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                       continuation::ConstVectorRef du, double dlambda, int first, continuation::ConstVectorRef values,
                       continuation::VectorRef slopes) const override;

  /// The Hellmann–Feynman rate vᵀ dH v + 2 ζᵀ dJ_h v along (du, dλ) of an eigenvalue of
  /// H = K_q − K_g on ker J_h and on rows that stay still along the tangent (locked joints:
  /// contact.h), from its unit eigenvector v (length n, zero on such joints) and the held rows'
  /// multipliers ζ (held order, H v + J_hᵀζ + … = μ v). O(n). False outside the domain.
  bool eigenvalueRate(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                      continuation::ConstVectorRef du, double dlambda, continuation::ConstVectorRef v,
                      const Eigen::Vector3d& zeta, double& rate) const;

  /// T of H = K_q − K_g(F(u, λ)) into ws (chain_structure.h) and the end Jacobian (3×n) into J,
  /// from the q-cache: what the structured stability and the structured solver linearise on.
  /// False outside the domain.
  bool assembleStructure(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                         ChainStructure& structure, continuation::MatrixRef J) const;

  /// The O(n) bordered solver of the chain (chain_solver.h).
  std::unique_ptr<continuation::BorderedSolver> makeStructuredSolver(continuation::ProblemWorkspace& ws) const override;

  /// The chain's own units (ProblemScales): with b̄, k̄ the mean triangle half-length and spring
  /// stiffness, angles 1, torque rows and the stability operator k̄b̄², held-position rows b̄,
  /// held-angle rows 1, force reactions k̄b̄, torque reactions k̄b̄², and λ the size that moves the
  /// first prescribed value by its unit (a force k̄b̄, a torque k̄b̄², a position b̄, an angle 1):
  /// min over the direction's components c of unit_c / |direction_c| (and, with body loads that
  /// grow with λ, k̄b̄ / Σ_i |F'_i|: body_loads.h).
  continuation::ProblemScales scales() const override;
  /// b̄ and k̄ of scales(): the mean triangle half-length and the mean spring stiffness.
  double lengthUnit() const;
  double stiffnessUnit() const;

  int boundaryCount() const override;
  double boundary(continuation::ProblemWorkspace& ws, int k, continuation::ConstVectorRef u,
                  double lambda) const override;
  void boundaries(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                  continuation::VectorRef g) const override;
  std::string boundaryName(int k) const override;
  /// The first of the two boundaries of EquilibriumOptions::heldRange (after the joint limits'),
  /// and how many there are (0 or 2).
  int rangeBoundaryBegin() const { return options_.jointLimitsAsBoundaries ? 2 * chain_.size() : 0; }
  int rangeBoundaryCount() const { return options_.heldRange.active() ? 2 : 0; }
  /// Whether a boundary's name (SpecialPoint::boundaryName) is one of heldRange's: the path's
  /// range end, not a limit of the model.
  bool isRangeBoundary(const std::string& name) const;
  /// The wall boundary (EquilibriumOptions::wallAsBoundary): its index (after heldRange's) and
  /// whether there is one.
  int wallBoundaryIndex() const { return rangeBoundaryBegin() + rangeBoundaryCount(); }
  bool wallIsBoundary() const { return options_.wallAsBoundary; }
  /// Its name (SpecialPoint::boundaryName where the tracer stopped on it).
  static const char* wallBoundaryName() { return "a vertex reaches the base wall x = 0"; }
  /// The self contact boundary (EquilibriumOptions::selfContactAsBoundary): its index and name.
  int selfContactBoundaryIndex() const { return wallBoundaryIndex() + (options_.wallAsBoundary ? 1 : 0); }
  bool selfContactIsBoundary() const { return options_.selfContactAsBoundary; }
  static const char* selfContactBoundaryName() { return "two links' triangles touch (self contact)"; }

 private:
  /// Inside the model's domain: finite, every joint within its geometric limits (or just past one,
  /// while the limits are traced as boundaries: equilibrium_problem.cpp).
  bool inDomain(const continuation::ConstVectorRef& u) const;
  /// The q-dependent part of every evaluation at u = (q, r): kinematics (d.data), the end
  /// Jacobian (d.J), ∂E/∂q (d.grad) and the diagonal of K_q (d.stiff), from one pass of the spring
  /// model. Cached in the workspace d for its last q (bitwise; it does not depend on r or λ): KINSOL
  /// evaluates F and then J at the same iterate, and the tracer then J and the stability at the
  /// corrected point, so each distinct q evaluates the spring model once.
  /// False (nothing cached) if u is outside the domain.
  /// Along a control path the free lengths, and so ∂E/∂q and K_q, depend on λ: the key is then
  /// (q, λ), bitwise, and points where a free length is not positive are refused.
  bool prepare(Workspace& d, const continuation::ConstVectorRef& u, double lambda) const;
  /// T at (u, λ) into ws from the cache (after prepare(u)).
  void assembleFromCache(Workspace& d, const continuation::ConstVectorRef& u, double lambda, ChainStructure& ws) const;
  /// The small dense route (n ≤ 16, equilibrium_problem.cpp) at (u, λ): the inertia and all eigenvalues on
  /// ker J_h into the workspace's spectrumInertia and spectrum, or nothing when (u, λ) is already their key.
  /// False (nothing cached) outside the domain.
  bool smallDenseSpectrum(Workspace& d, const continuation::ConstVectorRef& u, double lambda) const;
  /// The generator of K_q − H at (u, λ) from the cache: h(F) of eq 27 minus the body loads' γ
  /// (equilibrium_problem_body.cpp).
  void loadGenerator(Workspace& d, const continuation::ConstVectorRef& u, double lambda, VectorRef h) const;
  /// The body loads' dγ along (du_q, dλ) into the workspace's bodyWork (zero without them).
  void bodyGeneratorDerivative(Workspace& d, const continuation::ConstVectorRef& dq, double lambda,
                               double dlambda) const;
  /// The rates of H = K_q − K_g and of the held rows along (du, dλ) into d.rateKappa,
  /// d.rateGenerator, d.rateS, d.rateC, from the q-cache (after prepare(d, u, λ)). O(n).
  void stabilityRates(Workspace& d, const continuation::ConstVectorRef& u, double lambda,
                      const continuation::ConstVectorRef& du, double dlambda) const;
  /// stabilityRateBound on the joints `free` (null: every joint) with the held rows `heldRows`.
  bool rateBoundOn(Workspace& d, const continuation::ConstVectorRef& u, double lambda,
                   const continuation::ConstVectorRef& du, double dlambda, const std::vector<int>* free,
                   const continuation::Matrix& heldRows, double& bound) const;
  /// vᵀ dH v + 2 ζᵀ dJ_h v from the rates stabilityRates() left in d.
  double rateAlong(const Workspace& d, const continuation::ConstVectorRef& v, const Eigen::Vector3d& zeta) const;

  Chain chain_;
  EndCondition end_;
  Eigen::Vector3d direction_;
  EquilibriumOptions options_;
  std::vector<int> held_, loaded_;
  ControlDirection control_;
  Vector freeLength1_, freeLength2_;  // the chain's L1⁰, L2⁰ (control path only, size n)
  // inDomain()'s bounds per joint, geometric limit ± the overshoot allowed while the limits are
  // traced as boundaries, formed once (the same sums inDomain() formed per call; size n).
  Vector domainUpper_, domainLower_;
  BodyLoads body_;
  BodyLoadTerms bodyTerms_;  // the body loads' constant terms (a workspace updates its copy)
};

}  // namespace buckle::mechanics
