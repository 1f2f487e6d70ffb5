// The continuation core's one vocabulary of settings (as BifurcationKit's ContinuationPar nests
// NewtonPar): TracerOptions holds the step control, the corrector, the location and the
// detection as nested groups, and every layer above (the bifurcation tree, the chain's branches,
// scenes, Python) nests these same structs instead of copying their fields under other names.
// Each group has its defaults here and nowhere else, and validate() says what is wrong with a
// setting in the name the user wrote it under (e.g. "corrector.tolerance must be positive").
//
// Units: the tracer works in the problem's scaled variables (problem.h, ProblemScales), so the
// step sizes and the arclength bound are dimensionless, corrector.tolerance bounds ‖F̃‖∞ of the
// scaled residual and the location target is location.tolerance·max(λ₀, |λ|) with λ₀ the
// problem's parameter scale. The λ range and the box are in the user's units.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/problem.h"
#include "buckle/continuation/options_validity.h"
#include "buckle/continuation/step_control.h"

#include <functional>
#include <limits>
#include <string>

namespace buckle::continuation {

/// The Newton corrector (KINSOL) of every solve on the branch (corrector.h).
struct CorrectorOptions {
  /// Converged when ‖G‖∞ ≤ tolerance (KINSOL fnormtol), G the scaled Keller system.
  double tolerance = 1e-10;
  /// KINSOL scaled step tolerance: stop when the Newton step is this small relative to x.
  double stepTolerance = 1e-14;
  int maxIterations = 10;
  /// KIN_LINESEARCH instead of full Newton steps (KIN_NONE).
  bool lineSearch = false;
  /// Longest Newton step KINSOL may take (‖Δx‖₂). 0: unlimited. KINSOL's own default,
  /// 1000·max(1, ‖x₀‖), silently truncates steps from predictors near the origin.
  double maxNewtonStep = 0.0;
  /// A solve that stalls at the residual's rounding floor — on the step tolerance
  /// (KIN_STEP_LT_STPTOL) or with its iterations used up (KIN_MAXITER_REACHED) — still counts
  /// as converged if ‖G‖₂ ≤ stagnationFactor · tolerance.
  double stagnationFactor = 100.0;
  /// Opt-in: full Newton (lineSearch false) by Corrector's own reproduction of KINSOL's iteration
  /// where it converges plainly (the same iterates, flag, counts and norms, bit for bit), KINSOL
  /// itself otherwise. Off by default: the corrector is KINSOL's (the design card); on, it saves
  /// KINSOL's per-call bookkeeping for callers that trace many tiny systems.
  bool leanNewton = false;

  /// Empty when valid, else what is wrong, the field named as `prefix` + its name.
  std::string validate(const std::string &prefix = "corrector.") const;
  bool IsValid(std::string *why) const;
};

/// Locating special points and stop events inside a step (locator.h).
struct LocationOptions {
  /// Target |Δλ| ≤ tolerance·max(λ₀, |λ|) for located points and stop events (λ₀: the
  /// problem's parameter scale).
  double tolerance = 1e-12;
  /// Secant tolerance before an augmented-Newton refinement: near a branch point the corrector
  /// samples are ill-conditioned (the Keller Jacobian is singular there), so the secant stage
  /// only brackets and Newton on the regular augmented system does the rest. If refinement
  /// fails, the secant continues down to `tolerance`.
  double coarseTolerance = 1e-7;
  /// ‖G̃‖∞ target of the corrector solves made while locating.
  double newtonTolerance = 1e-13;
  int maxIterations = 60;             ///< secant/bisection evaluations per located point
  int maxRefinementIterations = 15;   ///< Newton steps on the augmented (fold / Moore) systems
  /// Two crossings inside one step that cannot be separated down to this fraction of the step
  /// are one point of higher multiplicity.
  double separationFraction = 1e-9;
  /// A speed crossover: above this N the locator builds no dense (N+1)² matrix. Special points
  /// are bracketed on O(N) test functions (t_λ, the determinant, the crossing eigenvalue) and
  /// refined, with their null vectors, by the O(N) minimally augmented systems of
  /// structured_refinement.h instead of the dense augmented Newton: the same points, the same
  /// geometry, branch switching included (points of multiplicity m ≥ 2 keep their dense kernel
  /// up to kMaxDenseMultiplePointDimension). The O(N) refinements win from N ≈ 11 on
  /// (benchmarks/RESULTS.md); below, the dense systems also check the kernel's dimension.
  int maxDenseDimension = 16;

