// Contact at the joints: a joint that reaches its limit (geometric: the closing spring's length
// goes to zero and the triangles meet; or the scene's limit) is locked there, a unilateral
// constraint (docs/mechanics.md, "Contact at the joints").
//
// Locked joints are eliminated, not bordered: with the set L locked at their limits q̄_i, the
// unknowns stay u = (q, r) (the same vector as EquilibriumProblem's, so branches, reports and
// shapes read it unchanged) and the rows of the locked joints become q̄_i − q_i = 0:
//   free i:    ∂E/∂q_i − (Jᵀ F)_i = 0
//   locked i:  q̄_i − q_i = 0
//   held c:    value_c(λ) − p_c(q) = 0.
// The contact torque of a locked joint is the reaction that closes its equilibrium row,
//   τ_c,i = ∂E/∂q_i − (Jᵀ F)_i,
// the generalised torque the contact applies to joint i (positive towards increasing q_i).
// A compressive contact pushes the joint back into its admissible range: τ_c ≤ 0 at an upper
// limit, τ_c ≥ 0 at a lower one; the *compression* c_i = −side·τ_c (side +1 upper, −1 lower) is
// ≥ 0 while the contact holds. It is exactly 0 where the branch reaches the limit (the free
// equilibrium holds there) and the contact releases where it returns to 0: that is a boundary
// g = c_i ≥ 0 of ContactProblem, located by the tracer like a joint limit.
//
// Vertices held on the base wall (wall_contact.h) are bordered, not eliminated: each adds its
// force μ_v to the unknowns, u = (q, r, μ), and its row −x_v(q) = 0; the q rows gain −μ_v ∇x_v
// and K_q − K_g's generator −μ_v (x_v − x_Pm) (the same generator form). A branch stores (q, r)
// only: μ is recovered at any equilibrium by least squares on the free rows, which it closes
// exactly (wallForces), as a locked joint's torque is read off its row.
//
// Self contacts (self_contact.h: a vertex held on another link's triangle edge) are bordered like
// the wall's vertices, after them: u = (q, r, μ_wall, μ_self), rows −g(q) = 0, the q rows gain
// −μ ∇g and the Hessian −μ ∂²g, whose rank-2 part leaves the chain structure: while one is held,
// the solves and the stability take the dense route (O(n³) a point).
//
// Structure (O(n)): with the locked rows eliminated, F_u restricted to the free joints is
// K_q − K_g on the free indices F, whose entries are κ_a δ_ab − h_max(a,b) (eq 27): the same
// generator form, so the free block is U T Uᵀ of a chain structure of size |F| (chain_structure.h)
// assembled from κ_F and h_F. The bordered solves and the constrained stability (K_q − K_g on
// the free joints and on ker of the held rows J_h,F) are those of that reduced structure, O(n).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/branch.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/eigenvalue_memory.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::continuation {
class Tracer;
}

