#include "scene/plot_range.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace buckle::scene {

std::pair<double, double> niceRange(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {0.0, 1.0};
  if (!(hi > lo)) {
    const double half = lo != 0.0 ? 0.1 * std::abs(lo) : 1.0;
    lo -= half;
    hi += half;
  }
  const double raw = (hi - lo) / 6.0, mag = std::pow(10.0, std::floor(std::log10(raw))), f = raw / mag;
  const double step = (f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0) * mag;
  return {std::floor(lo / step + 1e-9) * step, std::ceil(hi / step - 1e-9) * step};
}

std::pair<double, double> framedNiceRange(double lo, double hi) {
  auto [a, b] = niceRange(lo, hi);
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {a, b};
  const double margin = kFrameMargin * (b - a);
  if (lo - a < margin) a = lo - margin;
  if (b - hi < margin) b = hi + margin;
  return {a, b};
}

std::pair<double, double> framedRange(std::vector<double>& values) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  const double inf = std::numeric_limits<double>::infinity();
  if (values.empty()) return {inf, -inf};
  std::sort(values.begin(), values.end());
  const size_t last = values.size() - 1;
  const double lo = values[size_t(0.05 * double(last) + 0.5)], hi = values[size_t(0.95 * double(last) + 0.5)];
  // a flat bulk keeps its own size as the spread (a constant curve with one pole still shows)
  const double spread = hi > lo ? hi - lo : std::max(std::abs(lo), std::abs(hi));
  if (!(spread > 0.0)) return {values.front(), values.back()};
  const double reach = kPoleReach * spread;
  return {values.front() < lo - reach ? lo - spread : values.front(),
          values.back() > hi + reach ? hi + spread : values.back()};
}

double symlogThreshold(const std::vector<double>& values, double lo, double hi) {
  if (!(lo < 0.0 && hi > 0.0) || !std::isfinite(lo) || !std::isfinite(hi)) return 0.0;
  std::vector<double> magnitudes;
  for (double v : values)
    if (std::isfinite(v) && v != 0.0 && v >= lo && v <= hi) magnitudes.push_back(std::abs(v));
  if (magnitudes.empty()) return 0.0;
  const size_t k = magnitudes.size() / 10;
  std::nth_element(magnitudes.begin(), magnitudes.begin() + long(k), magnitudes.end());
  const double c = std::pow(10.0, std::floor(std::log10(magnitudes[k])));
  return std::max(-lo, hi) > 100.0 * c ? c : 0.0;
}

}  // namespace buckle::scene
