#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/chain_solver.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/linear_buckling.h"

#include "../malloc_counter_definition.h"
#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;
using buckle::continuation::DenseBorderedSolver;
using buckle::continuation::Factorization;

namespace {

using testing::randomChain;

EndCondition allHeld(double x, double y, double phi) {
  EndCondition e;
  e.control = {Control::Held, Control::Held, Control::Held};
  e.value = Eigen::Vector3d(x, y, phi);
  return e;
}

Chain uniformChain(int n) {
  SegmentParameters p;
  p.a1 = p.a2 = 0.5;
  p.b1 = p.b2 = 1.0;
  p.k1 = p.k2 = 1.0;
  p.L1_0 = p.L2_0 = 2.25;
  return Chain(std::vector<SegmentParameters>(size_t(n), p));
}

/// Factor and solve A(c) x = b with the structured and the dense solver; same determinant sign,
/// solutions within `tolerance` (relative). Returns whether the structured side used its fallback.
bool agreesWithDense(EquilibriumProblem& problem, const Vector& u, double lambda, const Vector& c, const Vector& b,
                     double tolerance) {
  const auto fastWorkspace = problem.createWorkspace();
  ChainBorderedSolver fast(problem, *fastWorkspace);
  DenseBorderedSolver dense(problem);
  REQUIRE(dense.factor(u, lambda, c) == Factorization::Regular);
  REQUIRE(fast.factor(u, lambda, c) == Factorization::Regular);
  CHECK(fast.determinantSign() == dense.determinantSign());
  CHECK(std::abs(fast.logAbsDeterminant() - dense.logAbsDeterminant()) <=
        1e-9 * std::max(1.0, std::abs(dense.logAbsDeterminant())));
  const int N = problem.dimension();
  Vector xf(N + 1), xd(N + 1);
  REQUIRE(fast.solve(b, xf));
  REQUIRE(dense.solve(b, xd));
  CHECK((xf - xd).norm() <= tolerance * xd.norm());
  return fast.usedDenseFallback();
}

}  // namespace

TEST_CASE("ChainBorderedSolver equals the dense LU of the same bordered Jacobian (m = 0..3 held)", "[chain_solver]") {
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.4, 0.4);
  for (int n : {1, 3, 17, 60}) {
    const Chain chain = randomChain(rng, n);
    const std::vector<std::pair<std::string, EndCondition>> ends = {
        {"free", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng)))},
        {"clamped-pinned", EndCondition::clampedPinned(W(rng), 0.1 * W(rng))},
        {"held position", EndCondition::heldPosition(0.5 * n + W(rng), W(rng))},
        {"all held", allHeld(0.5 * n, W(rng), W(rng))}};
    for (const auto& [name, end] : ends) {
      if (end.heldCount() > n) continue;  // more held coordinates than joints: singular by construction
      INFO("n = " << n << ", " << name);
      EquilibriumProblem problem(chain, end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      const int N = problem.dimension();
      Vector u(N), c(N + 1), b(N + 1);
      for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : W(rng);
      for (int i = 0; i <= N; ++i) c[i] = W(rng), b[i] = W(rng);
      const double lambda = W(rng);
      CHECK_FALSE(agreesWithDense(problem, u, lambda, c, b, 1e-10));
    }
  }
}

TEST_CASE("ChainBorderedSolver with body loads (weight, point loads growing with lambda) equals the dense LU",
          "[chain_solver][body_loads]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.4, 0.4);
  for (int n : {3, 40}) {
    const Chain chain = randomChain(rng, n);
    BodyLoads body = BodyLoads::weight(chain, InertiaData::uniformRods(chain, 0.7), {W(rng), W(rng)}, {W(rng), W(rng)});
    body.points.push_back({n / 2 + 1, {W(rng), W(rng)}, {W(rng), W(rng)}});
    for (const EndCondition& end : {EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), 0.0)),
                                    EndCondition::clampedPinned(W(rng), 0.1 * W(rng))}) {
      INFO("n = " << n << ", held " << end.heldCount());
      EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero(), {}, {}, body);
      const int N = problem.dimension();
      Vector u(N), c(N + 1), b(N + 1);
      for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : W(rng);
      for (int i = 0; i <= N; ++i) c[i] = W(rng), b[i] = W(rng);
      CHECK_FALSE(agreesWithDense(problem, u, W(rng), c, b, 1e-10));
    }
  }
}

