// Dynamics of the chain under fixed end loads / held end coordinates: what happens between two
// equilibria (a jump at a fold, the response to a sudden load). Conventions: conventions.h.
//
// Two models, "model only what the scene needs":
//
//  * GradientFlowModel — overdamped, massless joints (always available):
//        c · dq/dt = −P ∇Π(q) − κ_h J_h⁺ h(q)                                           (D1)
//    ∇Π = ∂E/∂q − J_lᵀ F_l (eq 9 with the given loads only), J_h the rows of the end Jacobian
//    (eq 11) of the held coordinates, h(q) = p_h(q) − target, J_h⁺ = J_hᵀ(J_h J_hᵀ)⁻¹ and
//    P = I − J_h⁺ J_h the projection onto the tangent space of the held coordinates. With h = 0
//    the held reactions are the least-squares multipliers r = (J_h J_hᵀ)⁻¹ J_h ∇Π, and
//    dΠ/dt = −c |dq/dt|² ≤ 0: Π is a Lyapunov function, the flow can only come to rest at an
//    equilibrium, and generically at a stable one. The κ_h term pulls any drift of h back at
//    the rate κ_h / c (dh/dt = −(κ_h/c) h exactly): no projection step is needed, so the
//    adaptive explicit integrators see one smooth ODE.
//
//  * InertialModel — links with mass and rotary inertia, viscous joint damping (only when
//    InertiaData is given; it has no other constructor):
//        M(q) q̈ + c(q, q̇) + D q̇ + ∇Π(q) = J_hᵀ r                                        (D2)
//        J_h q̈ + J̇_h q̇ = −2ω J_h q̇ − ω² h(q)                      (Baumgarte, critically damped)
//    Link m (m = 1 … n: between joint m and m+1, the last one being the end link; the base link
//    ℓ_0 is clamped) has mass m_m, centroidal inertia I_m and its centre of mass at distance d_m
//    from joint m along the link. In absolute angles θ = T q (T lower-triangular ones) the
//    kinetic energy is ½ θ̇ᵀ M_θ θ̇ with M_θ(i, j) = μ_ij cos(θ_i − θ_j),
//        μ_ii = I_i + m_i d_i² + ℓ_i² Σ_{k>i} m_k,   μ_ij = ℓ_i (m_j d_j + ℓ_j Σ_{k>j} m_k)  (i < j),
//    and Lagrange's equations give the velocity terms c_θ,i = Σ_j μ_ij sin(θ_i − θ_j) θ̇_j².
//    In joint angles M = Tᵀ M_θ T and c = Tᵀ c_θ. The dissipated energy ∫ q̇ᵀ D q̇ dt is an extra
//    state, so K + Π + W_d = const is checkable to the integrator tolerance.
//
// Joint limits are one-sided constraints (IntegrationOptions::contact, the default): a joint i
// that reaches a limit q̄_i (geometric or the scene's) is locked there, its row e_iᵀ joining the
// constraint rows of the held coordinates (h_i = q_i − q̄_i, held by the same κ_h / Baumgarte
// terms), so the gradient flow becomes the projected gradient flow (q̇_i = 0) and the inertial
// model a contact with an inelastic impact: at the contact instant the velocity is projected
// M-orthogonally onto the constraints, q̇⁺ = q̇⁻ − M⁻¹Cᵀ(CM⁻¹Cᵀ)⁻¹C q̇⁻ (C all constraint rows:
// q̇_i⁺ = 0), the kinetic energy lost counted as dissipated. The multiplier of row e_i is the
// contact torque τ_c,i = ∂E/∂q_i − (JᵀF)_i at rest (the torque the contact applies, positive
// towards increasing q_i); the contact is compressive while −side·τ_c,i ≥ 0 (side +1 at an upper
// limit, −1 at a lower one) and released where that compression returns to zero. Contact and
// release instants are events located by root finding (Illinois on the step length, each trial
// one step of the integrator's own method from the last accepted state) on q̄_i − q_i (its sign
// towards the inside) and on the compression — not by clamping steps.
//
// The base wall x = 0 (IntegrationOptions::wall) is a one-sided, friction-free contact of the
// same kind: a moving vertex v (wall_contact.h) that reaches it is held there, its row ∇x_vᵀ
// (h_v = x_v) joining the constraint rows, so the chain slides along the wall; its multiplier is
// the wall force μ_v (along +x on the chain; ∇Π = Σ μ_v ∇x_v + … at rest, as ContactProblem's
// rows), the velocity terms of the inertial model gain q̇ᵀ∇²x_v q̇ and the reactions' Hessian
// −μ_v ∂²x_v (the generator form of wall_contact.h, O(n)). A vertex leaves the wall where μ_v
// returns to zero; contact (x_v = 0, the impact as at a joint) and release are located events.
//
// The chain's contact with itself (IntegrationOptions::self) is one more contact of that kind: a
// vertex held on another link's triangle edge (self_contact.h), its row ∇gᵀ (h = g, the gap), its
// multiplier the contact force μ, the velocity terms gaining q̇ᵀ∂²g q̇ = −q̇ᵀG(γ)q̇ + 2(cᵀq̇)(wᵀq̇)
// (self_contact.h's generator γ and rank-2 pair c, w) and the reactions' Hessian −μ∂²g. The links
// touch where the clearance of the link pairs holding no contact reaches zero (the touching
// vertex–edge pair is held, with the impact), a contact releases where μ returns to zero, and a
// vertex at the base corner of its edge is held on the corner's other edge too (pinned there
// until either force returns to zero) or, at an end it cannot pass, released.
//
// Both models append the dissipated energy to the state; the integrator (simulate) stops at
// rest (velocity and equilibrium residual below tolerance) or at a guard (time, steps, a joint
// limit without contact, step-size underflow, a non-finite state) and says which. Models own
// their workspace: the right-hand side allocates nothing (locking or releasing a joint resizes
// it, at events only). A model is not thread-safe (one per thread).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Core>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/wall_contact.h"

