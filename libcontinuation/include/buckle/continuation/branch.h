// What a continuation run produces: points on a solution branch, the special points located
// between them, and why the run ended. Plain data, like AUTO's b./s. files or
// BifurcationKit's ContResult; the tracer and branch switching fill it.
#pragma once

#include "buckle/continuation/problem.h"

#include <string>
#include <vector>

namespace buckle::continuation {

/// One accepted point x = (u, λ) with the test functions the detectors compare between points.
struct ContinuationPoint {
  Vector u;
  double lambda = 0.0;
  Vector tangent;               ///< unit (N+1) tangent, oriented along the branch direction
  double arclength = 0.0;       ///< pseudo-arclength s from the branch start
  double stepSize = 0.0;        ///< ds used to reach this point (0 for the start)
  int newtonIterations = 0;
  double residualNorm = 0.0;    ///< ‖G‖₂ of the corrector at this point
  StabilityInfo stability;      ///< stability.valid() == false when not computed
  double foldTest = 0.0;        ///< λ-component of the tangent: changes sign at a fold
  int determinantSign = 0;      ///< sign of det [[F_u, F_λ], [tᵀ]]: changes sign at a simple BP
  double logAbsDeterminant = 0.0;

  /// x = (u, λ) as one vector (allocates; for tests and output, not for hot loops).
  Vector state() const;
};

enum class SpecialPointType { Fold, BranchPoint, Boundary, Endpoint };

/// AUTO/MATCONT labels: "LP", "BP", "BD", "EP".
const char *label(SpecialPointType type);

struct SpecialPoint {
  SpecialPointType type = SpecialPointType::Endpoint;
  /// The point lies between points[index] and points[index + 1] of its branch (for end points
  /// and boundaries at the end of a branch: index of the last point).
  int index = 0;
  double arclength = 0.0;
  Vector u;
  double lambda = 0.0;
  Vector tangent;               ///< tangent of the branch through the point (N+1)
  /// Fold: right null vector v of F_u (N×1). Branch point: orthonormal basis of ker [F_u F_λ]
  /// ((N+1)×2), first column along the branch being traced.
  Matrix nullVectors;
  Vector leftNullVector;        ///< branch point: ψ with ψᵀ[F_u F_λ] = 0
  int multiplicity = 1;         ///< eigenvalues crossing zero here (2: double zero)
  int inertiaBefore = -1;       ///< negative eigenvalues of the stability operator before/after
  int inertiaAfter = -1;
  /// Achieved accuracy: |Δλ| of the last location iterate (refinement Newton step, or last
  /// secant/bisection update when there was no refinement).
  double lambdaAccuracy = 0.0;
  double residualNorm = 0.0;    ///< ‖F(u, λ)‖₂ at the located point
  double augmentedResidualNorm = 0.0;  ///< residual of the refinement system (fold / Moore)
  /// Test function at the located point: fold → t_λ; branch point → smallest singular value of
  /// [F_u, F_λ]; boundary / parameter end → g (or λ_end − λ).
  double testFunctionValue = 0.0;
  int locationIterations = 0;   ///< secant/bisection evaluations + refinement Newton steps
  bool refined = false;         ///< Newton on the augmented system converged
  std::string boundaryName;     ///< Boundary/Endpoint: which limit was hit
  std::string note;             ///< free text: why a point was not refined or not switched
};

enum class StopReason {
  NotStarted,
  InvalidOptions,      ///< invalid options or input (sizes, dimension, no start point); stopMessage names it
  StartFailed,         ///< the start point could not be polished or has no unique tangent
  MaxPoints,
  LambdaRange,
  MaxArclength,
  Box,
  Boundary,
  StepSizeTooSmall,    ///< corrector failures, branch-jump rejections or singular tangents below minStep
  SwitchFailed,        ///< branch switching did not reach a point off the parent branch
  Interrupted,         ///< the Interrupt (time limit, signal) or the step callback asked to stop
};

const char *toString(StopReason reason);

struct Branch {
  int id = 0;
  int parentId = -1;                 ///< -1 for a root branch
  int parentSpecialPoint = -1;       ///< index into the parent's specialPoints
  int direction = 1;                 ///< +1 / −1: orientation chosen at the start
  std::vector<ContinuationPoint> points;
  std::vector<SpecialPoint> specialPoints;
  StopReason stopReason = StopReason::NotStarted;
  std::string stopMessage;

  /// Special points of one type, in arclength order.
  std::vector<const SpecialPoint *> specialPointsOfType(SpecialPointType type) const;
};

struct BranchTree {
  std::vector<Branch> branches;  ///< branches[i].id == i; children after their parent
  bool interrupted = false;      ///< stopped early by the Interrupt: later branches not traced
  std::string message;           ///< why it was interrupted
};

}  // namespace buckle::continuation
