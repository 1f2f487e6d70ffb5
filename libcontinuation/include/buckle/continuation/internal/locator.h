// Location of special points and stop events inside one continuation step.
//
// Two stages, as in MATCONT/BifurcationKit:
//  1. along the branch: a safeguarded secant (Illinois) iteration on a test function of the
//     pseudo-arclength s ∈ (0, ds) measured along the step's tangent; every evaluation is a
//     Keller corrector solve on the hyperplane t_aᵀ(x − x_a) = s, so every iterate is on the
//     branch. Test functions: t_λ for folds; for branch points the minimally augmented ψ when
//     the bordered determinant changed sign, else the eigenvalue of the stability operator that
//     crosses zero. Before a refinement the secant only brackets (coarseTolerance, and at most
//     1e-3 of its bracket): near a BP the corrector samples are ill-conditioned, the augmented
//     systems are not. A refined BP outside its bracket (a neighbour's) is rejected;
//  2. refinement: Newton on an augmented system whose regular solution IS the special point
//       fold          (F = 0, F_u v = 0, cᵀv = 1)                 unknowns (u, λ, v)
//       simple BP     (F(x) + βp = 0, F_xᵀp = 0, pᵀp = 1)  (Moore)  unknowns (x, β, p)
//     with second derivatives from Problem::jacobianDirectionalDerivative. The residuals are
//     exact, so even finite-difference second derivatives converge to the exact point.
//     Above the dense crossover (denseAlgebra false) the same points are refined by the
//     minimally augmented systems of structured_refinement.h with O(N) bordered solves, and
//     get the same geometry (null vectors, left null vector, bifurcation directions).
// Even numbers of eigenvalue crossings in one step (seen by the stability inertia only) are
// separated by bisection on the inertia count; crossings that stay together down to a tiny
// fraction of the step are reported as one point of higher multiplicity, unrefined.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/corrector.h"
#include "buckle/continuation/interrupt.h"
#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/root_finding.h"
#include "buckle/continuation/internal/spectral_monitor.h"
#include "buckle/continuation/internal/structured_refinement.h"
#include "buckle/continuation/internal/test_functions.h"
#include "buckle/continuation/tracer_options.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace buckle::continuation {

struct LocatorOptions {
  LocationOptions location;    ///< TracerOptions::location
  DetectionOptions detection;  ///< TracerOptions::detection (folds, branch points, touches)
  /// A sample whose tangent makes cos < this with the interpolated step tangent is rejected
  /// (StepOptions::minTangentCosine).
  double minSampleCosine = 0.9;
  /// Dense (N+1)² work allowed (N ≤ LocationOptions::maxDenseDimension): ψ, the augmented-Newton
  /// refinements and the kernel (null vectors, branch directions). False (large N): the same
  /// refinements and geometry with O(N) algebra (structured_refinement.h: the problem's
  /// structured solver, or dense LU without one); the secant brackets on O(N) test functions
  /// (t_λ, the determinant, the crossing eigenvalue).
  bool denseAlgebra = true;
  /// Dense kernel (SVD of F_x) at points of multiplicity m ≥ 2 even without denseAlgebra: their
  /// verification (`refined`: ker F_x (m+1)-dimensional) and null vectors (multiplicity_switching.h,
  /// kMaxDenseMultiplePointDimension).
  bool denseMultiplePoints = true;
  /// A requested interrupt makes every further sample fail: the point in hand is reported as
  /// located so far, and the tracer stops at its next step.
  Interrupt interrupt;
  /// Optional: told of each point as it is located (TracerOptions::onLocated).
  std::function<void(const SpecialPoint &)> onLocated;

  /// Empty when valid, else what is wrong, the field named by its path.
  std::string validate(const std::string &prefix = "") const {
    return firstProblem({location.validate(prefix + "location."), detection.validate(prefix + "detection."),
                         require(minSampleCosine > -1.0 && minSampleCosine <= 1.0, prefix, "minSampleCosine",
                                 "must lie in (-1, 1]")});
  }
  bool IsValid(std::string *why) const { return reportValidity(validate(), why); }
};

/// A point on the current step at offset s (s = 0: its start point a).
struct StepSample {
  double s = 0.0;
  ContinuationPoint point;
};

class Locator {
 public:
  Locator(const BoundProblem &problem, Corrector &corrector, PointEvaluator &evaluator, const LocatorOptions &options);

  /// The step from a to b (b was corrected on t_aᵀ(x − x_a) = ds).
  void setStep(const ContinuationPoint &a, const ContinuationPoint &b);
  /// Point of the traced branch at offset s (Hermite predictor through a and b). False if the
  /// corrector fails or lands on a crossing branch (tangent turned against the interpolated one).
  bool sample(double s, StepSample &out, CorrectorSummary *summary = nullptr);

