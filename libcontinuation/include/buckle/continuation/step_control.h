// Step-size adaptation of the pseudo-arclength tracer (tracer.h).
//
// Two rules for the step after an accepted one, both clamped to [stepShrink, stepGrowth] times
// the last step and to [minStep, maxStep]; after a failed step the step is halved. All steps
// are dimensionless arclengths in the tracer's scaled variables.
//
// Curvature: what the step taught about the branch sets the next one.
//  - Newton's contraction Θ = ‖Δx₁‖/‖Δx₀‖ ≈ ½ω‖Δx₀‖ (Deuflhard, Newton Methods for Nonlinear
//    Problems, 2004, §5.1.3: ω the Lipschitz constant of the Jacobian's inverse times its
//    derivative) and the first Newton step is the predictor's distance from the branch,
//    O(ds^(p+1)) for a predictor of order p (Euler p = 1; the second-order one p = 2). So the
//    step that gives the target contraction Θ̄ is ds·(Θ̄/Θ)^(1/(p+1)). Θ is a property of the
//    start point, not of the tolerance: unlike an iteration count it does not shrink the steps
//    when the tolerance is tight (more iterations from the same start), nor grow them when it is
//    loose.
//  - The branch's curvature: the tangent turns by α ≈ κ·ds in a step, so ds·ᾱ/α turns by the
//    target angle ᾱ. This bounds the steps where Newton converges easily but the branch bends
//    (the branch-jump guard minTangentCosine rejects a step that turns by more), and it keeps
//    the test functions, which follow the tangent, resolved: the λ component of the tangent (the
//    fold test) cannot change sign twice within a step that turns little unless the branch is
//    nearly perpendicular to λ, which the tracer's fold-pair guard checks (tracer.h).
// With one Newton iteration or none there is no contraction to measure: the predictor was on the
// branch to the tolerance, and the step grows (by the angle rule at most).
//
// NewtonCount (AUTO-07p's rule; the tracer's default, StepOptions::rule): ds·target/iterations, and at most 0.7 when Newton contracted
// slowly (contraction above slowContraction).
#pragma once

#include "buckle/continuation/options_validity.h"

#include <string>

namespace buckle::continuation {

/// What an accepted step showed: the inputs of the next step size.
struct StepObservation {
  int newtonIterations = 0;
  double contraction = 0.0;   ///< largest ‖Δx_{k+1}‖/‖Δx_k‖ of the corrector (0: fewer than two steps)
  double turningAngle = 0.0;  ///< angle between the tangents at the two ends of the step [rad]
  int predictorOrder = 1;     ///< 1: Euler (off the branch by O(ds²)); 2: second order (O(ds³))
};

/// The tracer's steps (TracerOptions::step): their sizes, the rule that adapts them and the
/// guards that reject a step. All sizes are dimensionless arclengths in the scaled variables.
struct StepOptions {
  double initialStep = 0.01;
  double minStep = 1e-8;
  double maxStep = 0.1;
  /// How the next step follows from the last one: Curvature from Newton's contraction and the
  /// tangent's turning angle, or NewtonCount (AUTO-07p's iteration count). NewtonCount by
  /// default until the curvature rule is measured against the regression baselines and the
  /// work-precision benchmark (benchmarks/work_precision --rule curvature).
  enum class Rule { Curvature, NewtonCount };
  Rule rule = Rule::NewtonCount;
  int targetNewtonIterations = 3;  ///< NewtonCount: ds·target/iterations
  double stepGrowth = 1.5;         ///< factors of the next step clamped to [stepShrink, stepGrowth]
  double stepShrink = 0.5;
  double slowContraction = 0.3;    ///< NewtonCount: contraction above this caps the next factor at 0.7
  double targetContraction = 0.2;  ///< Curvature: Θ̄
  double targetAngle = 0.2;        ///< Curvature: ᾱ [rad]
  double minTangentCosine = 0.9;   ///< branch-jump guard: t_newᵀt_old must stay ≥ this (MATCONT)
  /// Fold-pair guard: a step whose λ turns back and forth inside it (foldPairInside below: two
  /// folds that the sign test of t_λ at the ends cannot see) is rejected and retried smaller.
  /// Off by default for the same reason as `rule`.
  bool foldPairGuard = false;
  /// Second-order predictor x_a + ds·t_a + ½ds²·(t_a − t_p)/Δs_a (the curvature from the last
  /// two tangents) instead of x_a + ds·t_a: fewer Newton iterations per step on curved branches
  /// (benchmarks/RESULTS.md, work-precision). Off by default: it moves the points, and on the
  /// hysteresis scene's degenerate branch point that changes the reported mode shape.
  bool secondOrderPredictor = false;

  /// The step after an accepted step of size ds (either rule).
  double next(double ds, const StepObservation &step) const;
  /// NewtonCount: the step after an accepted step of size ds whose corrector took
  /// `newtonIterations` iterations with the given contraction rate.
  double next(double ds, int newtonIterations, double contraction) const;
  /// After a failed step: halves ds; false once it is below minStep (the branch must stop).
  bool halve(double &ds) const;

  /// Empty when valid, else what is wrong, the field named as `prefix` + its name.
  std::string validate(const std::string &prefix = "step.") const;
  bool IsValid(std::string *why) const;
};

}  // namespace buckle::continuation

namespace buckle::continuation {

/// Fold-pair test of a step of length h (the tracer's fold-pair guard): λ and its slope dλ/ds
/// (the tangents' λ components) at both ends. True when the slopes have the same sign but the
/// cubic Hermite interpolant of λ(s) turns back and forth inside the step: its derivative, a
/// quadratic, dips below −dip relative to that sign (two folds the end signs cannot see). The
/// slopes are components of unit tangents, so `dip` is relative to 1; it keeps rounding-level
/// slopes (a branch along which λ is constant to rounding) from counting as folds.
bool foldPairInside(double lambdaA, double slopeA, double lambdaB, double slopeB, double h, double dip = 1e-6);

}  // namespace buckle::continuation
