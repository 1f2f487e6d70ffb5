#include "buckle/continuation/branch_switching.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <vector>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;

using toys::vec1;

TEST_CASE("Pitchfork: both bifurcating directions, closed-form branch and its stability", "[branch_switching]") {
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 0.4;
  options.step.maxStep = 0.05;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options, 1);
  REQUIRE(tree.branches.size() == 3);
  const Branch &trivial = tree.branches[0];
  const auto bps = trivial.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  CHECK_THAT(bps[0]->note, Contains("switched"));
  // Beyond the branch point the trivial branch is unstable with one negative eigenvalue.
  for (const ContinuationPoint &p : trivial.points) {
    if (p.lambda > 1e-9) {
      CHECK(p.stability.negative == 1);
    }
    if (p.lambda < -1e-9) {
      CHECK(p.stability.negative == 0);
    }
  }

  int signs = 0;
  for (int k = 1; k <= 2; ++k) {
    const Branch &child = tree.branches[k];
    CHECK(child.id == k);
    CHECK(child.parentId == 0);
    CHECK(trivial.specialPoints[child.parentSpecialPoint].type == SpecialPointType::BranchPoint);
    CHECK(child.stopReason == StopReason::LambdaRange);
    CHECK(std::abs(child.points.back().lambda - 0.4) <= 1e-15);
    REQUIRE(child.points.size() > 5);
    // The child does not re-detect the branch point it starts from.
    CHECK(child.specialPointsOfType(SpecialPointType::BranchPoint).empty());
    const double side = child.points[2].u[0] > 0.0 ? 1.0 : -1.0;
    signs += static_cast<int>(side);
    for (std::size_t i = 1; i < child.points.size(); ++i) {
      const ContinuationPoint &p = child.points[i];
      // u₁² = λ to corrector tolerance (‖G‖∞ ≤ 1e-10 bounds |u₁|·|u₁² − λ|).
      CHECK(std::abs(p.u[0]) * std::abs(p.u[0] * p.u[0] - p.lambda) <= 1e-10);
      CHECK(std::abs(p.u[1]) < 1e-12);
      CHECK(p.u[0] * side > 0.0);
      CHECK(p.lambda > 0.0);
      REQUIRE(p.stability.valid());
      CHECK(p.stability.negative == 0);  // supercritical: the bifurcated branch is stable
    }
  }
  CHECK(signs == 0);  // one branch with u₁ > 0, one with u₁ < 0
  CHECK(tree.branches[1].direction == -tree.branches[2].direction);
}

TEST_CASE("Two levels of switching on the double pitchfork", "[branch_switching]") {
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 0.8;
  options.step.maxStep = 0.05;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options, 2);
  // trivial; 2 from λ=0 (u₁ = ±√λ); 2 from λ=c (u₂ = ±√(λ−c)); 2×2 from λ=c on the u₁ branches.
  REQUIRE(tree.branches.size() == 9);
  int mixed = 0;
  for (const Branch &branch : tree.branches) {
    CHECK(branch.stopReason == StopReason::LambdaRange);
    Vector F(2);
    for (const ContinuationPoint &p : branch.points) {
      BoundProblem(problem).residual(p.u, p.lambda, F);
      CHECK(F.norm() < 1e-10);
    }
    if (branch.parentId > 0) {
      ++mixed;
      for (std::size_t i = 1; i < branch.points.size(); ++i) {
        const ContinuationPoint &p = branch.points[i];
        // To corrector tolerance: ‖G‖∞ ≤ 1e-10 bounds |u_k|·|u_k² − (λ − c_k)|.
        CHECK(std::abs(p.u[0]) * std::abs(p.u[0] * p.u[0] - p.lambda) <= 1e-10);
        CHECK(std::abs(p.u[1]) * std::abs(p.u[1] * p.u[1] - (p.lambda - c)) <= 1e-10);
        CHECK(p.u[1] * p.u[1] > 0.0);
      }
    }
  }
  CHECK(mixed == 4);
}

