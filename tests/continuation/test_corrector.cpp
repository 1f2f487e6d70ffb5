#include "buckle/continuation/corrector.h"

#include "toy_problems.h"

#include <kinsol/kinsol.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

TEST_CASE("Keller corrector lands on the closed-form intersection", "[corrector]") {
  toys::Circle circle;
  Corrector corrector(circle);
  // Hyperplane u + λ = 1.4 meets the unit circle at (0.8, 0.6) and (0.6, 0.8).
  Vector predictor(2), tangent(2), x(2);
  predictor << 0.75, 0.65;
  tangent << 1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0);
  const CorrectorSummary summary = corrector.correct(predictor, tangent, x);
  REQUIRE(summary.converged);
  CHECK(std::string(summary.flagName) == "KIN_SUCCESS");
  CHECK(std::abs(x[0] - 0.8) < 1e-12);
  CHECK(std::abs(x[1] - 0.6) < 1e-12);
  CHECK(summary.iterations >= 2);
  CHECK(summary.iterations <= 6);
  CHECK(summary.residualNorm <= 1e-10);
  CHECK(summary.lastStepNorm > 0.0);
  CHECK(summary.lastStepNorm < 1e-4);
  CHECK(summary.contraction > 0.0);
  CHECK(summary.contraction < 0.5);  // quadratic convergence
}

TEST_CASE("Corrector at fixed lambda polishes a root", "[corrector]") {
  toys::Circle circle;
  Corrector corrector(circle);
  Vector u0(1), u(1);
  u0 << 0.95;
  const CorrectorSummary summary = corrector.solveAtFixedParameter(u0, 0.6, u);
  REQUIRE(summary.converged);
  CHECK(std::abs(u[0] - 0.8) < 1e-12);
  // Reuse of the same KINSOL instance: many solves, each independent of the previous one.
  CorrectorOptions tight;
  tight.tolerance = 1e-13;
  corrector.setOptions(tight);
  for (int k = 1; k <= 50; ++k) {
    const double lambda = 0.9 * std::sin(0.1 * k);
    u0 << 0.9;
    const CorrectorSummary again = corrector.solveAtFixedParameter(u0, lambda, u);
    REQUIRE(again.converged);
    CHECK(std::abs(u[0] - std::sqrt(1.0 - lambda * lambda)) < 1e-12);
  }
}

TEST_CASE("Corrector with fixed coordinate keeps it exactly", "[corrector]") {
  toys::Circle circle;
  Corrector corrector(circle);
  Vector predictor(2), x(2);
  predictor << 0.3, 0.7;  // hold u = 0.3
  const CorrectorSummary summary = corrector.solveWithFixedCoordinate(predictor, 0, x);
  REQUIRE(summary.converged);
  CHECK(x[0] == 0.3);
  CHECK(std::abs(x[1] - std::sqrt(1.0 - 0.09)) < 1e-12);
}

TEST_CASE("Corrector reports KINSOL failures by name", "[corrector]") {
  SECTION("predictor refused by the problem") {
    toys::LineWithDomain line(0.3);
    Corrector corrector(line);
    Vector predictor(2), tangent(2), x(2);
    predictor << 0.5, 0.5;
    tangent << 1.0, 0.0;
    const CorrectorSummary summary = corrector.correct(predictor, tangent, x);
    CHECK_FALSE(summary.converged);
    CHECK(std::string(summary.flagName) == "KIN_FIRST_SYSFUNC_ERR");
    CHECK(summary.refusedPoint);
  }
  SECTION("iteration limit") {
    toys::Circle circle;
    CorrectorOptions options;
    options.maxIterations = 1;
    Corrector corrector(circle, options);
    Vector u0(1), u(1);
    u0 << 5.0;
    const CorrectorSummary summary = corrector.solveAtFixedParameter(u0, 0.6, u);
    CHECK_FALSE(summary.converged);
    CHECK(std::string(summary.flagName) == "KIN_MAXITER_REACHED");
    CHECK(summary.iterations == 1);
  }
  SECTION("no real root: singular or non-converging") {
    toys::Circle circle;
    Corrector corrector(circle);
    Vector u0(1), u(1);
    u0 << 0.5;
    const CorrectorSummary summary = corrector.solveAtFixedParameter(u0, 1.5, u);  // u² = −1.25
    CHECK_FALSE(summary.converged);
    CHECK(summary.flag < 0);
  }
}

TEST_CASE("Corrector line search reaches a root from farther away", "[corrector]") {
  toys::CubicFold cubic;
  CorrectorOptions options;
  options.lineSearch = true;
  options.maxIterations = 50;
  Corrector corrector(cubic, options);
  Vector u0(1), u(1);
  u0 << 3.0;
  const CorrectorSummary summary = corrector.solveAtFixedParameter(u0, 0.0, u);  // roots 0, ±√3
  REQUIRE(summary.converged);
  Vector F(1);
  BoundProblem(cubic).residual(u, 0.0, F);
  CHECK(std::abs(F[0]) < 1e-10);
}