namespace buckle::mechanics {

struct BodyLoads;      // body_loads.h (which includes this header for InertiaData)
class BodyLoadTerms;

// ---- scene data ------------------------------------------------------------------------------

/// One moving link as a rigid body.
struct LinkInertia {
  double mass = 0.0;     ///< m_m > 0
  double inertia = 0.0;  ///< centroidal rotary inertia I_m >= 0
  /// Distance d_m of the centre of mass from the link's proximal joint along the link, in
  /// [0, ℓ_m]; NaN (default) means mid-link, ℓ_m / 2.
  double comOffset = std::numeric_limits<double>::quiet_NaN();
};

/// Masses of the n moving links (link m between joint m and m+1, the last one the end link).
struct InertiaData {
  std::vector<LinkInertia> links;

  /// Slender uniform rods: m = ρ ℓ_m, I = m ℓ_m² / 12, centre of mass mid-link.
  static InertiaData uniformRods(const Chain& chain, double massPerLength);
  /// The same mass, centroidal inertia and mid-link centre of mass for every link.
  static InertiaData uniform(const Chain& chain, double mass, double inertia);

  /// Sizes and values against the chain: n links, m > 0, I >= 0, d in [0, ℓ], all finite.
  bool IsValid(const Chain& chain, std::string* why) const;
};

/// What the scene provides. Without `inertia` the overdamped gradient flow is used and the
/// inertial model is never built.
struct DynamicsScene {
  std::optional<InertiaData> inertia;
  /// Viscous joint damping d_i (D = diag(d), size n) of the inertial model; empty = undamped.
  std::vector<double> jointDamping;
  /// Damping scale c > 0 of the gradient flow (D1): time is measured in units of c / stiffness.
  double flowDamping = 1.0;
  /// Gradient flow: constraint restoring stiffness κ_h in (D1) (same units as a joint
  /// stiffness). <= 0: automatic, 10·max(k̄b̄², max_i |K_q,ii(q0)|).
  double constraintStiffness = 0.0;
  /// Inertial model: Baumgarte rate ω (1/time) of the held coordinates. <= 0: automatic,
  /// 10·max_i √(|∂²Π/∂q_i²| / M_ii) at the start (ten times the fastest joint frequency).
  double baumgarteRate = 0.0;
  /// The links' weight and point loads at the state simulated (DynamicsModel::setBodyLoads);
  /// null: none.
  std::shared_ptr<const BodyLoads> body;

  bool IsValid(const Chain& chain, std::string* why) const;
};

// ---- models ----------------------------------------------------------------------------------

enum class DynamicsKind { GradientFlow, Inertial };

/// Common part: the chain, the fixed loads / held targets, Π, its gradient and the constraints.
/// State x = (q, [q̇,] W_d): joint angles, velocities (inertial only), dissipated energy.
class DynamicsModel {
 public:
  virtual ~DynamicsModel() = default;
  DynamicsModel(const DynamicsModel&) = delete;
  DynamicsModel& operator=(const DynamicsModel&) = delete;

  virtual DynamicsKind kind() const = 0;
  virtual int stateSize() const = 0;
  int segments() const { return chain_.size(); }
  const Chain& chain() const { return chain_; }
  const EndCondition& endCondition() const { return end_; }
  int heldCount() const { return static_cast<int>(held_.size()); }