  std::string validate(const std::string &prefix = "location.") const;
  bool IsValid(std::string *why) const;
};

/// What the tracer looks for and records at every point.
struct DetectionOptions {
  bool folds = true;
  bool branchPoints = true;
  bool boundaries = true;      ///< Problem::boundary(k) and the box
  bool stability = true;       ///< record Problem::stability() at every point
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

  std::string validate(const std::string &prefix = "detection.") const;
  bool IsValid(std::string *why) const;
};

/// What a step callback tells the tracer (as Ceres' CallbackReturnType).
/// Join: the branch has reached a curve already traced (deflated continuation's de-duplication):
/// it ends there as a regular end, StopReason::Joined, not as an interruption.
enum class StepAction { Continue, Stop, Join };

/// What the tracer tells a step callback after every accepted point, all in the problem's units:
/// the new point and the special points located on the step that led to it.
struct StepInfo {
  const ContinuationPoint &point;
  /// The special points located on the step that led to the point (most steps: none).
  const std::vector<SpecialPoint> &specialPoints;
  int pointCount = 0;          ///< the branch's points so far, the new one included
  int specialPointCount = 0;   ///< the branch's special points so far
  /// Which branch is traced: the same address for every step of a branch, its continuations
  /// (Tracer::continueBranch) included; for callbacks that follow several branches. Not to be
  /// read through: the branch's earlier points are in the tracer's scaled variables.
  const void *branch = nullptr;
  double startLambda = 0.0;    ///< λ of the branch's first point
};

/// Called after every accepted point: progress reports, custom stop rules (BifurcationKit's
/// finalise_solution). Stop ends the branch with StopReason::Interrupted, Join with
/// StopReason::Joined.
using StepCallback = std::function<StepAction(const StepInfo &step)>;

/// Told of each special point as it is located, before its step is accepted: a step over a
/// cluster of branch points can take seconds of refinement with no new point, and a progress
/// report wants to say so. The point is in the problem's units. It is final only once the step
/// is (onStep sees it): an interrupt can still drop the half-located step.
using LocatedCallback = std::function<void(const SpecialPoint &point)>;

struct TracerOptions {
  StepOptions step;
  CorrectorOptions corrector;
  LocationOptions location;
  DetectionOptions detection;

  // ---- where a branch ends ---------------------------------------------------------------
  int maxPoints = 500;              ///< including the start point
  double lambdaMin = -std::numeric_limits<double>::infinity();
  double lambdaMax = std::numeric_limits<double>::infinity();
  double maxArclength = std::numeric_limits<double>::infinity();
  /// Optional box on x = (u, λ): empty, or both of size N+1 (±inf entries allowed).
  Vector boxLower, boxUpper;

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

  // ---- stopping early ------------------------------------------------------------------
  /// Checked before every step and every location sample: a time limit or a signal ends the
  /// branch with StopReason::Interrupted, keeping its points.
  Interrupt interrupt;
  StepCallback onStep;              ///< optional; see StepCallback
  LocatedCallback onLocated;        ///< optional; see LocatedCallback

  /// Empty when valid, else what is wrong, the field named by its path (e.g. "step.maxStep"),
  /// after `prefix` (the path of this struct inside an enclosing one, e.g. "tracer.").
  std::string validate(const std::string &prefix = "") const;
  bool IsValid(std::string *why) const;
};

}  // namespace buckle::continuation
