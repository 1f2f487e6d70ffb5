#include "buckle/mechanics/equilibrium_branches.h"

#include <algorithm>
#include <cmath>

#include "buckle/continuation/multiplicity_switching.h"
#include "buckle/mechanics/mirror_symmetry.h"

namespace buckle::mechanics {

namespace {

// The boundary (joint, side) a branch's last special point stopped on, found by its name among
// the problem's boundaries; joint −1 when the branch did not end on one.
LockedJoint endBoundary(const continuation::Problem& problem, const continuation::Branch& branch, int segments) {
  if (branch.stopReason != continuation::StopReason::Boundary || branch.specialPoints.empty()) return {};
  const continuation::SpecialPoint& sp = branch.specialPoints.back();
  if (sp.type != continuation::SpecialPointType::Boundary) return {};
  for (int k = 0; k < std::min(problem.boundaryCount(), 2 * segments); ++k)  // the joints' limits and contacts
    if (problem.boundaryName(k) == sp.boundaryName) return limitOfBoundary(k, segments);
  return {};
}

// The mirror image's share of what continueUnderContact added to its source after the source's
// first `traced` (points, special points): the points after them and the special points from
// the last traced one on (where the contact began; its note may have grown), and the stop.
void appendMirroredTail(const continuation::Reflection& mirror, const continuation::Branch& source,
                        std::pair<size_t, size_t> traced, continuation::Branch& image) {
  if (source.points.size() == traced.first && source.specialPoints.size() == traced.second) return;
  for (size_t i = traced.first; i < source.points.size(); ++i) {
    image.points.push_back(source.points[i]);
    continuation::reflect(mirror, image.points.back());
  }
  const size_t from = traced.second > 0 ? traced.second - 1 : 0;
  image.specialPoints.resize(from);
  for (size_t k = from; k < source.specialPoints.size(); ++k) {
    image.specialPoints.push_back(source.specialPoints[k]);
    continuation::reflect(mirror, image.specialPoints.back());
  }
  image.stopReason = source.stopReason;
  image.stopMessage = mirror.mapText(source.stopMessage);
}

// The problem of a stretch with `locked` joints, its contact torques bounded by maxContactTorque
// torque units (what continueUnderContact traces a locked stretch on).
std::unique_ptr<ContactProblem> lockedProblem(EquilibriumProblem& problem, const ContactSet& locked,
                                              double maxContactTorque) {
  const double torqueUnit = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  return std::make_unique<ContactProblem>(problem, locked, maxContactTorque * torqueUnit);
}

}  // namespace

std::vector<ContactStretch> continueUnderContact(EquilibriumProblem& problem, continuation::Branch& branch,
                                                 const continuation::TracerOptions& options, int maxContactEvents,
                                                 double maxContactTorque, const ContactSet& initial) {
  const int n = problem.segments();
  std::vector<ContactStretch> stretches{ContactStretch{0, initial}};
  std::unique_ptr<ContactProblem> current;  // the problem of the last stretch (null: `problem`)
  if (!initial.empty()) current = lockedProblem(problem, initial, maxContactTorque);
  for (int events = 0; events < maxContactEvents && !branch.points.empty(); ++events) {
    const continuation::Problem& traced = current ? static_cast<const continuation::Problem&>(*current) : problem;
    const LockedJoint hit = endBoundary(traced, branch, n);
    if (hit.joint < 0) break;
    ContactSet locked = stretches.back().locked;
    const bool release = locked.locked(hit.joint) && locked.side(hit.joint) == hit.side;
    if (release)
      locked.release(hit.joint);
    else
      locked.lock(hit.joint, hit.side);
    const continuation::SpecialPoint& at = branch.specialPoints.back();
    // The budget of points and arclength is the whole branch's.
    continuation::TracerOptions o = options;
    o.maxPoints = options.maxPoints - int(branch.points.size()) + 1;
    o.maxArclength = options.maxArclength - branch.points.back().arclength;
    // The locked problem has no O(n) stabilityEigenvalues (the dense default is O(n³) per point
    // and made the near-zero spectrum most of a 50-segment tree's time): locked stretches keep
    // the inertia count and the determinant, without the hidden-crossing monitor.
    o.certifiedCounting = false;
    if (o.maxPoints < 2 || !(o.maxArclength > 0.0)) break;
    // Leave along the branch's tangent with the newly locked joint's component removed (the
    // locked branch cannot move it); orientation only.
    continuation::Vector t = at.tangent;
    if (!release && t.size() == problem.dimension() + 1) t[hit.joint] = 0.0;
    auto next = lockedProblem(problem, locked, maxContactTorque);
    const std::string what = std::string(release ? "release of joint " : "contact of joint ") +
                             std::to_string(hit.joint + 1) + " " + toString(hit.side);
    auto giveUp = [&branch, &what](const std::string& why) {
      std::string& note = branch.specialPoints.back().note;
      note += (note.empty() ? "" : "; ") + what + ": " + why;
    };
    // The start: the located point polished with the new set of locked joints. It lies on the
    // changed joint's boundary (g = 0 to the location's accuracy, either sign), so it is started
    // by continueBranch, which only looks for crossings from g ≥ 0, not by trace(), which refuses a
    // start with g < 0.
    const ConstrainedEquilibrium start =
        solveConstrainedEquilibrium(problem, locked, at.u, at.lambda, std::max(o.locationNewtonTolerance, 1e-12));
    if (!start.converged) {
      giveUp("the equilibrium could not be polished (" + start.message + ")");
      break;
    }
    continuation::Tracer tracer(*next, o);
    // The stretch leaves the point to the admissible side of the changed joint's boundary g
    // (compression of a new contact, distance to the limit of a released joint): dg/ds > 0 along
    // its tangent. The parent's direction decides only when that is ambiguous: on an unstable
    // branch a joint can reach its limit with the locked branch turning back in λ (a corner).
    const int changed = hit.side == LimitSide::Upper ? hit.joint : hit.joint + n;
    const int N = problem.dimension();
    auto startPoint = [&](const continuation::Vector& direction, continuation::ContinuationPoint& p) {
      p = continuation::ContinuationPoint();
      p.u = start.u;
      p.lambda = at.lambda;
      tracer.units().toScaled(p);
      if (!tracer.completePoint(p, tracer.units().directionToScaled(direction))) return false;
      tracer.units().toUser(p);
      return true;
    };
    continuation::Vector direction =
        t.size() == N + 1 && t.norm() > 0.0 ? t : continuation::Vector(continuation::Vector::Unit(N + 1, N));
    continuation::ContinuationPoint p0;
    if (!startPoint(direction, p0)) {
      giveUp("no unique tangent at the point");
      break;
    }
    // dg/ds: a released joint's g = side·(q̄ − q) moves with −side·t_q; a contact's compression
    // −side·τ_c with −side·(F_u,i t_u + F_λ,i t_λ) (the free equilibrium's row i, exact).
    double rate = 0.0;
    const double sideSign = hit.side == LimitSide::Upper ? 1.0 : -1.0;
    if (release) {
      rate = -sideSign * p0.tangent[hit.joint];
    } else {
      continuation::Matrix Fu(N, N);
      continuation::Vector Fl(N);
      if (problem.jacobian(p0.u, p0.lambda, Fu, Fl))
        rate = -sideSign * (Fu.row(hit.joint).dot(p0.tangent.head(N)) + Fl[hit.joint] * p0.tangent[N]);
    }
    if (rate < 0.0 && !startPoint(-p0.tangent, p0)) {
      giveUp("no unique tangent at the point");
      break;
    }
    p0.arclength = 0.0;
    continuation::Branch stretch;
    stretch.points.push_back(p0);
    tracer.continueBranch(stretch);
    // A stretch that does not leave its start, or leaves it to the wrong side (a contact that
    // pulls at once, or a released joint that goes on past its limit), would chatter: stop.
    if (stretch.points.size() < 2 || !(stretch.points.back().arclength > options.minStep)) {
      giveUp("the branch does not leave the point (" + stretch.stopMessage + ")");
      break;
    }
    if (next->boundary(changed, stretch.points[1].u, stretch.points[1].lambda) < 0.0) {
      giveUp(release ? "the free joint would go past its limit" : "the contact would pull (tension)");
      break;
    }
    const int base = int(branch.points.size()) - 1;  // the stretch's point 0 is the branch's last point
    const double s0 = branch.points.back().arclength;
    for (size_t i = 1; i < stretch.points.size(); ++i) {
      stretch.points[i].arclength += s0;
      branch.points.push_back(std::move(stretch.points[i]));
    }
    for (continuation::SpecialPoint& sp : stretch.specialPoints) {
      sp.index += base;
      sp.arclength += s0;
      branch.specialPoints.push_back(std::move(sp));
    }
    branch.stopReason = stretch.stopReason;
    branch.stopMessage = stretch.stopMessage;
    stretches.push_back(ContactStretch{base + 1, locked});
    current = std::move(next);
  }
  return stretches;
}

namespace {

// The branch points the tree never saw: traceTree switches at the branch points of the branches
// as traced, but those of their contact-continued stretches (continueUnderContact: locked
// stretches, and free ones after a release) are located later, on the problem of their stretch.
// Each is switched here on that problem (a ContactProblem with the stretch's joints locked),
// with the tree's guards — depth, switchAt, not the point a branch started from, not twice at
// the same point — and every child is itself continued through contact from the stretch's
// locked joints; its own branch points join the queue (breadth first, as in traceTree).
// `traced[b]`: the sizes of branch b before its contact stretches (what traceTree switched).
void switchOnContactStretches(EquilibriumProblem& problem, const EquilibriumBranchOptions& options,
                              std::vector<std::pair<size_t, size_t>>& traced, EquilibriumBranches& result) {
  continuation::BranchTree& tree = result.tree;
  const int N = problem.dimension();
  const continuation::ProblemScales scales = problem.scales();
  std::vector<int> depth;
  for (const continuation::Branch& b : tree.branches)
    depth.push_back(b.parentId >= 0 ? depth[size_t(b.parentId)] + 1 : 0);
  // The first special point of each branch not yet considered (0 for the children made here).
  std::vector<size_t> first;
  for (const auto& t : traced) first.push_back(t.second);
  std::vector<continuation::Vector> switchedAt;  // in the scaled variables
  const continuation::TracerOptions& childOptions = options.childTracer ? *options.childTracer : options.tracer;
  const double h = options.switching.amplitude > 0.0 ? options.switching.amplitude : childOptions.initialStep;
  auto addNote = [](std::string& note, const std::string& what) { note += (note.empty() ? "" : "; ") + what; };

  for (size_t b = 0; b < tree.branches.size(); ++b) {
    if (depth[b] >= options.switchingDepth) continue;
    for (size_t k = first[b]; k < tree.branches[b].specialPoints.size(); ++k) {
      continuation::SpecialPoint bp = tree.branches[b].specialPoints[k];
      const continuation::Branch& branch = tree.branches[b];
      if (bp.type != continuation::SpecialPointType::BranchPoint) continue;
      if (options.switchAt && !options.switchAt(branch, bp)) continue;
      if (!branch.points.empty() && bp.arclength - branch.points.front().arclength <= 1e-6 * h) continue;
      if (options.tracer.interrupt.requested()) {
        tree.interrupted = true;
        tree.message = options.tracer.interrupt.describe();
        return;
      }
      continuation::Vector x(N + 1);
      x << bp.u.cwiseQuotient(scales.unknowns), bp.lambda / scales.parameter;
      bool seen = false;
      for (const continuation::Vector& y : switchedAt)
        if ((y - x).norm() <= 1e-7 * std::max(1.0, x.norm())) seen = true;
      if (seen) {
        addNote(tree.branches[b].specialPoints[k].note, "already switched from another branch");
        continue;
      }
      switchedAt.push_back(x);
      // The interval [index, index + 1] lies in the stretch of its end point.
      const ContactSet locked = lockedAt(result.contact[b], bp.index + 1);
      std::unique_ptr<ContactProblem> lockedOne = locked.empty() ? nullptr
                                                                 : lockedProblem(problem, locked, options.maxContactTorque);
      continuation::TracerOptions o = childOptions;
      if (lockedOne) o.certifiedCounting = false;  // as on the stretch itself (continueUnderContact)
      continuation::Tracer tracer(lockedOne ? static_cast<continuation::Problem&>(*lockedOne) : problem, o);
      std::string how;
      std::vector<continuation::Branch> sides =
          bp.multiplicity > 1
              ? continuation::switchMultiple(tracer, bp, options.switching, &how)
              : continuation::switchBothSides(tracer, bp, options.switching, &how,
                                              [&](const continuation::Branch&) { return o.interrupt.requested(); });
      continuation::SpecialPoint& at = tree.branches[b].specialPoints[k];
      if (bp.multiplicity > 1) {
        at.branchesPredicted = bp.branchesPredicted;
        at.branchesFound = bp.branchesFound;
      }
      if (sides.empty()) {
        addNote(at.note, "not switched: " + how);
        continue;
      }
      std::string children;
      for (continuation::Branch& child : sides) {
        child.id = int(tree.branches.size());
        child.parentId = int(b);
        child.parentSpecialPoint = int(k);
        child.mirrorOf = -1;  // no reflection is used here: both sides are traced
        traced.emplace_back(child.points.size(), child.specialPoints.size());
        const bool stopped = child.stopReason == continuation::StopReason::Interrupted;
        result.contact.push_back(
            stopped ? std::vector<ContactStretch>{ContactStretch{0, locked}}
                    : continueUnderContact(problem, child, o, options.maxContactEvents, options.maxContactTorque, locked));
        children += (children.empty() ? "" : ", ") + std::to_string(child.id);
        tree.branches.push_back(std::move(child));
        depth.push_back(depth[b] + 1);
        first.push_back(0);
        if (stopped) {
          tree.interrupted = true;
          tree.message = tree.branches.back().stopMessage;
        }
        if (options.onBranch) options.onBranch(tree, tree.branches.back());
      }
      addNote(tree.branches[b].specialPoints[k].note,
              "switched on the contact stretch (" + how + "): branches " + children);
      if (tree.interrupted) return;
    }
  }
}

}  // namespace

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const std::vector<continuation::InitialDirection>& starts,
                                    const EquilibriumBranchOptions& options) {
  EquilibriumBranches result;
  const Eigen::VectorXd u0 = problem.initialGuess(q0, lambda0);
  continuation::TreeOptions tree;
  tree.maxDepth = options.switchingDepth;
  tree.switching = options.switching;
  tree.switchAt = options.switchAt;
  tree.childTracer = options.childTracer;
  tree.onBranch = options.onBranch;
  const bool box = options.tracer.boxLower.size() || (options.childTracer && options.childTracer->boxLower.size());
  if (options.mirror && !box) tree.symmetry = mirrorSymmetry(problem);
  result.tree = continuation::traceTree(problem, u0, lambda0, starts, options.tracer, tree);
  // Sizes of the branches as traced, before their contact stretches: a mirror image takes the
  // stretches of its source from there on.
  std::vector<std::pair<size_t, size_t>> traced;
  for (continuation::Branch& branch : result.tree.branches) {
    traced.emplace_back(branch.points.size(), branch.specialPoints.size());
    if (!options.contact || result.tree.interrupted) {
      result.contact.push_back(std::vector<ContactStretch>{ContactStretch{}});
    } else if (branch.mirrorOf >= 0) {
      result.contact.push_back(mirrored(result.contact[size_t(branch.mirrorOf)]));
      appendMirroredTail(tree.symmetry, result.tree.branches[size_t(branch.mirrorOf)], traced[size_t(branch.mirrorOf)],
                         branch);
    } else {
      const continuation::TracerOptions& o =
          branch.parentId >= 0 && options.childTracer ? *options.childTracer : options.tracer;
      result.contact.push_back(
          continueUnderContact(problem, branch, o, options.maxContactEvents, options.maxContactTorque));
    }
  }
  if (options.contact && !result.tree.interrupted) switchOnContactStretches(problem, options, traced, result);
  // A mirror image's base and self contacts are its source's mirrored (mirror_symmetry.h): the
  // source comes first in the tree, so its located contacts are at hand. Also in an interrupted
  // tree: an image is only made from a source that finished (branch_switching.cpp), and neither
  // got a contact stretch, so the image's points are its source's reflected, all of them. (The
  // reports are built after the time limit; locating the images' contacts again doubled that.)
  std::vector<GeometricContacts> geometric(result.tree.branches.size());
  for (size_t b = 0; b < result.tree.branches.size(); ++b) {
    const continuation::Branch& branch = result.tree.branches[b];
    std::vector<Classification> names;
    for (const continuation::SpecialPoint& sp : branch.specialPoints) names.push_back(classify(problem, sp));
    result.classifications.push_back(std::move(names));
    const int source = branch.mirrorOf;
    if (source >= 0 && size_t(source) < b) {
      geometric[b].given = true;
      for (const GeometricContact& g : geometric[size_t(source)].list)
        geometric[b].list.push_back(mirrored(tree.symmetry, g));
    }
    result.reports.push_back(reportBranch(problem, branch, options.report, result.contact[b], &geometric[b]));
  }
  if (!result.tree.branches.empty()) result.startUnstable = startIsUnstable(result.tree.branches.front());
  return result;
}

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options) {
  return traceEquilibria(problem, q0, lambda0, std::vector<continuation::InitialDirection>{direction}, options);
}

}  // namespace buckle::mechanics
