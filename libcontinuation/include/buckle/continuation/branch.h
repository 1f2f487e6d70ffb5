// What a continuation run produces: points on a solution branch, the special points located
// between them, and why the run ended. Plain data, like AUTO's b./s. files or
// BifurcationKit's ContResult; the tracer and branch switching fill it.
#pragma once

#include "buckle/continuation/problem.h"

#include <any>
#include <limits>
#include <string>
#include <vector>

namespace buckle::continuation {

/// The eigenvalues of the stability operator next to zero at a point and their rates of change
/// along the branch: what certified counting (spectral_monitor.h) compares between two points to
/// see crossings the inertia count cannot (two in opposite directions, a touch without crossing).
struct NearZeroSpectrum {
  int first = -1;       ///< ascending index of values[0]: ν − 1 (ν = negative count), or 0 when ν = 0; −1: not measured
  int count = 0;        ///< 1 or 2 tracked eigenvalues (indices first, first + 1)
  double values[2] = {0.0, 0.0};
  double slopes[2] = {0.0, 0.0};  ///< d/ds along the point's tangent (s: the tracer's arclength)
  bool slopesMeasured = false;    ///< slopes filled (measureNearZeroSlopes); values alone otherwise
  /// Upper bound on |dμ_i/ds| for every eigenvalue at the point (Problem::stabilityRateBound);
  /// +∞ when the problem offers none. Lets a step skip the slopes (spectral_monitor.h).
  double rateBound = std::numeric_limits<double>::infinity();
  bool valid() const { return first >= 0 && count > 0; }
};

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
  NearZeroSpectrum spectrum;    ///< certified counting only (TracerOptions::certifiedCounting)

  /// x = (u, λ) as one vector (allocates; for tests and output, not for hot loops).
  Vector state() const;
};

/// EigenvalueTouch: an eigenvalue of the stability operator reaches zero and turns back without
/// changing sign (no inertia change, no determinant sign change; BifurcationKit issue #223), found
/// by certified counting (spectral_monitor.h).
enum class SpecialPointType { Fold, BranchPoint, Boundary, Endpoint, EigenvalueTouch };

/// AUTO/MATCONT labels: "LP", "BP", "BD", "EP"; "ET" for an eigenvalue touch.
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
  /// Multiple branch points (multiplicity_switching.h): half-branches predicted by the reduced
  /// bifurcation equation (two per solution direction) and how many of them were traced off the
  /// point; −1 when not switched.
  int branchesPredicted = -1;
  int branchesFound = -1;
  int inertiaBefore = -1;       ///< negative eigenvalues of the stability operator before/after
  int inertiaAfter = -1;
  /// Achieved accuracy: |Δλ| of the last location iterate (refinement Newton step, or last
  /// secant/bisection update when there was no refinement).
  double lambdaAccuracy = 0.0;
  double residualNorm = 0.0;    ///< ‖F(u, λ)‖₂ at the located point
  double augmentedResidualNorm = 0.0;  ///< residual of the refinement system (fold / Moore)
  /// Test function at the located point: fold → t_λ; branch point → smallest singular value of
  /// [F_u, F_λ]; boundary / parameter end → g (or λ_end − λ); eigenvalue touch → the touching
  /// eigenvalue (its distance from zero is the touch's accuracy).
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
  Joined,              ///< the step callback found the branch on one already traced (StepAction::Join)
  /// A regular end: the branch came back to a point it had passed, in the same direction (a
  /// closed loop; from there it would trace the same curve again).
  ClosedLoop,
  /// Not a regular end: the branch reached a located event past which the problem changes (a
  /// caller's extension, e.g. a contact that starts or ends) and could not be continued through
  /// it — the new problem's equilibrium could not be polished, it has no unique tangent there, or
  /// a second event at the same point leaves nothing to step on. stopMessage says which.
  EventNotContinued,
  /// Not ended: the tracer returned after a step that located a branch point, as asked
  /// (Tracer::pauseAtBranchPoints); Tracer::continueBranch goes on from its last point with
  /// the step it would have taken (Branch::resumeStep): the same points as without the pause,
  /// unless a step crossed more than Tracer::kPausedCrossings branch points (then retried shorter).
  Paused,
};

const char *toString(StopReason reason);

struct Branch {
  int id = 0;
  int parentId = -1;                 ///< -1 for a root branch
  int parentSpecialPoint = -1;       ///< index into the parent's specialPoints
  int direction = 1;                 ///< +1 / −1: orientation chosen at the start
  /// Not traced: the image of branch mirrorOf under the tree's reflection (symmetry.h,
  /// TreeOptions::symmetry); −1 for a traced branch.
  int mirrorOf = -1;
  std::vector<ContinuationPoint> points;
  std::vector<SpecialPoint> specialPoints;
  StopReason stopReason = StopReason::NotStarted;
  std::string stopMessage;
  double resumeStep = 0.0;  ///< StopReason::Paused: the step (scaled arclength) continueBranch takes next
  /// What TreeOptions::childWork computed for this branch on a worker, for the tree's later
  /// callbacks (extend, onFinal) to take instead of computing it again; empty otherwise.
  std::any prepared;

  /// Special points of one type, in arclength order.
  std::vector<const SpecialPoint *> specialPointsOfType(SpecialPointType type) const;
};

struct BranchTree {
  std::vector<Branch> branches;  ///< branches[i].id == i; children after their parent
  bool interrupted = false;      ///< stopped early by the Interrupt: later branches not traced
  std::string message;           ///< why it was interrupted
};

}  // namespace buckle::continuation
