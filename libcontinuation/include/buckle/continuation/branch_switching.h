// Branch switching at simple branch points, and automatic tracing of the bifurcation tree.
//
// At a located simple BP, ker F_x (F_x = [F_u, F_λ], N×(N+1)) is 2-dimensional and spanned by
// the parent tangent t and an orthogonal φ. The tangents of the two crossing branches are the
// roots (α, β) of the algebraic bifurcation equation
//     ψᵀF_xx[αt + βφ, αt + βφ] = 0      (ψ: left null vector of F_x),
// one of which is the parent's. The child's direction is the other root (for a symmetric
// pitchfork it is φ; for a transcritical bifurcation it is not orthogonal to t). When the second
// derivatives are degenerate the direction falls back to φ, which still works: the first Keller
// step on the hyperplane φᵀ(x − x_BP) = h crosses the child branch transversally.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/symmetry.h"
#include "buckle/continuation/tracer.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace buckle::continuation {

struct BranchSwitchingOptions {
  /// Length h of the first step off the branch point; 0: the tracer's initialStep.
  double amplitude = 0.0;
  /// The first corrected point counts as off the parent branch when its distance from the
  /// parent's tangent line is at least this fraction of its distance from the BP.
  double minOffBranchFraction = 0.05;
  /// Empty when valid, else what is wrong, the field named as `prefix` + its name.
  std::string validate(const std::string &prefix = "") const;
  bool IsValid(std::string *why) const { return reportValidity(validate(), why); }
};

/// Unit tangent (N+1) of the branch that crosses the traced one at the simple branch point bp
/// (bp.nullVectors has the parent tangent and φ as columns). `note` says how it was obtained.
/// `structured`: the bifurcation equation from O(N) products (bifurcationDirectionsApplied) and
/// bp.leftNullVector required, no N×N matrix (switchBothSides: above the tracer's
/// maxDenseLocationDimension).
bool bifurcatingDirection(const BoundProblem &problem, const SpecialPoint &bp, Vector &direction,
                          std::string *note = nullptr, bool structured = false);

/// A new branch leaving bp along sign·direction: point 0 is the branch point itself, point 1
/// the first corrected point (confirmed off the parent branch), then traced with `tracer`.
/// Branch::stopReason == SwitchFailed when the first point could not be found. bp and direction
/// are in the problem's units; the first step (amplitude or initialStep) is dimensionless, in the
/// tracer's scaled variables.
Branch switchBranch(Tracer &tracer, const SpecialPoint &bp, const Vector &direction, int sign,
                    const BranchSwitchingOptions &options = BranchSwitchingOptions());

/// The branches crossing the traced one at the simple branch point bp, the tree driver's
/// switching step: bifurcatingDirection, then switchBranch on the + side and then the − side
/// (the + side: the direction's largest scaled component positive), each child traced with
/// `tracer`. `accept(child)`, when given, ends the search at the first child it accepts (the
/// later side is then not traced). `how` says how the direction was obtained, or why there is
/// none (then no branch is returned). With a `symmetry` (symmetry.h) that fixes bp and reverses
/// the direction (a symmetric pitchfork), the − side is not traced but the image of the + side
/// (its mirrorOf = 0, the index in the returned vector).
std::vector<Branch> switchBothSides(Tracer &tracer, const SpecialPoint &bp, const BranchSwitchingOptions &options,
                                    std::string *how = nullptr,
                                    const std::function<bool(const Branch &child)> &accept = nullptr,
                                    const Reflection &symmetry = Reflection());

