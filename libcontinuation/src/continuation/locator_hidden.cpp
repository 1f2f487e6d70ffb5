// Certified counting inside one step (spectral_monitor.h): the search for the interior minimum of
// |μ| of an eigenvalue the monitor suspects, and what it finds there.
#include "buckle/continuation/internal/locator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace buckle::continuation {

bool Locator::sideEigenvalue(const StepSample &at, int index, int side, double &value) {
  Eigen::Matrix<double, 1, 1> mu;
  if (!problem_.stabilityEigenvalues(at.point.u, at.point.lambda, index, mu) || !std::isfinite(mu[0])) return false;
  value = side * mu[0];
  return true;
}

std::vector<SpecialPoint> Locator::locateHiddenCrossings(const std::vector<SuspectedCrossing> &suspects) {
  std::vector<SpecialPoint> found;
  const double length = stepLength_;
  for (const SuspectedCrossing &c : suspects) {
    double fa = 0.0, fb = 0.0;
    if (!sideEigenvalue(a_, c.index, c.side, fa) || !sideEigenvalue(b_, c.index, c.side, fb)) continue;
    // Brent's minimisation (golden section with parabolic steps) of f(s) = side·μ(s) on (0, L),
    // started where the monitor's tangent lines meet; it stops as soon as f ≤ 0 (a sign change).
    const double golden = 0.3819660112501051;
    double lo = 0.0, hi = length;
    StepSample best;
    double x = std::min(std::max(c.predictedS, 0.02 * length), 0.98 * length);
    if (!sample(x, best)) continue;
    double fx = 0.0;
    if (!sideEigenvalue(best, c.index, c.side, fx)) continue;
    double w = x, v = x, fw = fx, fv = fx, d = 0.0, e = 0.0;
    const double tolS = std::max(1e-10 * std::abs(length), 1e-15);
    int evaluations = 1;
    bool failed = false;
    while (fx > 0.0 && evaluations < options_.location.maxIterations) {
      const double m = 0.5 * (lo + hi);
      const double tol1 = 1.5e-8 * std::abs(x) + tolS, tol2 = 2.0 * tol1;
      if (std::abs(x - m) <= tol2 - 0.5 * (hi - lo)) break;
      bool parabolic = false;
      if (std::abs(e) > tol1) {
        const double r = (x - w) * (fx - fv);
        double q = (x - v) * (fx - fw);
        double p = (x - v) * q - (x - w) * r;
        q = 2.0 * (q - r);
        if (q > 0.0) p = -p;
        q = std::abs(q);
        if (std::abs(p) < std::abs(0.5 * q * e) && p > q * (lo - x) && p < q * (hi - x)) {
          e = d;
          d = p / q;
          const double u = x + d;
          if (u - lo < tol2 || hi - u < tol2) d = x < m ? tol1 : -tol1;
          parabolic = true;
        }
      }
      if (!parabolic) {
        e = (x < m ? hi : lo) - x;
        d = golden * e;
      }
      const double u = x + (std::abs(d) >= tol1 ? d : (d > 0.0 ? tol1 : -tol1));
      StepSample trial;
      double fu = 0.0;
      ++evaluations;
      if (!sample(u, trial) || !sideEigenvalue(trial, c.index, c.side, fu)) {
        failed = true;
        break;
      }
      if (fu <= fx) {
        (u < x ? hi : lo) = x;
        v = w;
        fv = fw;
        w = x;
        fw = fx;
        x = u;
        fx = fu;
        best = trial;
      } else {
        (u < x ? lo : hi) = u;
        if (fu <= fw || w == x) {
          v = w;
          fv = fw;
          w = u;
          fw = fu;
        } else if (fu <= fv || v == x || v == w) {
          v = u;
          fv = fu;
        }
      }
    }
    if (failed) continue;
    if (fx <= 0.0) {
      // Two crossings the count could not see: the counts now differ between a, the minimum and b.
      std::vector<SpecialPoint> pair;
      locateBetween({a_, best, b_}, pair);
      for (SpecialPoint &sp : pair) {
        sp.note += (sp.note.empty() ? "" : "; ") +
                   std::string("certified counting: one of two opposite crossings inside one step");
        found.push_back(std::move(sp));
      }
      // No count differs (the minimum's eigenvalue is zero to the count's tolerance): an exact
      // touch whose minimum rounded to ≤ 0, as at a cusp of a fold curve. The touch test below.
      if (!pair.empty()) continue;
    }
    if (std::abs(fx) > options_.detection.touchTolerance * std::max({1.0, fa, fb})) continue;  // a dip that stays clear of zero
    SpecialPoint sp;
    sp.type = SpecialPointType::EigenvalueTouch;
    sp.arclength = best.point.arclength;
    sp.u = best.point.u;
    sp.lambda = best.point.lambda;
    sp.tangent = best.point.tangent;
    sp.inertiaBefore = sp.inertiaAfter = a_.point.stability.negative;
    sp.testFunctionValue = c.side * fx;
    // The minimiser's bracket in s, mapped to λ along the tangent.
    sp.lambdaAccuracy = std::abs(best.point.tangent[n_]) * (hi - lo);
    sp.locationIterations = evaluations;
    sp.residualNorm = residualNorm(sp.u, sp.lambda);
    char text[200];
    std::snprintf(text, sizeof text,
                  "certified counting: eigenvalue %d touches zero without crossing (minimum %.3g, scaled)", c.index,
                  c.side * fx);
    sp.note = text;
    keep(found, std::move(sp));
  }
  std::sort(found.begin(), found.end(),
            [](const SpecialPoint &p, const SpecialPoint &q) { return p.arclength < q.arclength; });
  return found;
}

}  // namespace buckle::continuation