TEST_CASE("CorrectorOptions::IsValid names the bad option", "[corrector]") {
  std::string why;
  CorrectorOptions options;
  CHECK(options.IsValid(&why));
  options.tolerance = -1.0;
  CHECK_FALSE(options.IsValid(&why));
  CHECK_THAT(why, Contains("corrector.tolerance"));
  options = CorrectorOptions();
  options.maxIterations = 0;
  CHECK_FALSE(options.IsValid(&why));
  CHECK_THAT(why, Contains("maxIterations"));
  options = CorrectorOptions();
  options.stepTolerance = std::nan("");
  CHECK_FALSE(options.IsValid(&why));
  CHECK_THAT(why, Contains("stepTolerance"));
}

namespace {
// A circle whose residual throws once u passes a threshold: the exception must come out of
// correct() intact (not be lost, and not unwind through KINSOL's C frames).
struct ThrowingCircle final : toys::Circle {
  double limit = 0.7;
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
    if (u[0] > limit) throw std::domain_error("residual refused to evaluate past the limit");
    return toys::Circle::residual(ws, u, lambda, F);
  }
};
}  // namespace

TEST_CASE("Corrector rethrows an exception thrown inside a KINSOL callback", "[corrector]") {
  ThrowingCircle circle;
  Corrector corrector(circle);
  Vector predictor(2), tangent(2), x(2);
  predictor << 0.75, 0.65;
  tangent << 1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0);
  CHECK_THROWS_WITH(corrector.correct(predictor, tangent, x), Contains("past the limit"));
  // The same corrector is usable afterwards: the stored exception does not leak into the next solve.
  circle.limit = 10.0;
  const CorrectorSummary summary = corrector.correct(predictor, tangent, x);
  REQUIRE(summary.converged);
  CHECK(std::abs(x[0] - 0.8) < 1e-12);
}