TEST_CASE("ChainBorderedSolver::factorGeneral equals the dense LU with the same borders (k = 1, 2, transposed)",
          "[chain_solver]") {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.4, 0.4);
  for (int n : {3, 17, 60}) {
    const Chain chain = randomChain(rng, n);
    const std::vector<std::pair<std::string, EndCondition>> ends = {
        {"free", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng)))},
        {"clamped-pinned", EndCondition::clampedPinned(W(rng), 0.1 * W(rng))},
        {"all held", allHeld(0.5 * n, W(rng), W(rng))}};
    for (const auto& [name, end] : ends) {
      EquilibriumProblem problem(chain, end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      const int N = problem.dimension();
      const auto fastWorkspace = problem.createWorkspace();
      ChainBorderedSolver fast(problem, *fastWorkspace);
      DenseBorderedSolver dense(problem);
      Vector u(N);
      for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : W(rng);
      const double lambda = W(rng);
      for (int k : {1, 2}) {
        for (bool transposed : {false, true}) {
          INFO("n = " << n << ", " << name << ", k = " << k << ", transposed " << transposed);
          REQUIRE(fast.maxGeneralBorder() >= k);
          Matrix B(N, k), C(N, k), D(k, k);
          for (int j = 0; j < k; ++j) {
            for (int i = 0; i < N; ++i) B(i, j) = W(rng), C(i, j) = W(rng);
            for (int i = 0; i < k; ++i) D(i, j) = W(rng);
          }
          Vector b(N + k), xf(N + k), xd(N + k);
          for (int i = 0; i < N + k; ++i) b[i] = W(rng);
          REQUIRE(dense.factorGeneral(u, lambda, B, C, D, transposed) == Factorization::Regular);
          REQUIRE(fast.factorGeneral(u, lambda, B, C, D, transposed) == Factorization::Regular);
          CHECK_FALSE(fast.usedDenseFallback());
          CHECK(fast.determinantSign() == dense.determinantSign());
          REQUIRE(dense.solve(b, xd));
          REQUIRE(fast.solve(b, xf));
          CHECK((xf - xd).norm() <= 1e-9 * xd.norm());
        }
      }
      // factor() afterwards solves A(c) again, with A(c)'s determinant.
      Vector c(N + 1), b(N + 1), xf(N + 1), xd(N + 1);
      for (int i = 0; i <= N; ++i) c[i] = W(rng), b[i] = W(rng);
      INFO("n = " << n << ", " << name << ": A(c) after general borders");
      REQUIRE(fast.factor(u, lambda, c) == Factorization::Regular);
      REQUIRE(dense.factor(u, lambda, c) == Factorization::Regular);
      CHECK(fast.determinantSign() == dense.determinantSign());
      REQUIRE(fast.solve(b, xf));
      REQUIRE(dense.solve(b, xd));
      CHECK((xf - xd).norm() <= 1e-10 * xd.norm());
    }
  }
}

TEST_CASE("ChainBorderedSolver near a singular H (an unconstrained critical load) stays accurate", "[chain_solver]") {
  // Clamped-pinned straight chain: the bordered Jacobian is regular at the free end's critical
  // loads, where H = K_q − K_g itself is singular and block elimination is at its worst.
  const int n = 12;
  const Chain chain = uniformChain(n);
  const Vector q0 = Vector::Zero(n);
  const LinearBucklingResult freeModes = linearBuckling(chain, q0, EndCondition::freeEnd());
  REQUIRE(!freeModes.modes.empty());
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const int N = problem.dimension();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  Vector c(N + 1), b(N + 1);
  for (int i = 0; i <= N; ++i) c[i] = W(rng), b[i] = W(rng);
  for (double relative : {1e-3, 1e-8, 1e-12, 0.0}) {
    const double lambda = freeModes.modes.front().lambda * (1.0 + relative);
    INFO("lambda = free critical load x (1 + " << relative << ")");
    const bool fallback = agreesWithDense(problem, Vector::Zero(N), lambda, c, b, 1e-8);
    // Block elimination itself serves to 1e-8 from the singular H (and is as accurate as dense
    // there); closer, its Schur complement is numerically singular and the dense fallback
    // (n + m <= kDenseFallback) takes over.
    if (relative >= 1e-8) CHECK_FALSE(fallback);
  }
}

