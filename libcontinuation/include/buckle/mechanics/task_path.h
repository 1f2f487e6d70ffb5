// Task-space paths (inverse statics, issue 29): the end pose — any subset of x, y, φ — follows a
// straight leg of a task path under a fixed payload (all three end loads given), and chosen
// control inputs (control_path.h) are unknowns beside the joint angles.
//
// Inputs p_j (j = 1 … m_in), each a named input of one segment or of every segment, move the free
// lengths from those of the chain (at the inputs' start values p⁰):
//   L⁰_{i,s}(p) = L⁰_{i,s} + Σ_j (p_j − p⁰_j)·r_j(i, s)        (r_j: ControlDirection::named rates)
// The equilibrium under the payload F, the links' weight and point loads (body_loads.h: potential
// V, ∂V/∂q = −τ, eq B2) and the task constraint on the chosen coordinates c (m of them):
//   g(q, p) = ∂E/∂q(q, p) − J(q)ᵀF − τ(q) = 0                    (eq 9 with eq B2, n rows)
//   τ(q, s) = c(q) − t(s) = 0,   t(s) = a + (s − s_a)·d          (m rows; d = dt/ds, the leg's direction)
// with s the arclength of the task path (an angle counted at the length `angleLength` per radian).
// Derivatives: ∂g/∂q = H = K_q − K_g(F) with the generator h − γ (eq 27, eq B3), ∂g/∂p_j = B_j with
//   B(i, j) = Σ_s r_j(i, s)·∂²E/∂q_i∂L⁰_{i,s} = −Σ_s r_j(i, s) k_s L_s′(q_i),
// ∂τ/∂q = J_c (rows of eq 11), ∂τ/∂s = −d.
//
// Redundancy rules:
//  (a) Chosen: m_in = m inputs, the others fixed. Unknowns u = (q, p), F_u = [[H, B], [J_c, 0]]:
//      regular except at a fold of the task map (the inputs-to-pose map on the equilibria is
//      singular there), which the tracer locates as a limit point in s.
//  (b) MinimumChange: m_in ≥ m inputs, the weighted least change from the start,
//        minimise ½ Σ_j w_j (p_j − p⁰_j)²/b̄²  subject to g = 0, τ = 0,
//      continued along the path through its optimality (KKT) system, u = (q, p, μ, ν):
//        R_q = H μ + J_cᵀ ν = 0                     (∂ℒ/∂q)
//        R_p = W (p − p⁰)/b̄² + Bᵀ μ = 0            (∂ℒ/∂p)
//        R_μ = g = 0,  R_ν = τ = 0
//      with ℒ = ½(p − p⁰)ᵀW(p − p⁰)/b̄² + μᵀg + νᵀτ. Its Jacobian is the symmetric Hessian of ℒ:
//        [[A, D, H, J_cᵀ], [Dᵀ, W/b̄², Bᵀ, 0], [H, B, 0, 0], [J_c, 0, 0, 0]]
//      A = ∂(Hμ)/∂q + Σ_c ν_c ∂²c/∂q² = diag(E‴ ⊙ μ) − K_a + K_b, where K_a(i, k) = a_max(i,k),
//        a_m = ρ_m Σ_{j≤m} μ_j + Σ_{j>m} ρ_j μ_j,  ρ_m = Fx S_m − Fy C_m − τ_m (the generator
//        moves as dh_m − dγ_m = Θ_m ρ_m + Σ_{j>m} ρ_j dq_j, eq B5: the third derivative of
//        F·pose − V depends on the largest index only, as eq 27's second does), and
//        K_b(i, k) = −ν_x C_max(i,k) − ν_y S_max(i,k) (∂²x/∂q², ∂²y/∂q²; φ is linear in q);
//      D(i, j) = ∂(K_q μ)_i/∂p_j = −Σ_s r_j(i, s) k_s L_s″(q_i) μ_i (E is quadratic in L⁰, so
//      ∂B/∂p = 0). At the start p = p⁰, μ = ν = 0 solves it exactly.
//
//  (c) MostStable: m_in ≥ m inputs chosen to keep the equilibrium as stable as the task allows:
//        maximise μ = μ_min(H(q, p)), the smallest eigenvalue of K_q − K_g at fixed inputs,
//        subject to g = 0, τ = 0,
//      continued along the path through its optimality system with the eigenpair (v, μ) as
//      unknowns, u = (q, p, α, β, v, μ) (size 3n + m_in + m + 1):
//        R_q = −θ ∇_q μ + H α + J_cᵀ β = 0,      ∇_q μ = vᵀ(∂H/∂q)v = A(v) v
//        R_p = (1 − θ) T W (p − p⁰)/b̄² − θ ∇_p μ + Bᵀ α = 0,   (∇_p μ)_j = Σ_i v_i² ∂²(K_q)_ii/∂p_j
//        R_α = g = 0,  R_β = τ = 0,  R_v = H v − μ v = 0,  R_μ = ½(vᵀv − 1) = 0
//      with A(v) = ∂(H v)/∂q as in (b) (ν = 0), T = k̄b̄² the torque unit. θ = 1 on the path; the
//      start is reached from rule (b)'s trivial point at the chain's own inputs (p = p⁰,
//      α = β = 0, v the lowest eigenvector) by continuation in θ from 0 to 1 at s = 0
//      (mostStableStart), so the path starts at the optimum connected to the chain's own
//      inputs. The Jacobian needs ∂(A(v)v)/∂(q, p), fourth derivatives of E: it is differenced
//      centrally from the exact residual (the points' accuracy is the residual's). The optimum
//      stays smooth while μ is a simple eigenvalue: where the next eigenvalue meets it (a
//      max–min optimum typically ends there), a boundary stops the path and says so.
//
// Stability of a point is that of the equilibrium at fixed inputs: H positive definite (the end
// is free under the payload). It is O(n) through the chain structure (chain_structure.h) and is
// reported to the tracer as a boundary (smallest eigenvalue ≥ 0), so the path ends on the exact
// point where the equilibrium that follows the task loses its stability. Joint limits and input
// bounds are boundaries too. The problem has no stability operator of its own for the tracer:
// the continuation's regularity is that of F_u above, not of H.
//
// Costs: rule (a) has an O(n) bordered solver (H = U T Uᵀ bordered by the m input columns, the
// tracer's column and the locator's, task_path_solver.h); rule (b) an O(n·(m_in + m)) block
// elimination through H (task_path_kkt_solver.h). Stability at fixed inputs is O(n).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/problem.h"
#include "buckle/continuation/tracer_options.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/control_path.h"

