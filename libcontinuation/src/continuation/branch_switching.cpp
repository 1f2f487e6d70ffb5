#include "buckle/continuation/branch_switching.h"

#include "buckle/continuation/multiplicity_switching.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/internal/test_functions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace buckle::continuation {

std::string BranchSwitchingOptions::validate(const std::string &prefix) const {
  return firstProblem({require(amplitude >= 0.0 && std::isfinite(amplitude), prefix, "amplitude", "must be finite and >= 0"),
                       require(minOffBranchFraction > 0.0 && minOffBranchFraction < 1.0, prefix,
                               "minOffBranchFraction", "must lie in (0, 1)")});
}

std::string TreeOptions::validate(const std::string &prefix) const {
  return firstProblem({require(branchSwitching >= 0, prefix, "branchSwitching", "must be >= 0"),
                       switching.validate(prefix + "switching."),
                       childTracer ? childTracer->validate(prefix + "childTracer.") : std::string()});
}

namespace {

// What is wrong with a tree's options for a problem of dimension n (the symmetry's size too).
std::string treeProblem(const TreeOptions &tree, int n) {
  std::string why = tree.validate();
  if (why.empty() && !tree.symmetry.IsValid(n, &why)) why = "symmetry: " + why;
  return why;
}

}  // namespace

namespace {

// The sign of a kernel vector is whatever the factorization gave: fix it so that the "+ side"
// of a branch point is the same in every unit system and with every linear algebra (the
// component of largest magnitude among the unknowns, in scaled variables, is positive).
void orient(Vector &direction, int n) {
  Eigen::Index largest = 0;
  direction.head(n).cwiseAbs().maxCoeff(&largest);
  if (direction[largest] < 0.0) direction = -direction;
}

// Whether the scaled point x is the start of the child `b`: closer to it than a millionth of
// the child's first step (the distance its own scale sets, in any units).
bool startsAt(const Branch &b, const Vector &x, const UnitScaling &units) {
  if (b.points.size() < 2) return true;
  auto scaled = [&](const ContinuationPoint &p) {
    Vector y(p.u.size() + 1);
    y << p.u, p.lambda;
    for (Eigen::Index j = 0; j < y.size(); ++j) y[j] /= units.state(int(j));
    return y;
  };
  const Vector x0 = scaled(b.points[0]);
  return (x - x0).norm() <= 1e-6 * (scaled(b.points[1]) - x0).norm();
}

// Whether the scaled point x (λ accuracy `accuracy`) is one of those switched at already.
bool switchedBefore(const std::vector<Vector> &switchedAt, const std::vector<double> &switchedAccuracy, const Vector &x,
                    double accuracy) {
  const Eigen::Index n = x.size() - 1;
  for (size_t j = 0; j < switchedAt.size(); ++j) {
    const Vector &y = switchedAt[j];
    const double dl = std::abs(y[n] - x[n]);
    if ((y - x).norm() <= 1e-7 * std::max(1.0, x.norm()) &&
        dl <= std::max({1e3 * (accuracy + switchedAccuracy[j]), 1e-6 * std::max(std::abs(y[n]), std::abs(x[n])),
                        4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(x[n]))}))
      return true;
  }
  return false;
}

}  // namespace

bool bifurcatingDirection(const BoundProblem &problem, const SpecialPoint &bp, Vector &direction, std::string *note,
                          bool structured) {
  const int n = problem.dimension();
  // In the problem's scaled variables (scaled_problem.h), where the kernel and the
  // bifurcation-equation thresholds are relative; the direction comes back in its units.
  const ProblemScales scales = problem.scales();
  if (!scales.identity() && scales.check(n).empty()) {
    const UnitScaling units(scales);
    const BoundScaledProblem scaledProblem(problem, units);
    const BoundProblem &scaled = scaledProblem.bound();  // its own scales are ones: no further recursion
    const bool found = bifurcatingDirection(scaled, units.scaled(bp), direction, note, structured);
    if (found) direction = units.directionToUser(direction);
    return found;
  }
  if (bp.type != SpecialPointType::BranchPoint || bp.nullVectors.cols() < 2 || bp.nullVectors.rows() != n + 1) {
    if (note) *note = "not a branch point with a 2-dimensional kernel";
    return false;
  }
  const Vector t = bp.nullVectors.col(0);
  const Vector phi = bp.nullVectors.col(1);
  Vector psi = bp.leftNullVector;
  if (psi.size() != n) {
    if (structured) {
      if (note) *note = "no left null vector (structured location did not refine the point)";
      return false;
    }
    KernelInfo kernel;
    if (!jacobianKernel(problem, bp.u, bp.lambda, kernel)) return false;
    psi = kernel.left.col(0);
  }
  direction = phi;
  Vector d1, d2;
  std::string why;
  const bool roots = structured ? bifurcationDirectionsApplied(problem, bp.u, bp.lambda, psi, t, phi, d1, d2, &why)
                                : bifurcationDirections(problem, bp.u, bp.lambda, psi, t, phi, d1, d2, &why);
  if (!roots) {
    orient(direction, n);
    if (note) *note = why + ": kernel direction orthogonal to the parent tangent";
    return true;
  }
  // The parent's own tangent is one root; the child is the one farther from it.
  direction = std::abs(d1.dot(t)) <= std::abs(d2.dot(t)) ? d1 : d2;
  orient(direction, n);
  if (note) *note = "algebraic bifurcation equation";
  return true;
}

