// Jumps (snap-through at a fold, escape from an unstable equilibrium) and sudden loads: the
// dynamic step between two equilibria, polished back onto the quasi-static model.
//
// simulateJump: from an equilibrium (u, λ) that is unstable or critical (a fold: the projected
// Hessian K_q − K_g on ker J_h has a negative or zero eigenvalue), or from a state just past a
// fold, the loads and held targets are frozen at their λ values and the chain is released:
//   1. δq = ε·v, v the eigenvector of the smallest eigenvalue of Zᵀ(K_q − K_g)Z (Z a basis of
//      ker J_h, eq 27), or the caller's direction. When that eigenvalue is multiple (eigenvalues
//      within δ = 1e-8 of the operator's scale of the lowest count as one, e.g. the straight chain
//      of identical segments, whose n − 1 eigenvalues on ker J_y coincide) v is the orthogonal
//      projection onto its eigenspace of the fixed reference vector z_i = 1 + ½ sin(1 + 2.399963 i)
//      (i = 0 … n−1; every component present, no symmetry of the chain), normalised: the same
//      direction on the dense and the O(n) routes, so both land on the same equilibrium (for a
//      simple eigenvalue this is its eigenvector). The sign is the one with the lower Π(q ± δq)
//      (at a fold the quadratic term vanishes and the cubic one decides where the chain goes);
//      with held coordinates the perturbed start is projected back onto them;
//   2. the dynamics (inertial if the scene has masses, else the gradient flow, see dynamics.h)
//      runs until rest — or, for the gradient flow with JumpOptions::handover, until the state
//      passes the basin test: projected Hessian positive definite at the state q, Newton from q
//      converges to a stable equilibrium q* with Π(q*) <= Π(q), and the Hessian is positive
//      definite at the midpoint of q and q* too. (If the Hessian is positive definite on the ball
//      around q* through q, the flow cannot leave it — d|q − q*|²/dt = −2(q − q*)ᵀ∇Π/c < 0 there —
//      and ends at q*; the test samples that ball on the segment, and is consulted only once the
//      equilibrium residual has fallen below IntegrationOptions::settleResidual.) The landing is
//      then q* itself: the creep to rest, hundreds of steps at the integrator's tolerance, is
//      replaced by a few Newton steps;
//   3. the rest point is polished by Newton on the EquilibriumProblem residual at fixed λ — the
//      continuation core's KINSOL corrector in its fixed-parameter mode — and its stability is
//      checked with Problem::stability() (K_q − K_g positive definite on ker J_h).
//      A chain that came to rest with joints in contact (dynamics.h: joint limits are one-sided
//      constraints) is polished with those joints fixed at their limits (contact.h,
//      solveConstrainedEquilibrium), and its stability is that of the constrained system
//      (constrainedStability: the reduced Hessian K_q − K_g on the free joints and ker J_h
//      positive definite) with every contact compressive (−side·τ_c,i > 0).
//
// simulateSuddenLoad: the "sporadic" case — the full end condition is applied at once to the
// chain at rest in its unloaded shape. The chain's dynamic answer can differ from the
// quasi-static one at the same load (it may overshoot into another basin of Π); the result
// says whether it does and which of the two is lower in Π.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/problem.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

/// Defaults of the rest-point polish: tight residual, line search, room for the iterations.
continuation::CorrectorOptions defaultPolishOptions();

struct PolishResult {
  Vector u;                  ///< unknowns (q, reactions) at the last iterate
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;     ///< ‖F(u, λ)‖∞ of the EquilibriumProblem at u
  std::string message;       ///< the corrector's flag name (and message on failure)
};

/// Newton on F(u, λ) = 0 at fixed λ from the joint angles q (reactions: least-squares guess).
PolishResult polishEquilibrium(EquilibriumProblem& problem, ConstVectorRef q, double lambda,
                               const continuation::CorrectorOptions& options = defaultPolishOptions());

