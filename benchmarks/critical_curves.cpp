// critical_curves: wall time of two-parameter continuation (issue 15). Rows:
//   fold  the fold curve of the imperfect subcritical three-segment chain (a = 2.5, b = 1, k = 1,
//         L0 = 0.5, clamped-pinned, eccentric end torque Me = 0.01 as μ), from its first fold,
//         200 points in one direction (increasing Me, toward the joint limit);
//   bp    the first branch-point curve of the straight n-segment chain (a = 0.5, L0 = 2.25) in L0,
//         200 points in one direction, with and without the Koiter coefficients at every point
//         (n ≤ 100: the coefficients are dense, O(n³) per point), dense and with the chain's
//         O(n) structure (CriticalCurveOptions::structuredFromDimension, the crossover);
//   fold  n = 1000: the fold curve of a free-end chain of slightly different paper segments
//         (a_i = 0.5(1 + 0.05 sin 1.3i), L0 = 2.25) under an end torque λ, μ = the axial end force
//         Fx (from −0.01), from the torque path's first fold, 200 points toward more compression
//         (the minimally augmented system, O(n) per point); the path to the fold is not timed.
// Best of `reps` runs.
//
//   critical_curves [--reps R]
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/critical_curves.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {
using Clock = std::chrono::steady_clock;

template <class F>
double best(int reps, F&& f) {
  double t = std::numeric_limits<double>::infinity();
  for (int r = 0; r < reps; ++r) {
    const Clock::time_point t0 = Clock::now();
    f();
    t = std::min(t, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return t;
}

CriticalCurveOptions twoHundred(double muMin, double muMax) {
  CriticalCurveOptions o;
  o.muMin = muMin;
  o.muMax = muMax;
  o.bothDirections = false;
  o.tracer.maxPoints = 200;
  o.tracer.step.maxStep = 0.01;
  return o;
}
}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  if (argc == 3 && std::string(argv[1]) == "--reps") reps = std::max(1, std::atoi(argv[2]));
  else if (argc != 1) {
    std::fprintf(stderr, "usage: critical_curves [--reps R]\n");
    return 2;
  }
  {
    EndCondition end = EndCondition::clampedPinned(0.0);
    end.value[2] = 0.01;
    ChainParameterProblem p(std::vector<SegmentParameters>(3, SegmentParameters::symmetric(2.5, 1.0, 1.0, 0.5)), end,
                            Eigen::Vector3d(1, 0, 0), SecondParameter::parse("phi"));
    cont::TracerOptions to;
    to.step.maxStep = 0.05;
    to.lambdaMin = -20;
    const cont::Branch path = cont::trace(p, p.equilibrium().initialGuess(Eigen::VectorXd::Zero(3), 0.0), 0.0,
                                          cont::InitialDirection::decreasingLambda(), to);
    const auto folds = path.specialPointsOfType(cont::SpecialPointType::Fold);
    if (folds.empty()) {
      std::fprintf(stderr, "critical_curves: no fold on the imperfect path\n");
      return 1;
    }
    const cont::SpecialPoint fold = *folds.front();
    CriticalCurve c;
    CriticalCurveOptions o = twoHundred(-1.0, 1.0);
    o.tracer.step.initialStep = o.tracer.step.maxStep = 0.004;  // 200 points before the joint limit (BD at Me ≈ 0.22)
    const double t = best(reps, [&] { c = foldCurve(p, fold, o); });
    std::printf("fold n=3: %zu points, %zu codim-2 points, %.2f ms\n", c.points.size(), c.special.size(), 1e3 * t);
  }
  using LA = cont::TracerOptions::LinearAlgebra;
  for (int n : {3, 10, 30, 100, 1000}) {
    for (bool coefficients : {false, true}) {
      if (coefficients && n > 100) continue;
      for (LA la : {LA::Dense, LA::Structured}) {
        if (la == LA::Dense && n > 100) continue;
        ChainParameterProblem p(std::vector<SegmentParameters>(size_t(n), SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                                EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0), SecondParameter::parse("L0"));
        CriticalCurveOptions o = twoHundred(2.25, 100.0);
        o.coefficients = coefficients;
        o.tracer.linearAlgebra = la;
        CriticalCurve c;
        const double t = best(reps, [&] { c = branchPointCurve(p, 0, o); });
        std::printf("bp n=%d %s%s: %zu points, %.2f ms\n", n, la == LA::Dense ? "dense" : "structured",
                    coefficients ? " with Koiter coefficients" : "", c.points.size(), 1e3 * t);
      }
    }
  }
  {
    const int n = 1000;
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < n; ++i)
      segs.push_back(SegmentParameters::symmetric(0.5 * (1 + 0.05 * std::sin(1.3 * i)), 1.0, 1.0, 2.25));
    ChainParameterProblem p(segs, EndCondition::freeEnd(Eigen::Vector3d(-0.01, 0.0, 0.0)), Eigen::Vector3d(0, 0, 1),
                            SecondParameter::parse("x"));
    cont::TracerOptions to;
    to.step.maxStep = 0.1;
    to.lambdaMax = 10.0;
    to.maxPoints = 3000;
    to.detection.lowestEigenvalues = 0;
    to.onStep = [](const cont::StepInfo& step) {
      for (const cont::SpecialPoint& sp : step.specialPoints)
        if (sp.type == cont::SpecialPointType::Fold) return cont::StepAction::Stop;
      return cont::StepAction::Continue;
    };
    const cont::Branch path = cont::trace(p.equilibrium(), p.equilibrium().initialGuess(Eigen::VectorXd::Zero(n), 0.0),
                                          0.0, cont::InitialDirection::increasingLambda(), to);
    const auto folds = path.specialPointsOfType(cont::SpecialPointType::Fold);
    if (folds.empty()) {
      std::fprintf(stderr, "critical_curves: no fold on the torque path (n = %d)\n", n);
      return 1;
    }
    const cont::SpecialPoint fold = *folds.front();
    CriticalCurveOptions o = twoHundred(-1.0, 1.0);
    o.tracer.step.maxStep = 0.05;
    CriticalCurve c;
    // toward more compression: the second direction of foldCurve, alone
    o.bothDirections = true;
    o.muMax = -0.01 + 1e-12;
    const double t = best(reps, [&] { c = foldCurve(p, fold, o); });
    std::printf("fold n=%d: %zu points (mu %.4g to %.4g), %zu codim-2 points, %.2f ms\n", n, c.points.size(),
                c.points.front().mu, c.points.back().mu, c.special.size(), 1e3 * t);
  }
  return 0;
}