  /// One-sided contact at the joint limits (file comment): per joint 0 free, +1 locked at its
  /// upper limit, −1 at its lower one.
  const std::vector<int>& contactSides() const { return sides_; }
  int lockedCount() const { return static_cast<int>(locked_.size()); }
  /// Locked joints in increasing order.
  const std::vector<int>& lockedJoints() const { return locked_; }
  /// The links' weight and point loads (body_loads.h) at the model's fixed state, their rates
  /// ignored (BodyLoads::atParameter): Π gains V (eq B1), ∇Π gains −τ (eq B2) and the Hessian's
  /// generator −γ (eq B3). Throws std::invalid_argument as BodyLoads::check. Inactive loads: none.
  void setBodyLoads(const BodyLoads& body);
  bool hasBodyLoads() const { return body_ != nullptr; }
  /// Sets the locked joints (size n, entries −1, 0, +1); resizes the constraint workspace.
  /// Throws std::invalid_argument for a wrong size or entry.
  void setContacts(const std::vector<int>& sides);
  /// The limit angle of joint i on `side` (+1 upper, −1 lower).
  double limitAngle(int joint, int side) const;
  /// Contact torques τ_c,i at state x (size n): the multipliers of the locked joints' constraint
  /// rows (file comment), 0 at free joints. Evaluates the right-hand side once.
  void contactTorques(const double* x, VectorRef torques);
  /// Vertices held on the base wall (file comment), in the order of their rows.
  const std::vector<WallVertex>& wallContacts() const { return wall_; }
  int wallCount() const { return static_cast<int>(wall_.size()); }
  /// Sets the vertices held on the wall (no duplicates); resizes the constraint workspace.
  /// Throws std::invalid_argument for a vertex that is not a moving one (checkWallVertex) or a
  /// duplicate.
  void setWallContacts(const std::vector<WallVertex>& vertices);
  /// Self contacts held (file comment), in the order of their rows (after the wall's).
  const std::vector<SelfContact>& selfContacts() const { return self_; }
  int selfCount() const { return static_cast<int>(self_.size()); }
  /// Sets the self contacts held (no duplicates); resizes the constraint workspace. Throws
  /// std::invalid_argument for a contact that is not one of the chain's (checkSelfContact) or a
  /// duplicate.
  void setSelfContacts(const std::vector<SelfContact>& contacts);
  /// Contact torques (as contactTorques) and the wall forces μ_v (one per wallContacts() entry)
  /// at state x: the multipliers of their rows. Evaluates the right-hand side once.
  void contactForces(const double* x, VectorRef torques, VectorRef wallForces);
  /// The same and the self contacts' forces μ (one per selfContacts() entry).
  void contactForces(const double* x, VectorRef torques, VectorRef wallForces, VectorRef selfForces);
  /// At a contact instant: sets the locked joints' angles to their limits and (inertial) makes
  /// the velocity admissible by the inelastic impact; returns the kinetic energy lost (added to
  /// the dissipated energy in x).
  virtual double impact(double* x);

  /// x0 from q and q̇ (q̇ ignored by the gradient flow), dissipated energy 0.
  virtual void packState(ConstVectorRef q, ConstVectorRef qdot, VectorRef x) const = 0;
  /// dx/dt at x. Allocation-free.
  virtual void rhs(const double* x, double* dxdt) = 0;
  /// ∂(dx/dt)/∂x, row-major stateSize² (for the stiff stepper). Exact for the unconstrained
  /// gradient flow, central differences of rhs() otherwise.
  virtual void jacobian(const double* x, double* jacobianRowMajor);
  /// k = (I − a·J̃(x))⁻¹ b for a > 0, J̃ the model's structured approximation of ∂(dx/dt)/∂x
  /// (the stage systems of a Rosenbrock stepper), in O(n). False when the
  /// model has none (the default) or the system is singular to working precision.
  virtual bool solveLinearized(const double* x, double a, const double* b, double* k);

  /// Joint angles / velocities / dissipated energy stored in x.
  Eigen::Map<const Vector> angles(const double* x) const { return Eigen::Map<const Vector>(x, segments()); }
  /// Joint velocity q̇ at x (the flow evaluates (D1); needs rhs(), hence non-const).
  virtual void velocity(const double* x, VectorRef qdot) = 0;
  /// The speed the rest criterion watches: ‖q̇‖∞ (the gradient flow: see its override).
  virtual double restSpeed(const double* x);
  virtual double dissipated(const double* x) const = 0;
  virtual double kineticEnergy(const double* x) = 0;