Branch switchBranch(Tracer &tracer, const SpecialPoint &userBp, const Vector &userDirection, int sign,
                    const BranchSwitchingOptions &options) {
  // The tracer's corrector and completePoint work in its scaled variables (dimensionless h).
  const SpecialPoint bp = tracer.units().scaled(userBp);
  const Vector direction = tracer.units().directionToScaled(userDirection);
  Branch child;
  child.direction = sign >= 0 ? 1 : -1;
  std::string why;
  if (!options.IsValid(&why)) {
    child.stopReason = StopReason::InvalidOptions;
    child.stopMessage = "BranchSwitchingOptions: " + why;
    return child;
  }
  const BoundProblem &problem = tracer.problem();
  const int n = problem.dimension();
  if (direction.size() != n + 1 || bp.u.size() != n) {
    child.stopReason = StopReason::InvalidOptions;
    child.stopMessage = "branch point or direction has the wrong size";
    return child;
  }
  const double h = options.amplitude > 0.0 ? options.amplitude : tracer.options().step.initialStep;
  const Vector d = child.direction * direction.normalized();
  Vector xBP(n + 1);
  xBP << bp.u, bp.lambda;
  const Vector predictor = xBP + h * d;
  Vector x(n + 1);
  const CorrectorSummary summary = tracer.corrector().correct(predictor, d, x);
  if (!summary.converged) {
    child.stopReason = StopReason::SwitchFailed;
    child.stopMessage = std::string("first point off the branch point did not converge (") + summary.flagName + ")";
    return child;
  }
  const Vector w = x - xBP;
  const Vector parentTangent = bp.nullVectors.cols() ? Vector(bp.nullVectors.col(0)) : bp.tangent;
  const double offLine = (w - w.dot(parentTangent) * parentTangent).norm();
  if (!(offLine >= options.minOffBranchFraction * w.norm()) || w.norm() == 0.0) {
    child.stopReason = StopReason::SwitchFailed;
    child.stopMessage = "first point converged back onto the parent branch";
    return child;
  }

  ContinuationPoint start;
  start.u = bp.u;
  start.lambda = bp.lambda;
  // The bordered Jacobian is singular exactly at the BP; completePoint still records stability.
  tracer.completePoint(start, d);
  start.tangent = d;
  start.foldTest = d[n];
  start.determinantSign = 0;
  start.residualNorm = bp.residualNorm;

  ContinuationPoint first;
  first.u = x.head(n);
  first.lambda = x[n];
  if (!tracer.completePoint(first, d)) {
    child.stopReason = StopReason::SwitchFailed;
    child.stopMessage = "singular bordered Jacobian at the first point off the branch point";
    return child;
  }
  first.arclength = d.dot(w);
  first.stepSize = first.arclength;
  first.newtonIterations = summary.iterations;
  first.residualNorm = summary.residualNorm;

  child.points.push_back(start);
  child.points.push_back(first);
  SpecialPoint ep;
  ep.type = SpecialPointType::Endpoint;
  ep.index = 0;
  ep.u = start.u;
  ep.lambda = start.lambda;
  ep.tangent = d;
  ep.residualNorm = bp.residualNorm;
  ep.inertiaBefore = ep.inertiaAfter = start.stability.negative;
  ep.note = "start: branch point of the parent branch";
  child.specialPoints.push_back(ep);
  // The branch point sits at point 0, where the test functions are degenerate: skip interval 0.
  tracer.units().toUser(child);
  tracer.continueBranch(child, 1);
  return child;
}