namespace buckle::mechanics {

/// One control input as an unknown: `input` of segment `segment` (0-based) or of every segment (−1).
struct TaskInput {
  ControlInput input = ControlInput::dL0;
  int segment = -1;
  double weight = 1.0;  ///< rule (b): w_j (relative; > 0)
  double lower = -std::numeric_limits<double>::infinity();  ///< bounds on the input's value
  double upper = std::numeric_limits<double>::infinity();
};
/// "dL0" (every segment) or "dL0[3]" (segment 3, 1-based): the name of an input column.
std::string taskInputName(const TaskInput& input);

enum class TaskRule { Chosen, MinimumChange, MostStable };

/// The payload, the constrained coordinates, the inputs and the rule (what does not move along a path).
struct TaskSetup {
  Wrench payload = Wrench::Zero();
  /// The links' weight and point loads, at their values for λ = 0 (BodyLoads::atParameter(0):
  /// the path's parameter is the task's arclength, not a load). Checked against the chain by
  /// TaskPathProblem.
  BodyLoads body;
  std::vector<int> coordinates;  ///< ascending subset of {0 x, 1 y, 2 φ}, 1 … 3 of them
  std::vector<TaskInput> inputs;
  TaskRule rule = TaskRule::Chosen;
  /// Report loss of stability at fixed inputs as a boundary (the path ends there).
  bool stabilityBoundary = true;
  /// Joint limits as boundaries (the path ends on one).
  bool jointLimits = true;
  /// Throws std::invalid_argument naming what is wrong (counts for the rule, segments, weights).
  void validate(int segments) const;
};

/// One straight leg of the task path: t(s) = start + (s − s0)·direction on the chosen coordinates.
struct TaskLeg {
  Eigen::VectorXd start;      ///< m values
  Eigen::VectorXd direction;  ///< dt/ds (m values)
  double s0 = 0.0;
};

class TaskPathProblem final : public continuation::Problem {
 public:
  /// Throws std::invalid_argument (TaskSetup::validate).
  TaskPathProblem(const Chain& chain, const TaskSetup& setup);