  /// Π(q) = E(q) − F_l · p_l(q) (+ V(q) with body loads; held coordinates do no work while held).
  double potential(ConstVectorRef q);
  /// ∂Π/∂q = ∂E/∂q − J_lᵀ F_l (− τ with body loads).
  void potentialGradient(ConstVectorRef q, VectorRef g);
  /// Equilibrium residual max(‖P ∇Π‖∞, ‖h‖∞): zero exactly at an equilibrium of the scene.
  double equilibriumResidual(ConstVectorRef q);
  /// The same in the chain's units: max(‖P ∇Π‖∞ / torqueUnit(), ‖h‖∞ / lengthUnit()).
  double naturalResidual(ConstVectorRef q);
  /// The chain's units: b̄ (mean triangle half-length) and k̄b̄² (k̄ the mean spring stiffness:
  /// the size of a joint stiffness and of a torque).
  double lengthUnit() const { return lengthUnit_; }
  double torqueUnit() const { return torqueUnit_; }
  /// The model's natural time unit: c / k̄b̄² for the gradient flow (D1), √(Ī / k̄b̄²) for the
  /// inertial model (Ī the mean joint inertia μ_ii). IntegrationOptions' times are in this unit.
  virtual double timeUnit() const = 0;
  /// ‖h(q)‖∞ = max over held coordinates |p_c(q) − target_c| (0 without held coordinates).
  double constraintViolation(ConstVectorRef q);
  /// Gauss–Newton onto h(q) = 0 (minimum-norm corrections J_h⁺ h); true when ‖h‖∞ <= tol·b̄.
  bool projectOntoConstraints(VectorRef q, double tolerance = 1e-13, int maxIterations = 20);
  /// Inside the joint limits (geometric ∩ user, open interval)? A locked joint counts as inside.
  bool withinLimits(ConstVectorRef q) const;

 protected:
  DynamicsModel(const Chain& chain, const EndCondition& end);
  /// Constraint rows: the held coordinates, the locked joints, the wall vertices, the self contacts.
  int constraintCount() const { return heldCount() + lockedCount() + wallCount() + selfCount(); }
  /// The first wall vertex's row, and the first self contact's.
  int wallRowBegin() const { return heldCount() + lockedCount(); }
  int selfRowBegin() const { return wallRowBegin() + wallCount(); }
  /// The derived model's constraint-sized workspace after setContacts().
  virtual void resizeConstraints() {}
  /// The constraint workspace for the current held, locked and wall rows (setContacts,
  /// setWallContacts); calls resizeConstraints().
  void rebuildConstraints();
  /// The wall vertices' rows ∇x_vᵀ, h = x_v and generators (wallGen_), then the self contacts'
  /// ∇gᵀ, h = g, generators and rank-2 pairs (selfCoupling_, selfWeights_), at the cached kinematics.
  void gapRows();
  /// Kinematics, J, E, ∇Π, the joint stiffnesses K_q and (with held coordinates) J_h, h, the
  /// Cholesky of J_h J_hᵀ at q, from one pass of the spring model. Cached for the last q (bitwise;
  /// setContacts() invalidates): a step evaluates the right-hand side at the accepted state, and
  /// the monitor then wants Π, the residual, the speed and the constraints at that same state.
  void evaluateStatics(ConstVectorRef q);
  /// With body loads, the Hessian generator h (eq 27's, of the end wrench) becomes h − γ at the
  /// cached statics (eq B3); without, nothing.
  void subtractBodyGenerator(VectorRef h);
  /// With body loads, H += Γ, Γ(i, j) = γ_max(i,j), at the cached statics (a dense Hessian).
  void addBodyHessian(MatrixRef H);

