// Located stiffness minima (mechanics/stiffness_extremum.h): the exact derivative of K_F against
// finite differences, KMIN on the Fig 9/10 chains against an independent search along the
// branch, and its independence of the step size and of the units.
#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <cmath>
#include <random>
#include <vector>

#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/stiffness_extremum.h"
#include "buckle/mechanics/unloaded_shape.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

Eigen::VectorXd figureShape() {
  const double theta = std::acos(7.0 / 8.0);
  Eigen::VectorXd q0(3);
  q0 << theta, -2.0 * theta, theta;
  return q0;
}

// The Fig 9/10 chain (data/scenes/fig9_fig10.json): three segments, q0 = (θ, −2θ, θ) with
// cos θ = 7/8, L1_0 + L2_0 = 4.5 b; lengths in units of `length`, spring stiffness `stiffness`.
Chain figureChain(double aOverB, double length = 1.0, double stiffness = 1.0) {
  const SegmentParameters p = SegmentParameters::symmetric(aOverB * length, length, stiffness, 2.25 * length);
  return Chain(preloadsForShape(std::vector<SegmentParameters>(3, p), figureShape()));
}

// The KMIN events of the branch of the Fig 9/10 chain under Fx from 0 to −2 k b.
std::vector<SpecialPointReport> kmin(EquilibriumProblem& problem, double forceUnit, double maxStep,
                                     StiffnessMeasure measure = StiffnessMeasure::Kxx) {
  EquilibriumBranchOptions opt;
  opt.tracer.lambdaMin = -2.0 * forceUnit;
  opt.tracer.lambdaMax = 0.0;
  if (maxStep > 0.0) opt.tracer.step.maxStep = maxStep;
  opt.tree.branchSwitching = 0;
  opt.report.stiffness = true;
  opt.report.stiffnessMeasure = measure;
  const EquilibriumBranches r =
      traceEquilibria(problem, figureShape(), 0.0, cont::InitialDirection::decreasingLambda(), opt);
  std::vector<SpecialPointReport> out;
  for (const SpecialPointReport& s : r.reports.front().specialPoints)
    if (s.type == EventType::StiffnessMinimum) out.push_back(s);
  return out;
}

// Independent equilibrium at fixed λ: plain dense Newton on the problem's residual, iterated to
// the rounding floor (three steps below 1e-14 of the unknowns' size: a few ulps, whatever
// rounding the residual's sums leave).
Vector newtonAt(EquilibriumProblem& problem, Vector u, double lambda) {
  const int N = problem.dimension();
  Vector F(N), Fl(N);
  Matrix Fu(N, N);
  int small = 0;
  for (int it = 0; it < 60 && small < 3; ++it) {
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
    REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, Fu, Fl));
    const Vector du = Fu.partialPivLu().solve(F);
    u -= du;
    if (du.lpNorm<Eigen::Infinity>() < 1e-14 * std::max(1.0, u.lpNorm<Eigen::Infinity>())) ++small;
  }
  REQUIRE(small >= 3);
  return u;
}

// K_xx along the branch as a function of λ (λ monotone there), warm-started Newton solves.
struct KxxAlongLoad {
  EquilibriumProblem& problem;
  Vector guess;
  double operator()(double lambda) {
    guess = newtonAt(problem, guess, lambda);
    return loadedStiffness(problem.chain(), guess, problem.wrench(guess, lambda), problem.endCondition()).stiffness(0, 0);
  }
};

