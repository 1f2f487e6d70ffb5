// Certified counting: eigenvalue crossings between two points that the inertia count misses.
//
// The branch-point test compares ν, the number of negative eigenvalues of the stability operator,
// at the two ends of a step. Two eigenvalues crossing zero in opposite directions inside one step
// leave ν (and the determinant's sign) unchanged, and an eigenvalue that reaches zero and turns
// back (a touch, BifurcationKit issue #223) never changes either. Both leave a trace in the two
// eigenvalues next to zero, μ_{ν−1} < 0 ≤ μ_ν (ascending indices; on an interval with the same ν at
// both ends they are the same two indices): one of them moves towards zero at the start of the
// step and away from it at the end, so it has an interior extremum. The monitor records these two
// eigenvalues and their rates dμ/ds along the tangent at every point (Problem::stabilityEigenvalues,
// O(n) for a chain by isolation on shifted Sturm counts; the rates from the eigenvectors where the
// problem offers them, Problem::stabilitySlopes, else one forward difference along the tangent),
// and flags an interval when, for one of them, the tangent lines from both ends meet on
// the far side of zero (or within `margin` of it): the interior minimum of |μ| may reach zero.
// The locator then minimises |μ| along the step (locator.h, locateHiddenCrossings): a sign change
// splits the step into intervals whose counts differ (two branch points, located separately), a
// minimum at zero within the touch tolerance is an eigenvalue touch.
//
// The slopes cost an eigenvector per value (or, differenced, a second eigenvalue search off the
// branch, at x + δt). They are needed only where an eigenvalue could come near zero: with a bound D ≥ |dμ_i/ds| for every
// eigenvalue (Problem::stabilityRateBound; Weyl: |dμ_i/ds| ≤ ‖dH/ds‖₂ for symmetric H), the
// tangent lines of suspectHiddenCrossings with any slopes in [−D, D] meet no lower than the
// lines of slopes ∓D_a, ±D_b; when that value stays above the margin, no slope the
// measurement could return flags the step, and the tracer skips the slopes there
// (rateBoundsExcludeCrossing). The step's outcome is the same as with the slopes measured.
#pragma once

#include "buckle/continuation/branch.h"
#include "buckle/continuation/bound_problem.h"

#include <vector>

namespace buckle::continuation {

/// Default margin of suspectHiddenCrossings and rateBoundsExcludeCrossing.
constexpr double kSuspectMargin = 0.25;

/// Fills point.spectrum: the eigenvalues with indices ν − 1 and ν (ν = point.stability.negative;
/// only ν when ν = 0, only ν − 1 when ν is the dimension) and their slopes along point.tangent,
/// from Problem::stabilitySlopes where offered, else by a forward difference with step `delta`
/// (backward if the problem refuses the forward point).
/// False (spectrum left invalid) without stability or when the problem refuses the eigenvalues.
bool measureNearZeroSpectrum(const BoundProblem &problem, ContinuationPoint &point, double delta = 1e-6);

/// The first half of measureNearZeroSpectrum: the values and the problem's rate bound at the
/// point's tangent (spectrum.rateBound; +∞ without one), no slopes (spectrum.slopesMeasured false).
bool measureNearZeroValues(const BoundProblem &problem, ContinuationPoint &point);
/// The second half: the slopes of the values measureNearZeroValues recorded (forward difference
/// with step `delta`, backward if refused). False (spectrum left without slopes) if refused.
/// `workspace` holds the shifted point's u: once it has at least N entries the call allocates
/// nothing itself (the tracer's hot loop; the problem's stabilityEigenvalues must not either).
bool measureNearZeroSlopes(const BoundProblem &problem, ContinuationPoint &point, Vector &workspace,
                           double delta = 1e-6);
/// The same with a workspace of its own (allocates: for tests and one-off use).
bool measureNearZeroSlopes(const BoundProblem &problem, ContinuationPoint &point, double delta = 1e-6);

/// True when suspectHiddenCrossings(a, b, stepLength, margin) returns no suspect for every pair
/// of slopes within the two points' rate bounds: for each tracked eigenvalue of one sign at both
/// ends, the lines side·μ_a − D_a·s and side·μ_b − D_b·(L − s) meet above margin·min(|μ_a|, |μ_b|).
/// Needs the values (not the slopes) at both points, the same ν and indices, and finite bounds.
bool rateBoundsExcludeCrossing(const ContinuationPoint &a, const ContinuationPoint &b, double stepLength,
                               double margin = kSuspectMargin);

/// One eigenvalue (ascending index) whose interior extremum in a step may reach zero.
struct SuspectedCrossing {
  int index = -1;
  int side = 1;                ///< sign of the eigenvalue at both ends: the search minimises side·μ
  double predictedS = 0.0;     ///< where the tangent lines from the ends meet, in (0, stepLength)
  double predictedValue = 0.0; ///< their value there
};

/// The tracked eigenvalues of a and b (same ν, same indices) whose tangent lines predict that
/// side·μ falls to ≤ margin·min(|μ_a|, |μ_b|) inside the step of length stepLength.
std::vector<SuspectedCrossing> suspectHiddenCrossings(const ContinuationPoint &a, const ContinuationPoint &b,
                                                      double stepLength, double margin = kSuspectMargin);

}  // namespace buckle::continuation
