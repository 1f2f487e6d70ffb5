#include "buckle/continuation/branch_switching.h"

#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/internal/test_functions.h"

#include <cmath>
#include <cstdio>
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
                       require(threads >= 0, prefix, "threads", "must be >= 0"),
                       childTracer ? childTracer->validate(prefix + "childTracer.") : std::string()});
}

namespace {

// The sign of a kernel vector is whatever the factorization gave: fix it so that the "+ side"
// of a branch point is the same in every unit system and with every linear algebra (the
// component of largest magnitude among the unknowns, in scaled variables, is positive).
void orient(Vector &direction, int n) {
  Eigen::Index largest = 0;
  direction.head(n).cwiseAbs().maxCoeff(&largest);
  if (direction[largest] < 0.0) direction = -direction;
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

}  // namespace buckle::continuation