// Golden-section search of K_xx(λ) on [lo, hi], then (value comparisons only locate a minimum to
// √ε of the interval) a secant on the fourth-order central difference of K_xx(λ) with step h,
// whose truncation O(h⁴) and rounding O(ε/h) are both far below 1e-9.
double independentMinimum(KxxAlongLoad& f, double lo, double hi) {
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  while (hi - lo > 1e-7 * std::abs(hi)) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - r * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + r * (hi - lo), f2 = f(x2);
    }
  }
  const double h = 1e-3 * std::abs(hi);
  const auto slope = [&](double x) {
    return (f(x - 2 * h) - 8 * f(x - h) + 8 * f(x + h) - f(x + 2 * h)) / (12 * h);
  };
  double a = 0.5 * (lo + hi) - 1e-5 * std::abs(hi), b = 0.5 * (lo + hi) + 1e-5 * std::abs(hi);
  double ga = slope(a), gb = slope(b);
  for (int it = 0; it < 30 && ga != gb && std::abs(b - a) > 1e-14 * std::abs(b); ++it) {
    const double c = b - gb * (b - a) / (gb - ga);
    a = b, ga = gb;
    b = c, gb = slope(c);
  }
  return b;
}

}  // namespace

TEST_CASE("the derivative of K_F along (dq, dF) equals finite differences of loadedStiffness", "[stiffness_extremum]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.4, 0.4);
  const Chain chain = figureChain(0.75);
  for (bool held : {false, true}) {
    for (int trial = 0; trial < 5; ++trial) {
      Vector q = figureShape(), dq(3);
      for (int i = 0; i < 3; ++i) q[i] += U(rng), dq[i] = U(rng);
      const Wrench F(U(rng), U(rng), 0.0), dF(U(rng), U(rng), U(rng));
      Eigen::Matrix2d K, dK;
      REQUIRE(loadedStiffnessDerivative(chain, q, F, held, dq, dF, K, dK));
      CHECK((K - loadedStiffness(chain, q, F, held).stiffness).norm() <= 1e-13 * K.norm());
      const double h = 1e-5;
      const auto at = [&](double t) { return loadedStiffness(chain, q + t * dq, F + t * dF, held).stiffness; };
      const Eigen::Matrix2d fd = (at(-2 * h) - 8 * at(-h) + 8 * at(h) - at(2 * h)) / (12 * h);
      CHECK((dK - fd).norm() <= 1e-8 * std::max(K.norm(), dK.norm()));
      // The smallest eigenvalue's rate (Hellmann–Feynman) against its finite difference.
      const auto mu = [&](double t) { return stiffnessMeasure(at(t), StiffnessMeasure::MinEigenvalue); };
      const double fdMu = (mu(-2 * h) - 8 * mu(-h) + 8 * mu(h) - mu(2 * h)) / (12 * h);
      CHECK(std::abs(stiffnessMeasureDerivative(K, dK, StiffnessMeasure::MinEigenvalue) - fdMu) <=
            1e-8 * std::max(K.norm(), dK.norm()));
    }
  }
}

TEST_CASE("stiffness measure names round-trip", "[stiffness_extremum]") {
  for (StiffnessMeasure m : {StiffnessMeasure::Kxx, StiffnessMeasure::Kyy, StiffnessMeasure::MinEigenvalue}) {
    StiffnessMeasure back = StiffnessMeasure::Kxx;
    REQUIRE(parseStiffnessMeasure(toString(m), back));
    CHECK(back == m);
  }
  StiffnessMeasure unused;
  CHECK_FALSE(parseStiffnessMeasure("Kzz", unused));
}

TEST_CASE("KMIN on the Fig 9/10 chains equals an independent search along the branch", "[stiffness_extremum]") {
  for (double aOverB : {0.75, 0.9}) {
    CAPTURE(aOverB);
    const Chain chain = figureChain(aOverB);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
    const std::vector<SpecialPointReport> found = kmin(problem, 1.0, 0.0);
    REQUIRE(found.size() == 1);
    const SpecialPointReport& s = found.front();
    REQUIRE(s.refined);
    CHECK(s.phenomenon == Phenomenon::QuasiBuckling);
    CHECK(s.accuracy <= 1e-12);
    // Independent: golden section over the load, pointwise Newton solves, around the event.
    KxxAlongLoad f{problem, problem.initialGuess(s.q, s.lambda)};
    const double lambda = independentMinimum(f, s.lambda - 0.05, s.lambda + 0.05);
    CHECK(std::abs(lambda - s.lambda) <= 1e-9 * std::abs(s.lambda));
    const double value = f(lambda);
    const double located = loadedStiffness(chain, s.q, s.F, problem.endCondition()).stiffness(0, 0);
    CHECK(std::abs(value - located) <= 1e-9 * value);
    // The located point is an equilibrium on the branch (Newton at its λ does not move it).
    CHECK((newtonAt(problem, problem.initialGuess(s.q, s.lambda), s.lambda).head(3) - s.q).norm() <= 1e-12);
  }
}