namespace buckle::mechanics {

/// Which limit of its range a joint touches: +1 upper (q_max), −1 lower (q_min).
enum class LimitSide { Lower = -1, Upper = 1 };

/// "upper" / "lower".
const char* toString(LimitSide side);

/// One locked joint (0-based index) at one of its limits.
struct LockedJoint {
  int joint = -1;
  LimitSide side = LimitSide::Upper;
  bool operator==(const LockedJoint& o) const { return joint == o.joint && side == o.side; }
};

/// The joints locked at their limits, sorted by joint, at most one side per joint, the vertices
/// held on the base wall (wall_contact.h), sorted, and the self contacts (self_contact.h), sorted.
class ContactSet {
 public:
  ContactSet() = default;
  /// Locks `joint` at `side` (replaces an existing lock of that joint). Throws
  /// std::invalid_argument for a negative joint.
  void lock(int joint, LimitSide side);
  /// Unlocks `joint` (no-op when it is free).
  void release(int joint);
  bool locked(int joint) const;
  /// Side of a locked joint (Upper for a free one: check locked() first).
  LimitSide side(int joint) const;
  /// Number of locked joints.
  int count() const { return int(joints_.size()); }
  /// No joint locked, no vertex on the wall, no self contact: the free chain.
  bool empty() const { return joints_.empty() && wall_.empty() && self_.empty(); }
  const std::vector<LockedJoint>& joints() const { return joints_; }
  /// 1-based joint numbers with their side, "3U 5L" ("" when none): the `locked` column.
  std::string label() const;
  /// Holds `vertex` on the wall (no-op when it is already held).
  void touch(const WallVertex& vertex);
  /// Lets `vertex` leave the wall (no-op when it is not held).
  void leave(const WallVertex& vertex);
  bool touching(const WallVertex& vertex) const;
  int wallCount() const { return int(wall_.size()); }
  const std::vector<WallVertex>& wall() const { return wall_; }
  /// The vertices on the wall, "3d+ 4j" ("" when none): the `wall` column.
  std::string wallLabel() const;
  /// Holds the self contact `c` (no-op when it is held).
  void hold(const SelfContact& c);
  /// Lets the self contact `c` go (no-op when it is not held).
  void separate(const SelfContact& c);
  bool holding(const SelfContact& c) const;
  int selfCount() const { return int(self_.size()); }
  const std::vector<SelfContact>& self() const { return self_; }
  /// The self contacts, "7d+ on 3d[j,+]; …" ("" when none): the `self` column.
  std::string selfLabel() const;
  /// Vertices on the wall and self contacts: the bordered contacts, whose forces follow (q, r).
  int gapCount() const { return wallCount() + selfCount(); }
  /// Throws std::invalid_argument naming the problem when a joint is outside [0, segments), a
  /// vertex is not a moving one (checkWallVertex) or a self contact is not one (checkSelfContact).
  void check(int segments) const;
  bool operator==(const ContactSet& o) const { return joints_ == o.joints_ && wall_ == o.wall_ && self_ == o.self_; }
  bool operator!=(const ContactSet& o) const { return !(*this == o); }

 private:
  std::vector<LockedJoint> joints_;
  std::vector<WallVertex> wall_;
  std::vector<SelfContact> self_;
};

/// The limit angle q̄ of joint i on `side` (the chain's limits: geometric or the scene's).
double limitAngle(const Chain& chain, int joint, LimitSide side);

/// The chain's equilibrium with the joints of `locked` held at their limits (file comment).
/// Same unknowns, parameter, scales and held-coordinate rows as `base`, which must outlive it.
/// Boundaries (2n, as EquilibriumProblem): k < n the upper side of joint k, k ≥ n the lower side
/// of joint k − n; for a free joint the joint limit g = q_max − q / q − q_min, for a joint locked
/// on that side its compression c ≥ 0 (release), for the other side of a locked joint the
/// (positive) distance to that limit. With a finite `maxCompression` (a torque, the problem's
/// units) one more boundary per locked joint, 2n + k for the k-th: maxCompression − c ≥ 0. Then,
/// when `base` traces the wall (EquilibriumOptions::wallAsBoundary), the smallest x over the
/// vertices not on the wall; then one per vertex on the wall, its force μ_v ≥ 0 (release).
class ContactProblem final : public continuation::Problem {
 public:
  /// Throws std::invalid_argument if a locked joint is outside the chain or maxCompression is
  /// not positive.
  ContactProblem(const EquilibriumProblem& base, ContactSet locked,
                 double maxCompression = std::numeric_limits<double>::infinity());

  const EquilibriumProblem& base() const { return base_; }
  const ContactSet& contacts() const { return locked_; }
  /// Free joints in increasing order.
  const std::vector<int>& freeJoints() const { return free_; }