  using TestFunction = std::function<bool(const ContinuationPoint &, double &)>;
  struct Root {
    StepSample at;
    double value = 0.0;
    double lastDs = 0.0;       ///< |Δs| of the last update
    double lastDLambda = 0.0;  ///< |Δλ| of the last update
    int evaluations = 0;
    bool converged = false;
    std::string message;
    StepSample left, right;  ///< final bracket and its test values
    double fLeft = 0.0, fRight = 0.0;
  };
  /// Zero of test along the step inside [lo.s, hi.s], where fLo·fHi ≤ 0, to
  /// |Δs| ≤ relativeTolerance·max(1, |λ|) (0: options().tolerance).
  bool findRoot(const StepSample &lo, double fLo, const StepSample &hi, double fHi, const TestFunction &test,
                Root &root, double relativeTolerance = 0.0);

  /// Folds and branch points inside the current step, in arclength order (index not set).
  std::vector<SpecialPoint> locateSpecialPoints(const IntervalCrossings &crossings);
  /// Certified counting (locator_hidden.cpp): for each suspected eigenvalue, minimise side·μ along
  /// the step; a sign change gives the pair of branch points (each located as a simple one), a
  /// minimum within touchTolerance of zero an EigenvalueTouch point. In arclength order.
  std::vector<SpecialPoint> locateHiddenCrossings(const std::vector<SuspectedCrossing> &suspects);

  const StepSample &start() const { return a_; }
  const StepSample &end() const { return b_; }
  double tolerance(double lambda) const { return options_.location.tolerance * std::max(1.0, std::abs(lambda)); }
  /// ‖F(u, λ)‖₂ (+∞ if the problem refuses the point), into a workspace sized once: no allocation.
  double residualNorm(ConstVectorRef u, double lambda);

 private:
  /// Appends `sp` to `found` and tells options_.onLocated.
  void keep(std::vector<SpecialPoint> &found, SpecialPoint &&sp) const;
  SpecialPoint locateFold(const StepSample &lo, const StepSample &hi);
  SpecialPoint locateSimpleBranchPoint(const StepSample &lo, const StepSample &hi);
  /// Relative tolerance (findRoot's) of a bracketing secant on [lo, hi]: coarseTolerance, but at
  /// most `fraction` of the bracket's width (λ may be ≪ 1 in the problem's units, e.g. the critical
  /// loads ~κ/n² of a long chain, and neighbouring points lie just outside the bracket).
  double bracketingTolerance(const StepSample &lo, const StepSample &hi, double fraction) const;
  /// A refined point lies in the bracket it was located in (its step coordinate, to rounding).
  bool insideBracket(const SpecialPoint &sp, const StepSample &lo, const StepSample &hi) const;
  SpecialPoint multipleBranchPoint(const StepSample &lo, const StepSample &hi, int multiplicity);
  /// Folds and branch points between consecutive samples (the count differs between neighbours).
  void locateBetween(const std::vector<StepSample> &samples, std::vector<SpecialPoint> &found);
  /// The eigenvalue with ascending index `index` at a sample, times side.
  bool sideEigenvalue(const StepSample &at, int index, int side, double &value);
  void separateCrossings(const StepSample &lo, const StepSample &hi, std::vector<std::pair<StepSample, StepSample>> &simple,
                         std::vector<std::pair<StepSample, StepSample>> &multiple, int depth);
  bool refineFold(SpecialPoint &point, const Vector &tangentRef);
  void finishSecant(SpecialPoint &sp, Root &root, const TestFunction &test, int &evaluations,
                    const std::function<void(bool)> &adopt);
  bool refineBranchPoint(SpecialPoint &point, const Vector &tangentRef);
  void fillBranchPointGeometry(SpecialPoint &point, const Vector &tangentRef, bool dense);
  // The O(N) path (denseAlgebra false).
  StructuredRefinement &structured();
  bool refineFoldStructured(SpecialPoint &point, const Vector &tangentRef);
  bool refineBranchPointStructured(SpecialPoint &point, const Vector &tangentRef);
  /// Tangent and kernel basis from an orthonormal kernel K ((N+1)×2) and left null vector psi.
  void setBranchPointGeometry(SpecialPoint &point, const Vector &tangentRef, const Matrix &K, const Vector &psi,
                              double testValue);
  /// The refined fold's fields (refined, accuracy, null vector, tangent, arclength) once u, λ are set.
  void adoptRefinedFold(SpecialPoint &point, const Vector &tangentRef, const Vector &v, double lastDLambda,
                        double augmentedResidual);

  BoundProblem problem_;
  Corrector &corrector_;
  PointEvaluator &evaluator_;
  LocatorOptions options_;
  int n_;
  StepSample a_, b_;
  Vector xa_, dx_, ta_, tb_, predictor_, x_;
  Vector residual_;  // workspace of residualNorm
  double stepLength_ = 0.0;
  std::unique_ptr<BorderedSolver> refinementSolver_;  // created on first use (denseAlgebra false)
  std::unique_ptr<StructuredRefinement> structured_;
};

}  // namespace buckle::continuation
