// Pseudo-arclength continuation of one branch (Keller; AUTO-07p / MATCONT style).
//
// Each step: tangent predictor x̂ = x + ds·t, Keller corrector on the bordered system, new
// tangent from [[F_u, F_λ], [t_prevᵀ]] t = e_{N+1} (which keeps the orientation, t_newᵀt_prev > 0),
// a branch-jump guard on the tangent turning angle, then detection and location of special
// points and of the stop conditions (parameter range, box, boundaries g_k = 0) between the last
// two points. The step adapts to the Newton iteration count and contraction.
//
// Units: the tracer works in the problem's scaled variables ũ = u/D_u, λ̃ = λ/λ₀, F̃ = F/D_F
// (Problem::scales(), scaled_problem.h). So the arclength is AUTO's weighted one, the step sizes
// (step.initialStep, minStep, maxStep, maxArclength) are dimensionless, corrector.tolerance bounds ‖F̃‖∞
// (relative to the size of the terms that balance in each row), the location target is
// location.tolerance·max(λ₀, |λ|), and every internal threshold is relative: the same chain in
// any units gives the same points. What trace() and continueBranch() return (u, λ, tangents,
// eigenvalues, accuracies) is in the user's units; arclength, step sizes, residual norms and
// the fold / branch-point test-function values are the scaled, dimensionless ones. The λ range
// and the box are given in the user's units.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch.h"
#include "buckle/continuation/corrector.h"
#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/step_control.h"
#include "buckle/continuation/internal/test_functions.h"
#include "buckle/continuation/tracer_options.h"

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace buckle::continuation {

/// Which way to leave the start point.
struct InitialDirection {
  int lambdaSign = 1;  ///< used when `tangent` is empty: sign of dλ/ds at the start
  Vector tangent;      ///< optional (N+1) direction; the start tangent is oriented along it

  static InitialDirection increasingLambda() { return InitialDirection{1, Vector()}; }
  static InitialDirection decreasingLambda() { return InitialDirection{-1, Vector()}; }
  static InitialDirection along(const Vector &t) { return InitialDirection{1, t}; }
};

class Locator;

/// Holds the corrector (one KINSOL instance) and the workspaces for a problem; trace() may be
/// called repeatedly.
class Tracer {
 public:
  Tracer(const BoundProblem &problem, const TracerOptions &options);
  ~Tracer();
  Tracer(const Tracer &) = delete;
  Tracer &operator=(const Tracer &) = delete;

  /// Polishes (u0, λ0) at fixed λ, takes the start tangent from the kernel of [F_u, F_λ] and
  /// traces until a stop condition. Never throws for bad input: invalid options, a problem of
  /// dimension 0 or vectors of the wrong size give an empty branch with
  /// StopReason::InvalidOptions and the reason in stopMessage (docs/continuation.md, "Errors").
  Branch trace(ConstVectorRef u0, double lambda0, const InitialDirection &direction);

  /// Continues `branch`, whose points are complete (tangent set); the last point is the
  /// current one. Special points are not searched in the first `skipIntervals` intervals
  /// (a branch that starts at a branch point). A branch without points: InvalidOptions.
  /// A StopReason::Paused branch goes on with the step it was paused before (resumeStep).
  void continueBranch(Branch &branch, int skipIntervals = 0);

  /// While set, trace() and continueBranch() return after the first step that located a branch
  /// point, with StopReason::Paused (no endpoint appended): the tree driver switches at the
  /// weakest branch points of a long branch before tracing it further (branch_switching.h).
  /// A step over more than kPausedCrossings branch points (the count's change) is then retried
  /// shorter.
  void pauseAtBranchPoints(bool pause) { pauseAtBranchPoints_ = pause; }
  static constexpr int kPausedCrossings = 8;
  /// Ends a paused branch where it stands, as an interrupt would (StopReason::Interrupted,
  /// an endpoint "interrupted" with `message`).
  static void endPaused(Branch &branch, const std::string &message);

  /// Fills tangent, test functions and stability of a point from its u, λ. In the scaled
  /// variables (units()), like corrector().
  bool completePoint(ContinuationPoint &point, ConstVectorRef referenceDirection);

  /// The corrector on the scaled problem: its x = (ũ, λ̃), units().toScaled/toUser convert.
  Corrector &corrector() { return *corrector_; }
  /// The problem as given (user units).
  const BoundProblem &problem() { return problem_; }
  /// The change of variables between the problem's units and the tracer's (scaled_problem.h).
  const UnitScaling &units() const { return units_; }
  const TracerOptions &options() const { return options_; }
  /// True when the bordered solves use the problem's structured solver.
  bool structured() const { return structuredSolver_ != nullptr; }

 private:
  bool pauseAtBranchPoints_ = false;
  // ---- one step (tracer.cpp) -------------------------------------------------------------
  /// Predictor x_a + ds·t_a (+ ½ds²·(t_a − t_p)/Δs_a when the point `previous` before a is
  /// given), Keller corrector, new tangent and the branch-jump guard. False with `failure` set
  /// when the step must be retried smaller.
  bool takeStep(const ContinuationPoint &a, const ContinuationPoint *previous, double ds, ContinuationPoint &b,
                CorrectorSummary &summary, double &turningAngle, std::string &failure);
  /// Folds and branch points between a and b (index not set).
  std::vector<SpecialPoint> locateSpecialPoints(const ContinuationPoint &a, const ContinuationPoint &b);

  // ---- stop events (tracer_events.cpp) ---------------------------------------------------
  /// The earliest stop event crossed between a and b, located on the branch.
  struct EventHit {
    int event = -1;  ///< -1: none
    ContinuationPoint point;
    double accuracy = 0.0;  ///< |Δλ| of the last location update
    double value = 0.0;     ///< the event's value at the point, in the user's units
  };
  /// Fills eventsB_ with the values at b (eventsA_ holds those at a) and hit with the earliest
  /// event crossed (hit.event = -1: none; hit.point is then left as it was). hit is the tracer's
  /// stopHit_, reused from step to step: a point's worth of vectors is not built and freed per step.
  void locateStopEvent(const ContinuationPoint &a, const ContinuationPoint &b, EventHit &hit);
  /// λ range and box faces are coordinates: one solve with that coordinate held at the bound.
  void landOnCoordinateBound(int event, const ContinuationPoint &a, ContinuationPoint &located, double &accuracy);
  double eventValue(int event, const ContinuationPoint &point);
  /// Every event's value at the point into values (size eventCount()): the problem's boundaries in one call.
  void eventValues(const ContinuationPoint &point, std::vector<double> &values);
  std::string eventName(int event) const;
  int eventCount() const;
  int boxEventCount() const;
  StopReason eventStopReason(int event) const;

  /// Scale of event `event`'s value g (user value = g · scale).
  double eventScale(int event) const;
  /// options_.onStep with the new point and the special points from `firstNew` on in the
  /// problem's units.
  StepAction notifyStep(const Branch &branch, size_t firstNew);
  /// a.tangent · (b.state() − a.state()), the arclength of the step from a to b along a's tangent,
  /// with the difference in along_: the same subtractions and the same Eigen dot product as that
  /// expression (bit for bit), without its two heap-allocated states per call.
  double stepAlong(const ContinuationPoint &a, const ContinuationPoint &b);

  BoundProblem problem_;
  TracerOptions options_;
  std::string invalidReason_;
  int n_;
  UnitScaling units_;
  std::unique_ptr<ScaledProblem> scaled_;  // null for the identity scaling
  std::unique_ptr<ProblemWorkspace> scaledWorkspace_;  // scaled_'s, on problem_'s workspace
  BoundProblem work_;                                  // what the core evaluates: scaled_ or problem_
  double lambdaMin_ = 0.0, lambdaMax_ = 0.0;  // the λ range and the box in the scaled variables
  Vector boxLower_, boxUpper_;
  std::unique_ptr<BorderedSolver> structuredSolver_, denseSolver_;
  std::unique_ptr<Corrector> corrector_;
  std::unique_ptr<PointEvaluator> evaluator_;
  std::unique_ptr<Locator> locator_;
  Vector predictor_, x_;
  ContinuationPoint stepPoint_;                  // notifyStep: the new point in the problem's units
  std::vector<SpecialPoint> stepSpecialPoints_;  // notifyStep: the step's special points, likewise
  Vector along_;  // stepAlong()'s x_b − x_a (size N+1)
  EventHit stopHit_;                      // locateStopEvent()'s result, reused
  std::vector<double> eventsA_, eventsB_;  // event values at the current point and the new one
};

/// One singularity, one report (tracer_coincident.cpp): a fold located at a simple branch point
/// of the branch (within a thousandth of their steps, among the special points from `firstNew`
/// on and those of the step before) is the tip of a bifurcated branch reached along it, which
/// turns in λ there: the fold is dropped and the branch point keeps the stability before the
/// first and after the last. Likewise a simple branch point in the step next to a multiple one
/// and within rounding of it (one crossing of the cluster counted a step early) is absorbed by the
/// multiple point. The tracer calls it after every located step.
void mergeCoincidentSpecialPoints(Branch &branch, size_t firstNew);

/// One-shot convenience: Tracer(problem, options).trace(u0, λ0, direction).
Branch trace(const BoundProblem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
             const TracerOptions &options = TracerOptions());

}  // namespace buckle::continuation
