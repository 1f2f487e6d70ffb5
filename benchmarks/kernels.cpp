// Kernel benchmarks over the chain length n: residual, Jacobian, stability (dense vs O(n)),
// linear solves (dense LU vs O(n) bordered), one KINSOL corrector solve, one continuation step
// of the core's tracer (with test functions), dense and with the chain's structured solver.
//
// Dense O(n³) kernels are capped at n = 1000 (n = 3000 would take seconds per call), the core's
// tracer with dense LU at n = 300. Structured kernels, and the tracer with the structured solver,
// run up to n = 10 000.
//
// Quick mode (CI): --benchmark_min_time=0.01 and BUCKLE_BENCH_MAX_N=100 in the environment.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <cstdlib>
#include <random>
#include <vector>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/problem.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/chain_structure.h"
#include "common.h"

using namespace buckle;
using namespace buckle::bench;

namespace {

long maxN() {
  const char* env = std::getenv("BUCKLE_BENCH_MAX_N");
  return env ? std::atol(env) : 1000000;
}

void sizes(benchmark::internal::Benchmark* b, long cap) {
  for (long n : {3L, 10L, 30L, 100L, 300L, 1000L, 3000L, 10000L})
    if (n <= cap && n <= maxN()) b->Arg(n);
}
void denseSizes(benchmark::internal::Benchmark* b) { sizes(b, 1000); }
void allSizes(benchmark::internal::Benchmark* b) { sizes(b, 3000); }
void structuredSizes(benchmark::internal::Benchmark* b) { sizes(b, 10000); }

void BM_Residual(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  // Two states in turn: the problem caches the kinematics and spring jets of the last q, and a
  // fixed u would time that cache hit (see BM_ResidualCached), not the evaluation.
  const Eigen::VectorXd us[2] = {bentState(n, 1), bentState(n, 1) * (1.0 + 1e-9)};
  Eigen::VectorXd F(n + 1);
  int k = 0;
  for (auto _ : state) {
    bound.residual(us[k ^= 1], -0.3, F);
    benchmark::DoNotOptimize(F.data());
  }
}
BENCHMARK(BM_Residual)->Apply(structuredSizes);

/// Residual at the q of the previous evaluation (KINSOL's F then J at one iterate, the
/// tracer's J then stability at one point): kinematics and spring jets come from the cache.
void BM_ResidualCached(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  Eigen::VectorXd F(n + 1);
  for (auto _ : state) {
    bound.residual(u, -0.3, F);
    benchmark::DoNotOptimize(F.data());
  }
}
BENCHMARK(BM_ResidualCached)->Apply(structuredSizes);

void BM_JacobianDense(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  const Eigen::VectorXd us[2] = {u, u * (1.0 + 1e-9)};  // two states in turn: no cache hit
  Eigen::MatrixXd Fu(n + 1, n + 1);
  Eigen::VectorXd Fl(n + 1);
  int k = 0;
  for (auto _ : state) {
    bound.jacobian(us[k ^= 1], -0.3, Fu, Fl);
    benchmark::DoNotOptimize(Fu.data());
  }
}
BENCHMARK(BM_JacobianDense)->Apply(allSizes);

void BM_TridiagonalAssemble(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  mechanics::ChainStructure ws(n);
  mechanics::ChainData data(p.chain());
  for (auto _ : state) {
    mechanics::forwardKinematics(p.chain(), u.head(n), data);
    mechanics::assemble(p.chain(), data, u.head(n), p.wrench(u, -0.3), ws);
    benchmark::DoNotOptimize(ws.diag.data());
  }
}
BENCHMARK(BM_TridiagonalAssemble)->Apply(structuredSizes);

/// EquilibriumProblem::stability(u, λ, lowestCount, …), dense (Problem's default) or structured.
/// u is fixed, so the problem's q-cache holds the kinematics and K_q after the first call (as in
/// the tracer, where the Jacobian at the same point precedes it).
void stabilityLoop(benchmark::State& state, bool structured, int lowestCount) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n, structured);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  continuation::StabilityInfo info;
  for (auto _ : state) {
    bound.stability(u, -0.3, lowestCount, info);
    benchmark::DoNotOptimize(info.negative);
  }
}

