// Stop events of the tracer: the λ range, the box on x = (u, λ) and the problem's boundaries
// g_k(u, λ) ≥ 0. An event is crossed in a step when its value goes from ≥ 0 at a to < 0 at b;
// the crossing is located along the step by the locator's secant (its points are corrector
// solves, so on the branch), and coordinate events are landed on exactly by one more solve
// with that coordinate held at its bound.
#include "buckle/continuation/internal/locator.h"
#include "buckle/continuation/tracer.h"

#include <algorithm>
#include <cmath>

namespace buckle::continuation {

// Events, g ≥ 0 inside: 0 λ ≥ λmin, 1 λ ≤ λmax, then the box faces of x = (u, λ) (lower,
// upper per coordinate), then the problem's boundaries.
int Tracer::eventCount() const {
  const int boundaries = options_.detection.boundaries ? problem_.boundaryCount() : 0;
  return 2 + boxEventCount() + boundaries;
}

int Tracer::boxEventCount() const { return options_.boxLower.size() ? 2 * (n_ + 1) : 0; }

StopReason Tracer::eventStopReason(int event) const {
  if (event < 2) return StopReason::LambdaRange;
  return event < 2 + boxEventCount() ? StopReason::Box : StopReason::Boundary;
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
  return work_.boundary(e, p.u, p.lambda);
}

void Tracer::eventValues(const ContinuationPoint &p, std::vector<double> &values) {
  const int first = 2 + boxEventCount();
  for (int e = 0; e < first; ++e) values[size_t(e)] = eventValue(e, p);
  const int boundaries = static_cast<int>(values.size()) - first;
  if (boundaries > 0) work_.boundaries(p.u, p.lambda, Eigen::Map<Vector>(values.data() + first, boundaries));
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

void Tracer::locateStopEvent(const ContinuationPoint &a, const ContinuationPoint &b, EventHit &hit) {
  hit.event = -1;
  hit.accuracy = 0.0;
  hit.value = 0.0;
  bool stepSet = false;
  const int events = eventCount();
  eventValues(b, eventsB_);
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
    if (e < 2 + boxEventCount() && ga != 0.0) landOnCoordinateBound(e, a, located, accuracy);
    // Keep the earliest event along the step.
    const double s = stepAlong(a, located);
    if (hit.event < 0 || s < stepAlong(a, hit.point)) {
      hit.event = e;
      hit.point = located;
      hit.accuracy = accuracy;
      hit.value = eventValue(e, located) * eventScale(e);
    }
  }
  if (hit.event >= 0) {
    // the landed point is traced: the eigenvalues a traced point records (a sample has its inertia only)
    const int lowest = options_.detection.lowestEigenvalues;
    if (options_.detection.stability && hit.point.stability.valid() && hit.point.stability.lowest.size() < lowest &&
        !work_.stability(hit.point.u, hit.point.lambda, lowest, hit.point.stability))
      hit.point.stability = StabilityInfo();
    const double s = stepAlong(a, hit.point);
    hit.point.arclength = a.arclength + s;
    hit.point.stepSize = s;
  }
}

void Tracer::landOnCoordinateBound(int event, const ContinuationPoint &a, ContinuationPoint &located,
                                   double &accuracy) {
  const int coordinate = event < 2 ? n_ : (event - 2) / 2;
  const double bound = event == 0   ? lambdaMin_
                       : event == 1 ? lambdaMax_
                                    : ((event - 2) % 2 == 0 ? boxLower_[coordinate] : boxUpper_[coordinate]);
  predictor_.head(n_) = located.u;
  predictor_[n_] = located.lambda;
  predictor_[coordinate] = bound;
  const CorrectorOptions saved = corrector_->options();
  CorrectorOptions tight = saved;
  tight.tolerance = std::min(saved.tolerance, options_.location.newtonTolerance);
  corrector_->setOptions(tight);
  const CorrectorSummary fixed = corrector_->solveWithFixedCoordinate(predictor_, coordinate, x_);
  corrector_->setOptions(saved);
  if (!fixed.converged) return;  // the secant's point stands, with the secant's accuracy
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

}  // namespace buckle::continuation
