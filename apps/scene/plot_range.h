// Axis ranges of the plots: round tic steps, and a frame that shows a curve's bulk where a few of
// its values run off to a pole (a stiffness 1/C through C = 0).
#pragma once

#include <utility>
#include <vector>

namespace buckle::scene {

/// [lo, hi] widened to multiples of a round tic step (1, 2 or 5 × 10^k, about six tics), as
/// gnuplot's autoscale would, so that fixing the range does not change the plot's look.
std::pair<double, double> niceRange(double lo, double hi);

/// niceRange(lo, hi), with an end that would meet the data (an extreme within kFrameMargin of the
/// span from it) moved out by kFrameMargin of the span: a curve at the data's extreme (the
/// straight branch at zero deflection) is drawn apart from the axis line, not on it.
std::pair<double, double> framedNiceRange(double lo, double hi);
constexpr double kFrameMargin = 0.03;

/// The range of `values` (finite ones; the order is changed) that a plot frames: all of them,
/// unless some lie further than kPoleReach interquantile spreads (the 5th to the 95th percentile)
/// beyond those percentiles — the run-up to a pole — in which case the frame ends one spread
/// beyond the percentile on that side, and the curve leaves the frame there.
/// {+inf, −inf} when no value is finite.
std::pair<double, double> framedRange(std::vector<double>& values);
constexpr double kPoleReach = 4.0;

/// The linear threshold c of a symmetric-log axis asinh(y / c) for the `values` drawn in
/// [lo, hi]: where the range holds both signs and its largest magnitude is over a hundred times
/// c = 10^floor(log10 of the 10th percentile of the nonzero magnitudes), c; otherwise 0 (a
/// linear axis serves).
double symlogThreshold(const std::vector<double>& values, double lo, double hi);

}  // namespace buckle::scene