TEST_CASE("KMIN does not move with the step size, nor with the units", "[stiffness_extremum]") {
  const Chain chain = figureChain(0.75);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
  std::vector<SpecialPointReport> runs;
  for (double maxStep : {0.3, 0.07, 0.02}) {
    const std::vector<SpecialPointReport> found = kmin(problem, 1.0, maxStep);
    REQUIRE(found.size() == 1);
    REQUIRE(found.front().refined);
    runs.push_back(found.front());
  }
  const double k0 = loadedStiffness(chain, runs[0].q, runs[0].F, problem.endCondition()).stiffness(0, 0);
  for (const SpecialPointReport& s : runs) {
    CHECK(std::abs(s.lambda - runs[0].lambda) <= 1e-10 * std::abs(runs[0].lambda));
    CHECK((s.q - runs[0].q).norm() <= 1e-10);
    CHECK(std::abs(loadedStiffness(chain, s.q, s.F, problem.endCondition()).stiffness(0, 0) - k0) <= 1e-10 * k0);
  }
  // Lengths ×1e3, spring stiffness ×1e-6: forces scale by 1e-3, K_F by 1e-6, angles not at all.
  const double length = 1e3, stiffness = 1e-6, force = length * stiffness;
  const Chain scaled = figureChain(0.75, length, stiffness);
  EquilibriumProblem scaledProblem(scaled, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
  const std::vector<SpecialPointReport> found = kmin(scaledProblem, force, 0.0);
  REQUIRE(found.size() == 1);
  const SpecialPointReport& s = found.front();
  CHECK(std::abs(s.lambda / force - runs[0].lambda) <= 1e-10 * std::abs(runs[0].lambda));
  CHECK((s.q - runs[0].q).norm() <= 1e-10);
  const double ks = loadedStiffness(scaled, s.q, s.F, scaledProblem.endCondition()).stiffness(0, 0);
  CHECK(std::abs(ks / stiffness - k0) <= 1e-10 * k0);
}

TEST_CASE("KMIN of the smallest eigenvalue of K_F: its rate vanishes there", "[stiffness_extremum]") {
  const Chain chain = figureChain(0.75);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
  for (StiffnessMeasure m : {StiffnessMeasure::MinEigenvalue, StiffnessMeasure::Kxx}) {
    CAPTURE(toString(m));
    const std::vector<SpecialPointReport> found = kmin(problem, 1.0, 0.0, m);
    REQUIRE(found.size() == 1);
    for (const SpecialPointReport& s : found) {
      REQUIRE(s.refined);
      // The measure along λ (monotone here): equal values at λ ± h within O(h²)·m'' of each other,
      // and both above the located value.
      const auto at = [&](double lambda) {
        const Vector u = newtonAt(problem, problem.initialGuess(s.q, s.lambda), lambda);
        return stiffnessMeasure(loadedStiffness(chain, u.head(3), problem.wrench(u, lambda), problem.endCondition()).stiffness, m);
      };
      const double h = 1e-3, v0 = at(s.lambda), vm = at(s.lambda - h), vp = at(s.lambda + h);
      CHECK(vm > v0);
      CHECK(vp > v0);
      CHECK(std::abs(vp - vm) <= 1e-2 * (vp + vm - 2 * v0));  // O(h³) against O(h²): no first-order term
    }
  }
}
