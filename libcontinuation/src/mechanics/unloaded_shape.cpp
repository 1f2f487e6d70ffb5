#include "buckle/mechanics/unloaded_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

namespace {

// Safeguarded Newton on M in the bracket [lo, hi] with M(lo)·M(hi) <= 0.
double refineRoot(const Segment& s, double lo, double hi, double tol) {
  double Mlo = s.torque(lo);
  double x = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const Jet3 e = s.energyJet(x);
    const double M = -e.d1, dM = -e.d2;
    if (M == 0.0) return x;
    if ((M < 0) == (Mlo < 0)) {
      lo = x;
      Mlo = M;
    } else {
      hi = x;
    }
    double next = (dM != 0.0) ? x - M / dM : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - x);
    x = next;
    if (step <= tol || hi - lo <= tol) break;
  }
  return x;
}

TorqueRoot makeRoot(const Segment& s, double q) {
  TorqueRoot r;
  r.q = q;
  r.stiffness = s.stiffness(q);
  r.stable = r.stiffness > 0.0;
  // K_q = Σ k (L'² + (L − L⁰) L'') is a sum of terms of size k b²; within their rounding it is
  // zero (a degenerate root, e.g. the borderline M'(0) = 0 of eq 4) and its sign is noise: the
  // restoring torque either side decides (stable: M > 0 below the root, M < 0 above).
  const SegmentParameters& p = s.parameters();
  const double rounding = 1e3 * std::numeric_limits<double>::epsilon() * (p.k1 * p.b1 * p.b1 + p.k2 * p.b2 * p.b2);
  if (std::abs(r.stiffness) <= rounding) {
    const double delta = 1e-3;  // rad
    const double below = std::max(q - delta, 0.5 * (q + s.lowerLimit())), above = std::min(q + delta, 0.5 * (q + s.upperLimit()));
    r.stable = s.torque(below) > 0.0 && s.torque(above) < 0.0;
  }
  return r;
}

}  // namespace

std::string UnloadedShapeOptions::validate(const std::string& prefix) const {
  namespace cont = continuation;
  return cont::firstProblem({cont::require(samples >= 2, prefix, "samples", "must be at least 2"),
                             cont::requirePositive(prefix, "tolerance", tolerance)});
}

SegmentUnloadedAngle unloadedAngle(const Segment& s, const UnloadedShapeOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("UnloadedShapeOptions: " + why);
  SegmentUnloadedAngle out;
  // The geometric limits are excluded (a spring of zero length); user limits are included.
  const double lo = s.lowerLimit(), hi = s.upperLimit();
  const double margin = 1e-9 * (hi - lo);
  const double a = (lo == s.geometricLowerLimit()) ? lo + margin : lo;
  const double b = (hi == s.geometricUpperLimit()) ? hi - margin : hi;
  const int N = std::max(16, options.samples);
  std::vector<TorqueRoot> roots;
  // Sample on a grid that contains q = 0 whenever 0 is inside, so the symmetric root is exact.
  std::vector<double> grid;
  grid.reserve(size_t(N) + 2);
  for (int i = 0; i <= N; ++i) grid.push_back(a + (b - a) * i / N);
  if (a < 0.0 && b > 0.0) grid.push_back(0.0);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  double qPrev = grid[0], MPrev = s.torque(qPrev);
  if (MPrev == 0.0) roots.push_back(makeRoot(s, qPrev));
  for (size_t i = 1; i < grid.size(); ++i) {
    const double qi = grid[i], Mi = s.torque(qi);
    if (Mi == 0.0) {
      roots.push_back(makeRoot(s, qi));
    } else if (MPrev != 0.0 && (Mi < 0) != (MPrev < 0)) {
      roots.push_back(makeRoot(s, refineRoot(s, qPrev, qi, options.tolerance)));
    }
    qPrev = qi;
    MPrev = Mi;
  }
  if (roots.empty()) return out;
  out.found = true;
  auto nearest = [&](bool requireStable) {
    int best = -1;
    for (size_t i = 0; i < roots.size(); ++i) {
      if (requireStable && !roots[i].stable) continue;
      if (best < 0 || std::abs(roots[i].q) < std::abs(roots[size_t(best)].q)) best = int(i);
    }
    return best;
  };
  int pick = nearest(true);
  if (pick < 0) pick = nearest(false);
  out.root = roots[size_t(pick)];
  for (size_t i = 0; i < roots.size(); ++i)
    if (int(i) != pick) out.others.push_back(roots[i]);
  return out;
}