  /// Contact torque τ_c,i = ∂E/∂q_i − (JᵀF)_i − Σ_v μ_v ∂x_v/∂q_i of joint i at (u, λ) (any
  /// joint; ~0 for a free one at an equilibrium); u is (q, r, μ) or (q, r) (μ then from
  /// wallForces). NaN outside the domain.
  double contactTorque(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                       int joint) const;
  /// Compression −side·τ_c,i of a locked joint (≥ 0 while the contact holds).
  double compression(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                     int joint) const;
  /// The wall forces μ (one per vertex of contacts().wall(), a force along +x on the chain) that
  /// close the free joints' rows of the base problem at (q, r) = u.head(base dimension) in the
  /// least-squares sense: exact at a constrained equilibrium. NaN outside the domain.
  Vector wallForces(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda) const;
  /// The self contacts' forces (one per contacts().self(), pushing the bodies apart along the
  /// edge's normal), read off the free rows as wallForces reads the wall's.
  Vector selfForces(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda) const;
  /// Both, wall then self (this problem's unknowns after (q, r)). NaN outside the domain.
  Vector contactForces(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda) const;
  /// (q, r) extended to this problem's unknowns (q, r, μ) with μ = contactForces.
  Vector withWallForces(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda) const;

  int dimension() const override { return base_.dimension() + locked_.gapCount(); }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::VectorRef F) const override;
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                continuation::MatrixRef Fu, continuation::VectorRef Flambda) const override;
  bool jacobianDirectionalDerivative(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                                     continuation::ConstVectorRef du, double dlambda, continuation::MatrixRef dFu,
                                     continuation::VectorRef dFlambda) const override;
  /// F_x x and F_xᵀ w in O(n) (contact_products.cpp): the base problem's products, the contacts'
  /// −Σ μ ∂²g in its generator form plus the self contacts' rank-2 terms, the gap rows and
  /// columns −∇g, the locked rows −e_i. The locator's structured refinements evaluate with them.
  bool jacobianApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                     continuation::ConstVectorRef x, continuation::VectorRef y) const override;
  bool jacobianTransposeApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                              continuation::ConstVectorRef w, continuation::VectorRef y) const override;
  /// F_xx[x, z] in O(n): with locked joints only the base problem's exact product, the locked rows
  /// (linear) zero; with gaps, whose rows and −Σ μ ∂²g move with ∂³g, central differences of
  /// jacobianApply() (Problem::secondDerivativeApplyByDifferences) — not the dense default's N×N.
  bool secondDerivativeApply(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                             continuation::ConstVectorRef x, continuation::ConstVectorRef z,
                             continuation::VectorRef y) const override;

  bool hasStabilityOperator() const override { return true; }
  /// H = K_q − K_g − Σ μ_v ∂²x_v (n×n), C = the held rows J_h, one row e_iᵀ per locked joint and
  /// one row ∇x_vᵀ per vertex on the wall.
  bool stabilityOperator(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, Matrix& H,
                         Matrix& C) const override;
  /// Inertia and lowest eigenvalues of K_q − K_g on the free joints and ker J_h,F, O(n) through
  /// the reduced chain structure (file comment).
  bool stability(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda, int lowestCount,
                 continuation::StabilityInfo& info) const override;
  /// The eigenvalues first … of the same operator by the certified searches, O(n) each
  /// (contact_stability.cpp); the core's dense default for short chains and beyond the borders.
  bool stabilityEigenvalues(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                            int first, continuation::VectorRef values) const override;
  /// With locked joints only (no wall or self contact): EquilibriumProblem's bound on every
  /// eigenvalue's rate for H on the free joints and the held rows' free columns
  /// (stabilityRateBoundOn), O(n); false otherwise (the slopes are then measured at every point).
  bool stabilityRateBound(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                          continuation::ConstVectorRef du, double dlambda, double& bound) const override;
  /// With locked joints only (no wall or self contact): the rates of those eigenvalues along
  /// (du, dλ) by Hellmann–Feynman, each eigenvector by inverse iteration on the reduced structure
  /// and EquilibriumProblem::eigenvalueRate — a locked joint's row e_iᵀ does not move along the
  /// tangent, so only the held rows' multipliers enter. O(n) each. False (the core then differences
  /// the eigenvalues along the tangent) with gaps, whose rows ∇gᵀ move with ∂²g, on the dense
  /// routes, and when an eigenvector's residual shows it was not found.
  bool stabilitySlopes(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                       continuation::ConstVectorRef du, double dlambda, int first, continuation::ConstVectorRef values,
                       continuation::VectorRef slopes) const override;
  /// The reduced structure's O(n) bordered solver (locked rows eliminated).
  std::unique_ptr<continuation::BorderedSolver> makeStructuredSolver(continuation::ProblemWorkspace& ws) const override;

  /// base.scales(), with the locked rows (angles) at scale 1.
  continuation::ProblemScales scales() const override;

  int boundaryCount() const override;
  /// The first torque bound (file comment), the wall's boundaries: the clearance of the vertices
  /// not on the wall (−1 when the base does not trace the wall), the release of wall vertex k.
  int torqueBoundBegin() const;
  int wallClearanceBoundary() const;
  int wallReleaseBoundary(int k) const;
  /// The self contacts' boundaries: the clearance of the link pairs not in contact (−1 when the
  /// base does not trace self contact, EquilibriumOptions::selfContactAsBoundary), the release of
  /// self contact k (its force ≥ 0) and, the first of two, its vertex's distance to the ends of
  /// its edge (t·|e| ≥ 0 to the apex end, then (1 − t)·|e| ≥ 0 to the base corner: it slides off
  /// the edge there; two smooth boundaries, as min(t, 1 − t) would let a step that crosses the
  /// whole edge locate the end it started at; |e|, never crossed, for a vertex held at a corner by
  /// both its edges: self_contact.h heldAtCorner).
  int selfClearanceBoundary() const;
  int selfReleaseBoundary(int k) const;
  int selfEdgeBoundary(int k) const;
  bool selfHeldAtCorner(int k) const { return selfAtCorner_[size_t(k)] != 0; }
  double boundary(continuation::ProblemWorkspace& ws, int k, continuation::ConstVectorRef u,
                  double lambda) const override;
  /// Every boundary(k) at once: the rows whose locked entries are the contact torques, and the
  /// wall forces, evaluated once for the point (boundary(k) evaluates them per locked joint).
  void boundaries(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                  continuation::VectorRef g) const override;
  std::string boundaryName(int k) const override;

  /// T of K_q − K_g (with the wall forces' terms) on the free joints into ws (size
  /// freeJoints().size()) and the end Jacobian's free columns into Jf (3×|F|); u = (q, r, μ).
  /// False outside the domain or when every joint is locked.
  bool assembleReduced(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                       ChainStructure& structure, continuation::MatrixRef Jf) const;
  /// The full structure (every joint) of K_q − K_g with the contact forces' terms in its generator,
  /// and the end Jacobian (3×n), at u = (q, r, μ): what the reduced structure is cut from. The self
  /// contacts' rank-2 terms, outside the structure, in selfColumns() and selfSigns().
  bool assembleFull(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                    ChainStructure& full, continuation::MatrixRef J) const;
  /// The wall vertices' ∇x_v (columns of wallGradients(), n×w) and generators of −∂²x_v (columns
  /// of wallGenerators(), wall_contact.h) at q, then the self contacts' ∇g and generators (their
  /// rank-2 terms in the workspace's selfCoupling, selfWeights); false when q is not finite.
  bool wallKinematics(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef q) const;
  static const Matrix& wallGradients(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).wallGrad;
  }
  static const Matrix& wallGenerators(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).wallGen;
  }
  /// The self contacts' rank-2 terms as R E Rᵀ (selfCouplingColumns) at the last assembleFull():
  /// R (n×2s, two columns per contact) and E's diagonal (±1).
  static const Matrix& selfColumns(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).selfColumns;
  }
  static const Vector& selfSigns(const continuation::ProblemWorkspace& ws) {
    return continuation::workspaceAs<Workspace>(ws).selfSigns;
  }

  /// The base problem's workspace and this problem's scratch (ProblemWorkspace).
  struct Workspace : continuation::ProblemWorkspace {
    explicit Workspace(const ContactProblem& problem);
    std::unique_ptr<continuation::ProblemWorkspace> base;
    ChainStructure full, reduced;
    Matrix J, Jf, heldRows;
    Vector kf, hf;    // κ_F, h_F of the reduced structure
    Vector residual;  // the free equilibrium's rows (contact torques), size N
    Vector lastLowest;
    Matrix wallGrad, wallGen;  // n×(w + s): ∇g and the generators of −∂²g (wallKinematics)
    Vector wallX;              // the gaps: x_v of the wall vertices, then the self contacts' g
    Matrix selfCoupling, selfWeights;  // n×s: −∂²g's rank-2 term (self_contact.h)
    Matrix selfColumns, selfColumnsFree;  // −μ∂²g's rank-2 terms as R E Rᵀ: R (n×2s) and its free rows
    Vector selfSigns;                     // E's diagonal (2s)
    Vector selfAlong, selfEdgeLength;  // where each self contact's vertex is along its edge
    Vector unknowns;           // (q, r, μ) of boundaries()
    Vector productIn, productOut;  // the base problem's (N + 1) operands of the O(n) products
    Vector slopeFree, slopeHv, slopeFull;  // stabilitySlopes(): v and H v on the free joints, v on all
    EigenvalueMemory found;  // stabilityEigenvalues(): warm starts from the values found lately
    Vector guess;            // (size ChainStructure::kMaxBorder)
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override;

 private:
  // The base problem's rows at (q, r) with the wall forces' terms −Σ μ_v ∇x_v added to the q rows.
  bool baseRowsWithWall(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda,
                        VectorRef F) const;

  // Whether the reduced structure's counts take this point's constraints and coupling (and more
  // than denseUpTo free joints); the reduced operator into the workspace (contact_stability.cpp).
  bool structuredSpectrum(int denseUpTo) const;
  bool reducedOperator(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double lambda) const;

  const EquilibriumProblem& base_;
  ContactSet locked_;
  double maxCompression_;
  std::vector<int> free_;
  std::vector<int> held_;
  std::vector<char> selfAtCorner_;  // per self contact: heldAtCorner
};

