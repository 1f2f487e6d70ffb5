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
// (initialStep, minStep, maxStep, maxArclength) are dimensionless, newtonTolerance bounds ‖F̃‖∞
// (relative to the size of the terms that balance in each row), the location target is
// locationTolerance·max(λ₀, |λ|), and every internal threshold is relative: the same chain in
// any units gives the same points. What trace() and continueBranch() return (u, λ, tangents,
// eigenvalues, accuracies) is in the user's units; arclength, step sizes, residual norms and
// the fold / branch-point test-function values are the scaled, dimensionless ones. The λ range
// and the box are given in the user's units.
#pragma once

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/branch.h"
#include "buckle/continuation/corrector.h"
#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/problem.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/step_control.h"
#include "buckle/continuation/test_functions.h"

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace buckle::continuation {

/// What a step callback tells the tracer (as Ceres' CallbackReturnType).
/// Join: the branch has reached a curve already traced (deflated continuation's de-duplication):
/// it ends there as a regular end, StopReason::Joined, not as an interruption.
enum class StepAction { Continue, Stop, Join };
/// Called after every accepted point, with the branch so far (its last point is the new one):
/// progress reports, custom stop rules (BifurcationKit's finalise_solution). Stop ends the
/// branch with StopReason::Interrupted, Join with StopReason::Joined. The new point and the special points are in the
/// problem's units; the earlier points may still be in the tracer's scaled variables (they are
/// converted when trace()/continueBranch() return), so read the last point only.
using StepCallback = std::function<StepAction(const Branch &branch)>;

/// Told of each special point as it is located, before its step is accepted: a step over a
/// cluster of branch points can take seconds of refinement with no new point, and a progress
/// report wants to say so. The point is in the problem's units. It is final only once the step
/// is (onStep sees it in the branch): an interrupt can still drop the half-located step.
using LocatedCallback = std::function<void(const SpecialPoint &point)>;

struct TracerOptions {
  // ---- step control (dimensionless: arclength in the scaled variables, header comment) -------
  double initialStep = 0.01;
  double minStep = 1e-8;
  double maxStep = 0.1;
  /// How the next step follows from the last one (step_control.h): Curvature from Newton's
  /// contraction and the tangent's turning angle, or NewtonCount (AUTO-07p's iteration count).
  /// NewtonCount by default until the curvature rule is measured against the regression
  /// baselines and the work-precision benchmark (benchmarks/work_precision --rule curvature).
  StepSizeControl::Rule stepRule = StepSizeControl::Rule::NewtonCount;
  double targetContraction = 0.2;   ///< Curvature: Newton contraction Θ̄ the next step aims at
  double targetAngle = 0.2;         ///< Curvature: tangent turning per step aimed at [rad]
  int targetNewtonIterations = 3;   ///< NewtonCount: ds·target/iterations
  double stepGrowth = 1.5;          ///< factors of the next step clamped to [stepShrink, stepGrowth]
  double stepShrink = 0.5;
  double slowContraction = 0.3;     ///< NewtonCount: contraction above this shrinks the next step
  double minTangentCosine = 0.9;    ///< branch-jump guard: t_newᵀt_old must stay ≥ this (MATCONT)
  /// Fold-pair guard: a step whose λ turns back and forth inside it (the cubic Hermite
  /// interpolant of λ(s) from the end values and the tangents' λ components has a derivative
  /// that changes sign twice: two folds that the sign test of t_λ at the ends cannot see) is
  /// rejected and retried smaller. Off by default for the same reason as stepRule.
  bool foldPairGuard = false;
  /// Second-order predictor x_a + ds·t_a + ½ds²·(t_a − t_p)/Δs_a (the curvature from the last
  /// two tangents) instead of x_a + ds·t_a: fewer Newton iterations per step on curved branches
  /// (benchmarks/RESULTS.md, work-precision). Off by default: it moves the points, and on the
  /// hysteresis scene's degenerate branch point that changes the reported mode shape.
  bool secondOrderPredictor = false;

  // ---- stop conditions -------------------------------------------------------------------
  int maxPoints = 500;              ///< including the start point
  double lambdaMin = -std::numeric_limits<double>::infinity();
  double lambdaMax = std::numeric_limits<double>::infinity();
  double maxArclength = std::numeric_limits<double>::infinity();
  /// Optional box on x = (u, λ): empty, or both of size N+1 (±inf entries allowed).
  Vector boxLower, boxUpper;

  // ---- corrector -------------------------------------------------------------------------
  double newtonTolerance = 1e-10;   ///< ‖G̃‖∞ of the Keller system in the scaled variables
  double newtonStepTolerance = 1e-14;
  int maxNewtonIterations = 10;
  bool lineSearch = false;
  bool leanNewton = false;          ///< CorrectorOptions::leanNewton (opt-in; KINSOL otherwise)

  // ---- detection and location ------------------------------------------------------------
  bool detectFolds = true;
  bool detectBranchPoints = true;
  bool detectBoundaries = true;     ///< Problem::boundary(k) and the box
  bool computeStability = true;     ///< record Problem::stability() at every point
  /// Lowest eigenvalues of the stability operator recorded at every point (plots, the
  /// smallest-eigenvalue column). 0: the inertia only, which is all the branch-point test
  /// needs and is much cheaper for structured problems; the locator still asks for the
  /// crossing eigenvalue where it needs one.
  int lowestEigenvalues = 3;
  /// Certified counting (spectral_monitor.h): record the two eigenvalues next to zero and their
  /// rates at every point (Problem::stabilityEigenvalues, two evaluations per point) and search
  /// the steps where one of them may reach zero unseen by the count: two opposite crossings are
  /// located as two branch points, a touch without crossing as an EigenvalueTouch point.
  bool certifiedCounting = true;
  /// An interior minimum of |μ| at most this (relative to max(1, |μ| at the step's ends), in the
  /// problem's stability scale) without a sign change is an eigenvalue touch.
  double touchTolerance = 1e-8;

  // ---- linear algebra --------------------------------------------------------------------
  enum class LinearAlgebra {
    Automatic,   ///< the problem's structured solver when it has one and N ≥ structuredFromDimension
    Dense,       ///< dense LU (KINSOL's SUNDIALS dense solver in the corrector)
    Structured,  ///< the problem's structured solver (Problem::makeStructuredSolver); invalid without one
  };
  LinearAlgebra linearAlgebra = LinearAlgebra::Automatic;
  /// Automatic switches to the structured solver from this N on. The chain's tracer step
  /// (benchmarks/RESULTS.md, BM_TracerStep) is faster dense at N = 4 and structured at N = 11.
  int structuredFromDimension = 8;
  /// A speed crossover: above this N the locator builds no dense (N+1)² matrix. Special points
  /// are bracketed on O(N) test functions (t_λ, the determinant, the crossing eigenvalue) and
  /// refined, with their null vectors, by the O(N) minimally augmented systems of
  /// structured_refinement.h instead of the dense augmented Newton: the same points, the same
  /// geometry, branch switching included (points of multiplicity m ≥ 2 keep their dense kernel
  /// up to kMaxDenseMultiplePointDimension). The O(N) refinements win from N ≈ 11 on
  /// (benchmarks/RESULTS.md); below, the dense systems also check the kernel's dimension.
  int maxDenseLocationDimension = 16;
  /// Target |Δλ| ≤ locationTolerance·max(λ₀, |λ|) for located points and stop events (λ₀: the
  /// problem's parameter scale).
  double locationTolerance = 1e-12;
  /// ‖G̃‖∞ target of the corrector solves made while locating.
  double locationNewtonTolerance = 1e-13;
  int maxLocationIterations = 60;   ///< secant/bisection evaluations per located point
  int maxRefinementIterations = 15; ///< Newton steps on the augmented (fold / Moore) systems
  /// Two crossings inside one step that cannot be separated down to this fraction of the step
  /// are one point of higher multiplicity.
  double separationFraction = 1e-9;

  // ---- stopping early ------------------------------------------------------------------
  /// Checked before every step and every location sample: a time limit or a signal ends the
  /// branch with StopReason::Interrupted, keeping its points.
  Interrupt interrupt;
  StepCallback onStep;              ///< optional; see StepCallback
  LocatedCallback onLocated;        ///< optional; see LocatedCallback

  bool IsValid(std::string *why) const;
};

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
  Tracer(Problem &problem, const TracerOptions &options);
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
  Problem &problem() { return problem_; }
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
  CorrectorOptions stepCorrectorOptions() const;

  /// Scale of event `event`'s value g (user value = g · scale).
  double eventScale(int event) const;
  /// options_.onStep(branch) with the new point and the special points in the problem's units.
  StepAction notifyStep(Branch &branch);
  /// a.tangent · (b.state() − a.state()), the arclength of the step from a to b along a's tangent,
  /// with the difference in along_: the same subtractions and the same Eigen dot product as that
  /// expression (bit for bit), without its two heap-allocated states per call.
  double stepAlong(const ContinuationPoint &a, const ContinuationPoint &b);

  Problem &problem_;
  TracerOptions options_;
  std::string invalidReason_;
  int n_;
  UnitScaling units_;
  std::unique_ptr<ScaledProblem> scaled_;  // null for the identity scaling
  Problem *work_;                          // what the core evaluates: scaled_ or problem_
  double lambdaMin_ = 0.0, lambdaMax_ = 0.0;  // the λ range and the box in the scaled variables
  Vector boxLower_, boxUpper_;
  std::unique_ptr<BorderedSolver> structuredSolver_, denseSolver_;
  std::unique_ptr<Corrector> corrector_;
  std::unique_ptr<PointEvaluator> evaluator_;
  std::unique_ptr<Locator> locator_;
  StepSizeControl stepControl_;
  Vector predictor_, x_;
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
Branch trace(Problem &problem, ConstVectorRef u0, double lambda0, const InitialDirection &direction,
             const TracerOptions &options = TracerOptions());

}  // namespace buckle::continuation