  Chain chain_;
  EndCondition end_;
  double lengthUnit_, torqueUnit_;
  std::vector<int> held_, loaded_;
  std::vector<int> sides_, locked_;  ///< contact side per joint; the locked joints
  std::vector<WallVertex> wall_;     ///< vertices held on the base wall
  std::vector<SelfContact> self_;    ///< self contacts held
  /// n×(w+s): generators g_m = x_v − x_Pm of −∂²x_v (wall_contact.h), then the self contacts' γ
  /// (self_contact.h), at the statics
  Matrix wallGen_;
  Matrix selfCoupling_, selfWeights_;  ///< n×s: the self contacts' rank-2 pairs c, w
  Wrench loads_;  ///< F_l on loaded coordinates, 0 on held ones
  ChainData data_;
  Matrix J_;      ///< 3×n end Jacobian
  Vector grad_;   ///< ∇Π
  Vector stiffness_;     ///< K_q diagonal ∂²E/∂q_i²
  double springEnergy_ = 0.0;  ///< E(q)
  Vector staticsQ_;      ///< q of the cached statics
  Vector sinHalf_, cosHalf_;  ///< sin(q_i/2), cos(q_i/2) of the cached statics (evaluateStatics)
  bool staticsValid_ = false;
  Matrix Jh_;     ///< m×n constraint rows: held coordinates, e_iᵀ of the locked joints, ∇x_vᵀ, ∇gᵀ
  Vector h_;      ///< p_h − target, then q_i − q̄_i, then x_v, then g
  Matrix A_;      ///< J_h J_hᵀ
  Eigen::LLT<Matrix> llt_;
  Vector r_, tmpM_;  // size m (r_: the multipliers of the last right-hand side)
  Vector tmpN_;      // size n
  std::vector<double> fdPlus_, fdMinus_, fdState_;  // for the finite-difference jacobian()
  Eigen::Matrix2Xd positions_;  ///< joint positions (jointPositions' columns) at the statics, with wall rows
  Vector wallRow_;               ///< scratch, size n
  Vector wallForces_, selfForces_;  ///< scratch of contactTorques, sizes w and s
  std::shared_ptr<BodyLoadTerms> body_;  ///< null: no body loads
  Vector bodyWork_;                      ///< τ or γ of the body loads (size n)
  double bodyPotential_ = 0.0;           ///< V at the cached statics
};

/// (D1). dx/dt = (q̇, c|q̇|²).
class GradientFlowModel final : public DynamicsModel {
 public:
  /// `q0` sets the automatic constraint stiffness (scene.constraintStiffness <= 0).
  GradientFlowModel(const Chain& chain, const EndCondition& end, const DynamicsScene& scene, ConstVectorRef q0);

  DynamicsKind kind() const override { return DynamicsKind::GradientFlow; }
  int stateSize() const override { return segments() + 1; }
  void packState(ConstVectorRef q, ConstVectorRef qdot, VectorRef x) const override;
  void rhs(const double* x, double* dxdt) override;
  void jacobian(const double* x, double* jacobianRowMajor) override;
  void velocity(const double* x, VectorRef qdot) override;
  /// ‖P∇Π‖∞ / c: the flow's speed along the constraints, without the κ_h term, which only
  /// pulls back the integrator's drift of the constraints (of the size of its tolerance) and
  /// would otherwise keep a chain at rest "moving" by κ_h/c times that drift.
  double restSpeed(const double* x) override;
  double dissipated(const double* x) const override { return x[segments()]; }
  double kineticEnergy(const double*) override { return 0.0; }

  /// The exact Jacobian J̃ = −(P H_r + κ_h J_h⁺ J_h − J_h⁺E)/c with H_r = K_q − K_g(F_l + r)
  /// (eq 27, the reactions r acting as end loads) and E_k = −c (∇²p_k q̇)ᵀ; the energy row
  /// 2c q̇ᵀJ̃. With H_r = U T Uᵀ (chain_structure.h), I − aJ̃ is the bordered system
  /// [[H_r + (c/a) I, J_hᵀ], [J_h (H_r − κ_h I) + E, J_h J_hᵀ]], block elimination: O(n m). The
  /// reactions' −Σ μ ∂²x_v and −Σ μ ∂²g join H_r's generator; a self contact's rank-2 part two
  /// more border columns (dynamics_gradient_flow.cpp). A border wider than
  /// ChainStructure::kMaxBorder takes the dense LU of I − aJ̃ (central differences of rhs()).
  bool solveLinearized(const double* x, double a, const double* b, double* k) override;

  double damping() const { return c_; }
  double constraintStiffness() const { return kappaH_; }
  double timeUnit() const override { return c_ / torqueUnit_; }

 protected:
  void resizeConstraints() override;

 private:
  double c_, kappaH_;
  Matrix H_;  // Hessian workspace for the exact Jacobian
  Vector qdot_;
  // solveLinearized workspace
  ChainStructure structure_;
  Vector shifted_, scaledRhs_, y_, zeroM_;
  Matrix V_, W_, factoredA_;
  Vector factoredQdot_;
  Vector lastState_;  ///< x of the factored system (with factoredFor_ = a; NaN: none)
  double factoredFor_ = std::numeric_limits<double>::quiet_NaN();
  // a border wider than ChainStructure::kMaxBorder: the dense LU of I − aJ̃ (central differences)
  bool solveLinearizedDense(const double* x, double a, const double* b, double* k);
  Eigen::PartialPivLU<Matrix> denseLU_;
};

/// (D2). x = (q, q̇, W_d), dx/dt = (q̇, q̈, q̇ᵀ D q̇). Only constructible from explicit mass data.
class InertialModel final : public DynamicsModel {
 public:
  /// Throws std::invalid_argument when the inertia data or the damping do not fit the chain.
  InertialModel(const Chain& chain, const EndCondition& end, const InertiaData& inertia,
                const std::vector<double>& jointDamping, double baumgarteRate, ConstVectorRef q0);
  ~InertialModel() override;