TEST_CASE("Transcritical: the bifurcation equation gives the u = lambda direction", "[branch_switching]") {
  toys::Transcritical problem;
  TracerOptions options;
  options.lambdaMin = -0.5;
  options.lambdaMax = 0.5;
  Tracer tracer(problem, options);
  const Branch trivial = tracer.trace(vec1(0.0), -0.45, InitialDirection::increasingLambda());
  const auto bps = trivial.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  Vector direction;
  std::string how;
  REQUIRE(bifurcatingDirection(problem, *bps[0], direction, &how));
  CHECK(how == "algebraic bifurcation equation");
  CHECK(std::abs(std::abs(direction[0]) - std::sqrt(0.5)) < 1e-6);
  CHECK(std::abs(direction[0] - direction[1]) < 1e-6);

  int reachedUpper = 0, reachedLower = 0;
  for (int sign : {1, -1}) {
    const Branch child = switchBranch(tracer, *bps[0], direction, sign);
    REQUIRE(child.points.size() > 5);
    for (const ContinuationPoint &p : child.points) CHECK(std::abs(p.u[0] - p.lambda) < 1e-10);
    if (std::abs(child.points.back().lambda - 0.5) <= 1e-15) ++reachedUpper;
    if (std::abs(child.points.back().lambda + 0.5) <= 1e-15) ++reachedLower;
    // Stability of u = λ: H = 2u − λ = λ, stable for λ > 0.
    for (std::size_t i = 1; i < child.points.size(); ++i)
      CHECK(child.points[i].stability.negative == (child.points[i].lambda < 0.0 ? 1 : 0));
  }
  CHECK(reachedUpper == 1);
  CHECK(reachedLower == 1);
}

TEST_CASE("Switching on a curved trivial branch follows u1 = 0.3 sin(lambda) +- sqrt(lambda)", "[branch_switching]") {
  toys::CurvedPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMax = 0.4;
  const BranchTree tree = traceTree(problem, toys::CurvedPitchforks::shift(-0.3), -0.3,
                                    InitialDirection::increasingLambda(), options, 1);
  REQUIRE(tree.branches.size() == 3);
  for (int k = 1; k <= 2; ++k) {
    const Branch &child = tree.branches[k];
    CHECK(child.stopReason == StopReason::LambdaRange);
    REQUIRE(child.points.size() > 5);
    for (std::size_t i = 1; i < child.points.size(); ++i) {
      const ContinuationPoint &p = child.points[i];
      const Vector v = p.u - toys::CurvedPitchforks::shift(p.lambda);
      CHECK(std::abs(v[0]) * std::abs(v[0] * v[0] - p.lambda) <= 1e-10);
      CHECK(std::abs(v[1]) < 1e-10);
      CHECK(p.stability.negative == 0);
    }
  }
}

TEST_CASE("Multiplicity-2 points are switched along every direction of the reduced equation", "[branch_switching]") {
  toys::DoubleZero problem;
  TracerOptions options;
  options.step.initialStep = 0.05;
  options.step.maxStep = 0.05;
  options.lambdaMax = 0.2;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.37, InitialDirection::increasingLambda(), options, 3);
  // [λu₁ − u₁³, λu₂ − u₂³]: the lines u₁ = 0, u₂ = 0, u₁ = ±u₂, both sides each (the children's own
  // branch points are each other's, switched once)
  const auto bps = tree.branches[0].specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 1);
  CHECK(bps[0]->multiplicity == 2);
  CHECK(bps[0]->branchesPredicted == 8);
  CHECK(bps[0]->branchesFound == 8);
  CHECK_THAT(bps[0]->note, Contains("switched"));
  REQUIRE(tree.branches.size() >= 9);
  for (size_t b = 1; b <= 8; ++b) CHECK(tree.branches[b].parentId == 0);
}

TEST_CASE("Switching from a point that is not a branch point is refused", "[branch_switching]") {
  toys::Circle circle;
  SpecialPoint fake;
  fake.type = SpecialPointType::Fold;
  fake.u = vec1(0.0);
  fake.lambda = 1.0;
  fake.nullVectors = Matrix::Identity(2, 1);
  Vector direction;
  std::string why;
  CHECK_FALSE(bifurcatingDirection(circle, fake, direction, &why));
  CHECK_THAT(why, Contains("not a branch point"));
  BranchSwitchingOptions bad;
  bad.minOffBranchFraction = 2.0;
  CHECK_FALSE(bad.IsValid(&why));
  CHECK_THAT(why, Contains("minOffBranchFraction"));
}