  const Chain& chain() const { return chain_; }
  const TaskSetup& setup() const { return setup_; }
  int segments() const { return n_; }
  int inputCount() const { return mIn_; }
  int taskCount() const { return m_; }
  /// The inputs' values on the chain (p⁰).
  const Vector& startInputs() const { return p0_; }
  void setLeg(const TaskLeg& leg) { leg_ = leg; }
  const TaskLeg& leg() const { return leg_; }
  /// t(s) of the current leg (m values).
  Vector target(double s) const { return leg_.start + (s - leg_.s0) * leg_.direction; }

  /// Views into u: joint angles and inputs.
  Vector jointAngles(continuation::ConstVectorRef u) const { return u.head(n_); }
  Vector inputs(continuation::ConstVectorRef u) const { return u.segment(n_, mIn_); }
  /// The unknown vector at joint angles q and inputs p (multipliers zero: the start of rule (b)).
  Vector pack(continuation::ConstVectorRef q, continuation::ConstVectorRef p) const;
  /// The chain with the free lengths at inputs p (throws std::invalid_argument if one is ≤ 0).
  Chain chainAt(continuation::ConstVectorRef p) const;
  /// n×2 change of the free lengths at inputs p from the chain's.
  Eigen::MatrixX2d freeLengthChange(continuation::ConstVectorRef p) const;