struct TreeOptions {
  int branchSwitching = 0;             ///< switching generations (0: only the start branches)
  BranchSwitchingOptions switching;
  /// Which branch points to switch at, among those the guards allow (default: all of them);
  /// e.g. only the first one, to see which way the first bifurcated branch goes.
  std::function<bool(const Branch &branch, const SpecialPoint &bp)> switchAt;
  /// Tracer options of the switched branches (default: those of the start branches), e.g. a
  /// few points only.
  std::optional<TracerOptions> childTracer;
  /// Called when a branch is finished (traced or switched), before the next one starts: for
  /// progress reports; again for a root each time it was traced further (its id the same, its
  /// points and special points more: StopReason::Paused while it is not yet ended). The
  /// tracer's own per-step callback and interrupt are in TracerOptions.
  std::function<void(const BranchTree &tree, const Branch &finished)> onBranch;
  /// A branch's own continuation past the end of its trace (e.g. through contact events, with
  /// problems of its own), called once on every branch when its trace has ended (its id,
  /// parentId, parentSpecialPoint and mirrorOf set; a mirror image after its source): a child as
  /// it joins the tree, a root when its trace ends, after the branches of the branch points
  /// before (traceTree), so not in the order of the ids. The special points it appends are
  /// switched at like the traced ones.
  std::function<void(const BranchTree &tree, Branch &branch)> extend;
  /// The tracer to switch at `bp` of branch `branch` with, when not the tree's (e.g. a branch
  /// point on a stretch that `extend` traced on another problem of the same dimension); null:
  /// the tree's. The reflection `symmetry` is not used with such a tracer.
  std::function<std::shared_ptr<Tracer>(const BranchTree &tree, std::size_t branch, const SpecialPoint &bp)>
      switchTracer;
  /// Called once per branch when it is final: its branch points were switched at (their notes
  /// written) or will not be (its generation is branchSwitching, or the tree was interrupted); a mirror
  /// image's source is final only after its image joined the tree. Branches become final in
  /// this order: the children of a branch point right after they are traced, their parent when
  /// all its branch points are done. A consumer may report the branch here and release its
  /// points (the tree touches a final branch's points no more).
  std::function<void(BranchTree &tree, std::size_t branch)> onFinal;
  /// Threads that switch at branch points (≤ 1: the calling thread alone). With more, the
  /// children of different branch points are traced at once, each switch on a tracer and a
  /// problem workspace of its own, while the calling thread goes on along the parent; the
  /// children join the tree in the order of their branch points, so ids, notes and the guards
  /// are those of one thread, and at most threads + 2 switches are scheduled and not joined
  /// (memory: that many children). The tracers' onStep and onLocated are not called for
  /// the children then (they run on other threads); onBranch reports each child as it joins.
  int threads = 1;
  /// The children's own work, done right after their trace and before they join the tree, on the
  /// thread that traced them (a worker with threads > 1, concurrently with the calling thread
  /// and the other workers: it must touch nothing the tree's other callbacks change). Made on the
  /// calling thread when a switch at `bp` of branch `branch` is scheduled (it may copy what it
  /// needs from the tree then); called with the traced sides of that branch point (parentId and
  /// parentSpecialPoint set, id not yet, mirrorOf an index into `sides`), it may extend them (as
  /// `extend` would) and leave results in Branch::prepared for extend and onFinal to take.
  using ChildWork = std::function<void(std::vector<Branch> &sides)>;
  std::function<ChildWork(const BranchTree &tree, std::size_t branch, const SpecialPoint &bp)> childWork;
  /// A reflection symmetry of the problem (symmetry.h; empty: none): at the simple branch points
  /// it fixes, with a bifurcating direction it reverses, the − side child is the image of the
  /// + side one (Branch::mirrorOf) instead of a second trace: the same tree, up to rounding, in
  /// half the work.
  Reflection symmetry;

  /// Empty when valid, else what is wrong, the field named by its path after `prefix`
  /// (`symmetry` needs the problem's dimension: traceTree checks it).
  std::string validate(const std::string &prefix = "") const;
  bool IsValid(std::string *why) const { return reportValidity(validate(), why); }
};

/// The bifurcation tree from one start point, breadth first: the start branches, one per entry
/// of `starts` (roots, in that order, whether or not they got off the start), then, down to
/// branchSwitching generations, both sides of every simple branch point that is not the one a branch
/// started from and was not already switched from another branch (the guards are noted on the
/// branch point). Multiple points (multiplicity ≥ 2) are reported but not switched. A requested
/// TracerOptions::interrupt stops the branch in progress and every later one; the tree then
/// says so (`interrupted`, `message`). With branchSwitching > 0 a root is traced lazily, up to the
/// next branch point the loop is about to switch at (Tracer::pauseAtBranchPoints): the ids,
/// branches and points are those of tracing it whole first, but an interrupted tree holds the
/// branches of a root's first branch points (the weakest, along a load path from zero) however
/// many it has further on.
BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0,
                     const std::vector<InitialDirection> &starts, const TracerOptions &options,
                     const TreeOptions &tree);

/// One start direction: traceTree(problem, u0, λ0, {direction}, options, {branchSwitching, switching}).
BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
                     const TracerOptions &options, int branchSwitching,
                     const BranchSwitchingOptions &switching = BranchSwitchingOptions());

}  // namespace buckle::continuation