TEST_CASE("Tracer on the chain: structured and dense give the same branch and branch points", "[chain_solver]") {
  const int n = 30;
  const Chain chain = uniformChain(n);
  EquilibriumProblem structuredProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumProblem denseProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  buckle::continuation::TracerOptions options;
  options.step.maxStep = 0.05;
  options.lambdaMin = -0.6;
  options.maxPoints = 400;
  options.detection.lowestEigenvalues = 0;  // inertia only: the branch-point test needs nothing more
  options.linearAlgebra = buckle::continuation::TracerOptions::LinearAlgebra::Structured;
  buckle::continuation::Tracer structured(structuredProblem, options);
  options.linearAlgebra = buckle::continuation::TracerOptions::LinearAlgebra::Dense;
  buckle::continuation::Tracer dense(denseProblem, options);
  REQUIRE(structured.structured());
  const Vector u0 = Vector::Zero(structuredProblem.dimension());
  using buckle::continuation::InitialDirection;
  const auto a = structured.trace(u0, 0.0, InitialDirection::decreasingLambda());
  const auto b = dense.trace(u0, 0.0, InitialDirection::decreasingLambda());
  CHECK(a.stopReason == b.stopReason);
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t k = 0; k < a.points.size(); ++k) {
    CHECK(a.points[k].stability.negative == b.points[k].stability.negative);
    CHECK(a.points[k].determinantSign == b.points[k].determinantSign);
  }
  // Every clamped-pinned critical load in the range, found once, as accurately as dense.
  const LinearBucklingResult modes = linearBuckling(chain, Vector::Zero(n), EndCondition::clampedPinned(0.0));
  std::vector<double> expected;
  for (const BucklingMode& m : modes.modes)
    if (m.lambda < 0.0 && m.lambda > -0.6) expected.push_back(m.lambda);
  REQUIRE(!expected.empty());
  auto branchPoints = [](const buckle::continuation::Branch& br) {
    std::vector<double> l;
    for (const auto& sp : br.specialPoints)
      if (sp.type == buckle::continuation::SpecialPointType::BranchPoint) l.push_back(sp.lambda);
    return l;
  };
  const std::vector<double> fa = branchPoints(a), fb = branchPoints(b);
  REQUIRE(fa.size() == expected.size());
  REQUIRE(fb.size() == expected.size());
  std::sort(expected.begin(), expected.end(), std::greater<double>());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    CHECK(std::abs(fa[k] - expected[k]) <= 1e-10 * std::abs(expected[k]));
    CHECK(std::abs(fa[k] - fb[k]) <= 1e-10 * std::abs(expected[k]));
  }
}

#if BUCKLE_COUNT_MALLOC
namespace {
// Ten corrector steps of λ0 + k·dλ on the problem's structured solver (inside KINSOL, custom
// SUNLinearSolver) after one warm-up solve: the heap calls they make.
long correctorAllocations(EquilibriumProblem& problem, double lambda0, double dlambda) {
  const int N = problem.dimension();
  const buckle::continuation::BoundProblem solverBound(problem);  // outlives the solver
  auto solver = solverBound.makeStructuredSolver();
  REQUIRE(solver != nullptr);
  buckle::continuation::Corrector corrector(problem, {}, solver.get());
  Vector u0 = Vector::Zero(N), u(N), x(N + 1), predictor(N + 1), tangent = Vector::Zero(N + 1);
  REQUIRE(corrector.solveAtFixedParameter(u0, lambda0, u).converged);  // warm-up
  tangent[N] = 1.0;
  const long before = buckle::testing::mallocCalls.load();
  int iterations = 0;
  bool converged = true;
  for (int k = 0; k < 10; ++k) {
    predictor.head(N) = u;
    predictor[N] = lambda0 + dlambda * (k + 1);
    const auto summary = corrector.correct(predictor, tangent, x);
    converged = converged && summary.converged;
    iterations += summary.iterations;
    u = x.head(N);
  }
  const long after = buckle::testing::mallocCalls.load();
  CHECK(converged);
  CHECK(iterations >= 10);
  return after - before;
}
}  // namespace
#endif

TEST_CASE("Corrector on the chain's structured solver allocates nothing after construction", "[chain_solver]") {
#if BUCKLE_COUNT_MALLOC
  // Clamped–pinned, end held off the axis: every Newton iterate factors and solves through
  // ChainBorderedSolver inside KINSOL (custom SUNLinearSolver).
  const int n = 60;
  EquilibriumProblem problem(uniformChain(n), EndCondition::clampedPinned(0.0, 0.5), Eigen::Vector3d(1, 0, 0));
  CHECK(correctorAllocations(problem, 0.2, 0.05) == 0);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}

TEST_CASE("Corrector along a control path (dL0, end held) allocates nothing after construction", "[chain_solver]") {
#if BUCKLE_COUNT_MALLOC
  // λ moves the free lengths: every iterate re-evaluates the springs at (q, λ) (the cache's key)
  // and the structured solver's F_λ border carries ∂²E/∂q∂λ.
  const int n = 60;
  EquilibriumProblem problem(uniformChain(n), EndCondition::clampedPinned(0.0, 0.5), Eigen::Vector3d::Zero(), {},
                             ControlDirection::named(n, ControlInput::dL0));
  CHECK(correctorAllocations(problem, 0.02, 0.005) == 0);
#else
  SUCCEED("malloc interposition is disabled under AddressSanitizer and ThreadSanitizer");
#endif
}