std::vector<Branch> switchBothSides(Tracer &tracer, const SpecialPoint &bp, const BranchSwitchingOptions &options,
                                    std::string *how, const std::function<bool(const Branch &child)> &accept,
                                    const Reflection &symmetry) {
  std::vector<Branch> sides;
  Vector direction;
  const bool structured = tracer.problem().dimension() > tracer.options().location.maxDenseDimension;
  if (!bifurcatingDirection(tracer.problem(), bp, direction, how, structured)) return sides;
  // A symmetric pitchfork (symmetry.h): bp fixed by S, direction reversed by it. Compared in the
  // tracer's scaled variables, where the tolerance is relative.
  bool pitchfork = symmetry.enabled() && symmetry.IsValid(tracer.problem().dimension(), nullptr);
  if (pitchfork) {
    Vector x(bp.u.size() + 1);
    x << bp.u, bp.lambda;
    for (Eigen::Index j = 0; j < x.size(); ++j) x[j] /= tracer.units().state(int(j));
    pitchfork = symmetry.maps(x, 1) && symmetry.maps(tracer.units().directionToScaled(direction), -1);
  }
  for (int sign : {1, -1}) {
    if (sign < 0 && pitchfork && sides.front().stopReason != StopReason::Interrupted) {
      // the − side leaves along −d = diag(S, 1)d from the same point: the image of the + side
      sides.push_back(reflected(symmetry, sides.front()));
      sides.back().direction = -1;
      sides.back().mirrorOf = 0;
      break;
    }
    sides.push_back(switchBranch(tracer, bp, direction, sign, options));
    if (accept && accept(sides.back())) break;
  }
  return sides;
}

BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0,
                     const std::vector<InitialDirection> &starts, const TracerOptions &options, const TreeOptions &treeOptions) {
  BranchTree tree;
  Tracer tracer(problem, options);
  std::unique_ptr<Tracer> childTracer;  // only when the children have options of their own
  if (treeOptions.childTracer) childTracer = std::make_unique<Tracer>(problem, *treeOptions.childTracer);
  Tracer &treeSwitchTracer = childTracer ? *childTracer : tracer;
  std::vector<int> depth;
  std::vector<char> isFinal;
  // A branch is final once (TreeOptions::onFinal); at the end every branch is.
  auto finalize = [&](std::size_t i) {
    if (isFinal[i]) return;
    isFinal[i] = 1;
    if (treeOptions.onFinal) treeOptions.onFinal(tree, i);
  };
  // A branch joins the tree (add) and is extended once its trace has ended (settle).
  auto settle = [&](std::size_t i) {
    Branch &b = tree.branches[i];
    if (treeOptions.extend && b.stopReason != StopReason::InvalidOptions) treeOptions.extend(tree, b);
    if (tree.branches[i].stopReason == StopReason::Interrupted) {
      tree.interrupted = true;
      tree.message = tree.branches[i].stopMessage;
    }
  };
  auto finish = [&]() -> BranchTree & {
    for (std::size_t i = 0; i < tree.branches.size(); ++i) {
      if (tree.branches[i].stopReason == StopReason::Paused) {  // stopped early: the tree is interrupted
        Tracer::endPaused(tree.branches[i], tree.message.empty() ? "interrupted" : tree.message);
        settle(i);
      }
      finalize(i);
    }
    return tree;
  };
  auto interrupted = [&]() {
    if (!options.interrupt.requested()) return false;
    tree.interrupted = true;
    tree.message = options.interrupt.describe();
    return true;
  };
  auto add = [&](Branch &&b, int generation) {
    b.id = static_cast<int>(tree.branches.size());
    tree.branches.push_back(std::move(b));
    depth.push_back(generation);
    isFinal.push_back(0);
    if (tree.branches.back().stopReason != StopReason::Paused) settle(tree.branches.size() - 1);
    if (treeOptions.onBranch) treeOptions.onBranch(tree, tree.branches.back());
  };
  // A paused root goes on to its next branch point or end; an interrupt ends it where it stands.
  auto resume = [&](std::size_t i) {
    if (tree.branches[i].stopReason != StopReason::Paused) return false;
    if (tree.interrupted || interrupted()) {
      Tracer::endPaused(tree.branches[i], tree.message);
    } else {
      tracer.pauseAtBranchPoints(true);
      tracer.continueBranch(tree.branches[i]);
      tracer.pauseAtBranchPoints(false);
    }
    if (tree.branches[i].stopReason != StopReason::Paused) settle(i);
    if (treeOptions.onBranch) treeOptions.onBranch(tree, tree.branches[i]);
    return true;
  };
  if (const std::string why = treeProblem(treeOptions, problem.dimension()); !why.empty()) {
    Branch invalid;
    invalid.stopReason = StopReason::InvalidOptions;
    invalid.stopMessage = "TreeOptions: " + why;
    add(std::move(invalid), 0);
    return finish();
  }
  // With switching the roots are traced lazily (header): here up to their first branch point.
  tracer.pauseAtBranchPoints(treeOptions.branchSwitching > 0);
  for (const InitialDirection &direction : starts) {
    if (tree.interrupted || interrupted()) return finish();
    add(tracer.trace(u0, lambda0, direction), 0);
    if (treeOptions.branchSwitching <= 0) finalize(tree.branches.size() - 1);
  }
  tracer.pauseAtBranchPoints(false);
  std::vector<Vector> switchedAt;
  std::vector<double> switchedAccuracy;  // |Δλ| of each, scaled
  const int n = problem.dimension();
  const BranchSwitchingOptions &switching = treeOptions.switching;

  for (std::size_t i = 0; i < tree.branches.size(); ++i) {
    if (depth[i] >= treeOptions.branchSwitching) continue;
    for (std::size_t k = 0;; ++k) {
      // past the last special point: a paused root goes on (and gains a branch point or its end)
      if (k >= tree.branches[i].specialPoints.size() && !(resume(i) && k < tree.branches[i].specialPoints.size()))
        break;
      SpecialPoint bp = tree.branches[i].specialPoints[k];
      if (bp.type != SpecialPointType::BranchPoint) continue;
      if (treeOptions.switchAt && !treeOptions.switchAt(tree.branches[i], bp)) continue;
      if (tree.interrupted || interrupted()) return finish();
      Vector xBP(n + 1);
      xBP << bp.u, bp.lambda;
      for (int j = 0; j <= n; ++j) xBP[j] /= tracer.units().state(j);  // compared in the scaled variables
      // The BP a child starts from is the parent's; never switch back at it. Only a child starts
      // at a branch point, and the same point is the one within a millionth of the child's first
      // step from its start: a root's branch points are switched however close to its start they
      // lie (at κ → 0 they crowd at λ ~ κ, 1e-10 of the path's range).
      if (tree.branches[i].parentId >= 0 && startsAt(tree.branches[i], xBP, tracer.units())) continue;
      // The same point located from another branch: near in the state, and in λ within the two
      // locations' accuracy or a millionth of λ itself (distinct points of a cluster at λ ~ 1e-10
      // lie far closer than 1e-7 in the state, but their λ differ by far more than that).
      const double accuracy = bp.lambdaAccuracy / tracer.units().parameter();
      const bool seen = switchedBefore(switchedAt, switchedAccuracy, xBP, accuracy);
      std::string &note = tree.branches[i].specialPoints[k].note;
      if (seen) {
        note += (note.empty() ? "" : "; ") + std::string("already switched from another branch");
        continue;
      }
      switchedAt.push_back(xBP);
      switchedAccuracy.push_back(std::isfinite(accuracy) ? accuracy : 0.0);
      const std::shared_ptr<Tracer> own = treeOptions.switchTracer ? treeOptions.switchTracer(tree, i, bp) : nullptr;
      Tracer &switchTracer = own ? *own : treeSwitchTracer;
      std::string how;
      std::vector<Branch> sides;
      if (bp.multiplicity > 1) {
        // every solution direction of the m-dimensional reduced equation, both sides
        sides = switchMultiple(switchTracer, bp, switching, &how);
        tree.branches[i].specialPoints[k].branchesPredicted = bp.branchesPredicted;
        tree.branches[i].specialPoints[k].branchesFound = bp.branchesFound;
      } else {
        // after the + side, the − side only if no stop was asked for meanwhile
        sides = switchBothSides(switchTracer, bp, switching, &how,
                                [&](const Branch &) { return options.interrupt.requested(); },
                                own ? Reflection() : treeOptions.symmetry);
      }
      if (sides.empty()) {
        note += (note.empty() ? "" : "; ") + std::string("not switched: ") + how;
        continue;
      }
      std::string children;
      const std::size_t firstChild = tree.branches.size();
      for (Branch &child : sides) {
        if (child.mirrorOf >= 0) child.mirrorOf += static_cast<int>(firstChild);  // an index into `sides` → a branch id
        child.parentId = static_cast<int>(i);
        child.parentSpecialPoint = static_cast<int>(k);
        children += (children.empty() ? "" : ", ") + std::to_string(tree.branches.size());
        add(std::move(child), depth[i] + 1);
      }
      std::string &noteAfter = tree.branches[i].specialPoints[k].note;
      noteAfter += (noteAfter.empty() ? "" : "; ") + ("switched (" + how + "): branches " + children);
      // the children that will not be switched at are final now, after a mirror image joined its source
      for (std::size_t c = firstChild; c < tree.branches.size(); ++c)
        if (depth[c] >= treeOptions.branchSwitching) finalize(c);
    }
    finalize(i);
  }
  return finish();
}

BranchTree traceTree(const BoundProblem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
                     const TracerOptions &options, int maxDepth, const BranchSwitchingOptions &switching) {
  TreeOptions tree;
  tree.branchSwitching = maxDepth;
  tree.switching = switching;
  return traceTree(problem, u0, lambda0, std::vector<InitialDirection>{direction}, options, tree);
}

}  // namespace buckle::continuation
