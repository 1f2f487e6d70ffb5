// A const Problem evaluated in workspaces its callers own (problem.h, bound_problem.h): the
// caches of one workspace are never another's, so one problem can be traced from two threads.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include "buckle/continuation/bound_problem.h"
#include "buckle/continuation/tracer.h"
#include "toy_problems.h"

using namespace buckle::continuation;

namespace {

/// Bratu (toy_problems.h) with e^u cached in its workspace for the last u evaluated (bitwise
/// key), shared by the residual and the Jacobian, as EquilibriumProblem keeps its q-cache. Each
/// workspace counts the evaluations of e^u it made (its cache misses).
class CachedBratu final : public Problem {
 public:
  explicit CachedBratu(int n) : n_(n), h_(1.0 / (n + 1)) {}

  struct Workspace : ProblemWorkspace {
    explicit Workspace(int n) : key(Vector::Constant(n, std::numeric_limits<double>::quiet_NaN())), expu(n) {}
    Vector key, expu;
    long misses = 0;
  };
  std::unique_ptr<ProblemWorkspace> createWorkspace() const override { return std::make_unique<Workspace>(n_); }

  int dimension() const override { return n_; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
    const Vector &e = expOf(workspaceAs<Workspace>(ws), u);
    for (int i = 0; i < n_; ++i) {
      const double left = i > 0 ? u[i - 1] : 0.0, right = i + 1 < n_ ? u[i + 1] : 0.0;
      F[i] = (left - 2.0 * u[i] + right) / (h_ * h_) + lambda * e[i];
    }
    return true;
  }
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    const Vector &e = expOf(workspaceAs<Workspace>(ws), u);
    Fu.setZero();
    for (int i = 0; i < n_; ++i) {
      Fu(i, i) = -2.0 / (h_ * h_) + lambda * e[i];
      if (i > 0) Fu(i, i - 1) = 1.0 / (h_ * h_);
      if (i + 1 < n_) Fu(i, i + 1) = 1.0 / (h_ * h_);
      Fl[i] = e[i];
    }
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return toys::negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  const Vector &expOf(Workspace &w, ConstVectorRef u) const {
    if (std::memcmp(u.data(), w.key.data(), sizeof(double) * size_t(n_)) != 0) {
      w.key = u;
      for (int i = 0; i < n_; ++i) w.expu[i] = std::exp(u[i]);
      ++w.misses;
    }
    return w.expu;
  }

  int n_;
  double h_;
};

/// Bit for bit the same branch: every point, its stability and every special point.
void requireIdentical(const Branch &a, const Branch &b) {
  CHECK(a.stopReason == b.stopReason);
  REQUIRE(a.points.size() == b.points.size());
  for (size_t k = 0; k < a.points.size(); ++k) {
    CHECK(a.points[k].u == b.points[k].u);
    CHECK(a.points[k].lambda == b.points[k].lambda);
    CHECK(a.points[k].tangent == b.points[k].tangent);
    CHECK(a.points[k].stability.negative == b.points[k].stability.negative);
  }
  REQUIRE(a.specialPoints.size() == b.specialPoints.size());
  for (size_t k = 0; k < a.specialPoints.size(); ++k) {
    CHECK(a.specialPoints[k].type == b.specialPoints[k].type);
    CHECK(a.specialPoints[k].lambda == b.specialPoints[k].lambda);
    CHECK(a.specialPoints[k].u == b.specialPoints[k].u);
  }
}

const SpecialPoint *firstOf(const Branch &b, SpecialPointType type) {
  for (const SpecialPoint &sp : b.specialPoints)
    if (sp.type == type) return &sp;
  return nullptr;
}

}  // namespace