struct UnstableDirection {
  Vector direction;          ///< unit vector in joint space, in ker J_h (empty if none)
  double eigenvalue = 0.0;   ///< the smallest eigenvalue of Zᵀ(K_q − K_g)Z
  bool valid = false;        ///< false: the stability operator could not be evaluated
};

/// Dense (eigen-solve of Zᵀ(K_q − K_g)Z, O(n³)) or O(n) (Sturm counts and inverse iteration on
/// the chain structure) computation of the unstable direction; Automatic: O(n) above kSmallDense.
enum class DirectionRoute { Automatic, Dense, Structured };

/// Eigenvector of the smallest eigenvalue of the stability operator on ker J_h at (u, λ)
/// (u = joint angles, or the full unknowns); for a multiple smallest eigenvalue the projection
/// of the reference vector onto its eigenspace (file comment, step 1). Sign not chosen here.
UnstableDirection unstableDirection(EquilibriumProblem& problem, ConstVectorRef u, double lambda,
                                    DirectionRoute route = DirectionRoute::Automatic);

/// The rule's reference vector z_i = 1 + ½ sin(1 + 2.399963 i), i = 0 … n−1 (file comment).
Vector directionReference(int n);

/// Integration settings for a jump of a chain of `segments` segments. A jump starts at a fold,
/// where the flow is slowest (critical slowing down) while the chain's other modes stay fast: a
/// stiff problem whose stiffness ratio grows with n. From 10 segments on the L-stable Rosenbrock
/// method, which steps by the slow mode (the default scene with 50 segments: 0.2 s per jump,
/// against 15 s with dopri5, one of which did not reach rest by maxTime); below, dopri5, whose
/// finite-difference-free steps are as fast there and which the short chains' tests pin. Above
/// kStructuredJumpFrom segments the dense Rosenbrock method's O(n³) per step dominates: the same
/// method on the chain structure (StepperKind::StructuredRosenbrock4, O(n) per step; for the
/// inertial model too, through its exact Jacobian, dynamics.h). There the stepper is
/// StepperKind::StructuredSwitching: Dormand–Prince 5(4) while the flow is not stiff, that
/// Rosenbrock method while it is (Hairer's stiffness test). A fold's start is stiff (the slow
/// mode against the chain's fast ones) and gets the Rosenbrock steps; the cascade of the
/// straight chain below is not: its steps are limited by accuracy, Dormand–Prince's order-4
/// error estimate allows about twice the step of Rosenbrock4's order-3 one, at a fraction of the
/// cost per step (no factorization, no stage solves): 735 steps instead of 1989 at n = 1000,
/// the same landing (benchmarks/RESULTS.md).
///
/// Above kStructuredJumpFrom segments the local error tolerance (absolute and relative) is
/// kLongJumpTolerance instead of IntegrationOptions' 1e-10. There the gradient flow hands over to
/// Newton (Handover::Automatic) and the landing is the polished equilibrium either way: the
/// integration has to find the basin, not the path to 1e-10. What a long chain's jump costs is
/// the number of steps, and a fourth-order method's steps grow as tol^(-1/4): the straight chain
/// of 1000 identical bistable segments released at Fx = 0 (jump_timing, case degenerate) takes
/// 6158 steps at 1e-10 and about 2000 at 1e-8 — the cascade of joints snapping while the chain
/// coils (the absolute angles, sums of up to n joint angles, turn about n times faster than a
/// joint, and the held end's Jacobian follows them), not the escape from the start (about 100
/// steps) — and lands on the same equilibrium at every tolerance from 1e-6 to 1e-11 (‖Δq‖∞ ≤
/// 2e-15, benchmarks/RESULTS.md). The shorter chains, whose jumps the scenes' regression
/// baselines pin, keep 1e-10.
constexpr int kStructuredJumpFrom = 64;
constexpr double kLongJumpTolerance = 1e-8;
IntegrationOptions jumpIntegrationDefaults(int segments);

/// When the gradient flow of a jump hands over to Newton in a stable basin (file comment, step
/// 2): Automatic above kStructuredJumpFrom segments (the shorter chains' jumps, which the scenes'
/// regression baselines pin, integrate to rest), Always, Never. The inertial model always
/// integrates to rest (its kinetic energy can carry it out of a convex region).
enum class Handover { Automatic, Always, Never };