  /// How many InertialModel objects were ever constructed in this process (tests check that a
  /// scene without masses never builds one).
  static long constructedCount();

  DynamicsKind kind() const override { return DynamicsKind::Inertial; }
  int stateSize() const override { return 2 * segments() + 1; }
  void packState(ConstVectorRef q, ConstVectorRef qdot, VectorRef x) const override;
  void rhs(const double* x, double* dxdt) override;
  void velocity(const double* x, VectorRef qdot) override;
  double dissipated(const double* x) const override { return x[2 * segments()]; }
  double kineticEnergy(const double* x) override;

  /// Joint-space mass matrix M(q) = Tᵀ M_θ(q) T (n×n, symmetric positive definite), dense: for
  /// cross-checks (the model itself works on the O(n) factorization).
  void massMatrix(ConstVectorRef q, MatrixRef M);
  /// Velocity-dependent generalized force c(q, q̇) = Tᵀ c_θ of (D2), O(n).
  void velocityTerms(ConstVectorRef q, ConstVectorRef qdot, VectorRef c);
  /// Positions of the link centres of mass (2×n) — an independent kinematic check.
  void centresOfMass(ConstVectorRef q, Eigen::Ref<Eigen::Matrix2Xd> G) const;
  const Vector& jointDamping() const { return d_; }
  double baumgarteRate() const { return omega_; }
  double timeUnit() const override { return timeUnit_; }
  double impact(double* x) override;

  /// ∂(dx/dt)/∂x (row-major, (2n+1)²). Without constraints exact (dynamics_inertial_linearized.cpp:
  /// A_q = −M⁻¹(H + C_q + G), A_v = −M⁻¹(C_v + D), the energy row 2(Dq̇)ᵀ); with held coordinates
  /// or locked joints central differences of rhs().
  void jacobian(const double* x, double* jacobianRowMajor) override;
  /// (I − aJ)k = b with the exact J. Without constraints in O(n): the stage system reduces to
  /// [M + a(C_v + D) + a²(H + C_q + G)] k_v = M b_v − a(H + C_q + G) b_q, in absolute angles a
  /// tridiagonal plus rank-2 semiseparable matrix, solved as a banded sparse system with the
  /// semiseparable sums as auxiliary unknowns. With constraints: a dense LU of I − aJ (O(n³)).
  bool solveLinearized(const double* x, double a, const double* b, double* k) override;

 protected:
  void resizeConstraints() override;

 private:
  struct Linearization;  // workspace of jacobian() / solveLinearized() (dynamics_inertial_linearized.cpp)
  struct LinearizationDeleter {  // (defined where Linearization is complete)
    void operator()(Linearization* p) const;
  };
  /// θ̇ = Tq̇, θ̈ = Tq̈, T of H = U T Uᵀ and the diagonal of the velocity terms' stiffness at x.
  void linearizeAt(const double* x);
  /// out_i = Σ_{j≠i} μ_ij [cos(θ_i − θ_j) β_j + sin(θ_i − θ_j) γ_j] y_j (after factorMass), O(n).
  void applyCoupling(ConstVectorRef beta, ConstVectorRef gamma, ConstVectorRef y, VectorRef out) const;
  /// out = K_θ y, K_θ = T + (C_q + G)_θ the stiffness in absolute angles (after linearizeAt).
  void applyStiffnessTheta(ConstVectorRef y, VectorRef out) const;

  /// cos θ_i, sin θ_i and the LDLᵀ factors of M_θ at q (dynamics_inertial.cpp, "O(n)
  /// mass matrix"); false if a pivot is not positive (M_θ not positive definite to rounding).
  bool factorMass(ConstVectorRef q);
  /// f ← M⁻¹ f = T⁻¹ M_θ⁻¹ T⁻ᵀ f after factorMass(), O(n).
  void solveMass(VectorRef f) const;