/// K_q − K_g on the joints `free` (increasing) of `full`: the generator form κ_a δ_ab − h_max(a,b)
/// (eq 27) with κ_F, h_F (scratch kf, hf of size |F|) assembled into `reduced`. O(n).
void reduceToFreeJoints(const ChainStructure& full, const std::vector<int>& free, VectorRef kf, VectorRef hf,
                        ChainStructure& reduced);

/// The name of ContactProblem's release boundary of a vertex on the wall.
std::string wallReleaseName(const WallVertex& v);
/// The names of a self contact's release boundary and of its edge-end boundary.
std::string selfReleaseName(const SelfContact& c);
std::string selfEdgeName(const SelfContact& c);

/// A stretch of a traced branch with one set of locked joints: points [firstPoint, the next
/// stretch's firstPoint) of the branch (equilibrium_branches.h). The point where a contact
/// starts or releases ends the stretch before it.
struct ContactStretch {
  int firstPoint = 0;
  ContactSet locked;
};

/// The locked joints at point `index` of a branch with these stretches (empty set when none).
const ContactSet& lockedAt(const std::vector<ContactStretch>& stretches, int index);

/// Boundary k of ContactProblem / EquilibriumProblem as (joint, side).
LockedJoint limitOfBoundary(int k, int segments);

