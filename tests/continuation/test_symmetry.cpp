#include "buckle/continuation/symmetry.h"

#include "buckle/continuation/branch_switching.h"
#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace buckle::continuation;

namespace {

double relativeDifference(const Vector &a, const Vector &b) {
  if (a.size() != b.size()) return INFINITY;
  return a.size() == 0 ? 0.0 : (a - b).norm() / std::max(1.0, a.norm());
}

// The two trees have the same branches, points and special points, to rounding.
void requireSameTree(const BranchTree &a, const BranchTree &b, double tol) {
  REQUIRE(a.branches.size() == b.branches.size());
  for (size_t i = 0; i < a.branches.size(); ++i) {
    const Branch &x = a.branches[i], &y = b.branches[i];
    INFO("branch " << i);
    CHECK(x.parentId == y.parentId);
    CHECK(x.parentSpecialPoint == y.parentSpecialPoint);
    CHECK(x.direction == y.direction);
    CHECK(x.stopReason == y.stopReason);
    REQUIRE(x.points.size() == y.points.size());
    for (size_t k = 0; k < x.points.size(); ++k) {
      CHECK(relativeDifference(x.points[k].state(), y.points[k].state()) <= tol);
      CHECK(relativeDifference(x.points[k].tangent, y.points[k].tangent) <= tol);
      CHECK(x.points[k].stability.negative == y.points[k].stability.negative);
      CHECK(x.points[k].determinantSign == y.points[k].determinantSign);
    }
    REQUIRE(x.specialPoints.size() == y.specialPoints.size());
    for (size_t k = 0; k < x.specialPoints.size(); ++k) {
      const SpecialPoint &p = x.specialPoints[k], &q = y.specialPoints[k];
      CHECK(p.type == q.type);
      CHECK(p.index == q.index);
      CHECK(std::abs(p.lambda - q.lambda) <= tol * std::max(1.0, std::abs(p.lambda)));
      CHECK(relativeDifference(p.u, q.u) <= tol);
      CHECK(p.inertiaBefore == q.inertiaBefore);
      CHECK(p.inertiaAfter == q.inertiaAfter);
    }
  }
}

}  // namespace

TEST_CASE("Reflection: images of states, tangents, kernels and texts", "[symmetry]") {
  Reflection r;
  r.signs = (Vector(3) << -1.0, 1.0, -1.0).finished();
  r.text = [](const std::string &s) { return s == "left" ? std::string("right") : s; };
  SpecialPoint sp;
  sp.type = SpecialPointType::BranchPoint;
  sp.u = (Vector(3) << 1.0, 2.0, 3.0).finished();
  sp.lambda = 0.7;
  sp.tangent = (Vector(4) << 0.1, 0.2, 0.3, 0.4).finished();
  sp.nullVectors = Matrix::Identity(4, 2);
  sp.leftNullVector = (Vector(3) << 4.0, 5.0, 6.0).finished();
  sp.boundaryName = "left";
  reflect(r, sp);
  CHECK(sp.u == (Vector(3) << -1.0, 2.0, -3.0).finished());
  CHECK(sp.lambda == 0.7);
  CHECK(sp.tangent == (Vector(4) << -0.1, 0.2, -0.3, 0.4).finished());  // λ component kept
  CHECK(sp.nullVectors(0, 0) == -1.0);
  CHECK(sp.nullVectors(1, 1) == 1.0);
  CHECK(sp.leftNullVector == (Vector(3) << -4.0, 5.0, -6.0).finished());
  CHECK(sp.boundaryName == "right");
  // An involution: twice is the identity.
  reflect(r, sp);
  CHECK(sp.u == (Vector(3) << 1.0, 2.0, 3.0).finished());

  CHECK(r.maps((Vector(4) << 0.0, 1.0, 0.0, 2.0).finished(), 1));    // fixed
  CHECK(!r.maps((Vector(4) << 1e-3, 1.0, 0.0, 2.0).finished(), 1));
  CHECK(r.maps((Vector(4) << 1.0, 0.0, 1.0, 0.0).finished(), -1));   // reversed
  CHECK(!r.maps((Vector(4) << 1.0, 0.0, 1.0, 1e-3).finished(), -1));  // a λ component is not reversed

  std::string why;
  CHECK(r.IsValid(3, &why));
  CHECK(!r.IsValid(2, &why));
  r.signs[1] = 0.5;
  CHECK(!r.IsValid(3, &why));
  CHECK(Reflection().IsValid(5, &why));  // empty: no symmetry
}

