#include "buckle/mechanics/equilibrium_branches.h"

#include <algorithm>
#include <any>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "buckle/continuation/multiplicity_switching.h"
#include "buckle/mechanics/mirror_symmetry.h"
#include "contact_events.h"

namespace buckle::mechanics {

namespace {

// A stretch's point or special point in the branch's unknowns (q, r): the wall forces μ, which
// the stretch's problem carries after them (contact.h), are dropped (wallForces recovers them).
void toBaseUnknowns(continuation::Vector& u, continuation::Vector& tangent, int N) {
  if (u.size() > N) u.conservativeResize(N);
  if (tangent.size() > N + 1) {
    const double tl = tangent[tangent.size() - 1];
    tangent.conservativeResize(N + 1);
    tangent[N] = tl;
  }
}
void toBaseUnknowns(continuation::SpecialPoint& sp, int N) {
  const Eigen::Index D = sp.u.size();
  toBaseUnknowns(sp.u, sp.tangent, N);
  if (sp.leftNullVector.size() > N) sp.leftNullVector.conservativeResize(N);
  if (sp.nullVectors.rows() == D + 1 && D > N) {  // branch point: (D + 1)×2, λ last
    continuation::Matrix v(N + 1, sp.nullVectors.cols());
    v.topRows(N) = sp.nullVectors.topRows(N);
    v.row(N) = sp.nullVectors.row(D);
    sp.nullVectors = v;
  } else if (sp.nullVectors.rows() == D && D > N) {  // fold: D×1
    sp.nullVectors.conservativeResize(N, sp.nullVectors.cols());
  }
}

// A stretch traced from the branch's last point appended to the branch (its points after the
// first, its special points), in the branch's unknowns and arclength; the index of the branch's
// point the stretch started from.
int appendStretch(continuation::Branch& stretch, int N, continuation::Branch& branch) {
  const int base = int(branch.points.size()) - 1;  // the stretch's point 0 is the branch's last point
  const double s0 = branch.points.back().arclength;
  for (size_t i = 1; i < stretch.points.size(); ++i) {
    stretch.points[i].arclength += s0;
    toBaseUnknowns(stretch.points[i].u, stretch.points[i].tangent, N);
    branch.points.push_back(std::move(stretch.points[i]));
  }
  for (continuation::SpecialPoint& sp : stretch.specialPoints) {
    sp.index += base;
    sp.arclength += s0;
    toBaseUnknowns(sp, N);
    branch.specialPoints.push_back(std::move(sp));
  }
  return base;
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

// What a child's own work (TreeOptions::childWork) computed on the thread that traced it: its
// sizes as traced and its contact stretches; for a child never switched at, its report too.
struct PreparedChild {
  std::pair<size_t, size_t> traced;
  std::vector<ContactStretch> contact;
  bool reported = false;
  std::vector<Classification> classifications;
  GeometricContacts geometric;
  BranchReport report;
};

PreparedChild* preparedOf(const continuation::Branch& b) {
  const auto* p = std::any_cast<std::shared_ptr<PreparedChild>>(&b.prepared);
  return p ? p->get() : nullptr;
}

// Switching generation of branch b (0: a root).
int generationOf(const continuation::BranchTree& t, size_t b) {
  int g = 0;
  for (int p = t.branches[b].parentId; p >= 0; p = t.branches[size_t(p)].parentId) ++g;
  return g;
}

// The earlier stretch that started where the branch stands now (its last point, a located contact
// event), with the same contacts and leaving in the same direction as p0 (the new stretch's
// start, oriented), or −1. Continuation from that start traced the curve the branch would trace
// again (the events are points of the curve, located to the location tolerance): the branch is a
// closed loop from there.
int repeatedStretch(const EquilibriumProblem& problem, const continuation::Branch& branch,
                    const std::vector<ContactStretch>& stretches, const ContactSet& locked,
                    const continuation::ContinuationPoint& p0) {
  const continuation::ContinuationPoint& here = branch.points.back();
  const continuation::ProblemScales s = problem.scales();
  const int N = problem.dimension(), D = int(p0.u.size());
  // relative to the unknowns' and λ's scales: far above the events' location accuracy (≈1e−12),
  // far below any distance between two different events with the same contacts
  constexpr double kSame = 1e-6;
  const auto near = [](double a, double b, double scale) {
    return std::abs(a - b) <= kSame * std::max(scale, std::max(std::abs(a), std::abs(b)));
  };
  for (size_t k = 1; k < stretches.size(); ++k) {
    const int e = stretches[k].firstPoint - 1;
    if (!(stretches[k].locked == locked) || e < 0 || e + 1 >= int(branch.points.size()) - 1) continue;
    const continuation::ContinuationPoint &then = branch.points[size_t(e)], &next = branch.points[size_t(e) + 1];
    bool same = near(here.lambda, then.lambda, s.parameter);
    for (int i = 0; same && i < N; ++i) same = near(here.u[i], then.u[i], s.unknowns[i]);
    if (!same) continue;
    // the direction the earlier stretch left in (its first step) against p0's tangent, in scaled units
    double along = (next.lambda - then.lambda) * p0.tangent[D] / (s.parameter * s.parameter);
    for (int i = 0; i < N; ++i) along += (next.u[i] - then.u[i]) * p0.tangent[i] / (s.unknowns[i] * s.unknowns[i]);
    if (along > 0.0) return int(k);
  }
  return -1;
}

// Whether the branch, standing at an event with p0 the next stretch's start, is back at one of
// its earlier events (repeatedStretch): then it ends there as a closed loop.
bool endsInLoop(const EquilibriumProblem& problem, continuation::Branch& branch,
                const std::vector<ContactStretch>& stretches, const ContactSet& locked,
                const continuation::ContinuationPoint& p0) {
  const int k = repeatedStretch(problem, branch, stretches, locked, p0);
  if (k <= 0) return false;
  const int at = stretches[size_t(k)].firstPoint - 1;
  char lambda[64];
  std::snprintf(lambda, sizeof lambda, "%.10g", branch.points[size_t(at)].lambda);
  branch.stopReason = continuation::StopReason::ClosedLoop;
  branch.stopMessage = "closed loop: back at point " + std::to_string(at) + " (parameter " + lambda +
                       ") with the same contacts and direction; from there it repeats itself";
  return true;
}

// Whether two contact events change the same contact (a joint's stop, a wall vertex, a self
// contact): a stretch that meets the change of another contact at once, at the event it started
// from, has met two contacts changing at one point (joints alike reaching their stops together,
// e.g. under a pure moment or in symmetric lobes of a long chain), taken one after the other there;
// the same contact changing again at once is chattering.
bool sameContact(const BoundaryEvent& a, const BoundaryEvent& b) {
  return (a.joint.joint >= 0 && a.joint.joint == b.joint.joint) || (a.vertex.segment >= 0 && a.vertex == b.vertex) ||
         (a.onSelf && b.onSelf && a.self == b.self);
}

// The budget's end as a branch's stop message.
std::string maxPointsMessage(int maxPoints, size_t stretches, bool atEvent) {
  return "reached maxPoints = " + std::to_string(maxPoints) + (atEvent ? " at a contact event" : "") +
         " (the whole branch, over " + std::to_string(stretches) + " contact stretches)";
}

// The tracer options of the next stretch: the budget of points and arclength is the whole
// branch's. False when the branch has spent it at the event it stands on: it ends for its
// budget there, not at a regular boundary.
bool budgetLeft(const continuation::TracerOptions& options, size_t stretches, continuation::Branch& branch,
                continuation::TracerOptions& next) {
  next.maxPoints = options.maxPoints - int(branch.points.size()) + 1;
  next.maxArclength = options.maxArclength - branch.points.back().arclength;
  if (next.maxPoints < 2) {
    branch.stopReason = continuation::StopReason::MaxPoints;
    branch.stopMessage = maxPointsMessage(options.maxPoints, stretches, true);
    return false;
  }
  if (!(next.maxArclength > 0.0)) {
    branch.stopReason = continuation::StopReason::MaxArclength;
    branch.stopMessage = "reached maxArclength at a contact event";
    return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<ContactProblem> lockedProblem(EquilibriumProblem& problem, const ContactSet& locked,
                                              double maxContactTorque) {
  const double torqueUnit = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  return std::make_unique<ContactProblem>(problem, locked, maxContactTorque * torqueUnit);
}

std::vector<ContactStretch> continueUnderContact(EquilibriumProblem& problem, continuation::Branch& branch,
                                                 const continuation::TracerOptions& options, double maxContactTorque,
                                                 const ContactSet& initial) {
  const int n = problem.segments();
  std::vector<ContactStretch> stretches{ContactStretch{0, initial}};
  std::unique_ptr<ContactProblem> current;  // the problem of the last stretch (null: `problem`)
  if (!initial.empty()) current = lockedProblem(problem, initial, maxContactTorque);
  if (initial.gapCount() > 0) {  // traced with the contact forces among the unknowns: keep (q, r)
    for (continuation::ContinuationPoint& p : branch.points) toBaseUnknowns(p.u, p.tangent, problem.dimension());
    for (continuation::SpecialPoint& sp : branch.specialPoints) toBaseUnknowns(sp, problem.dimension());
  }
  // No count of events: every stretch has two points or more, so the branch's budget ends the loop.
  int atOnce = 0;  // changes taken together at one point so far
  while (!branch.points.empty()) {
    const continuation::Problem& traced = current ? static_cast<const continuation::Problem&>(*current) : problem;
    const BoundaryEvent hit = endEvent(problem, traced, branch, stretches.back().locked);
    if (!hit.any()) break;
    // A time limit or a signal during the contact event: the branch ends interrupted, not as if
    // its contact boundary were a regular end.
    const auto interrupted = [&branch](const std::string& why) {
      branch.stopReason = continuation::StopReason::Interrupted;
      branch.stopMessage = why + " (at a contact event)";
    };
    if (options.interrupt.requested()) {
      interrupted(options.interrupt.describe());
      break;
    }
    const continuation::SpecialPoint& at = branch.specialPoints.back();
    const ContactChange change = changeOf(problem, at, hit, stretches.back().locked);
    if (!change.followed) {
      std::string& note = branch.specialPoints.back().note;
      note += std::string(note.empty() ? "" : "; ") + change.what +
              ": the vertex reaches an end of its edge; sliding past it is not followed, the branch ends here";
      break;
    }
    const ContactSet& locked = change.after;
    const bool onJoint = hit.joint.joint >= 0, release = change.release;
    continuation::TracerOptions o = options;
    if (!budgetLeft(options, stretches.size(), branch, o)) break;
    auto next = lockedProblem(problem, locked, maxContactTorque);
    auto giveUp = [&branch, &change](const std::string& why) {
      std::string& note = branch.specialPoints.back().note;
      note += (note.empty() ? "" : "; ") + change.what + ": " + why;
    };
    // The branch goes on past the event but is not followed: unfinished, not a regular end.
    auto notContinued = [&branch, &change, &giveUp](const std::string& why) {
      giveUp(why);
      branch.stopReason = continuation::StopReason::EventNotContinued;
      branch.stopMessage = change.what + ": " + why;
    };
    continuation::Tracer tracer(*next, o);
    // The stretch leaves the point to the admissible side of the changed contact's boundary g
    // (compression of a new contact, distance to the limit of a released joint or to the wall of a
    // released vertex): dg/ds > 0 along its tangent. The parent's direction decides only when that
    // is ambiguous: on an unstable branch a joint can reach its limit with the locked branch
    // turning back in λ (a corner).
    const int N = problem.dimension(), D = next->dimension(), wallIndex = change.index;
    // (a vertex leaving a corner along the edge that stays: that edge's end distance)
    const int changed = onJoint      ? (hit.joint.side == LimitSide::Upper ? hit.joint.joint : hit.joint.joint + n)
                        : change.slidesOn >= 0 ? next->selfEdgeBoundary(change.slidesOn) + 1
                        : hit.onSelf ? (release ? next->selfClearanceBoundary() : next->selfReleaseBoundary(wallIndex))
                        : release    ? next->wallClearanceBoundary()
                                     : next->wallReleaseBoundary(wallIndex);
    // Leave along the branch's tangent (q, r, λ; the wall forces' rates 0) with the newly locked
    // joint's component removed (the locked branch cannot move it); orientation only.
    continuation::Vector direction = continuation::Vector::Unit(D + 1, D);
    if (at.tangent.size() == N + 1 && at.tangent.norm() > 0.0) {
      direction.setZero();
      direction.head(N) = at.tangent.head(N);
      direction[D] = at.tangent[N];
      if (onJoint && !release) direction[hit.joint.joint] = 0.0;
    }
    // The start polished (polishEventStart). On the changed contact's boundary (g = 0 to the location's
    // accuracy, either sign), it is started by continueBranch, which only looks for crossings from
    // g ≥ 0, not by trace(), which refuses a start with g < 0.
    const EventStart start = polishEventStart(problem, locked, at, tracer, direction);
    if (!start.polished) {
      notContinued(start.message);
      break;
    }
    auto startPoint = [&](const continuation::Vector& along, continuation::ContinuationPoint& p) {
      p = continuation::ContinuationPoint();
      p.u = start.u;
      p.lambda = start.lambda;
      tracer.units().toScaled(p);
      if (!tracer.completePoint(p, tracer.units().directionToScaled(along))) return false;
      tracer.units().toUser(p);
      return true;
    };
    continuation::ContinuationPoint p0;
    if (!startPoint(direction, p0)) {
      notContinued("no unique tangent at the point");
      break;
    }
    const double rate = contactRate(problem, stretches.back().locked, hit, change, p0);
    if (rate < 0.0 && !startPoint(-p0.tangent, p0)) {
      notContinued("no unique tangent at the point");
      break;
    }
    if (endsInLoop(problem, branch, stretches, locked, p0)) {
      giveUp(branch.stopMessage);
      break;
    }
    p0.arclength = 0.0;
    continuation::Branch stretch;
    stretch.points.push_back(p0);
    tracer.continueBranch(stretch);
    if (stretch.stopReason == continuation::StopReason::Interrupted && stretch.points.size() < 2) {
      interrupted(stretch.stopMessage);
      break;
    }
    // A stretch that does not leave its start, or leaves it to the wrong side (a contact that
    // pulls at once, or a released joint or vertex that goes on past its limit or the wall),
    // would chatter: stop — unless it ends at once on a second contact change (two contacts
    // changing at one point), which the next pass takes with this one.
    const bool left = stretch.points.size() >= 2 && stretch.points.back().arclength > options.step.minStep;
    const BoundaryEvent second = left ? BoundaryEvent() : endEvent(problem, *next, stretch, locked);
    const bool together = second.any() && !sameContact(hit, second) && ++atOnce <= 2 * n;
    if (!left && !together) {
      const std::string why = "the branch does not leave the point (" + stretch.stopMessage + ")";
      if (stretch.stopReason == continuation::StopReason::Boundary && !second.any())
        giveUp(why);  // a boundary that is no contact event: the branch ends there
      else
        notContinued(why);
      break;
    }
    if (left) atOnce = 0;
    if (left && continuation::BoundProblem(*next).boundary(changed, stretch.points[1].u, stretch.points[1].lambda) < 0.0) {
      giveUp(release ? (onJoint                ? "the free joint would go past its limit"
                        : change.slidesOn >= 0 ? "the vertex would slide off the corner, away from both edges"
                        : hit.onSelf           ? "the bodies would pass into each other"
                                     : "the vertex would go through the wall")
                     : "the contact would pull (tension)");
      break;
    }
    const int base = appendStretch(stretch, N, branch);
    branch.stopReason = stretch.stopReason;
    branch.stopMessage = stretch.stopMessage;
    if (branch.stopReason == continuation::StopReason::MaxPoints)  // the stretch's share named the branch's
      branch.stopMessage = maxPointsMessage(options.maxPoints, stretches.size() + 1, false);
    stretches.push_back(ContactStretch{base + 1, locked});
    current = std::move(next);
  }
  return stretches;
}

// One branch at a time, in the core's tree driver (continuation::traceTree): each branch as it
// joins the tree is continued through contact (TreeOptions::extend), so the branch points of its
// locked stretches are switched at like the traced ones, on the stretch's own problem
// (TreeOptions::switchTracer); each branch is reported as soon as it is final (onFinal), so an
// interrupted tree has its finished branches reported and the time limit bounds the reports too.
std::string EquilibriumBranchOptions::validate(const std::string& prefix) const {
  namespace cont = continuation;
  return cont::firstProblem({tracer.validate(prefix + "tracer."), tree.validate(prefix + "tree."),
                             report.validate(prefix + "report."),
                             cont::requirePositive(prefix, "maxContactTorque", maxContactTorque)});
}

namespace {

// The children's own work (TreeOptions::childWork) on the thread that traced them: their contact
// stretches from the parent's contacts at the branch point (`locked`, copied when the switch was
// scheduled) and, for children never switched at (`leaves`), their classifications and reports.
continuation::TreeOptions::ChildWork childWork(EquilibriumProblem& problem, const EquilibriumBranchOptions& options,
                                               const continuation::TracerOptions& workerOptions,
                                               const continuation::Reflection& symmetry, ContactSet locked, bool leaves) {
  return [&problem, &options, &workerOptions, &symmetry, locked = std::move(locked),
          leaves](std::vector<continuation::Branch>& sides) {
    std::vector<std::shared_ptr<PreparedChild>> done;
    for (continuation::Branch& child : sides) {
      auto p = std::make_shared<PreparedChild>();
      p->traced = {child.points.size(), child.specialPoints.size()};
      const PreparedChild* source = child.mirrorOf >= 0 ? done[size_t(child.mirrorOf)].get() : nullptr;
      if (!options.contact || child.stopReason == continuation::StopReason::Interrupted) {
        p->contact = std::vector<ContactStretch>{ContactStretch{0, locked}};
      } else if (source) {
        p->contact = mirrored(source->contact);
        appendMirroredTail(symmetry, sides[size_t(child.mirrorOf)], source->traced, child);
      } else {
        p->contact = continueUnderContact(problem, child, workerOptions, options.maxContactTorque, locked);
      }
      if (leaves) {
        for (const continuation::SpecialPoint& sp : child.specialPoints)
          p->classifications.push_back(classify(problem, sp));
        if (source) {  // a mirror image's base and self contacts are its source's mirrored
          p->geometric.given = true;
          for (const GeometricContact& g : source->geometric.list)
            p->geometric.list.push_back(mirrored(symmetry, g));
        }
        p->report = reportBranch(problem, child, options.report, p->contact, &p->geometric);
        p->reported = true;
      }
      done.push_back(p);
    }
    for (size_t c = 0; c < sides.size(); ++c) sides[c].prepared = std::move(done[c]);
  };
}

}  // namespace

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const std::vector<continuation::InitialDirection>& starts,
                                    const EquilibriumBranchOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("EquilibriumBranchOptions: " + why);
  EquilibriumBranches result;
  const Eigen::VectorXd u0 = problem.initialGuess(q0, lambda0);
  continuation::TreeOptions tree = options.tree;
  // Not at a branch point on a stretch with vertices on the wall: its problem's unknowns carry
  // the wall forces, which the branch does not store (continueUnderContact); the point is reported.
  tree.switchAt = [&result, &options](const continuation::Branch& b, const continuation::SpecialPoint& bp) {
    if (size_t(b.id) < result.contact.size() && lockedAt(result.contact[size_t(b.id)], bp.index + 1).wallCount() > 0)
      return false;
    return !options.tree.switchAt || options.tree.switchAt(b, bp);
  };
  const bool box =
      options.tracer.boxLower.size() || (options.tree.childTracer && options.tree.childTracer->boxLower.size());
  if (options.mirror && !box) tree.symmetry = mirrorSymmetry(problem);
  const continuation::TracerOptions& childOptions = options.tree.childTracer ? *options.tree.childTracer : options.tracer;

  // traced[b]: the sizes of branch b as traced, before its contact stretches (a mirror image
  // takes its source's stretches from there on); geometric[b]: its base and self contacts.
  // All three indexed by branch id: a root is extended when its trace ends, after the branches
  // of its first branch points (continuation::traceTree), so extend() does not see the ids in order.
  std::vector<std::pair<size_t, size_t>> traced;
  std::vector<GeometricContacts> geometric;
  auto slot = [&](size_t id) {
    if (result.contact.size() > id) return;
    // a branch not (yet) extended: one stretch from its first point, no joint locked
    result.contact.resize(id + 1, std::vector<ContactStretch>{ContactStretch{}});
    traced.resize(id + 1);
    geometric.resize(id + 1);
  };
  // The joints locked where a child leaves its parent: those of the parent's stretch that holds
  // the branch point (the interval [index, index + 1] lies in the stretch of its end point).
  auto lockedAtParent = [&](const continuation::BranchTree& t, const continuation::Branch& b) {
    if (b.parentId < 0) return ContactSet();
    slot(size_t(b.parentId));
    const continuation::SpecialPoint& bp =
        t.branches[size_t(b.parentId)].specialPoints[size_t(b.parentSpecialPoint)];
    return lockedAt(result.contact[size_t(b.parentId)], bp.index + 1);
  };
  tree.extend = [&](const continuation::BranchTree& t, continuation::Branch& branch) {
    const size_t id = size_t(branch.id);
    slot(id);
    if (PreparedChild* p = preparedOf(branch)) {  // its work done where it was traced (childWork)
      traced[id] = p->traced;
      result.contact[id] = std::move(p->contact);
      return;
    }
    traced[id] = {branch.points.size(), branch.specialPoints.size()};
    const ContactSet locked = lockedAtParent(t, branch);
    if (!options.contact || branch.stopReason == continuation::StopReason::Interrupted) {
      result.contact[id] = std::vector<ContactStretch>{ContactStretch{0, locked}};
    } else if (branch.mirrorOf >= 0) {
      const size_t source = size_t(branch.mirrorOf);
      result.contact[id] = mirrored(result.contact[source]);
      appendMirroredTail(tree.symmetry, t.branches[source], traced[source], branch);
    } else {
      const continuation::TracerOptions& o = branch.parentId >= 0 ? childOptions : options.tracer;
      result.contact[id] = continueUnderContact(problem, branch, o, options.maxContactTorque, locked);
    }
  };
  // The children's stretches, and the reports of those never switched at, on the thread that
  // traced them (TreeOptions::threads; their progress callbacks stay on this thread).
  continuation::TracerOptions workerOptions = childOptions;
  if (options.tree.threads > 1) workerOptions.onStep = nullptr, workerOptions.onLocated = nullptr;
  tree.childWork = [&](const continuation::BranchTree& t, size_t b,
                       const continuation::SpecialPoint& bp) -> continuation::TreeOptions::ChildWork {
    slot(b);
    const bool leaves = generationOf(t, b) + 1 >= tree.branchSwitching;
    return childWork(problem, options, workerOptions, tree.symmetry, lockedAt(result.contact[b], bp.index + 1), leaves);
  };
  tree.switchTracer = [&](const continuation::BranchTree&, size_t b,
                          const continuation::SpecialPoint& bp) -> std::shared_ptr<continuation::Tracer> {
    slot(b);
    const ContactSet locked = lockedAt(result.contact[b], bp.index + 1);
    if (locked.empty()) return nullptr;
    // the stretch's problem lives as long as its tracer (aliasing shared_ptr)
    struct Owned {
      std::unique_ptr<ContactProblem> problem;
      std::optional<continuation::Tracer> tracer;
    };
    auto owned = std::make_shared<Owned>();
    owned->problem = lockedProblem(problem, locked, options.maxContactTorque);
    continuation::TracerOptions o = workerOptions;  // it may run on a worker (TreeOptions::threads)
    o.detection.certifiedCounting = false;  // as on the stretch itself (continueUnderContact)
    owned->tracer.emplace(*owned->problem, o);
    return std::shared_ptr<continuation::Tracer>(owned, &*owned->tracer);
  };
  tree.onFinal = [&](continuation::BranchTree& t, size_t b) {
    continuation::Branch& branch = t.branches[b];
    slot(b);  // a branch extend() never saw (invalid options)
    if (result.reports.size() < t.branches.size()) {
      result.reports.resize(t.branches.size());
      result.classifications.resize(t.branches.size());
    }
    BranchReport report;
    if (PreparedChild* prepared = preparedOf(branch); prepared && prepared->reported) {
      result.classifications[b] = std::move(prepared->classifications);
      geometric[b] = std::move(prepared->geometric);
      report = std::move(prepared->report);
      branch.prepared.reset();
      for (PointReport& p : report.points) p.branch = branch.id;  // its id is known from here on
      for (SpecialPointReport& sp : report.specialPoints) sp.branch = branch.id;
    } else {
      std::vector<Classification> names;
      for (const continuation::SpecialPoint& sp : branch.specialPoints) names.push_back(classify(problem, sp));
      result.classifications[b] = std::move(names);
      // A mirror image's base and self contacts are its source's mirrored (mirror_symmetry.h): the
      // source is final before its image (the + side is traced and reported first).
      const int source = branch.mirrorOf;
      if (source >= 0 && size_t(source) < b) {
        geometric[b].given = true;
        for (const GeometricContact& g : geometric[size_t(source)].list)
          geometric[b].list.push_back(mirrored(tree.symmetry, g));
      }
      report = reportBranch(problem, branch, options.report, result.contact[b], &geometric[b]);
    }
    if (b == 0) result.startUnstable = startIsUnstable(branch);
    if (!options.onReport) {
      result.reports[b] = std::move(report);
      return;
    }
    options.onReport(branch, std::move(report));
    // handed over: the tree needs the branch's points no more (TreeOptions::onFinal)
    std::vector<continuation::ContinuationPoint>().swap(branch.points);
  };
  result.tree = continuation::traceTree(problem, u0, lambda0, starts, options.tracer, tree);
  return result;
}

EquilibriumBranches traceEquilibria(EquilibriumProblem& problem, const Eigen::VectorXd& q0, double lambda0,
                                    const continuation::InitialDirection& direction,
                                    const EquilibriumBranchOptions& options) {
  return traceEquilibria(problem, q0, lambda0, std::vector<continuation::InitialDirection>{direction}, options);
}

}  // namespace buckle::mechanics