  int dimension() const override { return dim_; }
  bool residual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double s,
                continuation::VectorRef F) const override;
  bool jacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double s,
                continuation::MatrixRef Fu, continuation::VectorRef Fs) const override;
  bool jacobianWritesAllEntries() const override { return true; }

  /// Boundaries: joint upper limits (n), lower limits (n), input upper / lower bounds (2 m_in),
  /// the free lengths L1⁰, L2⁰ of every segment (2n, > 0: the inputs' admissible range), then
  /// the smallest eigenvalue of H at fixed inputs over the stability scale (1); rule (c) also
  /// the gap from the tracked eigenvalue μ to the nearest other one (1, header).
  int boundaryCount() const override { return 4 * n_ + 2 * mIn_ + 1 + (setup_.rule == TaskRule::MostStable ? 1 : 0); }
  double boundary(continuation::ProblemWorkspace& ws, int k, continuation::ConstVectorRef u, double s) const override;
  std::string boundaryName(int k) const override;
  /// What kind of boundary k is.
  enum class BoundaryKind { JointLimit, InputBound, Stability, Coalescence };
  BoundaryKind boundaryKind(int k) const;

  /// Inertia and smallest eigenvalue of H = K_q − K_g at fixed inputs, O(n). False outside the domain.
  bool fixedInputStability(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, Inertia& inertia,
                           double& smallest) const;

  /// Rule (c): the residual with the objective's homotopy weight θ (header; θ = 1 on the path).
  bool mostStableResidual(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double s, double theta,
                          continuation::VectorRef F) const;
  /// The path's first point at joint angles q0 (the chain's own inputs, the end at the leg's
  /// start): pack(q0, p⁰) for rules (a), (b); for rule (c) the optimum reached by continuation in
  /// θ (header) with `options`' step settings. Throws std::runtime_error saying why it failed.
  Vector startPoint(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef q0,
                    const continuation::TracerOptions& options) const;
  /// Rule (c): the tracked eigenvalue μ and eigenvector v of u.
  double trackedEigenvalue(continuation::ConstVectorRef u) const { return u[dim_ - 1]; }

  /// Rule (a): the O(n) bordered solver; rule (b): null (dense).
  std::unique_ptr<continuation::BorderedSolver> makeStructuredSolver(continuation::ProblemWorkspace& ws) const override;
  /// q 1, inputs b̄, torque rows k̄b̄², task rows b̄ (x, y) or 1 (φ), s b̄; rule (b): μ 1/(k̄b̄²),
  /// ν 1/b̄ or 1, R_q rows 1, R_p rows 1/b̄.
  continuation::ProblemScales scales() const override;
  double lengthUnit() const { return lengthUnit_; }
  double stiffnessUnit() const { return stiffnessUnit_; }

  /// Rule (b): the blocks of its Jacobian (header) at u: T of H into ws, A = diag(diagA) +
  /// [genA_max(i,k)], B, D, J_c and the weights w_j/b̄² of the p-block. False outside the domain or for rule (a).
  struct OptimalityBlocks {
    Vector diagA, genA, weights;
    Matrix B, D, Jc;
  };
  bool assembleOptimality(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, ChainStructure& structure,
                          OptimalityBlocks& blocks) const;

  /// T of H at (q, p) into ws, the inputs' columns B (n × m_in) and the task rows J_c (m × n):
  /// what the structured solver linearises on. False outside the domain.
  bool assembleStructure(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, ChainStructure& structure,
                         Matrix& B, Matrix& Jc) const;

  /// prepare()'s cache (keyed bitwise on (q, p)) and the warm start of fixedInputStability().
  struct Workspace : continuation::ProblemWorkspace {
    explicit Workspace(const TaskPathProblem& problem);
    ChainData data;
    Matrix J;                   // 3×n
    Vector grad, stiff, third;  // E′, E″, E‴ per joint
    Eigen::MatrixX2d e1, e2;    // −k_s L_s′, −k_s L_s″ per joint and spring
    Vector h, work;
    BodyLoadTerms body;  // the body loads at the cached q
    Vector tau;          // their torques τ (eq B4)
    Matrix B;            // n × m_in
    ChainStructure structure;
    Vector cachedKey;  // (q, p) of the cache (bitwise)
    bool cacheValid = false;
    Vector lastSmallest;  // warm start of the smallest eigenvalue
  };
  std::unique_ptr<continuation::ProblemWorkspace> createWorkspace() const override;

 private:
  /// Spring model, kinematics and the per-segment input derivatives at u (q, p). False outside the domain.
  bool prepare(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u) const;
  /// Rule (b), after prepare(u): A = diag(diagA) + [genA_max(i,k)] and D (header).
  void optimalityBlocks(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, Vector& diagA, Vector& genA,
                        Matrix& D) const;
  /// A(w) = ∂(H w)/∂q + ν_x ∂²x/∂q² + ν_y ∂²y/∂q² = diag(diagA) + [genA_max(i,k)] (header), after prepare.
  void hessianDerivative(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef w, double nx, double ny,
                         Vector& diagA, Vector& genA) const;
  /// Rule (c): its Jacobian by central differences of mostStableResidual (header).
  bool mostStableJacobian(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u, double s, double theta,
                          continuation::MatrixRef Fu, continuation::VectorRef Fparameter, bool parameterIsTheta) const;
  /// Rule (c): the gap boundary (header), after prepare.
  double coalescenceGap(continuation::ProblemWorkspace& ws, continuation::ConstVectorRef u) const;
  /// Rule (c)'s scales (header) on top of the common ones in `s`.
  continuation::ProblemScales mostStableScales(continuation::ProblemScales s) const;
  friend class MostStableHomotopy;
  /// Column j of B (or of D with the joint weights μ) from the per-segment derivatives e (n×2).
  void inputColumns(const Eigen::MatrixX2d& e, Matrix& out) const;

  Chain chain_;
  TaskSetup setup_;
  int n_, m_, mIn_, dim_;
  std::vector<Eigen::MatrixX2d> rates_;  // r_j, n×2 each
  Vector p0_, L1_, L2_;                  // start inputs, the chain's free lengths
  Vector domainUpper_, domainLower_;
  double lengthUnit_ = 1.0, stiffnessUnit_ = 1.0;
  TaskLeg leg_;
  BodyLoadTerms body_;  // the weight and point loads (inactive: none); a workspace updates its copy
};

}  // namespace buckle::mechanics
