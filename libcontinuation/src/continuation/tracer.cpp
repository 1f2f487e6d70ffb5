#include "buckle/continuation/tracer.h"

#include "buckle/continuation/locator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace buckle::continuation {

namespace {

bool finite(double x) { return std::isfinite(x); }

std::string formatDouble(const char *pattern, double value) {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

}  // namespace

bool TracerOptions::IsValid(std::string *why) const {
  auto fail = [why](const std::string &message) {
    if (why) *why = message;
    return false;
  };
  if (!(initialStep > 0.0) || !finite(initialStep)) return fail("initialStep must be positive and finite");
  if (!(minStep > 0.0) || !finite(minStep)) return fail("minStep must be positive and finite");
  if (!(maxStep > 0.0) || !finite(maxStep)) return fail("maxStep must be positive and finite");
  if (minStep > maxStep) return fail("minStep must not exceed maxStep");
  if (initialStep < minStep || initialStep > maxStep) return fail("initialStep must lie in [minStep, maxStep]");
  if (targetNewtonIterations < 1) return fail("targetNewtonIterations must be at least 1");
  if (!(stepGrowth >= 1.0) || !finite(stepGrowth)) return fail("stepGrowth must be finite and >= 1");
  if (!(stepShrink > 0.0 && stepShrink <= 1.0)) return fail("stepShrink must lie in (0, 1]");
  if (!(slowContraction > 0.0) || !finite(slowContraction)) return fail("slowContraction must be positive");
  if (!(minTangentCosine > -1.0 && minTangentCosine <= 1.0))
    return fail("minTangentCosine must lie in (-1, 1]");
  if (maxPoints < 2) return fail("maxPoints must be at least 2");
  if (std::isnan(lambdaMin) || std::isnan(lambdaMax)) return fail("lambdaMin/lambdaMax must not be NaN");
  if (!(lambdaMin < lambdaMax)) return fail("lambdaMin must be smaller than lambdaMax");
  if (!(maxArclength > 0.0)) return fail("maxArclength must be positive");
  if (boxLower.size() != boxUpper.size()) return fail("boxLower and boxUpper must have the same size");
  for (Eigen::Index i = 0; i < boxLower.size(); ++i)
    if (std::isnan(boxLower[i]) || std::isnan(boxUpper[i]) || !(boxLower[i] < boxUpper[i]))
      return fail("boxLower[" + std::to_string(i) + "] must be smaller than boxUpper[" + std::to_string(i) + "]");
  if (!(newtonTolerance > 0.0) || !finite(newtonTolerance)) return fail("newtonTolerance must be positive and finite");
  if (!(newtonStepTolerance > 0.0) || !finite(newtonStepTolerance))
    return fail("newtonStepTolerance must be positive and finite");
  if (maxNewtonIterations < 1) return fail("maxNewtonIterations must be at least 1");
  if (!(locationTolerance > 0.0) || !finite(locationTolerance))
    return fail("locationTolerance must be positive and finite");
  if (!(locationNewtonTolerance > 0.0) || !finite(locationNewtonTolerance))
    return fail("locationNewtonTolerance must be positive and finite");
  if (maxLocationIterations < 1) return fail("maxLocationIterations must be at least 1");
  if (maxRefinementIterations < 1) return fail("maxRefinementIterations must be at least 1");
  if (!(separationFraction > 0.0 && separationFraction < 1.0)) return fail("separationFraction must lie in (0, 1)");
  if (lowestEigenvalues < 0) return fail("lowestEigenvalues must be >= 0");
  if (structuredFromDimension < 1) return fail("structuredFromDimension must be at least 1");
  if (maxDenseLocationDimension < 1) return fail("maxDenseLocationDimension must be at least 1");
  return true;
}

CorrectorOptions Tracer::stepCorrectorOptions() const {
  CorrectorOptions c;
  c.residualTolerance = options_.newtonTolerance;
  c.stepTolerance = options_.newtonStepTolerance;
  c.maxIterations = options_.maxNewtonIterations;
  c.lineSearch = options_.lineSearch;
  return c;
}

Tracer::Tracer(Problem &problem, const TracerOptions &options)
    : problem_(problem), options_(options), n_(problem.dimension()), work_(&problem) {
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
    scaled_ = std::make_unique<ScaledProblem>(problem_, units_);
    work_ = scaled_.get();
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
    structuredSolver_ = work_->makeStructuredSolver();
  if (options_.linearAlgebra == LA::Structured && !structuredSolver_) {
    invalidReason_ = "linearAlgebra = Structured, but the problem offers no structured solver";
    return;
  }
  BorderedSolver *solver = structuredSolver_.get();
  if (!solver) {
    denseSolver_ = std::make_unique<DenseBorderedSolver>(*work_);
    solver = denseSolver_.get();
  }
  corrector_ = std::make_unique<Corrector>(*work_, stepCorrectorOptions(), structuredSolver_.get());
  evaluator_ = std::make_unique<PointEvaluator>(*work_, *solver, options_.computeStability, options_.lowestEigenvalues);
  LocatorOptions lo;
  lo.tolerance = options_.locationTolerance;
  lo.newtonTolerance = options_.locationNewtonTolerance;
  lo.maxIterations = options_.maxLocationIterations;
  lo.maxRefinementIterations = options_.maxRefinementIterations;
  lo.separationFraction = options_.separationFraction;
  lo.minSampleCosine = options_.minTangentCosine;
  lo.detectFolds = options_.detectFolds;
  lo.detectBranchPoints = options_.detectBranchPoints;
  lo.denseAlgebra = n_ <= options_.maxDenseLocationDimension;
  lo.interrupt = options_.interrupt;
  locator_ = std::make_unique<Locator>(*work_, *corrector_, *evaluator_, lo);
  predictor_ = Vector::Zero(n_ + 1);
  x_ = Vector::Zero(n_ + 1);
}

Tracer::~Tracer() = default;

bool Tracer::completePoint(ContinuationPoint &point, ConstVectorRef referenceDirection) {
  return evaluator_ && evaluator_->complete(point, referenceDirection);
}

// Events, g ≥ 0 inside: 0 λ ≥ λmin, 1 λ ≤ λmax, then the box faces of x = (u, λ) (lower,
// upper per coordinate), then the problem's boundaries.
int Tracer::eventCount() const {
  const int box = options_.boxLower.size() ? 2 * (n_ + 1) : 0;
  const int boundaries = options_.detectBoundaries ? problem_.boundaryCount() : 0;
  return 2 + box + boundaries;
}

// Event values of a point in the scaled variables.
double Tracer::eventValue(int event, const ContinuationPoint &p) {
  if (event == 0) return p.lambda - lambdaMin_;
  if (event == 1) return lambdaMax_ - p.lambda;
  int e = event - 2;
  if (boxLower_.size()) {
    if (e < 2 * (n_ + 1)) {
      const int i = e / 2;
      const double xi = i < n_ ? p.u[i] : p.lambda;
      return e % 2 == 0 ? xi - boxLower_[i] : boxUpper_[i] - xi;
    }
    e -= 2 * (n_ + 1);
  }
  return work_->boundary(e, p.u, p.lambda);
}

StepAction Tracer::notifyStep(Branch &branch) {
  if (units_.identity()) return options_.onStep(branch);
  // The callback sees the new point and the special points in the problem's units; converting
  // only those keeps a step O(N) (the earlier points are converted when the tracer returns).
  // Restored from copies afterwards, so the tracer's own values are untouched bit for bit.
  const ContinuationPoint last = branch.points.back();
  const std::vector<SpecialPoint> specials = branch.specialPoints;
  units_.toUser(branch.points.back());
  for (SpecialPoint &sp : branch.specialPoints) units_.toUser(sp);
  const StepAction action = options_.onStep(branch);
  branch.points.back() = last;
  branch.specialPoints = specials;
  return action;
}

double Tracer::eventScale(int event) const {
  if (event < 2) return units_.parameter();
  const int e = event - 2;
  if (boxLower_.size() && e < 2 * (n_ + 1)) return units_.state(e / 2);
  return 1.0;  // the problem's boundaries g_k are evaluated in its own units
}

std::string Tracer::eventName(int event) const {
  if (event == 0) return "lambda min";
  if (event == 1) return "lambda max";
  int e = event - 2;
  if (options_.boxLower.size()) {
    if (e < 2 * (n_ + 1)) {
      const int i = e / 2;
      const std::string coordinate = i < n_ ? "u[" + std::to_string(i) + "]" : std::string("lambda");
      return std::string(e % 2 == 0 ? "box lower " : "box upper ") + coordinate;
    }
    e -= 2 * (n_ + 1);
  }
  return problem_.boundaryName(e);
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
    if (!jacobianKernel(*work_, start.u, start.lambda, kernel)) {
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
  SpecialPoint ep;
  ep.type = SpecialPointType::Endpoint;
  ep.index = 0;
  ep.u = start.u;
  ep.lambda = start.lambda;
  ep.tangent = start.tangent;
  ep.residualNorm = start.residualNorm;
  ep.inertiaBefore = ep.inertiaAfter = start.stability.negative;
  ep.note = startNote;
  branch.specialPoints.push_back(ep);
  units_.toUser(branch);

  for (int e = 0; e < eventCount(); ++e) {
    if (eventValue(e, start) < 0.0) {
      branch.stopReason = e < 2 ? StopReason::LambdaRange
                                : (e < 2 + (options_.boxLower.size() ? 2 * (n_ + 1) : 0) ? StopReason::Box
                                                                                         : StopReason::Boundary);
      branch.stopMessage = "start point outside the admissible set: " + eventName(e);
      return branch;
    }
  }
  continueBranch(branch, skipIntervals);
  return branch;
}

void Tracer::continueBranch(Branch &branch, int skipIntervals) {
  const ScopedScaling scaledBranch(units_, branch);  // the work is done in the scaled variables
  if (!invalidReason_.empty()) {
    branch.stopReason = StopReason::InvalidOptions;
    branch.stopMessage = invalidReason_;
    return;
  }
  if (branch.points.empty()) {
    branch.stopReason = StopReason::StartFailed;
    branch.stopMessage = "continueBranch needs a start point";
    return;
  }
  const int boxEvents = options_.boxLower.size() ? 2 * (n_ + 1) : 0;
  // Event values of the current point are kept from the step that produced it (each is O(1)
  // to O(N), and there are 2 + 2(N+1) + boundaries of them).
  const int events = eventCount();
  eventsA_.resize(size_t(events));
  eventsB_.resize(size_t(events));
  for (int e = 0; e < events; ++e) eventsA_[size_t(e)] = eventValue(e, branch.points.back());
  double ds = options_.initialStep;
  std::string lastFailure = "no failure";

  auto stop = [&branch](StopReason reason, const std::string &message) {
    branch.stopReason = reason;
    branch.stopMessage = message;
  };
  auto endpoint = [&branch](SpecialPointType type, const std::string &name, double accuracy, double value) {
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
  };
  // Halve after a failure; false (and the branch stopped) once below minStep.
  auto halve = [&]() {
    ds *= 0.5;
    if (ds < options_.minStep) {
      stop(StopReason::StepSizeTooSmall, "step size below minimum after " + lastFailure);
      return false;
    }
    return true;
  };

  for (;;) {
    if (options_.interrupt.requested()) {
      stop(StopReason::Interrupted, options_.interrupt.describe());
      endpoint(SpecialPointType::Endpoint, "interrupted", 0.0, 0.0);
      return;
    }
    if (static_cast<int>(branch.points.size()) >= options_.maxPoints) {
      stop(StopReason::MaxPoints, "reached maxPoints = " + std::to_string(options_.maxPoints));
      endpoint(SpecialPointType::Endpoint, "max points", 0.0, 0.0);
      return;
    }
    const int ia = static_cast<int>(branch.points.size()) - 1;
    const ContinuationPoint &a = branch.points[ia];
    const double remaining = options_.maxArclength - a.arclength;
    if (!(remaining > 0.0)) {
      stop(StopReason::MaxArclength, "reached maxArclength");
      endpoint(SpecialPointType::Endpoint, "max arclength", 0.0, 0.0);
      return;
    }
    const double dsTry = std::min(ds, remaining);
    predictor_.head(n_) = a.u + dsTry * a.tangent.head(n_);
    predictor_[n_] = a.lambda + dsTry * a.tangent[n_];
    const CorrectorSummary summary = corrector_->correct(predictor_, a.tangent, x_);
    if (!summary.converged) {
      lastFailure = summary.flagName;
      if (!halve()) return;
      continue;
    }
    ContinuationPoint b;
    b.u = x_.head(n_);
    b.lambda = x_[n_];
    if (!evaluator_->complete(b, a.tangent)) {
      lastFailure = "singular bordered Jacobian at the corrected point";
      if (!halve()) return;
      continue;
    }
    const double cosine = b.tangent.dot(a.tangent);
    if (cosine < options_.minTangentCosine) {
      lastFailure = formatDouble("branch-jump guard (tangent turned by %.3g degrees)",
                                 std::acos(std::max(-1.0, std::min(1.0, cosine))) * 180.0 / std::acos(-1.0));
      if (!halve()) return;
      continue;
    }
    b.arclength = a.arclength + dsTry;
    b.stepSize = dsTry;
    b.newtonIterations = summary.iterations;
    b.residualNorm = summary.residualNorm;

    // ---- stop events inside the step: keep the earliest, land exactly on it ----------------
    int hitEvent = -1;
    double hitAccuracy = 0.0, hitValue = 0.0;
    ContinuationPoint hitPoint;
    bool stepSet = false;
    for (int e = 0; e < events; ++e) eventsB_[size_t(e)] = eventValue(e, b);
    for (int e = 0; e < events; ++e) {
      const double ga = eventsA_[size_t(e)], gb = eventsB_[size_t(e)];
      if (!(ga >= 0.0 && gb < 0.0)) continue;
      if (!stepSet) {
        locator_->setStep(a, b);
        stepSet = true;
      }
      Locator::Root root;
      const auto test = [this, e](const ContinuationPoint &p, double &f) {
        f = eventValue(e, p);
        return std::isfinite(f);
      };
      ContinuationPoint located;
      double accuracy = 0.0;
      if (ga == 0.0) {
        located = a;
      } else if (locator_->findRoot(locator_->start(), ga, locator_->end(), gb, test, root)) {
        located = root.at.point;
        accuracy = root.lastDLambda;
      } else {
        continue;
      }
      // λ and box faces are coordinates: a last solve with that coordinate held lands exactly.
      if (e < 2 + boxEvents && ga != 0.0) {
        const int coordinate = e < 2 ? n_ : (e - 2) / 2;
        const double bound = e == 0 ? lambdaMin_
                             : e == 1 ? lambdaMax_
                             : ((e - 2) % 2 == 0 ? boxLower_[coordinate] : boxUpper_[coordinate]);
        predictor_.head(n_) = located.u;
        predictor_[n_] = located.lambda;
        predictor_[coordinate] = bound;
        const CorrectorOptions saved = corrector_->options();
        CorrectorOptions tight = saved;
        tight.residualTolerance = std::min(saved.residualTolerance, options_.locationNewtonTolerance);
        corrector_->setOptions(tight);
        const CorrectorSummary fixed = corrector_->solveWithFixedCoordinate(predictor_, coordinate, x_);
        corrector_->setOptions(saved);
        if (fixed.converged) {
          ContinuationPoint polished;
          polished.u = x_.head(n_);
          polished.lambda = x_[n_];
          polished.newtonIterations = fixed.iterations;
          polished.residualNorm = fixed.residualNorm;
          if (evaluator_->complete(polished, a.tangent)) {
            accuracy = std::abs(polished.lambda - located.lambda);
            located = polished;
          }
        }
      }
      const double s = a.tangent.dot(located.state() - a.state());
      if (hitEvent < 0 || s < a.tangent.dot(hitPoint.state() - a.state())) {
        hitEvent = e;
        hitPoint = located;
        hitAccuracy = accuracy;
        hitValue = eventValue(e, located) * eventScale(e);
      }
    }
    if (hitEvent >= 0) {
      const double s = a.tangent.dot(hitPoint.state() - a.state());
      hitPoint.arclength = a.arclength + s;
      hitPoint.stepSize = s;
      b = hitPoint;
    }

    // ---- special points between a and b -----------------------------------------------------
    std::vector<SpecialPoint> found;
    if (ia >= skipIntervals && (hitEvent < 0 || b.arclength > a.arclength)) {
      const IntervalCrossings crossings =
          classifyInterval(a, b, options_.detectFolds, options_.detectBranchPoints);
      if (crossings.fold || crossings.branchPointCrossings > 0) {
        locator_->setStep(a, b);
        found = locator_->locateSpecialPoints(crossings);
      }
    }
    // An interrupt during location leaves the step's special points half located: the step is
    // dropped, so every point the branch keeps is fully located, and the branch ends at a.
    if ((!found.empty() || hitEvent >= 0) && options_.interrupt.requested()) {
      stop(StopReason::Interrupted, options_.interrupt.describe());
      endpoint(SpecialPointType::Endpoint, "interrupted", 0.0, 0.0);
      return;
    }
    const bool landedOnStart = hitEvent >= 0 && !(b.arclength > a.arclength);
    // `a` refers into branch.points: everything that reads it is done before the push.
    if (!landedOnStart) branch.points.push_back(std::move(b));
    for (SpecialPoint &sp : found) {
      sp.index = ia;
      branch.specialPoints.push_back(std::move(sp));
    }
    if (options_.onStep && !landedOnStart && notifyStep(branch) == StepAction::Stop) {
      stop(StopReason::Interrupted, "stopped by the step callback");
      endpoint(SpecialPointType::Endpoint, "interrupted", 0.0, 0.0);
      return;
    }

    if (hitEvent >= 0) {
      const bool lambdaEvent = hitEvent < 2;
      const bool boxEvent = !lambdaEvent && hitEvent < 2 + boxEvents;
      const std::string name = eventName(hitEvent);
      stop(lambdaEvent ? StopReason::LambdaRange : (boxEvent ? StopReason::Box : StopReason::Boundary),
           "reached " + name);
      endpoint(lambdaEvent ? SpecialPointType::Endpoint : SpecialPointType::Boundary, name, hitAccuracy, hitValue);
      return;
    }
    if (branch.points.back().arclength >= options_.maxArclength * (1.0 - 1e-15)) {
      stop(StopReason::MaxArclength, "reached maxArclength");
      endpoint(SpecialPointType::Endpoint, "max arclength", 0.0, 0.0);
      return;
    }

    // ---- step adaptation ---------------------------------------------------------------------
    double factor = summary.iterations <= 1
                        ? options_.stepGrowth
                        : static_cast<double>(options_.targetNewtonIterations) / summary.iterations;
    factor = std::min(options_.stepGrowth, std::max(options_.stepShrink, factor));
    if (summary.contraction > options_.slowContraction) factor = std::min(factor, 0.7);
    ds = std::min(options_.maxStep, std::max(options_.minStep, ds * factor));
    eventsA_.swap(eventsB_);
  }
}

Branch trace(Problem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
             const TracerOptions &options) {
  Tracer tracer(problem, options);
  return tracer.trace(u0, lambda0, direction);
}

}  // namespace buckle::continuation