struct JumpOptions {
  DynamicsScene scene;                   ///< masses given → inertial dynamics, else gradient flow
  IntegrationOptions integration;       ///< see jumpIntegrationDefaults for long chains
  continuation::CorrectorOptions polish = defaultPolishOptions();
  /// ‖δq‖₂ of the initial perturbation along the unstable direction (0: none, e.g. just past a
  /// fold where the state is not an equilibrium any more).
  double perturbation = 1e-3;
  /// Caller's direction (size n, any length); empty: the unstable eigenvector.
  Vector direction;
  /// A landing closer than this (‖Δq‖∞) to the start means the chain did not jump.
  double sameStateTolerance = 1e-6;
  Handover handover = Handover::Automatic;
  /// The base wall x = 0 as a one-sided contact (wall_contact.h; the scene traces the wall): a
  /// moving vertex that reaches it during the dynamics is held on it and slides along it
  /// (IntegrationOptions::wall), leaves it where its force returns to zero, and the chain comes
  /// to rest on the constrained equilibrium, polished with the vertices then on the wall
  /// (wall_landing.h's active set). false: the wall is ignored
  /// (the chain passes through it, as the continuation without the wall); a landing behind it is
  /// flagged (JumpResult::behindWall) and said so in the message.
  bool wall = false;
  /// The chain's contact with itself as a one-sided contact (self_contact.h; the scene traces
  /// self contact): links that meet during the dynamics are held apart by the touching vertex–edge
  /// pair (IntegrationOptions::self), which slides, and releases where its force returns to zero;
  /// the chain comes to rest on the constrained equilibrium with the self contacts then
  /// (wall_landing.h's active set). false: the links pass through each other.
  bool self = false;

  /// Empty when valid for `problem`, else what is wrong, the field named by its path.
  std::string validate(const EquilibriumProblem& problem, const std::string& prefix = "") const;
  bool IsValid(const EquilibriumProblem& problem, std::string* why) const {
    return continuation::reportValidity(validate(problem), why);
  }
};

struct JumpResult {
  bool success = false;      ///< rest reached (or settled), polish converged, landing stable and distinct
  std::string message;       ///< why it ended (or what failed)
  IntegrationStop stopReason = IntegrationStop::MaxSteps;
  double lambda = 0.0;
  Eigen::Vector3d prescribed = Eigen::Vector3d::Zero();  ///< loads / held targets at λ
  Vector from, to;           ///< unknowns (q, reactions) at the start and at the polished landing
  Vector restPoint;          ///< q where the integration stopped, before polishing
  Vector direction;          ///< the signed perturbation direction used (unit, joint space)
  double directionEigenvalue = 0.0;  ///< its Hessian eigenvalue (NaN if the caller gave it)
  double potentialFrom = 0.0, potentialTo = 0.0;
  double energyReleased = 0.0;       ///< ΔΠ = Π(from) − Π(to)
  double distance = 0.0;             ///< ‖q_to − q_from‖∞
  double duration = 0.0;             ///< model time until rest (or the hand-over)
  long steps = 0, rejectedSteps = 0;
  int basinTests = 0;                ///< hand-over tests run (step 2), the last passed if settled
  double wallSeconds = 0.0;
  double residual = 0.0;             ///< ‖F‖∞ of the EquilibriumProblem at `to`
  bool polishConverged = false;
  int polishIterations = 0;
  double polishShift = 0.0;          ///< ‖q_to − restPoint‖∞
  continuation::StabilityInfo stabilityFrom, stabilityTo;
  bool stable = false;               ///< stabilityTo.stable() (and, in contact, every contact compressive)
  /// Joints in contact at the landing (per joint 0, +1 upper, −1 lower; all 0 without contact)
  /// and their contact torques τ_c,i (contact.h: ∂E/∂q_i − (JᵀF)_i, 0 at free joints).
  std::vector<int> contactSides;
  Vector contactTorques;
  /// JumpOptions::wall: the chain reached the base wall during the dynamics, `wallVertex` first
  /// (its x then `wallGap`: 0 to the event location's accuracy; or the caller's barrier
  /// IntegrationOptions::admissible stopped the dynamics there, IntegrationStop::Barrier).
  bool reachedWall = false;
  WallVertex wallVertex;
  double wallGap = 0.0;
  /// Vertices held on the wall at the landing and their forces μ_v (wall_contact.h; empty: none).
  std::vector<WallVertex> wallContacts;
  Vector wallForces;
  /// Self contacts held at the landing and their forces (self_contact.h; empty: none).
  std::vector<SelfContact> selfContacts;
  Vector selfForces;
  /// Without JumpOptions::wall: the polished landing has a vertex behind the base wall (the
  /// dynamics passed through it; detected, not prevented).
  bool behindWall = false;
  DynamicsResult dynamics;           ///< the trajectory and its energies
};

