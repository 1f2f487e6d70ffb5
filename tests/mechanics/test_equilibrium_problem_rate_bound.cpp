// EquilibriumProblem::stabilitySlopes (equilibrium_problem_rate_bound.cpp): the rates of the
// eigenvalues of K_q − K_g on ker J_h along a direction, from their eigenvectors, against central
// differences of the dense spectrum; in the paper's units and in scaled ones, through the
// tracer's ScaledProblem; refused where it must be. (The bound of the same file: its tests are in
// test_equilibrium_problem.cpp.)
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "buckle/continuation/scaled_problem.h"
#include "buckle/mechanics/equilibrium_problem.h"

#include "../malloc_counter.h"
#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;
using buckle::continuation::BoundProblem;

namespace {

/// A random chain with its lengths scaled by `length` and its stiffnesses by `stiffness`.
Chain slopeTestChain(std::mt19937& rng, int n, double length, double stiffness) {
  std::vector<SegmentParameters> segments;
  for (int i = 0; i < n; ++i) {
    SegmentParameters p = testing::randomSegment(rng);
    p.a1 *= length;
    p.a2 *= length;
    p.b1 *= length;
    p.b2 *= length;
    p.L1_0 *= length;
    p.L2_0 *= length;
    p.k1 *= stiffness;
    p.k2 *= stiffness;
    segments.push_back(p);
  }
  return Chain(segments);
}

struct SlopeCase {
  std::string name;
  EndCondition end;
};

/// Free end, y held (clamped–pinned) and x, y held, with loads and held values in the units of
/// force k·b and length b.
std::vector<SlopeCase> slopeCases(std::mt19937& rng, double length, double force) {
  std::uniform_real_distribution<double> W(-1.5, 1.5);
  return {{"free", EndCondition::freeEnd(force * Eigen::Vector3d(W(rng), W(rng), length * W(rng)))},
          {"clamped-pinned", EndCondition::clampedPinned(force * W(rng), length * W(rng))},
          {"held position", EndCondition::heldPosition(length * (3.0 + W(rng)), length * W(rng))}};
}

/// Central difference of the dense eigenvalue `index` along (du, dλ).
double differencedRate(const EquilibriumProblem& dense, const Vector& u, double lambda, const Vector& du,
                       double dlambda, int index) {
  Eigen::Matrix<double, 1, 1> plus, minus;
  const double h = 1e-6;
  REQUIRE(BoundProblem(dense).stabilityEigenvalues(u + h * du, lambda + h * dlambda, index, plus));
  REQUIRE(BoundProblem(dense).stabilityEigenvalues(u - h * du, lambda - h * dlambda, index, minus));
  return (plus[0] - minus[0]) / (2.0 * h);
}

}  // namespace

TEST_CASE("stabilitySlopes: the eigenvalues' rates from their eigenvectors equal differences of the dense spectrum",
          "[equilibrium]") {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  struct Units {
    double length, stiffness;
  };
  for (const Units units : {Units{1.0, 1.0}, Units{1e4, 1e-8}, Units{1e-4, 1e8}}) {
    const double force = units.stiffness * units.length, torque = force * units.length;
    for (int n : {5, 17, 40}) {
      const Chain chain = slopeTestChain(rng, n, units.length, units.stiffness);
      for (const SlopeCase& c : slopeCases(rng, units.length, force)) {
        const Eigen::Vector3d direction = force * Eigen::Vector3d(W(rng), W(rng), units.length * W(rng));
        EquilibriumProblem problem(chain, c.end, direction);
        EquilibriumProblem dense(chain, c.end, direction, EquilibriumOptions{true, false});
        const int N = problem.dimension(), m = N - n;
        for (int trial = 0; trial < 3; ++trial) {
          INFO("units b = " << units.length << ", k = " << units.stiffness << ", n = " << n << ", end: " << c.name
                            << ", trial " << trial);
          Vector u = testing::randomState(rng, chain, N);
          u.tail(m) *= force;  // the reactions in the chain's units
          const double lambda = Lam(rng);
          Vector du(N);
          for (int i = 0; i < N; ++i) du[i] = i < n ? W(rng) : force * W(rng);
          const double dlambda = W(rng);
          Vector all(n - m);
          REQUIRE(BoundProblem(dense).stabilityEigenvalues(u, lambda, 0, all));
          double bound = 0.0;
          REQUIRE(BoundProblem(problem).stabilityRateBound(u, lambda, du, dlambda, bound));
          // the lowest two, two in the middle and the highest: each isolated from its neighbours
          // well above the difference's resolution
          int checked = 0;
          for (int first : {0, (n - m) / 2 - 1, n - m - 2}) {
            Eigen::Vector2d values, slopes;
            REQUIRE(BoundProblem(problem).stabilityEigenvalues(u, lambda, first, values));
            REQUIRE(BoundProblem(problem).stabilitySlopes(u, lambda, du, dlambda, first, values, slopes));
            for (int k = 0; k < 2; ++k) {
              const int j = first + k;
              const double gap = std::min(j > 0 ? all[j] - all[j - 1] : INFINITY,
                                          j + 1 < n - m ? all[j + 1] - all[j] : INFINITY);
              if (gap < 1e-3 * torque) continue;
              ++checked;
              CHECK(std::abs(slopes[k] - differencedRate(dense, u, lambda, du, dlambda, j)) <= 1e-6 * bound);
            }
          }
          CHECK(checked >= 3);
        }
      }
    }
  }
}

