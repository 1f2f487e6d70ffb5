// What a traced equilibrium branch means physically: its points in physical quantities and its
// special points named in the field's words (paper §III; docs/mechanics.md, "What the physics
// does"). The one place that decides what a branch point, a fold, a joint limit or a stiffness
// minimum of the chain is, under any mix of load and displacement control — the command line,
// the atlas and the tests only read what it says.
//
// A path under displacement control of one end coordinate c may be traced *through the
// reaction*: coordinate c is released, its force F_c is the continuation parameter and the
// report maps everything back onto the held coordinate (ReportOptions::heldCoordinate): the
// reported parameter is the end's coordinate c, stability is that of the chain with c held
// (K_q − K_g on ker J_h including row c), a fold of the force F_c(s) is no event there (LPF),
// and a turning point of the coordinate c(s) — where the displacement-controlled stability
// changes away from branch points — is where the chain jumps under displacement control.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "buckle/continuation/branch.h"
#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/mechanics/classification.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/imperfection_sensitivity.h"
#include "buckle/mechanics/stiffness_extremum.h"

namespace buckle::mechanics {

/// What kind of event a reported special point is. Labels (label): AUTO/MATCONT's where
/// they exist.
enum class EventType {
  BranchPoint,       ///< "BP": a branch point of the traced equilibria
  Fold,              ///< "LP": a fold of the traced parameter (or of the held coordinate)
  ReactionFold,      ///< "LPF": a fold of the reaction force of a held coordinate: no jump
  Boundary,          ///< "BD": a joint limit or another boundary of the model, located
  JointLimit,        ///< "BD": the steps collapsed at a geometric joint limit (not located)
  StiffnessMinimum,  ///< "KMIN": a deep local minimum of a stiffness measure along a stable stretch
  Jump,              ///< "JUMP": a load history leaves its stable state (load_history.h)
  Contact,           ///< "CT": a joint reaches its limit and locks there (contact.h)
  Release,           ///< "RL": a locked joint's contact torque returns to zero: it is free again
  BaseContact,       ///< "BC": the chain reaches (or leaves) the clamp's wall (contact_geometry.h)
  SelfContact,       ///< "SC": two non-adjacent links meet (or separate) (contact_geometry.h)
  EigenvalueTouch,   ///< "ET": an eigenvalue of the stability operator touches zero without crossing
  StabilityLoss,     ///< "LS": along a task path, the equilibrium at fixed inputs loses its stability
  InputBound,        ///< "IB": along a task path, a control input reaches its bound (task_path.h)
  WallContact,       ///< "WC": a vertex reaches the base wall and is held on it (contact.h, wall_contact.h)
  WallRelease,       ///< "WR": a vertex's wall force returns to zero: it leaves the wall
  SelfHold,          ///< "SH": a vertex reaches another link's triangle and is held on it (self_contact.h)
  SelfRelease,       ///< "SR": a self contact's force returns to zero: the bodies separate
};

/// "BP", "LP", "LPF", "BD", "KMIN", "JUMP", "CT", "RL", "BC", "SC", "ET", "LS", "IB": the one spelling
/// of the labels in every output.
const char* label(EventType type);

/// "stable", "unstable (k negative)", or "unknown" for a count that was not computed (< 0).
std::string stabilityLabel(int negativeEigenvalues);

struct ReportOptions {
  /// ≥ 0: the branch was traced through the reaction of this end coordinate (0 x, 1 y, 2 φ),
  /// which the path holds (file comment); −1: report the traced parameter as it is.
  int heldCoordinate = -1;
  /// Range of the reported parameter (the held coordinate when traced through the reaction):
  /// points and special points outside it, by more than 1e-9 of its width, are left out.
  double rangeLow = -std::numeric_limits<double>::infinity();
  double rangeHigh = std::numeric_limits<double>::infinity();
  /// The loaded Cartesian stiffness K_F (eq 29) at every point, and KMIN events.
  bool stiffness = false;
  /// KMIN: the stiffness measure watched (stiffness_extremum.h): K_xx, K_yy or the smallest
  /// eigenvalue of K_F.
  StiffnessMeasure stiffnessMeasure = StiffnessMeasure::Kxx;
  /// KMIN: a local minimum of the measure along a stable stretch, located where its rate along
  /// the branch vanishes, is "deep" (quasi-buckling) when it is below this fraction of the
  /// measure at the branch start (scale-free: a ratio of stiffnesses).
  double deepStiffnessRatio = 0.5;
  /// Once requested (the run's time limit, a signal), the refinements of a report are skipped,
  /// each with a note saying why: Koiter's coefficients and the imperfection sensitivities of the
  /// branch points, and the location of base and self contacts (then to the point spacing); the
  /// loaded stiffness of the points not yet reached (haveStiffness false, K NaN) and the stiffness
  /// minima — BranchReport::skipped says what was left out.
  continuation::Interrupt interrupt;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

/// One point of a branch, in physical quantities.
struct PointReport {
  int branch = -1;                     ///< the traced branch's id (continuation::Branch::id)
  int index = 0;                       ///< index of the point in the traced branch
  double parameter = 0.0;              ///< the traced λ, or the held coordinate (ReportOptions)
  Wrench F = Wrench::Zero();           ///< total end wrench (loads and reactions)
  Pose pose = Pose::Zero();
  Eigen::VectorXd q;
  int negative = -1;                   ///< negative eigenvalues of the stability operator (−1: unknown)
  double minEigenvalue = 0.0;
  bool stable = false;
  double residual = 0.0;               ///< corrector residual (scaled, dimensionless)
  bool haveStiffness = false;
  Eigen::Matrix2d K = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The compliance C_F = K_F⁻¹ of the same computation (finite where K_F is not: a rigid
  /// direction, e.g. x at the straight chain; NaN where K_F is singular).
  Eigen::Matrix2d C = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The end's rotational stiffness K_φ = 1/C_φφ with the end forces unchanged, where the end
  /// rotation is free (CartesianStiffness::rotationalStiffness; NaN where φ is held).
  double rotationalStiffness = std::numeric_limits<double>::quiet_NaN();
  /// Joints locked at their limits at this point (contact.h); stability and K are those of the
  /// constrained chain.
  ContactSet locked;
  /// Largest compression −side·τ_c over the locked joints (0 when none is locked).
  double contactTorque = 0.0;
  /// The signed natural frequencies ω_i at the point (vibration.h: negative is unstable, minus the
  /// growth rate; NaN beyond the constrained chain's modes) where the caller computed them, else empty.
  Eigen::VectorXd omega;
  /// Along a task path: the control inputs' values at the point (task_path.h), else empty.
  Eigen::VectorXd inputs;
  /// The wall forces μ_v (a force along +x on the chain), one per vertex of locked.wall().
  Eigen::VectorXd wallForces;
  /// The self contacts' forces (pushing the bodies apart), one per locked.self().
  Eigen::VectorXd selfForces;
};

/// One special point of a branch, named in the field's words.
struct SpecialPointReport {
  int branch = -1;                     ///< the traced branch's id (continuation::Branch::id)
  EventType type = EventType::BranchPoint;
  Phenomenon phenomenon = Phenomenon::None;
  int source = -1;                     ///< index into the traced branch's specialPoints (−1: found here)
  int index = 0;                       ///< the point lies between points[index] and [index + 1]
  double parameter = 0.0;
  double lambda = 0.0;                 ///< the traced λ at the point
  Wrench F = Wrench::Zero();
  Pose pose = Pose::Zero();
  Eigen::VectorXd q;
  std::string shape;                   ///< of the bifurcating mode at a BP, of q elsewhere
  int negativeBefore = -1, negativeAfter = -1;
  std::string stabilityBefore, stabilityAfter;  ///< stabilityLabel of the counts, or "critical"
  double accuracy = 0.0;               ///< achieved |Δ parameter| of the location
  /// The loaded stiffness K_F at the point where the report computed it (KMIN), else NaN.
  Eigen::Matrix2d K = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double residual = 0.0;
  bool refined = false;                ///< Newton on an augmented system converged
  int multiplicity = 1;
  /// Multiple branch points: half-branches predicted by the reduced bifurcation equation and
  /// traced off the point (−1: not switched; SpecialPoint::branchesPredicted / branchesFound).
  int branchesPredicted = -1, branchesFound = -1;
  std::string note;
  /// A fold whose stable side ends there: the chain must jump (jumpFromFold, landing.h, simulates
  /// where it lands; statics do not depend on dynamics, so the landing is kept beside the report).
  bool jumps = false;
  /// CT / RL: the joint (0-based) that locks or releases, and its contact torque τ_c at the point
  /// (≈ 0 there: the free and the locked equilibria meet); NaN / −1 for other events.
  int joint = -1;
  double contactTorque = std::numeric_limits<double>::quiet_NaN();
  /// The locked joints and the vertices on the wall after the point (CT, RL, WC, WR).
  ContactSet lockedAfter;
  /// WC / WR: the vertex that reaches or leaves the wall (segment −1 otherwise) and its wall force
  /// at the point (≈ 0 there; NaN otherwise).
  WallVertex vertex{-1, 0};
  double contactForce = std::numeric_limits<double>::quiet_NaN();
  /// SH / SR: the self contact held or released (vertex.segment −1 otherwise); its force is contactForce.
  SelfContact selfContact;
  /// Located on a stretch with vertices on the wall: those vertices (the stretch's, i.e. the traced
  /// point's before it) and their forces μ_v at the point, in the same order; empty otherwise.
  std::vector<WallVertex> wallVertices;
  Eigen::VectorXd wallForces;
  /// The same for the stretch's self contacts (its ContactSet::self() order).
  Eigen::VectorXd selfForces;
  /// BC / SC / WC / WR: where the chain touches the wall or itself (NaN otherwise).
  Eigen::Vector2d contactPoint = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// BP of free joints: Koiter's coefficients of the bifurcated branch, λ(ξ) = λ + aξ + bξ² in the
  /// traced λ's units with ξ the unit joint-angle mode's amplitude in rad (koiter.h); invalid
  /// (the reason in its error, also in the note) where not computed.
  KoiterCoefficients koiter;
  /// BP with valid koiter: the knockdown of λ by an imperfection of each end coordinate x, y, φ,
  /// by a preload asymmetry of every segment and of the most sensitive single segment (n > 1)
  /// (imperfection_sensitivity.h).
  std::vector<ImperfectionSensitivity> imperfections;
  /// As PointReport::omega and PointReport::inputs, at the located point.
  Eigen::VectorXd omega;
  Eigen::VectorXd inputs;
};

struct BranchReport {
  std::vector<PointReport> points;            ///< within the range, in branch order
  std::vector<SpecialPointReport> specialPoints;
  /// The branch ended on a regular stop (range, boundary, box, arclength, a joint limit);
  /// false: it could not go on.
  bool finished = true;
  std::string stopReason;                     ///< continuation::toString(StopReason), or "joint limit"
  std::string stopMessage;
  double worstResidual = 0.0;                 ///< max corrector residual over the points
  /// Empty when the report computed everything its options ask for; else what it left out because
  /// ReportOptions::interrupt was requested, and why (the report is then incomplete).
  std::string skipped;
  /// Adds `what` to the parts left out (once each); reportBranch appends the reason at its end.
  void skip(const std::string& what);
};

/// Reports `branch`, traced on `problem`. Never throws for a numerical condition.
BranchReport reportBranch(EquilibriumProblem& problem, const continuation::Branch& branch,
                          const ReportOptions& options = {});
/// Same, for a branch continued through contact (continueUnderContact, equilibrium_branches.h):
/// its points carry their locked joints, and a boundary where the set changes is reported as
/// CT (a joint locks) or RL (it releases).
/// `geometric` (contact_geometry.h): the base and self contacts given (a mirror image's) or
/// returned as located.
BranchReport reportBranch(EquilibriumProblem& problem, const continuation::Branch& branch, const ReportOptions& options,
                          const std::vector<ContactStretch>& stretches, GeometricContacts* geometric = nullptr);

}  // namespace buckle::mechanics