namespace {
// KINSOL with its own dense matrix and linear solver (SUNLinSol_Dense) on the Keller system, with
// the Corrector's options and the same arithmetic for G and its Jacobian: the reference the
// Corrector's DenseLU-based linear solver must reproduce.
struct ReferenceKeller {
  Problem *problem;
  Vector predictor, tangent;
  static int system(N_Vector xv, N_Vector gv, void *self) {
    auto &r = *static_cast<ReferenceKeller *>(self);
    const int m = static_cast<int>(r.predictor.size()), n = m - 1;
    Eigen::Map<const Vector> x(N_VGetArrayPointer(xv), m);
    Eigen::Map<Vector> g(N_VGetArrayPointer(gv), m);
    if (!BoundProblem(*r.problem).residual(x.head(n), x[n], g.head(n))) return 1;
    g[n] = r.tangent.dot(x - r.predictor);
    return 0;
  }
  static int jacobian(N_Vector xv, N_Vector, SUNMatrix J, void *self, N_Vector, N_Vector) {
    auto &r = *static_cast<ReferenceKeller *>(self);
    const int m = static_cast<int>(r.predictor.size()), n = m - 1;
    Eigen::Map<const Vector> x(N_VGetArrayPointer(xv), m);
    Eigen::Map<Matrix> A(SUNDenseMatrix_Data(J), m, m);
    A.setZero();
    if (!BoundProblem(*r.problem).jacobian(x.head(n), x[n], A.topLeftCorner(n, n), A.col(n).head(n))) return -1;
    A.row(n) = r.tangent.transpose();
    return 0;
  }
  // Solves from the predictor; x, iterations and ‖G‖ at the end.
  int solve(const CorrectorOptions &options, Vector &x, long &iterations, double &fnorm) {
    const sunindextype m = predictor.size();
    SunContextPtr context = makeSunContext();
    NVectorPtr xv = makeSerialVector(m, context.get()), scale = makeSerialVector(m, context.get());
    N_VConst(1.0, scale.get());
    SunMatrixPtr J = makeDenseMatrix(m, m, context.get());
    SunLinearSolverPtr ls = makeDenseLinearSolver(xv.get(), J.get(), context.get());
    KinsolMemoryPtr kinsol = makeKinsolMemory(context.get());
    void *mem = kinsol.get();
    KINInit(mem, &ReferenceKeller::system, xv.get());
    KINSetUserData(mem, this);
    KINSetLinearSolver(mem, ls.get(), J.get());
    KINSetJacFn(mem, &ReferenceKeller::jacobian);
    KINSetMaxSetupCalls(mem, 1);
    KINSetFuncNormTol(mem, options.tolerance);
    KINSetScaledStepTol(mem, options.stepTolerance);
    KINSetNumMaxIters(mem, options.maxIterations);
    KINSetMaxNewtonStep(mem, 1e100);
    Eigen::Map<Vector>(N_VGetArrayPointer(xv.get()), m) = predictor;
    const int flag = KINSol(mem, xv.get(), KIN_NONE, scale.get(), scale.get());
    KINGetNumNonlinSolvIters(mem, &iterations);
    KINGetFuncNorm(mem, &fnorm);
    x = Eigen::Map<const Vector>(N_VGetArrayPointer(xv.get()), m);
    return flag;
  }
};

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST_CASE("Corrector's dense linear solver: the same Newton iterates as KINSOL's SUNLinSol_Dense, bit for bit",
          "[corrector]") {
  toys::Bratu bratu(6);
  toys::CurvedPitchforks pitchforks(0.7);
  toys::CubicFold cubic;
  struct Case {
    Problem *problem;
    Vector predictor, tangent;
  };
  std::vector<Case> cases;
  {
    const int n = bratu.dimension();
    Vector p = Vector::LinSpaced(n + 1, 0.2, 0.5), t = Vector::LinSpaced(n + 1, 0.1, 1.0);
    p[n] = 2.0;
    cases.push_back({&bratu, p, t.normalized()});
    Vector t2 = Vector::Zero(n + 1);
    t2[n] = 1.0;
    cases.push_back({&bratu, p, t2});
  }
  for (double lambda : {0.9, 1.4}) {
    Vector p(3), t(3);
    p << 0.4, -0.2, lambda;
    t << 0.3, 0.1, 1.0;
    cases.push_back({&pitchforks, p, t.normalized()});
  }
  {
    Vector p(2), t(2);
    p << 1.2, -0.5;
    t << 0.6, 0.8;
    cases.push_back({&cubic, p, t});
  }
  int converged = 0;
  for (const Case &c : cases) {
    CorrectorOptions options;
    options.tolerance = 1e-13;
    Corrector corrector(*c.problem, options);
    Vector x(c.predictor.size()), xr;
    const CorrectorSummary summary = corrector.correct(c.predictor, c.tangent, x);
    ReferenceKeller reference{c.problem, c.predictor, c.tangent};
    long iterations = 0;
    double fnorm = 0.0;
    const int flag = reference.solve(options, xr, iterations, fnorm);
    CHECK(summary.flag == flag);
    CHECK(summary.iterations == iterations);
    CHECK(sameBits(summary.residualNorm, fnorm));
    for (Eigen::Index i = 0; i < x.size(); ++i) CHECK(sameBits(x[i], xr[i]));
    INFO("case " << converged);
    CHECK(summary.converged);
    ++converged;
  }
}

TEST_CASE("Corrector's lean Newton: KINSOL's outcome bit for bit on every path with dense and bordered solvers", "[corrector]") {
  // CorrectorOptions::leanNewton runs KINSOL's full-Newton iteration itself where it converges
  // plainly and hands every other outcome to KINSOL. Against KINSOL alone (leanNewton = false),
  // from many predictors, the flag, the counts, the norms and the iterate must agree to the bit:
  // converged runs (lean), the initial guess already a root (lean), and the paths it hands over
  // (the iteration limit, refused points, no root, a tiny maximum step).
  toys::Bratu bratu(5);
  toys::CurvedPitchforks pitchforks(0.7);
  toys::CubicFold cubic;
  toys::Circle circle;
  toys::LineWithDomain line(0.3);
  std::vector<Problem *> problems{&bratu, &pitchforks, &cubic, &circle, &line};
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  std::map<std::string, int> flags;
  int lean = 0, handed = 0;
  for (Problem *problem : problems) {
    const int n = problem->dimension();
    DenseBorderedSolver bordered(*problem);
    for (int trial = 0; trial < 40; ++trial) {
      CorrectorOptions options;
      options.maxIterations = trial % 7 == 3 ? 1 : 10;
      if (trial % 11 == 5) options.maxNewtonStep = 1e-3;
      if (trial % 13 == 7) options.tolerance = 1e-300;  // only the step tolerance can stop it
      const bool useBordered = trial % 2 == 1;
      Vector predictor(n + 1), tangent(n + 1);
      for (int i = 0; i <= n; ++i) {
        predictor[i] = 0.5 * W(rng);
        tangent[i] = W(rng);
      }
      if (problem == &circle) predictor[n] = 0.6 + 0.3 * W(rng);
      if (problem == &bratu) predictor[n] = 1.0 + W(rng);
      tangent.normalize();
      Vector xLean(n + 1), xKinsol(n + 1);
      options.leanNewton = true;
      CorrectorOptions kinsolOnly = options;
      kinsolOnly.leanNewton = false;
      Corrector a(*problem, options, useBordered ? &bordered : nullptr);
      Corrector b(*problem, kinsolOnly, useBordered ? &bordered : nullptr);
      const CorrectorSummary sa = a.correct(predictor, tangent, xLean);
      const CorrectorSummary sb = b.correct(predictor, tangent, xKinsol);
      INFO("trial " << trial << ", flag " << sb.flagName);
      CHECK(sa.flag == sb.flag);
      CHECK(std::string(sa.flagName) == sb.flagName);
      CHECK(sa.converged == sb.converged);
      CHECK(sa.iterations == sb.iterations);
      CHECK(sa.residualEvaluations == sb.residualEvaluations);
      CHECK(sa.refusedPoint == sb.refusedPoint);
      CHECK(sa.message == sb.message);
      CHECK(sameBits(sa.residualNorm, sb.residualNorm));
      CHECK(sameBits(sa.lastStepNorm, sb.lastStepNorm));
      CHECK(sameBits(sa.contraction, sb.contraction));
      for (int i = 0; i <= n; ++i) CHECK(sameBits(xLean[i], xKinsol[i]));
      ++flags[sb.flagName];
      (sb.flag == KIN_SUCCESS || sb.flag == KIN_INITIAL_GUESS_OK ? lean : handed)++;
      // The root itself as predictor: KINSOL's initial-guess exit, taken by the lean path too.
      if (sb.flag == KIN_SUCCESS && sb.residualNorm < 1e-14) {
        Vector again(n + 1), againKinsol(n + 1);
        const CorrectorSummary ra = a.correct(xKinsol, tangent, again);
        const CorrectorSummary rb = b.correct(xKinsol, tangent, againKinsol);
        CHECK(ra.flag == rb.flag);
        CHECK(ra.iterations == rb.iterations);
        CHECK(sameBits(ra.residualNorm, rb.residualNorm));
        for (int i = 0; i <= n; ++i) CHECK(sameBits(again[i], againKinsol[i]));
        ++flags[std::string("again ") + rb.flagName];
      }
    }
  }
  std::string seen;
  for (const auto &[name, count] : flags) seen += name + ": " + std::to_string(count) + "; ";
  INFO(seen);
  // Every kind of outcome occurred, so each path was compared.
  CHECK(flags["KIN_SUCCESS"] > 20);
  CHECK(flags["again KIN_INITIAL_GUESS_OK"] > 5);
  CHECK(flags["KIN_MAXITER_REACHED"] > 0);
  CHECK(flags["KIN_FIRST_SYSFUNC_ERR"] > 0);
  CHECK(lean > 0);
  CHECK(handed > 0);
}

TEST_CASE("Corrector: a residual whose rounding floor lies above the tolerance converges within stagnationFactor of it",
          "[corrector]") {
  // F = u − λ + A·sin(1e12·u): the sine stands for the rounding noise of a long sum (its slope
  // left out of the Jacobian, as rounding is), amplitude A. Newton's steps chase the noise, never
  // smaller than the step tolerance, until the iterations are used up (KIN_MAXITER_REACHED).
  class Noisy : public Problem {
   public:
    explicit Noisy(double amplitude) : amplitude_(amplitude) {}
    int dimension() const override { return 1; }
    bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
      F[0] = u[0] - lambda + amplitude_ * std::sin(1e12 * u[0]);
      return true;
    }
    bool jacobian(ProblemWorkspace &, ConstVectorRef, double, MatrixRef Fu, VectorRef Fl) const override {
      Fu(0, 0) = 1.0;
      Fl[0] = -1.0;
      return true;
    }

   private:
    double amplitude_;
  };
  CorrectorOptions o;  // tolerance 1e-10, stagnationFactor 100
  for (double amplitude : {1e-9, 1e-7}) {
    Noisy problem(amplitude);
    Corrector corrector(problem, o);
    Vector u(1), guess(1);
    guess << 0.3;
    const CorrectorSummary s = corrector.solveAtFixedParameter(guess, 0.7, u);
    INFO("amplitude " << amplitude << ": " << s.flagName << ", residual " << s.residualNorm);
    CHECK(std::string(s.flagName) == "KIN_MAXITER_REACHED");
    CHECK(s.residualNorm > o.tolerance);  // the floor: never below the tolerance
    if (amplitude * 10.0 <= o.stagnationFactor * o.tolerance) {
      CHECK(s.converged);
      CHECK(s.residualNorm <= o.stagnationFactor * o.tolerance);
      CHECK(std::abs(u[0] - 0.7) <= 2.0 * amplitude);
    } else {
      CHECK_FALSE(s.converged);  // a floor above the factor is a failure, as before
    }
  }
}
