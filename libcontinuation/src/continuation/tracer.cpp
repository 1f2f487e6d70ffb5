#include "buckle/continuation/tracer.h"

#include "buckle/continuation/internal/locator.h"
#include "buckle/continuation/multiplicity_switching.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace buckle::continuation {

namespace {

std::string formatDouble(const char *pattern, double value) {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

// The point the branch ends on (its last point) as a special point of the given type.
void appendEndpoint(Branch &branch, SpecialPointType type, const std::string &name, double accuracy, double value) {
  const ContinuationPoint &last = branch.points.back();
  SpecialPoint sp;
  sp.type = type;
  sp.index = static_cast<int>(branch.points.size()) - 1;
  sp.arclength = last.arclength;
  sp.u = last.u;
  sp.lambda = last.lambda;
  sp.tangent = last.tangent;
  sp.residualNorm = last.residualNorm;
  sp.inertiaBefore = sp.inertiaAfter = last.stability.negative;
  sp.lambdaAccuracy = accuracy;
  sp.testFunctionValue = value;
  sp.boundaryName = name;
  branch.specialPoints.push_back(sp);
}

// Pausing at branch points (the tree switches at each before the branch goes on): a step a → b
// of length dsTry over more than Tracer::kPausedCrossings of them is retried shorter (true, ds
// that step), so the pause comes after a few and not after the thousands one first step of a
// long chain crosses (n = 10 000: about 1600 in the first 0.02 of the default path, its critical
// loads ∝ k²).
bool retryShorter(const ContinuationPoint &a, const ContinuationPoint &b, double dsTry, double minStep, double &ds) {
  if (!a.stability.valid() || !b.stability.valid()) return false;
  const int crossed = std::abs(b.stability.negative - a.stability.negative);
  const double shorter = dsTry * std::max(0.02, 0.5 * double(Tracer::kPausedCrossings) / double(crossed));
  if (crossed <= Tracer::kPausedCrossings || shorter < minStep) return false;
  ds = shorter;
  return true;
}

}  // namespace

Tracer::Tracer(const BoundProblem &problem, const TracerOptions &options)
    : problem_(problem), options_(options), n_(problem.dimension()), work_(problem) {
  // Invalid input is reported by trace()/continueBranch() as StopReason::InvalidOptions, never
  // thrown (docs/continuation.md, "Errors"): nothing below is built for it.
  if (n_ < 1) {
    invalidReason_ = "Problem::dimension() must be at least 1, got " + std::to_string(n_);
    return;
  }
  if (!options_.IsValid(&invalidReason_)) {
    if (invalidReason_.empty()) invalidReason_ = "invalid options";
    return;
  }
  if (options_.boxLower.size() != 0 && options_.boxLower.size() != n_ + 1) {
    invalidReason_ = "boxLower/boxUpper must be empty or have size N+1 = " + std::to_string(n_ + 1);
    return;
  }
  // The problem's units: everything below works in its scaled variables (scaled_problem.h).
  const ProblemScales scales = problem_.scales();
  const std::string badScales = scales.check(n_);
  if (!badScales.empty()) {
    invalidReason_ = "Problem::scales(): " + badScales;
    return;
  }
  units_ = UnitScaling(scales);
  if (!units_.identity()) {
    scaled_ = std::make_unique<ScaledProblem>(problem_.problem(), units_);
    scaledWorkspace_ = scaled_->workspaceOn(problem_);
    work_ = BoundProblem(*scaled_, *scaledWorkspace_);
  }
  lambdaMin_ = options_.lambdaMin / units_.parameter();
  lambdaMax_ = options_.lambdaMax / units_.parameter();
  boxLower_ = options_.boxLower;
  boxUpper_ = options_.boxUpper;
  for (Eigen::Index i = 0; i < boxLower_.size(); ++i) {
    boxLower_[i] /= units_.state(int(i));
    boxUpper_[i] /= units_.state(int(i));
  }
  using LA = TracerOptions::LinearAlgebra;
  if (options_.linearAlgebra != LA::Dense &&
      (options_.linearAlgebra == LA::Structured || n_ >= options_.structuredFromDimension))
    structuredSolver_ = work_.makeStructuredSolver();
  if (options_.linearAlgebra == LA::Structured && !structuredSolver_) {
    invalidReason_ = "linearAlgebra = Structured, but the problem offers no structured solver";
    return;
  }
  BorderedSolver *solver = structuredSolver_.get();
  if (!solver) {
    denseSolver_ = std::make_unique<DenseBorderedSolver>(work_);
    solver = denseSolver_.get();
  }
  corrector_ = std::make_unique<Corrector>(work_, options_.corrector, structuredSolver_.get());
  evaluator_ = std::make_unique<PointEvaluator>(work_, *solver, options_.detection.stability,
                                                options_.detection.lowestEigenvalues);
  LocatorOptions lo;
  lo.location = options_.location;
  lo.detection = options_.detection;
  lo.minSampleCosine = options_.step.minTangentCosine;
  lo.denseAlgebra = n_ <= options_.location.maxDenseDimension;
  lo.denseMultiplePoints = n_ <= kMaxDenseMultiplePointDimension;
  lo.interrupt = options_.interrupt;
  if (options_.onLocated)
    lo.onLocated = [this](const SpecialPoint &sp) {
      if (units_.identity()) return options_.onLocated(sp);
      SpecialPoint user = sp;
      units_.toUser(user);
      options_.onLocated(user);
    };
  locator_ = std::make_unique<Locator>(work_, *corrector_, *evaluator_, lo);
  predictor_ = Vector::Zero(n_ + 1);
  x_ = Vector::Zero(n_ + 1);
  along_ = Vector::Zero(n_ + 1);
}

double Tracer::stepAlong(const ContinuationPoint &a, const ContinuationPoint &b) {
  along_.head(n_) = b.u - a.u;
  along_[n_] = b.lambda - a.lambda;
  return a.tangent.dot(along_);
}

Tracer::~Tracer() = default;

bool Tracer::completePoint(ContinuationPoint &point, ConstVectorRef referenceDirection) {
  return evaluator_ && evaluator_->complete(point, referenceDirection);
}

StepAction Tracer::notifyStep(const Branch &branch, size_t firstNew) {
  // The callback sees the new point and the step's special points in the problem's units, as
  // copies into storage kept from step to step: a step stays O(N) and allocation-free (the
  // branch's own points stay in the scaled variables until the tracer returns).
  const ContinuationPoint *point = &branch.points.back();
  if (!units_.identity()) {
    stepPoint_ = *point;
    units_.toUser(stepPoint_);
    point = &stepPoint_;
  }
  stepSpecialPoints_.assign(branch.specialPoints.begin() + std::ptrdiff_t(std::min(firstNew, branch.specialPoints.size())),
                            branch.specialPoints.end());
  if (!units_.identity())
    for (SpecialPoint &sp : stepSpecialPoints_) units_.toUser(sp);
  const StepInfo info{*point,           stepSpecialPoints_, int(branch.points.size()), int(branch.specialPoints.size()),
                      &branch,          branch.points.front().lambda * units_.parameter()};
  return options_.onStep(info);
}

Branch Tracer::trace(ConstVectorRef u0, double lambda0, const InitialDirection &direction) {
  Branch branch;
  branch.direction = direction.tangent.size() ? 1 : (direction.lambdaSign >= 0 ? 1 : -1);
  if (!invalidReason_.empty()) {
    branch.stopReason = StopReason::InvalidOptions;
    branch.stopMessage = invalidReason_;
    return branch;
  }
  if (u0.size() != n_ || (direction.tangent.size() != 0 && direction.tangent.size() != n_ + 1)) {
    branch.stopReason = StopReason::InvalidOptions;
    branch.stopMessage = "start vector or direction has the wrong size for dimension " + std::to_string(n_);
    return branch;
  }

  // Inputs in the scaled variables; the branch goes back to the user's units before
  // continueBranch (which converts it for its own work).
  const Vector su0 = units_.identity() ? Vector(u0) : Vector(u0.cwiseQuotient(units_.scales().unknowns));
  const double slambda0 = lambda0 / units_.parameter();
  InitialDirection scaledDirection = direction;
  scaledDirection.tangent = units_.directionToScaled(direction.tangent);
  ContinuationPoint start;
  start.u = Vector::Zero(n_);
  const CorrectorSummary polish = corrector_->solveAtFixedParameter(su0, slambda0, start.u);
  if (!polish.converged) {
    branch.stopReason = StopReason::StartFailed;
    branch.stopMessage = std::string("start point did not converge at fixed lambda (") + polish.flagName + ")";
    return branch;
  }
  start.lambda = slambda0;
  start.newtonIterations = polish.iterations;
  start.residualNorm = polish.residualNorm;

  std::string startNote = "start";
  Vector t;
  // Large structured problems: the tangent from one bordered solve with the requested direction
  // (or e_λ) as border row, O(N); the dense kernel (SVD) only if that matrix is singular (a start
  // on a fold or a branch point) or for dense problems, where it also detects a 2-d kernel.
  if (structuredSolver_) {
    Vector reference = scaledDirection.tangent;
    if (!reference.size()) {
      reference = Vector::Zero(n_ + 1);
      reference[n_] = direction.lambdaSign >= 0 ? 1.0 : -1.0;
    }
    Vector rhs = Vector::Zero(n_ + 1), y(n_ + 1);
    rhs[n_] = 1.0;
    const bool regular = structuredSolver_->factor(start.u, start.lambda, reference) == Factorization::Regular &&
                         structuredSolver_->solve(rhs, y) && y.allFinite() && y.norm() > 0.0;
    if (regular) t = y.normalized();  // referenceᵀy = 1 > 0: oriented along the request
  }
  if (!t.size()) {
    KernelInfo kernel;
    if (!jacobianKernel(work_, start.u, start.lambda, kernel)) {
      branch.stopReason = StopReason::StartFailed;
      branch.stopMessage = "the problem refused the Jacobian at the start point";
      return branch;
    }
    t = kernel.right.col(0);
    const double sigmaScale = std::max(1.0, kernel.singularValues.maxCoeff());
    const bool twoDimensional = kernel.singularValues.size() > 1 && kernel.singularValues[1] <= 1e-10 * sigmaScale;
    if (scaledDirection.tangent.size()) {
      if (twoDimensional) {
        const Matrix K = kernel.right.leftCols(2);
        const Vector projected = K * (K.transpose() * scaledDirection.tangent);
        if (projected.norm() > 1e-12) t = projected.normalized();
        startNote += " (at a singular point: direction projected onto the 2-dimensional kernel)";
      }
      if (t.dot(scaledDirection.tangent) < 0.0) t = -t;
    } else {
      if (twoDimensional) startNote += " (at a singular point: kernel is 2-dimensional, direction arbitrary)";
      if (std::abs(t[n_]) < 1e-12) startNote += " (at a fold: lambda sign cannot orient the tangent)";
      if (t[n_] * direction.lambdaSign < 0.0) t = -t;
    }
  }
  int skipIntervals = 0;
  if (!evaluator_->complete(start, t)) {
    if (!evaluator_->lastWasSingular() || !scaledDirection.tangent.size()) {
      branch.stopReason = StopReason::StartFailed;
      branch.stopMessage = "singular bordered Jacobian at the start point";
      return branch;
    }
    // Starting on a branch point along a chosen kernel direction: the test functions are
    // degenerate here, so the first interval is not searched (as for a switched branch).
    start.tangent = t;
    start.foldTest = t[n_];
    skipIntervals = 1;
  }
  branch.points.push_back(start);
  appendEndpoint(branch, SpecialPointType::Endpoint, "", 0.0, 0.0);
  branch.specialPoints.back().note = startNote;
  units_.toUser(branch);

  for (int e = 0; e < eventCount(); ++e) {
    if (eventValue(e, start) < 0.0) {
      branch.stopReason = eventStopReason(e);
      branch.stopMessage = "start point outside the admissible set: " + eventName(e);
      return branch;
    }
  }
  continueBranch(branch, skipIntervals);
  return branch;
}

bool Tracer::takeStep(const ContinuationPoint &a, const ContinuationPoint *previous, double ds, ContinuationPoint &b,
                      CorrectorSummary &summary, double &turningAngle, std::string &failure) {
  predictor_.head(n_) = a.u + ds * a.tangent.head(n_);
  predictor_[n_] = a.lambda + ds * a.tangent[n_];
  // Second-order (Taylor) predictor: (t_a − t_p)/Δs_a is the branch's curvature vector x'' to
  // O(Δs), so adding ½ds²·x'' leaves the predictor O(ds³) from the branch instead of O(ds²):
  // fewer Newton iterations per step for the same step (both tangents are already known).
  if (previous && a.stepSize > 0.0) {
    const double c = 0.5 * ds * ds / a.stepSize;
    predictor_.head(n_) += c * (a.tangent.head(n_) - previous->tangent.head(n_));
    predictor_[n_] += c * (a.tangent[n_] - previous->tangent[n_]);
  }
  summary = corrector_->correct(predictor_, a.tangent, x_);
  if (!summary.converged) {
    failure = summary.flagName;
    return false;
  }
  b.u = x_.head(n_);
  b.lambda = x_[n_];
  if (!evaluator_->complete(b, a.tangent)) {
    failure = "singular bordered Jacobian at the corrected point";
    return false;
  }
  const double cosine = b.tangent.dot(a.tangent);
  // The angle itself only where something reads it: the guard's message, and the step rule that
  // limits the turning (NewtonCount, the default, does not; an acos per point is ≈ 85 instructions).
  turningAngle = 0.0;
  if (cosine < options_.step.minTangentCosine || options_.step.rule != StepOptions::Rule::NewtonCount)
    turningAngle = std::acos(std::max(-1.0, std::min(1.0, cosine)));
  if (cosine < options_.step.minTangentCosine) {
    failure = formatDouble("branch-jump guard (tangent turned by %.3g degrees)", turningAngle * 180.0 / std::acos(-1.0));
    return false;
  }
  // Two folds inside the step leave t_λ with the same sign at both ends (tracer.h).
  if (options_.step.foldPairGuard && options_.detection.folds &&
      foldPairInside(a.lambda, a.tangent[n_], b.lambda, b.tangent[n_],
                     std::sqrt((b.u - a.u).squaredNorm() + (b.lambda - a.lambda) * (b.lambda - a.lambda)))) {
    failure = "fold-pair guard (lambda turns back and forth inside the step)";
    return false;
  }
  b.arclength = a.arclength + ds;
  b.stepSize = ds;
  b.newtonIterations = summary.iterations;
  b.residualNorm = summary.residualNorm;
  return true;
}

std::vector<SpecialPoint> Tracer::locateSpecialPoints(const ContinuationPoint &a, const ContinuationPoint &b) {
  const IntervalCrossings crossings = classifyInterval(a, b, options_.detection.folds, options_.detection.branchPoints);
  if (!crossings.fold && crossings.branchPointCrossings == 0) {
    // Certified counting: the count saw nothing; do the eigenvalues next to zero agree?
    if (!options_.detection.certifiedCounting || !options_.detection.branchPoints) return {};
    const std::vector<SuspectedCrossing> suspects =
        suspectHiddenCrossings(a, b, stepAlong(a, b));
    if (suspects.empty()) return {};
    locator_->setStep(a, b);
    return locator_->locateHiddenCrossings(suspects);
  }
  locator_->setStep(a, b);
  return locator_->locateSpecialPoints(crossings);
}

void Tracer::continueBranch(Branch &branch, int skipIntervals) {
  const ScopedScaling scaledBranch(units_, branch);  // the work is done in the scaled variables
  if (!invalidReason_.empty()) {
    branch.stopReason = StopReason::InvalidOptions;
    branch.stopMessage = invalidReason_;
    return;
  }
  if (branch.points.empty()) {
    branch.stopReason = StopReason::InvalidOptions;
    branch.stopMessage = "continueBranch needs a branch with a start point";
    return;
  }
  // Event values of the current point are kept from the step that produced it (each is O(1)
  // to O(N), and there are 2 + 2(N+1) + boundaries of them).
  const int events = eventCount();
  eventsA_.resize(size_t(events));
  eventsB_.resize(size_t(events));
  eventValues(branch.points.back(), eventsA_);
  double ds = branch.stopReason == StopReason::Paused ? branch.resumeStep : options_.step.initialStep;
  if (branch.stopReason == StopReason::Paused) branch.stopReason = StopReason::NotStarted;
  std::string lastFailure = "no failure";
  bool pause = false;  // a branch point was located in the last step (pauseAtBranchPoints)

  // Ends the branch at its last point.
  auto stop = [&branch](StopReason reason, const std::string &message, SpecialPointType type, const std::string &name,
                        double accuracy = 0.0, double value = 0.0) {
    branch.stopReason = reason;
    branch.stopMessage = message;
    appendEndpoint(branch, type, name, accuracy, value);
  };
  auto interrupted = [&](const std::string &message) {
    stop(StopReason::Interrupted, message, SpecialPointType::Endpoint, "interrupted");
  };
  // After a failure: false (and the branch stopped, without an endpoint) once below minStep.
  auto halve = [&]() {
    if (options_.step.halve(ds)) return true;
    branch.stopReason = StopReason::StepSizeTooSmall;
    branch.stopMessage = "step size below minimum after " + lastFailure;
    return false;
  };

  for (;;) {
    if (options_.interrupt.requested()) {
      interrupted(options_.interrupt.describe());
      return;
    }
    if (pause) {
      branch.stopReason = StopReason::Paused;
      branch.stopMessage.clear();
      branch.resumeStep = ds;
      return;
    }
    if (static_cast<int>(branch.points.size()) >= options_.maxPoints) {
      stop(StopReason::MaxPoints, "reached maxPoints = " + std::to_string(options_.maxPoints),
           SpecialPointType::Endpoint, "max points");
      return;
    }
    const int ia = static_cast<int>(branch.points.size()) - 1;
    const ContinuationPoint &a = branch.points[ia];
    const double remaining = options_.maxArclength - a.arclength;
    if (!(remaining > 0.0)) {
      stop(StopReason::MaxArclength, "reached maxArclength", SpecialPointType::Endpoint, "max arclength");
      return;
    }
    const double dsTry = std::min(ds, remaining);
    ContinuationPoint b;
    CorrectorSummary summary;
    double turningAngle = 0.0;
    const ContinuationPoint *previous = options_.step.secondOrderPredictor && ia > 0 ? &branch.points[ia - 1] : nullptr;
    if (!takeStep(a, previous, dsTry, b, summary, turningAngle, lastFailure)) {
      if (!halve()) return;
      continue;
    }
    if (pauseAtBranchPoints_ && ia >= skipIntervals && retryShorter(a, b, dsTry, options_.step.minStep, ds)) continue;
    // What the step showed, for the next one (read before `a` and `previous` dangle on the push).
    StepObservation observed;
    observed.newtonIterations = summary.iterations;
    observed.contraction = summary.contraction;
    observed.turningAngle = turningAngle;
    observed.predictorOrder = previous && a.stepSize > 0.0 ? 2 : 1;  // as takeStep's predictor

    // Stop events inside the step: the earliest one, landed on exactly, ends the step there.
    // (Read into locals at once: the step callback below may run the tracer again.)
    locateStopEvent(a, b, stopHit_);
    const int hitEvent = stopHit_.event;
    const double hitAccuracy = stopHit_.accuracy, hitValue = stopHit_.value;
    if (hitEvent >= 0) b = std::move(stopHit_.point);

    std::vector<SpecialPoint> found;
    if (ia >= skipIntervals && (hitEvent < 0 || b.arclength > a.arclength)) {
      if (options_.detection.certifiedCounting && options_.detection.branchPoints) {
        // The values next to zero at both ends; their slopes only where the problem's rate bound
        // cannot exclude a hidden crossing (spectral_monitor.h): the same steps are searched.
        ContinuationPoint &start = branch.points[size_t(ia)];
        if (!start.spectrum.valid()) measureNearZeroValues(work_, start);
        measureNearZeroValues(work_, b);
        if (!rateBoundsExcludeCrossing(start, b, stepAlong(start, b))) {
          // x_ (the corrector's output, already copied into b) is free here: the shifted points'
          // workspace, so the hot loop allocates nothing.
          measureNearZeroSlopes(work_, start, x_);
          measureNearZeroSlopes(work_, b, x_);
        }
      }
      found = locateSpecialPoints(a, b);
    }
    // An interrupt during location leaves the step's special points half located: the step is
    // dropped, so every point the branch keeps is fully located, and the branch ends at a.
    if ((!found.empty() || hitEvent >= 0) && options_.interrupt.requested()) {
      interrupted(options_.interrupt.describe());
      return;
    }
    const bool landedOnStart = hitEvent >= 0 && !(b.arclength > a.arclength);
    // `a` refers into branch.points: everything that reads it is done before the push.
    if (!landedOnStart) branch.points.push_back(std::move(b));
    const size_t firstNew = branch.specialPoints.size();
    for (SpecialPoint &sp : found) {
      sp.index = ia;
      branch.specialPoints.push_back(std::move(sp));
    }
    if (!found.empty()) mergeCoincidentSpecialPoints(branch, firstNew);
    for (size_t k = firstNew; pauseAtBranchPoints_ && k < branch.specialPoints.size(); ++k)
      pause = pause || branch.specialPoints[k].type == SpecialPointType::BranchPoint;
    if (options_.onStep && !landedOnStart) {
      const StepAction action = notifyStep(branch, firstNew);
      if (action == StepAction::Stop) {
        interrupted("stopped by the step callback");
        return;
      }
      if (action == StepAction::Join) {
        stop(StopReason::Joined, "joined a branch already traced", SpecialPointType::Endpoint, "joined");
        return;
      }
    }

    if (hitEvent >= 0) {
      const std::string name = eventName(hitEvent);
      stop(eventStopReason(hitEvent), "reached " + name,
           hitEvent < 2 ? SpecialPointType::Endpoint : SpecialPointType::Boundary, name, hitAccuracy, hitValue);
      return;
    }
    if (branch.points.back().arclength >= options_.maxArclength * (1.0 - 1e-15)) {
      stop(StopReason::MaxArclength, "reached maxArclength", SpecialPointType::Endpoint, "max arclength");
      return;
    }
    ds = options_.step.next(ds, observed);
    eventsA_.swap(eventsB_);
  }
}

void Tracer::endPaused(Branch &branch, const std::string &message) {
  if (branch.stopReason != StopReason::Paused || branch.points.empty()) return;
  branch.stopReason = StopReason::Interrupted;
  branch.stopMessage = message;
  branch.resumeStep = 0.0;
  appendEndpoint(branch, SpecialPointType::Endpoint, "interrupted", 0.0, 0.0);
}

Branch trace(const BoundProblem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
             const TracerOptions &options) {
  Tracer tracer(problem, options);
  return tracer.trace(u0, lambda0, direction);
}

}  // namespace buckle::continuation