void BM_StabilityDense(benchmark::State& state) { stabilityLoop(state, false, 3); }
BENCHMARK(BM_StabilityDense)->Apply(denseSizes)->Unit(benchmark::kMicrosecond);

void BM_StabilityStructured(benchmark::State& state) { stabilityLoop(state, true, 3); }
BENCHMARK(BM_StabilityStructured)->Apply(structuredSizes)->Unit(benchmark::kMicrosecond);

/// lowestCount = 0: what the tracer asks at every point in bench_cases.
void BM_StabilityInertiaOnly(benchmark::State& state) { stabilityLoop(state, true, 0); }
BENCHMARK(BM_StabilityInertiaOnly)->Apply(structuredSizes)->Unit(benchmark::kMicrosecond);

/// Inertia only (two O(n) counts on the bordered tridiagonal), no eigenvalues.
void BM_InertiaStructured(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  mechanics::ChainStructure ws(n);
  mechanics::ChainData data(p.chain());
  Eigen::MatrixXd J(3, n);
  mechanics::forwardKinematics(p.chain(), u.head(n), data);
  mechanics::endJacobian(data, J);
  const Eigen::MatrixXd C = J.row(1);
  mechanics::assemble(p.chain(), data, u.head(n), p.wrench(u, -0.3), ws);
  for (auto _ : state) {
    auto in = mechanics::constrainedInertia(ws, C);
    benchmark::DoNotOptimize(in.negative);
  }
}
BENCHMARK(BM_InertiaStructured)->Apply(structuredSizes)->Unit(benchmark::kMicrosecond);