/// An equilibrium at fixed λ with the joints of `locked` held at their limits and its wall
/// vertices on the wall: Newton on the ContactProblem's rows with its O(n) solver from u0 = (q, r)
/// (q of locked joints set to their limits first, the wall forces from least squares); `u` of the
/// result is (q, r). `tolerance` bounds the scaled residual (rows over ProblemScales::residuals).
struct ConstrainedEquilibrium {
  bool converged = false;
  continuation::Vector u;          ///< (q, r)
  double residual = 0.0;           ///< max scaled |F_i| at u
  int iterations = 0;
  continuation::Vector torques;    ///< contact torque τ_c,i of every joint (0 at free ones)
  /// The wall forces μ_v, one per vertex of locked.wall() (a force along +x on the chain).
  continuation::Vector wallForces;
  /// The self contacts' forces, one per locked.self().
  continuation::Vector selfForces;
  /// Smallest compression among the locked joints and the wall forces (+inf when none): < 0
  /// means the contact would pull, so that joint or vertex should be released.
  double minCompression = 0.0;
  std::string message;             ///< why it did not converge
};
ConstrainedEquilibrium solveConstrainedEquilibrium(const EquilibriumProblem& base, const ContactSet& locked,
                                                   continuation::ConstVectorRef u0, double lambda,
                                                   double tolerance = 1e-12, int maxIterations = 30);

