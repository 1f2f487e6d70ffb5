#include "buckle/continuation/curve_zeros.h"

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/root_finding.h"
#include "buckle/continuation/scaled_problem.h"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace buckle::continuation {

std::vector<CurveZero> locateCurveZeros(const BoundProblem &curve, const Branch &branch, const CurveTest &g,
                                        const CurveZeroOptions &options) {
  std::vector<CurveZero> zeros;
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("CurveZeroOptions: " + why);
  const int n = curve.dimension();
  if (branch.points.size() < 2) return zeros;
  const UnitScaling units(curve.scales());
  const BoundScaledProblem scaledProblem(curve, units);
  const BoundProblem &scaled = scaledProblem.bound();
  // the curve's structured solver when it offers one (O(N) curve systems), else dense LU
  const std::unique_ptr<BorderedSolver> structured = scaled.makeStructuredSolver();
  Corrector corrector(scaled, options.corrector, structured.get());
  Vector scales(n + 1);
  for (int i = 0; i <= n; ++i) scales[i] = units.state(i);
  auto toScaled = [&](const ContinuationPoint &p) {
    Vector x(n + 1);
    x << p.u, p.lambda;
    return Vector(x.cwiseQuotient(scales));
  };
  auto value = [&](ConstVectorRef xs, double &out) {
    const Vector x = xs.cwiseProduct(scales);
    return g(x.head(n), x[n], out);
  };

  Vector xa, xb, chord, predictor, x(n + 1);
  double ga = 0.0, gb = 0.0;
  bool haveA = false;
  for (size_t i = 0; i + 1 < branch.points.size(); ++i) {
    if (!haveA) {
      xa = toScaled(branch.points[i]);
      haveA = value(xa, ga);
    }
    xb = toScaled(branch.points[i + 1]);
    const bool haveB = value(xb, gb);
    if (haveA && haveB && !sameSign(ga, gb)) {
      chord = xb - xa;
      const double length = chord.norm();
      const Vector normal = chord / length;
      IllinoisBracket bracket{0.0, 1.0, ga, gb, 0};
      CurveZero zero;
      zero.index = int(i);
      Vector best = std::abs(ga) < std::abs(gb) ? xa : xb;
      double bestValue = std::abs(ga) < std::abs(gb) ? ga : gb;
      for (int it = 0; it < options.maxIterations && bracket.width() * length > options.tolerance; ++it) {
        const double s = bracket.next();
        predictor = xa + s * chord;
        double gs = 0.0;
        const CorrectorSummary summary = corrector.correct(predictor, normal, x);
        ++zero.iterations;
        if (!summary.converged || !value(x, gs)) break;
        best = x;
        bestValue = gs;
        if (gs == 0.0) {
          bracket.left = bracket.right = s;
          break;
        }
        bracket.update(s, gs);
      }
      zero.accuracy = bracket.width() * length;
      zero.converged = zero.accuracy <= options.tolerance;
      const Vector user = best.cwiseProduct(scales);
      zero.u = user.head(n);
      zero.lambda = user[n];
      zero.value = bestValue;
      zeros.push_back(zero);
    }
    xa = xb;
    ga = gb;
    haveA = haveB;
  }
  return zeros;
}

}  // namespace buckle::continuation
