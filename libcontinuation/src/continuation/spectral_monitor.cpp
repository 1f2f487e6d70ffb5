#include "buckle/continuation/internal/spectral_monitor.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace buckle::continuation {

namespace {

bool eigenvaluesAt(const BoundProblem &problem, ConstVectorRef u, double lambda, int first, int count,
                   Eigen::Vector2d &out) {
  return problem.stabilityEigenvalues(u, lambda, first, out.head(count)) && out.head(count).allFinite();
}

}  // namespace

bool measureNearZeroValues(const BoundProblem &problem, ContinuationPoint &point) {
  point.spectrum = NearZeroSpectrum();
  const int n = problem.dimension();
  if (!point.stability.valid() || point.tangent.size() != n + 1 || point.u.size() != n) return false;
  const int nu = point.stability.negative;
  int first = std::max(0, nu - 1);
  int count = nu > 0 ? 2 : 1;
  Eigen::Vector2d here, rest;
  // The leading ones the point's stability() already isolated (its lowest eigenvalues: ν − 1 = 0
  // when ν = 1) are not searched again.
  const Vector &lowest = point.stability.lowest;
  const int have = std::clamp(int(lowest.size()) - first, 0, count);
  if (have > 0) here.head(have) = lowest.segment(first, have);
  if (have < count) {
    if (eigenvaluesAt(problem, point.u, point.lambda, first + have, count - have, rest)) {
      here.segment(have, count - have) = rest.head(count - have);
    } else {
      // ν is the dimension (no eigenvalue ν), or the problem offers only part of the spectrum
      if (count == 1 || (have == 0 && !eigenvaluesAt(problem, point.u, point.lambda, first, 1, here))) return false;
      count = 1;
    }
  }
  point.spectrum.first = first;
  point.spectrum.count = count;
  for (int k = 0; k < count; ++k) point.spectrum.values[k] = here[k];
  double bound = 0.0;
  if (problem.stabilityRateBound(point.u, point.lambda, point.tangent.head(n), point.tangent[n], bound) &&
      bound >= 0.0 && std::isfinite(bound))
    point.spectrum.rateBound = bound;
  return true;
}

bool measureNearZeroSlopes(const BoundProblem &problem, ContinuationPoint &point, Vector &workspace, double delta) {
  NearZeroSpectrum &sp = point.spectrum;
  const int n = problem.dimension();
  if (!sp.valid() || point.tangent.size() != n + 1 || point.u.size() != n) return false;
  if (sp.slopesMeasured) return true;
  // From the eigenvectors (Hellmann–Feynman) where the problem offers it: no second eigenvalue
  // search at a point off the branch.
  const Eigen::Map<const Vector> values(sp.values, sp.count);
  Eigen::Map<Vector> slopes(sp.slopes, sp.count);
  if (problem.stabilitySlopes(point.u, point.lambda, point.tangent.head(n), point.tangent[n], sp.first, values,
                              slopes) &&
      std::isfinite(sp.slopes[0]) && (sp.count < 2 || std::isfinite(sp.slopes[1]))) {
    sp.slopesMeasured = true;
    return true;
  }
  if (workspace.size() < n) workspace.resize(n);
  // Rate along the tangent: dμ/ds = (μ(x + δt) − μ(x))/δ. The point x + δt is off the branch by
  // O(δ²) only, so the slope is the branch's to O(δ) (Hellmann–Feynman needs no eigenvector).
  // The shifted u goes into the caller's workspace: an expression passed as ConstVectorRef
  // would be a temporary on the heap at every call.
  Eigen::Vector2d there;
  auto shifted = workspace.head(n);
  double h = delta;
  shifted = point.u + h * point.tangent.head(n);
  if (!eigenvaluesAt(problem, shifted, point.lambda + h * point.tangent[n], sp.first, sp.count, there)) {
    h = -delta;
    shifted = point.u + h * point.tangent.head(n);
    if (!eigenvaluesAt(problem, shifted, point.lambda + h * point.tangent[n], sp.first, sp.count, there)) return false;
  }
  for (int k = 0; k < sp.count; ++k) sp.slopes[k] = (there[k] - sp.values[k]) / h;
  sp.slopesMeasured = true;
  return true;
}

