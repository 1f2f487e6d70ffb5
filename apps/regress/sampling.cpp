#include "regress/sampling.h"

#include <algorithm>
#include <cmath>

namespace buckle::regress {

namespace {

/// λ strictly monotone over points [first, first + 3], consecutive along the branch.
bool monotoneStencil(const MeasuredBranch& b, int first) {
  if (first < 0 || first + 3 >= int(b.lambda.size())) return false;
  double sign = 0.0;
  for (int i = first; i < first + 3; ++i) {
    if (b.index[size_t(i) + 1] != b.index[size_t(i)] + 1) return false;
    const double d = b.lambda[size_t(i) + 1] - b.lambda[size_t(i)];
    const double scale = std::max(1.0, std::abs(b.lambda[size_t(i)]));
    if (std::abs(d) <= 1e-9 * scale) return false;
    if (sign != 0.0 && (d > 0) != (sign > 0)) return false;
    sign = d;
  }
  return true;
}

bool crosses(const MeasuredBranch& b, size_t j, double lambda) {
  const double a = b.lambda[j] - lambda, c = b.lambda[j + 1] - lambda;
  return (a < 0 && c > 0) || (a > 0 && c < 0) || (c == 0 && a != 0);
}

/// Lagrange interpolation through points [first, first + k) at x.
double lagrange(const MeasuredBranch& b, int first, int k, int coordinate, double x) {
  double sum = 0.0;
  for (int i = first; i < first + k; ++i) {
    double w = 1.0;
    for (int j = first; j < first + k; ++j)
      if (j != i) w *= (x - b.lambda[size_t(j)]) / (b.lambda[size_t(i)] - b.lambda[size_t(j)]);
    sum += w * b.q[size_t(i)][coordinate];
  }
  return sum;
}

}  // namespace

std::vector<SampleSite> chooseSites(const MeasuredBranch& b, int count) {
  std::vector<SampleSite> sites;
  const int m = int(b.lambda.size());
  if (m < 5 || count <= 0) return sites;
  std::vector<int> used;
  for (int s = 1; s <= count; ++s) {
    const int target = int(std::lround(double(s) * (m - 1) / (count + 1)));
    // nearest segment i (points i, i+1) whose stencil i-1 .. i+2 is monotone
    for (int off = 0; off < m; ++off) {
      int i = -1;
      for (int cand : {target + off, target - off})
        if (i < 0 && monotoneStencil(b, cand - 1) && std::find(used.begin(), used.end(), cand) == used.end()) i = cand;
      if (i < 0) continue;
      used.push_back(i);
      SampleSite site;
      site.lambda = 0.5 * (b.lambda[size_t(i)] + b.lambda[size_t(i) + 1]);
      for (int j = 0; j < i; ++j)
        if (crosses(b, size_t(j), site.lambda)) ++site.crossing;
      sites.push_back(site);
      break;
    }
  }
  return sites;
}

SampleValue sampleAt(const MeasuredBranch& b, const SampleSite& site, const std::vector<int>& coordinates) {
  SampleValue v;
  const int m = int(b.lambda.size());
  int seen = 0, segment = -1;
  for (int j = 0; j + 1 < m && segment < 0; ++j)
    if (crosses(b, size_t(j), site.lambda) && seen++ == site.crossing) segment = j;
  if (segment < 0) return v;
  for (int c : coordinates)
    if (c < 0 || c >= b.q[size_t(segment)].size()) return v;
  // cubic through the segment and one neighbour each side (shifted inwards at the ends); where
  // λ turns back inside the stencil only the linear interpolant is meaningful
  const int first = std::clamp(segment - 1, 0, std::max(0, m - 4));
  const bool cubic = monotoneStencil(b, first);
  const double x = site.lambda;
  for (int c : coordinates) {
    if (cubic) {
      // the two quadratics of the stencil differ from the cubic by about the quadratic's own
      // error (h³), a safe upper bound for the cubic's (h⁴)
      const double p3 = lagrange(b, first, 4, c, x);
      const double d = std::max(std::abs(p3 - lagrange(b, first, 3, c, x)), std::abs(p3 - lagrange(b, first + 1, 3, c, x)));
      v.values.push_back(p3);
      v.errorEstimate = std::max(v.errorEstimate, d);
    } else {
      const double p1 = lagrange(b, segment, 2, c, x);
      v.values.push_back(p1);
      // the linear interpolant is only as good as the points are close
      v.errorEstimate = std::max(v.errorEstimate, std::abs(b.q[size_t(segment) + 1][c] - b.q[size_t(segment)][c]));
    }
  }
  v.found = true;
  return v;
}

}  // namespace buckle::regress