TEST_CASE("The tree's hooks: a branch extended past its trace is switched at on its own tracer, each branch final once",
          "[branch_switching]") {
  // TwoPitchforks: branch points at λ = 0 (u₁ = ±√λ) and λ = c (u₂ = ±√(λ − c)). The start
  // branch is traced to λ = 0.25 only; `extend` goes on to 0.8 with a tracer of its own and
  // appends what it finds, as contact continuation does, so the BP at λ = c exists only on the
  // extension. The tree switches there with the tracer `switchTracer` gives (a few points only).
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 0.25;
  options.step.maxStep = 0.05;
  TracerOptions beyond = options;
  beyond.lambdaMax = 0.8;
  TreeOptions tree;
  tree.branchSwitching = 1;
  tree.childTracer = beyond;
  Tracer extension(problem, beyond);
  int extended = 0;
  tree.extend = [&](const BranchTree &, Branch &branch) {
    ++extended;
    if (branch.parentId >= 0) return;
    Branch rest;
    rest.points.push_back(branch.points.back());
    const double s0 = rest.points[0].arclength;
    rest.points[0].arclength = 0.0;
    extension.continueBranch(rest);
    const int base = static_cast<int>(branch.points.size()) - 1;
    for (std::size_t i = 1; i < rest.points.size(); ++i) {
      branch.points.push_back(rest.points[i]);
      branch.points.back().arclength += s0;
    }
    for (SpecialPoint sp : rest.specialPoints) {
      sp.index += base;
      sp.arclength += s0;
      branch.specialPoints.push_back(sp);
    }
    branch.stopReason = rest.stopReason;
  };
  TracerOptions few = beyond;
  few.maxPoints = 6;
  int ownTracers = 0;
  tree.switchTracer = [&](const BranchTree &, std::size_t, const SpecialPoint &bp) -> std::shared_ptr<Tracer> {
    if (std::abs(bp.lambda - c) > 1e-6) return nullptr;
    ++ownTracers;
    return std::make_shared<Tracer>(problem, few);
  };
  std::vector<std::size_t> order;
  std::vector<bool> notesDone;
  tree.onFinal = [&](BranchTree &t, std::size_t b) {
    order.push_back(b);
    bool done = true;  // a final branch's branch points all carry the switching outcome
    if (t.branches[b].parentId < 0)
      for (const SpecialPoint &sp : t.branches[b].specialPoints)
        if (sp.type == SpecialPointType::BranchPoint) done = done && sp.note.find("switched") != std::string::npos;
    notesDone.push_back(done);
  };
  const BranchTree result = traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()},
                                      options, tree);
  REQUIRE(result.branches.size() == 5);
  CHECK(extended == 5);
  CHECK(ownTracers == 1);
  CHECK(std::abs(result.branches[0].points.back().lambda - 0.8) <= 1e-15);
  int fromC = 0;
  for (std::size_t b = 1; b < result.branches.size(); ++b) {
    const Branch &child = result.branches[b];
    const SpecialPoint &at = result.branches[0].specialPoints[std::size_t(child.parentSpecialPoint)];
    if (std::abs(at.lambda - c) > 1e-6) {
      CHECK(child.points.size() > 6);  // the tree's child tracer, to λ = 0.8
      continue;
    }
    ++fromC;
    CHECK(child.points.size() <= 6);  // the hook's tracer
    for (std::size_t i = 1; i < child.points.size(); ++i) {
      const ContinuationPoint &p = child.points[i];
      CHECK(std::abs(p.u[1]) * std::abs(p.u[1] * p.u[1] - (p.lambda - c)) <= 1e-10);
      CHECK(std::abs(p.u[0]) < 1e-12);
    }
  }
  CHECK(fromC == 2);
  // every branch final exactly once, the children of each branch point before their parent
  REQUIRE(order.size() == 5);
  CHECK(std::vector<std::size_t>(order.begin(), order.end()) == std::vector<std::size_t>{1, 2, 3, 4, 0});
  for (bool done : notesDone) CHECK(done);
}

TEST_CASE("An interrupted tree makes every branch final, the unfinished ones included", "[branch_switching]") {
  toys::TwoPitchforks problem(0.5);
  TracerOptions options;
  options.lambdaMax = 0.8;
  options.step.maxStep = 0.05;
  TreeOptions tree;
  tree.branchSwitching = 2;
  std::atomic<bool> stop{false};
  options.interrupt.watch(&stop, "test");
  std::vector<int> finals;
  // stop as soon as the first grandchild is final: the tree has then traced part of the tree
  tree.onFinal = [&](BranchTree &t, std::size_t b) {
    finals.push_back(int(b));
    if (t.branches[b].parentId > 0) stop = true;
  };
  const BranchTree result = traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()},
                                      options, tree);
  CHECK(result.interrupted);
  std::vector<int> sorted = finals;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> expected(result.branches.size());
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = int(i);
  CHECK(sorted == expected);  // each once
  CHECK(result.branches.size() < 9);
}