/// The Keller bordered matrix [[F_u, F_λ], [tᵀ]] ((N+1)², N = n + 1): dense LU and solve.
void BM_SolveDenseLU(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  const int N = n + 1;
  Eigen::MatrixXd A(N + 1, N + 1);
  Eigen::VectorXd Fl(N);
  bound.jacobian(u, -0.3, A.topLeftCorner(N, N), Fl);
  A.topRightCorner(N, 1) = Fl;
  A.bottomRows(1).setConstant(1.0 / std::sqrt(N + 1.0));
  Eigen::VectorXd rhs = Eigen::VectorXd::Ones(N + 1), x(N + 1);
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(N + 1);
  for (auto _ : state) {
    lu.compute(A);
    x = lu.solve(rhs);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(BM_SolveDenseLU)->Apply(denseSizes)->Unit(benchmark::kMicrosecond);

/// The same Keller system through the chain structure: assemble T + solveBordered (p = 2).
void BM_SolveStructured(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const Eigen::VectorXd u = bentState(n, 1);
  mechanics::ChainStructure ws(n);
  mechanics::ChainData data(p.chain());
  Eigen::MatrixXd J(3, n), V(n, 2), W(n, 2), D(2, 2);
  Eigen::VectorXd f = Eigen::VectorXd::Ones(n), g = Eigen::VectorXd::Ones(2), x(n), y(2);
  for (auto _ : state) {
    mechanics::forwardKinematics(p.chain(), u.head(n), data);
    mechanics::endJacobian(data, J);
    mechanics::assemble(p.chain(), data, u.head(n), p.wrench(u, -0.3), ws);
    V.col(0) = -J.row(1).transpose();
    V.col(1) = data.S;
    W.col(0) = V.col(0);
    W.col(1).setConstant(1.0 / std::sqrt(n + 2.0));
    D << 0.0, 0.0, 1.0 / std::sqrt(n + 2.0), 1.0 / std::sqrt(n + 2.0);
    mechanics::solveBordered(ws, V, W, D, f, g, x, y);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(BM_SolveStructured)->Apply(structuredSizes)->Unit(benchmark::kMicrosecond);

/// One KINSOL Keller corrector solve (dense LU inside), from a predictor 0.01 off the straight
/// trivial branch under tension (typically 2 Newton iterations).
void BM_CorrectorSolve(benchmark::State& state) {
  const int n = int(state.range(0));
  auto p = clampedPinned(n);
  const continuation::BoundProblem bound(p);  // one workspace, as a trace has
  const int N = n + 1;
  continuation::Corrector corrector(p);
  Eigen::VectorXd pred = Eigen::VectorXd::Zero(N + 1), t = Eigen::VectorXd::Zero(N + 1), x(N + 1);
  pred[N] = 0.5;
  for (int i = 0; i < n; ++i) pred[i] = 0.01 * std::sin(0.7 * i);
  t[N] = 1.0;
  int iters = 0;
  for (auto _ : state) {
    auto s = corrector.correct(pred, t, x);
    iters = s.iterations;
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["newton_it"] = iters;
}
BENCHMARK(BM_CorrectorSolve)->Apply(denseSizes)->Unit(benchmark::kMicrosecond);

/// The core's tracer, with test functions (fold, determinant sign, inertia) at every point: time
/// per continuation point, start-up amortised over 40 points. Clamped–pinned chain whose end is
/// held 0.02·n off the axis (so every joint bends and each step needs real Newton corrections),
/// λ = Fx from 0.1 up. Arg 1: 0 = dense LU, 1 = the chain's O(n) structured solver; both with
/// the inertia only (TracerOptions::lowestEigenvalues = 0), as a long continuation would run.
/// Arg 2: 0 = steps of 0.02 in arclength (about one Newton iteration per point), 1 = steps of
/// 1.0 (several iterations per point: the cost of a hard step).
// The tracer's points: `detect` false leaves the predictor–corrector alone (no stability, no
// special points, no boundaries), the tracer-only cost a whole run is compared with.
void tracerSteps(benchmark::State& state, bool detect) {
  const int n = int(state.range(0));
  const bool structured = state.range(1) != 0;
  const double step = state.range(2) != 0 ? 1.0 : 0.02;
  EquilibriumProblem p(Chain::uniform(n, mainSegment(2.25)), EndCondition::clampedPinned(0.0, 0.02 * n),
                       Eigen::Vector3d(1, 0, 0));
  continuation::TracerOptions o;
  o.maxPoints = 41;
  o.step.initialStep = step;
  o.step.maxStep = step;
  o.step.minStep = step / 1024;
  o.lambdaMax = 1000.0;
  o.detection.lowestEigenvalues = 0;
  if (!detect) {
    o.detection.folds = o.detection.branchPoints = o.detection.boundaries = o.detection.stability = false;
    o.detection.certifiedCounting = false;
  }
  o.linearAlgebra = structured ? continuation::TracerOptions::LinearAlgebra::Structured
                               : continuation::TracerOptions::LinearAlgebra::Dense;
  continuation::Tracer tracer(p, o);
  const Eigen::VectorXd u0 = Eigen::VectorXd::Zero(n + 1);
  size_t points = 0, iterations = 0;
  for (auto _ : state) {
    auto b = tracer.trace(u0, 0.1, continuation::InitialDirection::increasingLambda());
    if (b.points.size() < 41) state.SkipWithError(("tracer stopped early: " + b.stopMessage).c_str());
    points += b.points.size() - 1;
    for (std::size_t k = 1; k < b.points.size(); ++k) iterations += size_t(b.points[k].newtonIterations);
    benchmark::DoNotOptimize(b.points.data());
  }
  state.counters["per_point"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["newton_it"] = double(iterations) / double(std::max<size_t>(1, points));
}
void BM_TracerStep(benchmark::State& state) { tracerSteps(state, true); }
void BM_TracerOnly(benchmark::State& state) { tracerSteps(state, false); }
void tracerArgs(benchmark::internal::Benchmark* b) {
  for (long n : {3L, 10L, 30L, 100L, 300L, 1000L, 3000L, 10000L}) {
    if (n > maxN()) continue;
    if (n <= 300) b->Args({n, 0, 0});
    b->Args({n, 1, 0});
    b->Args({n, 1, 1});
  }
}
BENCHMARK(BM_TracerStep)->Apply(tracerArgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TracerOnly)->Apply(tracerArgs)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