/// Releases the chain from (u, λ) with the problem's loads / targets frozen at λ. u is the joint
/// angles (size n) or the full unknowns. Throws std::invalid_argument for invalid options or
/// sizes; every other outcome is reported in JumpResult.
JumpResult simulateJump(EquilibriumProblem& problem, ConstVectorRef u, double lambda, const JumpOptions& options);

struct SuddenLoadOptions {
  DynamicsScene scene;
  IntegrationOptions integration;
  continuation::CorrectorOptions polish = defaultPolishOptions();
  /// ‖q_dynamic − q_static‖∞ above this: the two answers differ.
  double sameStateTolerance = 1e-6;
  /// The base wall and the chain's contact with itself as one-sided contacts (as JumpOptions).
  bool wall = false;
  bool self = false;

  /// Empty when valid for `chain`, else what is wrong, the field named by its path.
  std::string validate(const Chain& chain, const std::string& prefix = "") const;
  bool IsValid(const Chain& chain, std::string* why) const { return continuation::reportValidity(validate(chain), why); }
};

enum class LowerPotential { Dynamic, Static, Equal };
const char* toString(LowerPotential lower);

struct SuddenLoadResult {
  bool success = false;              ///< rest reached, polish converged, stable
  std::string message;
  bool inertial = false;             ///< which model ran
  Vector start;                      ///< the start (unloaded shape, projected onto held targets)
  Vector rest;                       ///< polished final rest shape q
  Vector restUnknowns;               ///< (q, reactions)
  double residual = 0.0;
  bool polishConverged = false;
  continuation::StabilityInfo stability;
  bool stable = false;               ///< (in contact: of the constrained system, contacts compressive)
  std::vector<int> contactSides;     ///< joints in contact at rest (as JumpResult)
  Vector contactTorques;             ///< their contact torques τ_c,i
  bool reachedWall = false;          ///< as JumpResult
  WallVertex wallVertex;
  std::vector<WallVertex> wallContacts;
  Vector wallForces;
  std::vector<SelfContact> selfContacts;  ///< as JumpResult
  Vector selfForces;
  double peakKinetic = 0.0;          ///< over the recorded trajectory
  double maxExcursion = 0.0;         ///< max ‖q(t) − start‖∞ over the recorded trajectory
  // comparison with the quasi-static answer (NaN / false when no q_static was given)
  bool compared = false;
  Vector staticShape;
  double maxDifference = 0.0;        ///< ‖rest − q_static‖∞
  bool differs = false;
  double potentialDynamic = 0.0, potentialStatic = 0.0;
  LowerPotential lower = LowerPotential::Equal;
  DynamicsResult dynamics;
};

/// Applies `loaded` at once to the chain at rest in `qUnloaded` and follows it to rest; compares
/// with `qStatic` (the quasi-static answer at the same load; pass an empty vector to skip).
SuddenLoadResult simulateSuddenLoad(const Chain& chain, const EndCondition& loaded, ConstVectorRef qUnloaded,
                                    ConstVectorRef qStatic, const SuddenLoadOptions& options);

}  // namespace buckle::mechanics