TEST_CASE("A root is traced lazily: the tree's root is the branch traced whole, its children in branch-point order",
          "[branch_switching]") {
  toys::ManyPitchforks problem(5, 0.1);  // branch points at λ = 0, 0.1, …, 0.4 on u = 0
  TracerOptions options;
  options.lambdaMax = 0.6;
  options.step.maxStep = 0.05;
  Tracer whole(problem, options);
  const Branch reference = whole.trace(Vector::Zero(5), -0.2, InitialDirection::increasingLambda());
  REQUIRE(reference.specialPointsOfType(SpecialPointType::BranchPoint).size() == 5);
  TreeOptions tree;
  tree.branchSwitching = 1;
  std::vector<std::pair<int, StopReason>> reports;  // onBranch: (id, stop reason)
  std::vector<int> extended;
  tree.onBranch = [&](const BranchTree &, const Branch &b) { reports.emplace_back(b.id, b.stopReason); };
  tree.extend = [&](const BranchTree &, Branch &b) {
    CHECK(b.stopReason != StopReason::Paused);  // only a trace that has ended is extended
    extended.push_back(b.id);
  };
  const BranchTree result =
      traceTree(problem, Vector::Zero(5), -0.2, {InitialDirection::increasingLambda()}, options, tree);
  REQUIRE(result.branches.size() == 11);
  const Branch &root = result.branches[0];
  CHECK(root.stopReason == StopReason::LambdaRange);
  REQUIRE(root.points.size() == reference.points.size());
  for (std::size_t i = 0; i < root.points.size(); ++i) {
    CHECK(root.points[i].u == reference.points[i].u);
    CHECK(root.points[i].lambda == reference.points[i].lambda);
  }
  // children 2k + 1, 2k + 2 from the k-th branch point, in order, all finished
  int lastParentPoint = -1;
  for (std::size_t b = 1; b < result.branches.size(); ++b) {
    const Branch &child = result.branches[b];
    CHECK(child.parentId == 0);
    CHECK(child.stopReason == StopReason::LambdaRange);
    CHECK(child.parentSpecialPoint >= lastParentPoint);
    lastParentPoint = child.parentSpecialPoint;
  }
  // the root reported as it went on (paused), its last report the ended trace; extended once, last
  int rootReports = 0;
  for (const auto &r : reports)
    if (r.first == 0) ++rootReports;
  CHECK(rootReports == 6);  // paused at each of its 5 branch points, then ended (after the last children)
  CHECK(reports.back().first == 0);
  CHECK(reports.back().second == StopReason::LambdaRange);
  CHECK(std::find(extended.begin(), extended.end(), 0) == extended.end() - 1);
  CHECK(extended.size() == 11);
}

TEST_CASE("Under an interrupt the tree holds the branches of the root's first branch points, not a whole root",
          "[branch_switching]") {
  toys::ManyPitchforks problem(5, 0.1);
  TracerOptions options;
  options.lambdaMax = 0.6;
  options.step.maxStep = 0.05;
  TreeOptions tree;
  tree.branchSwitching = 1;
  std::atomic<bool> stop{false};
  options.interrupt.watch(&stop, "test stop");
  int finalChildren = 0;
  tree.onFinal = [&](BranchTree &t, std::size_t b) {
    if (t.branches[b].parentId >= 0 && ++finalChildren == 4) stop = true;  // both sides of two branch points
  };
  const BranchTree result =
      traceTree(problem, Vector::Zero(5), -0.2, {InitialDirection::increasingLambda()}, options, tree);
  CHECK(result.interrupted);
  REQUIRE(result.branches.size() == 5);
  const Branch &root = result.branches[0];
  CHECK(root.stopReason == StopReason::Interrupted);
  CHECK(root.stopMessage == "test stop");
  CHECK(root.specialPointsOfType(SpecialPointType::BranchPoint).size() == 2);  // λ = 0 and 0.1 only
  CHECK(root.points.back().lambda < 0.2);
  for (std::size_t b = 1; b < 5; ++b) CHECK(result.branches[b].stopReason == StopReason::LambdaRange);
}