  Vector mass_, inertia_, com_, d_;
  Vector tailMass_;  // Σ_{k>i} m_k
  /// M_θ(i, i) = μ_ii = a_i, M_θ(i, j) = μ_ij cos(θ_i − θ_j) with μ_ij = ℓ_i w_j (i < j), constant
  Vector muDiag_, w_, len_;
  Vector cos_, sin_;  // cos θ_i, sin θ_i
  Vector pivot_;      // LDLᵀ of M_θ: the pivots d_j
  Matrix gen_;        // n×2 generators g_j of L (L(i, j) = p_iᵀ g_j, i > j)
  bool massFactored_ = false;
  Vector massQ_;      // q of the factored M_θ
  Vector thetaDot_, cTheta_, f_, acc_;
  Matrix B_, S_;  // M⁻¹ J_hᵀ (n×m), J_h M⁻¹ J_hᵀ (m×m)
  Eigen::LLT<Matrix> sllt_;
  double omega_;
  double timeUnit_;
  std::unique_ptr<Linearization, LinearizationDeleter> lin_;
};

/// The only way scenes build a model: the inertial one if and only if scene.inertia is set.
/// Throws std::invalid_argument (with the reason) if the scene does not fit the chain.
std::unique_ptr<DynamicsModel> makeDynamicsModel(const Chain& chain, const EndCondition& end,
                                                 const DynamicsScene& scene, ConstVectorRef q0);

// ---- integration -----------------------------------------------------------------------------

enum class StepperKind {
  DormandPrince5,  ///< runge_kutta_dopri5, FSAL, error-controlled (default)
  CashKarp54,      ///< runge_kutta_cash_karp54, error-controlled
  Rosenbrock4,     ///< rosenbrock4 (L-stable, uses the model's Jacobian) for stiff scenes
  /// rosenbrock4's coefficients with the model's O(n) solveLinearized() instead of a dense LU
  /// (O(n) per step instead of O(n³)): stiff long chains (both models; the inertial one with
  /// constraints solves its stages densely).
  StructuredRosenbrock4,
  /// Dormand–Prince 5(4) while the flow is not stiff, StructuredRosenbrock4 while it is
  /// (Hairer's stiffness test on the explicit steps; dynamics_steppers.h, SwitchingStepper).
  StructuredSwitching,
};

/// Times (initialStep, maxStep, minStep, maxTime, recordInterval) are in the model's natural
/// time unit (DynamicsModel::timeUnit()), velocityTolerance in rad per that unit and
/// residualTolerance bounds DynamicsModel::naturalResidual(): the horizon and the rest criterion
/// mean the same for the same chain in any units. Results (times, residuals) are in the model's
/// own units.
struct IntegrationOptions {
  StepperKind stepper = StepperKind::DormandPrince5;
  double absoluteTolerance = 1e-10;  ///< per-step local error control (odeint eps_abs)
  double relativeTolerance = 1e-10;  ///< (odeint eps_rel)
  double initialStep = 1e-3;
  double maxStep = 0.0;              ///< 0: unlimited
  double minStep = 1e-13;            ///< below this the step size has underflowed: stop
  double maxTime = 1e5;              ///< guard
  long maxSteps = 1000000;           ///< guard (accepted steps)
  /// Rest: speed <= velocityTolerance and equilibrium residual <= residualTolerance; the speed
  /// is DynamicsModel::restSpeed() (the gradient flow's without its drift correction).
  double velocityTolerance = 1e-9;
  double residualTolerance = 1e-9;
  /// Record a sample when at least this much time passed since the last one (0: every
  /// accepted step); the first and the last states are always recorded.
  double recordInterval = 0.0;
  bool recordTrajectory = true;
  std::size_t maxSamples = 200000;   ///< recording stops (trajectoryTruncated) beyond this
  /// Checked before every step: a time limit or a signal stops the integration
  /// (IntegrationStop::Interrupted) with the state reached.
  continuation::Interrupt interrupt;
  /// Joint limits as one-sided constraints (file comment); false: stop at the first limit
  /// reached (IntegrationStop::JointLimit), the time bisected down to minStep.
  bool contact = true;
  /// The base wall x = 0 as a one-sided, friction-free contact (file comment; jump.h
  /// JumpOptions::wall): a moving vertex that reaches it is held on it and slides along it, and
  /// leaves it where its wall force returns to zero. The integration starts with the model's
  /// wall vertices (setWallContacts) and ends with those on the wall then
  /// (DynamicsResult::wallContacts). false: the chain passes through the wall.
  bool wall = false;
  /// The chain's contact with itself as a one-sided, friction-free contact (file comment): a
  /// vertex that reaches another link's triangle is held on its edge and slides along it, and
  /// leaves it where its force returns to zero. The integration starts with the model's self
  /// contacts (setSelfContacts) and ends with those held then (DynamicsResult::selfContacts).
  /// false: the links pass through each other.
  bool self = false;
  /// Hand-over test (optional; jump.h, JumpOptions::handover): consulted after an accepted step
  /// without contacts (no locked joint, no vertex on the wall) whose naturalResidual() is <= settleResidual, at most every
  /// settleInterval accepted steps, with the joint angles of that step. True ends the
  /// integration (IntegrationStop::Settled): the caller has certified where the flow goes from
  /// there and takes over (e.g. with Newton), so the creep to rest is not integrated.
  std::function<bool(ConstVectorRef q)> settled;
  double settleResidual = 1e-2;
  long settleInterval = 8;
  /// A barrier the chain may not cross (optional; e.g. the base wall, jump.h JumpOptions::wall):
  /// false for joint angles outside the admissible set. A step that ends outside is rolled back
  /// and retried at half the size, as a step past a joint limit without contact, so the
  /// integration stops (IntegrationStop::Barrier) at the last admissible state, within minStep of
  /// the instant the barrier is reached. A start outside stops at once.
  std::function<bool(ConstVectorRef q)> admissible;

  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// Settled: stopped by IntegrationOptions::settled (not at rest; the caller's test says where
/// the flow goes). Barrier: stopped at IntegrationOptions::admissible's boundary (not at rest).
enum class IntegrationStop {
  Rest, MaxTime, MaxSteps, JointLimit, StepSizeUnderflow, NonFinite, Interrupted, Settled, Barrier
};
const char* toString(IntegrationStop reason);

struct TrajectorySample {
  double t = 0.0;
  Vector q, qdot;
  double potential = 0.0;    ///< Π
  double kinetic = 0.0;      ///< ½ q̇ᵀ M q̇ (0 for the gradient flow)
  double dissipated = 0.0;   ///< ∫ q̇ᵀ D q̇ dt  (gradient flow: ∫ c |q̇|² dt)
  double residual = 0.0;     ///< equilibrium residual
  double constraintViolation = 0.0;
};

/// A contact or release instant of the one-sided joint limits or of the base wall.
struct ContactEvent {
  double t = 0.0;          ///< model time
  int joint = -1;          ///< 0-based; −1 for a wall event
  int side = 0;            ///< +1 upper limit, −1 lower
  /// A wall event (segment ≥ 0): the vertex that reached or left the wall (joint −1).
  WallVertex vertex{-1, 0};
  /// A self contact event (self.vertex.segment ≥ 0): the contact held or released (joint −1).
  SelfContact self;
  bool contact = true;     ///< true: the joint locked / the vertex held; false: released
  /// Contact torque τ_c,i (a joint), wall force μ_v (a vertex) or self contact force just after
  /// the contact / at the release.
  double torque = 0.0;
  double kineticLost = 0.0;  ///< inertial: the impact's kinetic-energy loss
};

struct DynamicsResult {
  IntegrationStop reason = IntegrationStop::MaxSteps;
  std::string message;              ///< human-readable reason
  DynamicsKind kind = DynamicsKind::GradientFlow;
  double time = 0.0;                ///< duration (model time)
  long steps = 0, rejectedSteps = 0;
  long stiffSteps = 0;              ///< StructuredSwitching: accepted steps taken by Rosenbrock4
  Vector q, qdot;                   ///< final state
  double initialEnergy = 0.0;       ///< Π + K at t = 0
  double potential = 0.0, kinetic = 0.0, dissipated = 0.0;
  double residual = 0.0, speed = 0.0;  ///< final equilibrium residual and ‖q̇‖∞
  double maxConstraintViolation = 0.0;  ///< over every accepted step
  double maxEnergyBalanceError = 0.0;   ///< max |Π + K + W_d − initialEnergy| over accepted steps
  double wallSeconds = 0.0;
  std::vector<ContactEvent> contactEvents;  ///< in time order
  std::vector<int> contactSides;            ///< the model's locked joints at the end (per joint)
  Vector contactTorques;                    ///< τ_c,i at the end (0 at free joints)
  std::vector<WallVertex> wallContacts;     ///< IntegrationOptions::wall: the vertices on the wall at the end
  Vector wallForces;                        ///< their wall forces μ_v at the end
  std::vector<SelfContact> selfContacts;    ///< IntegrationOptions::self: the self contacts held at the end
  Vector selfForces;                        ///< their forces at the end
  std::vector<TrajectorySample> trajectory;
  bool trajectoryTruncated = false;
};

/// Integrates the model from (q0, q̇0) until rest or a guard, starting with the model's locked
/// joints (setContacts; their angles are set to the limits) and wall vertices (setWallContacts).
/// With options.contact (options.wall) the joint (wall) contacts change at the located events
/// (DynamicsResult::contactEvents, contactSides and wallContacts at the end); the model's own
/// contact set is restored on return. Throws
/// std::invalid_argument for invalid options or sizes; every other ending is reported in
/// DynamicsResult::reason.
DynamicsResult simulate(DynamicsModel& model, ConstVectorRef q0, ConstVectorRef qdot0, const IntegrationOptions& options);

}  // namespace buckle::mechanics