TEST_CASE("Reflection: the mirrored child of a symmetric pitchfork equals the traced one", "[symmetry]") {
  // TwoPitchforks: S = diag(−1, 1) fixes u = 0 and reverses the child u₁ = ±√λ of the branch
  // point at λ = 0, but not the child u₂ = ±√(λ − c) of the one at λ = c (S d = d there), nor the
  // branch points on the u₁ children (u₁ ≠ 0, not fixed): only one branch is mirrored.
  toys::TwoPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMax = 0.8;
  options.step.maxStep = 0.05;
  TreeOptions plain;
  plain.branchSwitching = 2;
  const BranchTree traced =
      traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()}, options, plain);
  TreeOptions withMirror = plain;
  withMirror.symmetry.signs = (Vector(2) << -1.0, 1.0).finished();
  const BranchTree mirrored =
      traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()}, options, withMirror);

  requireSameTree(traced, mirrored, 1e-12);
  int images = 0;
  for (const Branch &b : mirrored.branches) {
    if (b.mirrorOf < 0) continue;
    ++images;
    const Branch &source = mirrored.branches[size_t(b.mirrorOf)];
    CHECK(b.parentId == 0);
    CHECK(source.parentId == 0);
    CHECK(source.parentSpecialPoint == b.parentSpecialPoint);
    CHECK(source.direction == 1);
    CHECK(b.direction == -1);
    CHECK(std::abs(mirrored.branches[0].specialPoints[size_t(b.parentSpecialPoint)].lambda) <= 1e-12);
    REQUIRE(b.points.size() > 5);
    CHECK(b.points[3].u[0] == -source.points[3].u[0]);  // the image, exactly
  }
  CHECK(images == 1);
  for (const Branch &b : traced.branches) CHECK(b.mirrorOf == -1);
}

TEST_CASE("Reflection: a branch point whose direction the reflection does not reverse is traced", "[symmetry]") {
  // Transcritical λu − u²: S = −1 fixes u = 0, but the child's direction (1, 1)/√2 is not reversed
  // (its λ component is kept): both sides are traced, as without the reflection.
  toys::Transcritical problem;
  TracerOptions options;
  options.lambdaMin = -0.5;
  options.lambdaMax = 0.5;
  options.step.maxStep = 0.05;
  TreeOptions plain;
  plain.branchSwitching = 1;
  TreeOptions withMirror = plain;
  withMirror.symmetry.signs = Vector::Constant(1, -1.0);
  const BranchTree a =
      traceTree(problem, Vector::Zero(1), -0.3, {InitialDirection::increasingLambda()}, options, plain);
  const BranchTree b =
      traceTree(problem, Vector::Zero(1), -0.3, {InitialDirection::increasingLambda()}, options, withMirror);
  REQUIRE(a.branches.size() == 3);
  requireSameTree(a, b, 0.0);
  for (const Branch &branch : b.branches) CHECK(branch.mirrorOf == -1);
}

TEST_CASE("Reflection: invalid signs are refused by the tree driver", "[symmetry]") {
  toys::TwoPitchforks problem(0.5);
  TreeOptions tree;
  tree.branchSwitching = 1;
  tree.symmetry.signs = Vector::Constant(3, -1.0);  // the problem has 2 unknowns
  const BranchTree t =
      traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()}, TracerOptions(), tree);
  REQUIRE(t.branches.size() == 1);
  CHECK(t.branches[0].stopReason == StopReason::InvalidOptions);
  CHECK_THAT(t.branches[0].stopMessage, Catch::Matchers::Contains("symmetry"));
}