bool measureNearZeroSlopes(const BoundProblem &problem, ContinuationPoint &point, double delta) {
  Vector workspace;
  return measureNearZeroSlopes(problem, point, workspace, delta);
}

bool measureNearZeroSpectrum(const BoundProblem &problem, ContinuationPoint &point, double delta) {
  if (!measureNearZeroValues(problem, point)) return false;
  if (measureNearZeroSlopes(problem, point, delta)) return true;
  point.spectrum = NearZeroSpectrum();
  return false;
}

bool rateBoundsExcludeCrossing(const ContinuationPoint &a, const ContinuationPoint &b, double stepLength,
                               double margin) {
  const NearZeroSpectrum &sa = a.spectrum, &sb = b.spectrum;
  // The cases in which suspectHiddenCrossings() flags nothing whatever the slopes.
  if (!sa.valid() || !sb.valid() || !(stepLength > 0.0)) return true;
  if (a.stability.negative != b.stability.negative || sa.first != sb.first) return true;
  // The bounds hold for the derivatives at the points; the measured slopes are difference
  // quotients over δ, i.e. derivatives at most δ away: 1 % covers their change.
  const double Da = 1.01 * sa.rateBound, Db = 1.01 * sb.rateBound;
  if (!std::isfinite(Da) || !std::isfinite(Db)) return false;
  const int count = std::min(sa.count, sb.count);
  for (int k = 0; k < count; ++k) {
    const double ma = sa.values[k], mb = sb.values[k];
    const int side = ma > 0.0 ? 1 : -1;
    if (ma == 0.0 || mb == 0.0 || (mb > 0.0 ? 1 : -1) != side) continue;  // as suspectHiddenCrossings
    const double fa = side * ma, fb = side * mb;
    if (Da + Db == 0.0) continue;  // no slope can be negative at a: no interior minimum
    // Lowest meeting value of a line through (0, fa) with slope ≥ −Da and one through (L, fb) with
    // slope ≤ Db, meeting inside (0, L): min over s of max(fa − Da·s, fb − Db·(L − s)).
    const double s = std::clamp((fa - fb + Db * stepLength) / (Da + Db), 0.0, stepLength);
    const double lowest = std::max(fa - Da * s, fb - Db * (stepLength - s));
    if (!(lowest > margin * std::min(fa, fb))) return false;
  }
  return true;
}

std::vector<SuspectedCrossing> suspectHiddenCrossings(const ContinuationPoint &a, const ContinuationPoint &b,
                                                      double stepLength, double margin) {
  std::vector<SuspectedCrossing> suspects;
  const NearZeroSpectrum &sa = a.spectrum, &sb = b.spectrum;
  if (!sa.valid() || !sb.valid() || !sa.slopesMeasured || !sb.slopesMeasured || !(stepLength > 0.0)) return suspects;
  if (a.stability.negative != b.stability.negative || sa.first != sb.first) return suspects;
  const int count = std::min(sa.count, sb.count);
  for (int k = 0; k < count; ++k) {
    const double ma = sa.values[k], mb = sb.values[k];
    const int side = ma > 0.0 ? 1 : -1;
    if (ma == 0.0 || mb == 0.0 || (mb > 0.0 ? 1 : -1) != side) continue;  // a zero end is the count's business
    const double da = side * sa.slopes[k], db = side * sb.slopes[k];   // rates of side·μ
    if (!(da < 0.0 && db > 0.0)) continue;  // no interior minimum of side·μ
    // Tangent lines side·μ_a + da·s and side·μ_b + db·(s − L) meet at s*.
    const double fa = side * ma, fb = side * mb;
    const double s = (fb - db * stepLength - fa) / (da - db);
    if (!(s > 0.0 && s < stepLength)) continue;
    const double value = fa + da * s;
    if (value > margin * std::min(fa, fb)) continue;
    SuspectedCrossing c;
    c.index = sa.first + k;
    c.side = side;
    c.predictedS = s;
    c.predictedValue = side * value;
    suspects.push_back(c);
  }
  return suspects;
}

}  // namespace buckle::continuation