UnloadedShape unloadedShape(const Chain& chain, const UnloadedShapeOptions& options) {
  UnloadedShape out;
  const int n = chain.size();
  out.q = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  out.allFound = true;
  out.allStable = true;
  for (int i = 0; i < n; ++i) {
    out.segments.push_back(unloadedAngle(chain.segment(i), options));
    const SegmentUnloadedAngle& s = out.segments.back();
    if (s.found) out.q[i] = s.root.q;
    out.allFound = out.allFound && s.found;
    out.allStable = out.allStable && s.found && s.root.stable;
  }
  return out;
}

PreloadResult preloadsForAngle(const SegmentParameters& p, double q0) {
  const Segment s(p);  // validates the geometry and current preloads
  if (!std::isfinite(q0)) throw std::invalid_argument("q0 must be a finite number");
  // The geometric limits themselves are excluded: a spring would have zero length.
  const bool inside = q0 > s.geometricLowerLimit() && q0 < s.geometricUpperLimit() && q0 >= s.lowerLimit() &&
                      q0 <= s.upperLimit();
  if (!inside) {
    std::ostringstream os;
    os << "q0 = " << q0 << " is outside the joint limits [" << s.lowerLimit() << ", " << s.upperLimit() << "]";
    throw std::invalid_argument(os.str());
  }
  const Jet3 L1 = s.spring1(q0), L2 = s.spring2(q0);
  const double S = p.L1_0 + p.L2_0;
  // k1 L1' (L1 − L1⁰) + k2 L2' (L2 − L2⁰) = 0 with L2⁰ = S − L1⁰.
  const double denom = p.k1 * L1.d1 - p.k2 * L2.d1;
  const double numer = p.k1 * L1.d1 * L1.value + p.k2 * L2.d1 * (L2.value - S);
  if (!(std::abs(denom) > 1e-14 * (std::abs(p.k1 * L1.d1) + std::abs(p.k2 * L2.d1)))) {
    std::ostringstream os;
    os << "q0 = " << q0 << ": the torque does not depend on the preload split (L1_0, L2_0) there";
    throw std::invalid_argument(os.str());
  }
  const double L1_0 = numer / denom, L2_0 = S - L1_0;
  auto reject = [&](const char* name, double value) {
    std::ostringstream os;
    os << name << " would be " << value << " (<= 0) to hold q0 = " << q0 << " with L1_0 + L2_0 = " << S;
    throw std::invalid_argument(os.str());
  };
  if (!(L1_0 > 0.0)) reject("L1_0", L1_0);
  if (!(L2_0 > 0.0)) reject("L2_0", L2_0);
  PreloadResult r;
  r.parameters = p;
  r.parameters.L1_0 = L1_0;
  r.parameters.L2_0 = L2_0;
  r.stiffness = Segment(r.parameters).stiffness(q0);
  r.stable = r.stiffness > 0.0;
  return r;
}

std::vector<SegmentParameters> preloadsForShape(const std::vector<SegmentParameters>& segments,
                                                const Eigen::Ref<const Eigen::VectorXd>& q0) {
  if (segments.empty()) throw std::invalid_argument("n (segment count) must be >= 1 (got 0)");
  if (q0.size() != Eigen::Index(segments.size())) {
    std::ostringstream os;
    os << "q0 must have one angle per segment (got " << q0.size() << " for " << segments.size() << " segments)";
    throw std::invalid_argument(os.str());
  }
  std::vector<SegmentParameters> out;
  out.reserve(segments.size());
  for (size_t i = 0; i < segments.size(); ++i) {
    try {
      out.push_back(preloadsForAngle(segments[i], q0[Eigen::Index(i)]).parameters);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("segment " + std::to_string(i + 1) + ": " + e.what());
    }
  }
  return out;
}

TorqueCurve torqueCurve(const Segment& seg, double from, double to, int points) {
  const double margin = 1e-6;  // radians: the angles' own unit
  const double lo = std::max(from, seg.lowerLimit() + margin);
  const double hi = std::min(to, seg.upperLimit() - margin);
  TorqueCurve c;
  for (int i = 0; i < points; ++i) {
    const double q = points > 1 ? lo + (hi - lo) * i / (points - 1) : lo;
    c.q.push_back(q);
    c.M.push_back(seg.torque(q));
    c.Kq.push_back(seg.stiffness(q));
  }
  const SegmentUnloadedAngle roots = unloadedAngle(seg);
  auto add = [&](const TorqueRoot& r) {
    if (r.q >= lo && r.q <= hi) c.equilibria.emplace_back(r.q, r.stable);
  };
  if (roots.found) add(roots.root);
  for (const auto& r : roots.others) add(r);
  std::sort(c.equilibria.begin(), c.equilibria.end());
  // a root found from both sides of a sign change is one root
  c.equilibria.erase(std::unique(c.equilibria.begin(), c.equilibria.end(),
                                 [](const auto& x, const auto& y) { return std::abs(x.first - y.first) < 1e-9; }),
                     c.equilibria.end());
  return c;
}

}  // namespace buckle::mechanics
