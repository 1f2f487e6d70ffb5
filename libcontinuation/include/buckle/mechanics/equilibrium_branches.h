// Equilibrium branches of a chain under a load path: the continuation core's bifurcation tree
// (continuation::traceTree: start branches, branch switching with its guards, interruption)
// with every branch reported in physical quantities and every special point named in the
// field's words (branch_report.h). This is the mechanics layer's one entry to the core: the
// command line, the atlas and the tests all trace through it.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/chain_tracer_options.h"
#include "buckle/mechanics/classification.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

struct EquilibriumBranchOptions {
  continuation::TracerOptions tracer;
  /// The bifurcation tree (branch_switching.h): generations of switching (one by default: a
  /// chain's analysis wants the branches of its buckling modes), how and where to switch, the
  /// switched branches' own tracer options and the per-branch callback. Its extend,
  /// switchTracer, onFinal and symmetry are traceEquilibria's own (contact, the stretches'
  /// problems, the reports and `mirror` below): set there, not here.
  continuation::TreeOptions tree = [] {
    continuation::TreeOptions oneGeneration;
    oneGeneration.branchSwitching = 1;
    return oneGeneration;
  }();
  ReportOptions report;            ///< how the branches are reported (stiffness, held coordinate)
  /// Called with each branch and its report as soon as both are final (TreeOptions::onFinal:
  /// children right after they are traced, a parent when its branch points are all switched at).
  /// When given, the report is handed over, `reports[b]` stays empty and the branch's points are
  /// released afterwards (its special points stay): the tree's memory then follows its largest
  /// branch, not its size. Null: every report is kept in `reports`.
  std::function<void(const continuation::Branch&, BranchReport&&)> onReport;
  /// Contact at the joints (contact.h): a branch that ends on a located joint limit goes on with
  /// that joint locked, in the same branch (its points appended), and with the joint free again
  /// where its contact torque returns to zero. False: the branch ends at the limit ("BD").
  /// Needs the problem's joint limits traced as boundaries (EquilibriumOptions).
  bool contact = true;
  /// A locked stretch ends (a located boundary, "BD") where a contact torque reaches this many
  /// torque units k̄b̄² of the chain (EquilibriumProblem::scales()): beyond, the chain is pressed
  /// against its stops far harder than its springs carry (e.g. a locked mechanism at a kinematic
  /// singularity under displacement control, whose reaction grows without bound).
  double maxContactTorque = 10.0;
  /// Mirror symmetry (mirror_symmetry.h): when the problem is exactly mirror symmetric (and the
  /// tracers have no box on the unknowns), the − side child of every symmetric pitchfork is the
  /// mirror image of the + side one, contact stretches included, instead of a second trace.
  /// False: both traced (for checking).
  bool mirror = true;
  /// Empty when valid, else what is wrong, the field named by its path after `prefix`.
  std::string validate(const std::string& prefix = "") const;
  bool IsValid(std::string* why) const { return continuation::reportValidity(validate(), why); }
};

struct EquilibriumBranches {
  continuation::BranchTree tree;
  /// reports[b] reports tree.branches[b] (empty when EquilibriumBranchOptions::onReport took it).
  std::vector<BranchReport> reports;
  /// classifications[b][s] names tree.branches[b].specialPoints[s].
  std::vector<std::vector<Classification>> classifications;
  bool startUnstable = false;      ///< the start state itself is unstable: "jumping" (Fig 6b)
  /// contact[b]: the stretches of tree.branches[b] with their locked joints (one stretch with no
  /// joint locked when the branch never touched a limit).
  std::vector<std::vector<ContactStretch>> contact;
};

/// Continues `branch`, traced on `problem` with the joints `initial` locked (a ContactProblem
/// with maxContactTorque; none: `problem` itself), through contact and release events
/// (contact.h) while it ends on a located joint limit or contact release; appends the new points
/// and special points to it and returns its stretches, the first with `initial`. `options` are
/// the branch's tracer options (maxPoints and maxArclength count the whole branch). The branch
/// keeps (q, r) per point: the wall forces of stretches with vertices on the wall (contact.h),
/// also those of a branch traced with `initial` vertices on the wall, are dropped
/// (ContactProblem::wallForces recovers them), and its branch points are not switched at.
/// The problem of a stretch with `locked` joints and wall vertices, its contact torques bounded by
/// maxContactTorque torque units (k b² of the problem's scales): what continueUnderContact traces
/// a stretch on.
std::unique_ptr<ContactProblem> lockedProblem(EquilibriumProblem& problem, const ContactSet& locked,
                                              double maxContactTorque);

std::vector<ContactStretch> continueUnderContact(EquilibriumProblem& problem, continuation::Branch& branch,
                                                 const continuation::TracerOptions& options,
                                                 double maxContactTorque = 10.0,
                                                 const ContactSet& initial = ContactSet());

/// Traces from joint angles q0 at λ0 (the held reactions are initialised by least squares, then
/// polished by the tracer's fixed-parameter corrector), one start branch per entry of `starts`.
EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const std::vector<continuation::InitialDirection>& starts,
                                    const EquilibriumBranchOptions& options);

/// One start direction.
EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options);

}  // namespace buckle::mechanics