/// The start of the stretch after a contact event (continueUnderContact), on `tracer`'s problem:
/// the ContactProblem of the new contacts `locked`. The located event point `at` is polished at
/// its λ (solveConstrainedEquilibrium); a start short of the polish's tolerance but within the
/// corrector's is as accurate as any traced point. Where that fails — the new stretch (nearly)
/// turns back in λ at the event, so the equilibrium at fixed λ is (nearly) singular: a release
/// right after its contact, where the free motion returns from the stop (a grazing contact) —
/// on the hyperplane through the point normal to `direction` (the branch's, size D + 1 of the
/// tracer's problem), by the corrector's Keller system, regular at a fold in λ, to the
/// corrector's tolerance.
struct EventStart {
  bool polished = false;
  bool acrossBranch = false;   ///< by the Keller system (λ moved off the event's), not at fixed λ
  continuation::Vector u;      ///< (q, r) of the tracer's problem
  double lambda = 0.0;
  std::string message;         ///< why not polished
};
EventStart polishEventStart(const EquilibriumProblem& base, const ContactSet& locked,
                            const continuation::SpecialPoint& at, continuation::Tracer& tracer,
                            continuation::ConstVectorRef direction);

/// Stability of the constrained system at (u, λ): K_q − K_g on the free joints and ker J_h,F.
continuation::StabilityInfo constrainedStability(const EquilibriumProblem& base, const ContactSet& locked,
                                                 continuation::ConstVectorRef u, double lambda, int lowestCount = 1);

/// The joints within `tolerance` (radians) of a limit at q, on that side.
ContactSet jointsAtLimits(const Chain& chain, continuation::ConstVectorRef q, double tolerance);

/// Loaded stiffness K_F (eq 29) with the locked joints rigid (δq_i = 0): C_F = J_p P J_pᵀ, P the
/// inverse of K_q − K_g on ker [E_L; J_φ if the rotation is held], E_L the locked rows. With
/// vertices on the wall, their rows ∇x_vᵀ join E_L and their forces `wallForces` (one per vertex
/// of locked.wall()) add −Σ μ_v ∂²x_v to the Hessian (wall_contact.h).
CartesianStiffness lockedLoadedStiffness(const Chain& chain, continuation::ConstVectorRef q, const Wrench& F,
                                         const EndCondition& end, const ContactSet& locked,
                                         const StiffnessOptions& options = {},
                                         continuation::ConstVectorRef wallForces = continuation::Vector());

/// The loaded stiffness of `problem`'s constrained chain at (u, λ) (u = (q, r) or with the contact
/// forces), dense: C_F = J_p Z (Zᵀ H Z)⁻¹ Zᵀ J_pᵀ with H its stability operator (the contacts'
/// Hessian terms, a self contact's rank-2 one included) and Z a basis of the motions that keep the
/// locked joints, the contacts and φ where it is held. O(n³): what points holding a self contact
/// take, where lockedLoadedStiffness has no room for the rank-2 term.
CartesianStiffness denseContactStiffness(const ContactProblem& problem, continuation::ConstVectorRef u, double lambda);

/// The same quantities in O(n) through the reduced chain structure (contact_stiffness_structured.cpp):
/// the counts and certified eigenvalue searches for the inertia and the condition number, bordered
/// solves for C_F; where ZᵀHZ is singular (`singular`), K_F from the position-held system instead of
/// NaN. False (s unusable: take the dense one) with more than three constraint rows (gaps and a
/// held φ), more borders than the structure holds, or a factorization that fails.
bool structuredContactStiffness(const ContactProblem& problem, continuation::ConstVectorRef u, double lambda,
                                CartesianStiffness& s);

}  // namespace buckle::mechanics