TEST_CASE("stabilitySlopes through the tracer's ScaledProblem: the user's rates along the user direction, per "
          "stability unit",
          "[equilibrium]") {
  std::mt19937 rng(77);
  const Chain chain = slopeTestChain(rng, 30, 1e-3, 1e5);
  const double force = 1e5 * 1e-3;
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.1 * force, 2e-3), Eigen::Vector3d(force, 0, 0));
  const buckle::continuation::UnitScaling units(problem.scales());
  buckle::continuation::ScaledProblem scaled(problem, units);
  const int N = problem.dimension();
  Vector u = testing::randomState(rng, chain, N);
  u[N - 1] *= force;
  Vector duScaled = Vector::Constant(N, 0.3);
  duScaled[N - 1] = -0.2;
  const double lambda = 0.4, dlambdaScaled = 0.5;
  const auto& s = units.scales();
  const Vector du = duScaled.cwiseProduct(s.unknowns);
  Eigen::Vector2d values, slopes, scaledValues, scaledSlopes;
  REQUIRE(BoundProblem(problem).stabilityEigenvalues(u, lambda, 3, values));
  REQUIRE(BoundProblem(problem).stabilitySlopes(u, lambda, du, dlambdaScaled * s.parameter, 3, values, slopes));
  const Vector uScaled = u.cwiseQuotient(s.unknowns);
  REQUIRE(BoundProblem(scaled).stabilityEigenvalues(uScaled, lambda / s.parameter, 3, scaledValues));
  REQUIRE(BoundProblem(scaled).stabilitySlopes(uScaled, lambda / s.parameter, duScaled, dlambdaScaled, 3,
                                               scaledValues, scaledSlopes));
  for (int k = 0; k < 2; ++k) CHECK(scaledSlopes[k] == Approx(slopes[k] / s.stability).epsilon(1e-9));
}

TEST_CASE("stabilitySlopes is refused for short chains, a value that is no eigenvalue and rank-deficient held rows",
          "[equilibrium]") {
  std::mt19937 rng(5);
  const Vector du = Vector::Constant(41, 0.1);
  {
    // chains of n ≤ 4: the certified counting differences their tiny dense spectra
    const Chain shortChain = testing::randomChain(rng, 4);
    EquilibriumProblem problem(shortChain, EndCondition::clampedPinned(0.2, 0.3), Eigen::Vector3d(1, 0, 0));
    const Vector u = testing::randomState(rng, shortChain, 5);
    Eigen::Vector2d values, slopes;
    REQUIRE(BoundProblem(problem).stabilityEigenvalues(u, 0.1, 0, values));
    CHECK_FALSE(BoundProblem(problem).stabilitySlopes(u, 0.1, du.head(5), 1.0, 0, values, slopes));
  }
  const Chain chain = testing::randomChain(rng, 40);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.2, 0.3), Eigen::Vector3d(1, 0, 0));
  const Vector u = testing::randomState(rng, chain, 41);
  Eigen::Vector2d values, slopes;
  REQUIRE(BoundProblem(problem).stabilityEigenvalues(u, 0.1, 4, values));
  REQUIRE(BoundProblem(problem).stabilitySlopes(u, 0.1, du, 1.0, 4, values, slopes));
  // midway between two eigenvalues: inverse iteration finds no eigenvector there
  Eigen::Matrix<double, 1, 1> between, slope;
  between[0] = 0.5 * (values[0] + values[1]);
  CHECK_FALSE(BoundProblem(problem).stabilitySlopes(u, 0.1, du, 1.0, 4, between, slope));
  // x held on the straight chain: J_x = 0, ker C jumps along any direction
  EquilibriumProblem held(chain, EndCondition::heldPosition(chain.linkLengths().sum(), 0.0), Eigen::Vector3d(1, 0, 0));
  Eigen::Matrix<double, 1, 1> one, oneSlope;
  one[0] = 1.0;
  CHECK_FALSE(BoundProblem(held).stabilitySlopes(Vector::Zero(42), 0.0, Vector::Ones(42), 1.0, 0, one, oneSlope));
}

TEST_CASE("stabilitySlopes allocates nothing once its workspace exists", "[equilibrium][allocation]") {
#if BUCKLE_COUNT_MALLOC
  std::mt19937 rng(9);
  const Chain chain = testing::randomChain(rng, 60);
  EquilibriumProblem problem(chain, EndCondition::heldPosition(100.0, 3.0), Eigen::Vector3d(0.5, -0.2, 0));
  const BoundProblem bound(problem);  // one workspace for every call below
  const Vector u = testing::randomState(rng, chain, 62);
  const Vector du = Vector::Constant(62, 0.05);
  Eigen::Vector2d values, slopes;
  REQUIRE(bound.stabilityEigenvalues(u, 0.3, 10, values));
  REQUIRE(bound.stabilitySlopes(u, 0.3, du, 1.0, 10, values, slopes));  // warm-up
  const long before = buckle::testing::mallocCalls.load();
  bool ok = true;
  for (int k = 0; k < 5; ++k) ok = bound.stabilitySlopes(u, 0.3, du, 1.0 + k, 10, values, slopes) && ok;
  CHECK(ok);
  CHECK(buckle::testing::mallocCalls.load() - before == 0);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}