TEST_CASE("One const problem traced from two threads at once: each trace as when run alone", "[bound_problem]") {
  const int n = 24;
  const CachedBratu bratu(n);
  TracerOptions options;
  options.lambdaMin = -4.0;
  options.lambdaMax = 4.0;
  options.maxPoints = 200;
  const Vector u0 = Vector::Zero(n);
  // Through the fold (λ ≈ 3.51, the lower branch turning back) and along λ < 0 (no fold).
  auto up = [&] { return trace(bratu, u0, 0.0, InitialDirection::increasingLambda(), options); };
  auto down = [&] { return trace(bratu, u0, 0.0, InitialDirection::decreasingLambda(), options); };
  const Branch upAlone = up(), downAlone = down();
  const SpecialPoint *fold = firstOf(upAlone, SpecialPointType::Fold);
  REQUIRE(fold);
  CHECK(std::abs(fold->lambda - 3.51) < 0.02);  // the discrete Bratu fold near the continuous 3.5138
  REQUIRE(downAlone.points.size() > 10);
  CHECK(firstOf(downAlone, SpecialPointType::Fold) == nullptr);

  // Several traces per thread, so that the two interleave over many evaluations; each result
  // compared with the same trace run alone.
  auto concurrently = [&](const std::function<Branch()> &first, const Branch &firstAlone,
                          const std::function<Branch()> &second, const Branch &secondAlone) {
    const int rounds = 4;
    std::vector<Branch> a(rounds), b(rounds);
    std::thread one([&] {
      for (Branch &r : a) r = first();
    });
    std::thread two([&] {
      for (Branch &r : b) r = second();
    });
    one.join();
    two.join();
    for (int k = 0; k < rounds; ++k) {
      requireIdentical(a[size_t(k)], firstAlone);
      requireIdentical(b[size_t(k)], secondAlone);
    }
  };
  SECTION("different starts") { concurrently(up, upAlone, down, downAlone); }
  SECTION("the same start") { concurrently(up, upAlone, up, upAlone); }
}

TEST_CASE("Each workspace keeps its own cache, a bound problem borrows or owns one", "[bound_problem]") {
  const int n = 5;
  const CachedBratu bratu(n);
  const Vector u1 = Vector::Constant(n, 0.1), u2 = Vector::Constant(n, -0.2);
  Vector F(n), G(n);
  const auto ws1 = bratu.createWorkspace(), ws2 = bratu.createWorkspace();
  auto &w1 = workspaceAs<CachedBratu::Workspace>(*ws1);
  auto &w2 = workspaceAs<CachedBratu::Workspace>(*ws2);
  REQUIRE(bratu.residual(*ws1, u1, 1.0, F));
  REQUIRE(bratu.residual(*ws2, u2, 1.0, G));
  REQUIRE(bratu.residual(*ws1, u1, 2.0, F));  // ws2's evaluation at u2 left ws1's cache as it was
  CHECK(w1.misses == 1);
  CHECK(w2.misses == 1);
  // F = (tridiagonal second difference of u) + λ e^u at the constant u1, λ = 2: closed form per row
  const double h = 1.0 / (n + 1);
  CHECK(std::abs(F[0] - (-0.1 / (h * h) + 2.0 * std::exp(0.1))) <= 1e-12 * std::abs(F[0]));
  CHECK(std::abs(F[2] - 2.0 * std::exp(0.1)) <= 1e-12);

  // Borrowed: evaluations land in ws1, and copies of the handle share it.
  const BoundProblem borrowed(bratu, *ws1);
  CHECK(&borrowed.workspace() == ws1.get());
  const BoundProblem copy = borrowed;
  REQUIRE(copy.residual(u2, 1.0, G));
  CHECK(w1.misses == 2);
  CHECK(w2.misses == 1);
  // Owned: a workspace of its own, made by the problem.
  const BoundProblem owned(bratu);
  CHECK(&owned.workspace() != ws1.get());
  REQUIRE(owned.residual(u1, 1.0, F));
  CHECK(workspaceAs<CachedBratu::Workspace>(owned.workspace()).misses == 1);
}

TEST_CASE("A workspace of another kind of problem is refused", "[bound_problem]") {
  const CachedBratu bratu(3);
  const toys::Circle circle;
  const auto foreign = circle.createWorkspace();  // the base ProblemWorkspace
  Vector F(3);
  CHECK_THROWS_AS(bratu.residual(*foreign, Vector::Zero(3), 1.0, F), std::invalid_argument);
  CHECK_THROWS_WITH(bratu.residual(*foreign, Vector::Zero(3), 1.0, F), Catch::Contains("createWorkspace"));
}
