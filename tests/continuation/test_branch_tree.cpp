#include "buckle/continuation/branch_switching.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using namespace buckle::continuation;

namespace {

// Options of the trees below: to λ = lambdaMax in steps of at most 0.05.
TracerOptions upTo(double lambdaMax) {
  TracerOptions options;
  options.lambdaMax = lambdaMax;
  options.step.maxStep = 0.05;
  return options;
}

// A tree of ManyPitchforks (branch points at λ = 0, 0.1, …, 0.4 on u = 0), two generations deep,
// on `threads` threads; childWork counts its calls and leaves the sides' sizes in `prepared`.
BranchTree manyPitchforksTree(int threads, int &works, const std::function<void(int)> &onWork = nullptr,
                              const Interrupt &interrupt = Interrupt()) {
  static const toys::ManyPitchforks problem(5, 0.1);
  TracerOptions options = upTo(0.6);
  options.interrupt = interrupt;
  TreeOptions tree;
  tree.branchSwitching = 2;
  tree.threads = threads;
  std::atomic<int> calls{0};
  tree.childWork = [&](const BranchTree &, std::size_t, const SpecialPoint &) -> TreeOptions::ChildWork {
    return [&](std::vector<Branch> &sides) {
      const int call = ++calls;
      if (onWork) onWork(call);
      for (Branch &b : sides) b.prepared = b.points.size();
    };
  };
  BranchTree result = traceTree(problem, Vector::Zero(5), -0.2, {InitialDirection::increasingLambda()}, options, tree);
  works = calls;
  return result;
}

}  // namespace

TEST_CASE("The tree is the same on 1, 2 and 3 threads: ids, parents, notes and points", "[branch_tree]") {
  int serialWorks = 0;
  const BranchTree serial = manyPitchforksTree(1, serialWorks);
  REQUIRE(serial.branches.size() > 11);  // the grandchildren too
  for (int threads : {2, 3}) {
    INFO("threads " << threads);
    int works = 0;
    const BranchTree parallel = manyPitchforksTree(threads, works);
    CHECK(works == serialWorks);
    REQUIRE(parallel.branches.size() == serial.branches.size());
    for (std::size_t b = 0; b < serial.branches.size(); ++b) {
      const Branch &x = serial.branches[b], &y = parallel.branches[b];
      INFO("branch " << b);
      CHECK(y.id == int(b));
      CHECK(y.parentId == x.parentId);
      CHECK(y.parentSpecialPoint == x.parentSpecialPoint);
      CHECK(y.direction == x.direction);
      CHECK(y.stopReason == x.stopReason);
      REQUIRE(y.points.size() == x.points.size());
      for (std::size_t i = 0; i < x.points.size(); ++i) {
        CHECK((y.points[i].u - x.points[i].u).norm() <= 1e-12);
        CHECK(std::abs(y.points[i].lambda - x.points[i].lambda) <= 1e-12);
      }
      REQUIRE(y.specialPoints.size() == x.specialPoints.size());
      for (std::size_t k = 0; k < x.specialPoints.size(); ++k) CHECK(y.specialPoints[k].note == x.specialPoints[k].note);
      // childWork saw the child as traced, before it joined the tree
      if (y.parentId >= 0) CHECK(std::any_cast<std::size_t>(y.prepared) == y.points.size());
    }
  }
}

TEST_CASE("On threads, an interrupted tree keeps the first branch points' children, each joined once",
          "[branch_tree]") {
  std::atomic<bool> stop{false};
  Interrupt interrupt;
  interrupt.watch(&stop, "test stop");
  int works = 0;
  const BranchTree tree = manyPitchforksTree(2, works, [&](int call) { if (call == 3) stop = true; }, interrupt);
  CHECK(tree.interrupted);
  CHECK(tree.message == "test stop");
  // the switched branch points of the root are its first ones, with no gap
  std::set<int> switched;
  for (std::size_t b = 0; b < tree.branches.size(); ++b) {
    CHECK(tree.branches[b].id == int(b));
    const int parent = tree.branches[b].parentId;
    CHECK(parent < int(b));
    if (parent == 0) switched.insert(tree.branches[b].parentSpecialPoint);
  }
  REQUIRE(!switched.empty());
  int expected = *switched.begin();
  for (int k : switched) CHECK(k == expected++);
  CHECK(works <= 3 + 2 + 2);  // the scheduled ones not started are dropped: at most threads + 2 scheduled
}

TEST_CASE("A tree stopped anywhere numbers its branches as the complete tree does", "[branch_tree]") {
  // A stop that falls between the + and the − side of a switch must not shift the ids of the
  // children joined after it: a stopped run's branch b is the complete run's branch b.
  const toys::ManyPitchforks problem(5, 0.1);
  TreeOptions tree;
  tree.branchSwitching = 2;
  auto run = [&](int stopAfter) {
    TracerOptions options = upTo(0.6);
    std::atomic<bool> stop{false};
    options.interrupt.watch(&stop, "test stop");
    int steps = 0;
    options.onStep = [&](const StepInfo &) {
      if (++steps == stopAfter) stop = true;
      return StepAction::Continue;
    };
    return traceTree(problem, Vector::Zero(5), -0.2, {InitialDirection::increasingLambda()}, options, tree);
  };
  const BranchTree complete = run(-1);
  REQUIRE(!complete.interrupted);
  int stoppedInsideASwitch = 0;
  for (int stopAfter = 1; stopAfter < 400; stopAfter += 3) {
    const BranchTree stopped = run(stopAfter);
    if (!stopped.interrupted) break;
    INFO("stopped after step " << stopAfter);
    REQUIRE(stopped.branches.size() <= complete.branches.size());
    for (std::size_t b = 0; b < stopped.branches.size(); ++b) {
      const Branch &x = complete.branches[b], &y = stopped.branches[b];
      INFO("branch " << b);
      CHECK(y.parentId == x.parentId);
      CHECK(y.parentSpecialPoint == x.parentSpecialPoint);
      CHECK(y.direction == x.direction);
      CHECK(std::abs(y.points.front().lambda - x.points.front().lambda) <= 1e-12);
    }
    // the − side of a switch the stop cut: there, ended at its first point
    for (const Branch &b : stopped.branches)
      if (b.parentId >= 0 && b.direction < 0 && b.points.size() <= 2) ++stoppedInsideASwitch;
  }
  CHECK(stoppedInsideASwitch > 0);
}

TEST_CASE("On threads, what a worker throws reaches the caller", "[branch_tree]") {
  int works = 0;
  CHECK_THROWS_WITH(manyPitchforksTree(2, works, [](int call) {
                      if (call == 2) throw std::runtime_error("child work failed");
                    }),
                    "child work failed");
}

TEST_CASE("The tree's hooks: a branch extended past its trace is switched at on its own tracer, each branch final once",
          "[branch_tree]") {
  // TwoPitchforks: branch points at λ = 0 (u₁ = ±√λ) and λ = c (u₂ = ±√(λ − c)). The start
  // branch is traced to λ = 0.25 only; `extend` goes on to 0.8 with a tracer of its own and
  // appends what it finds, as contact continuation does, so the BP at λ = c exists only on the
  // extension. The tree switches there with the tracer `switchTracer` gives (a few points only).
  const double c = 0.5;
  toys::TwoPitchforks problem(c);
  TracerOptions options = upTo(0.25);
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

TEST_CASE("An interrupted tree makes every branch final, the unfinished ones included", "[branch_tree]") {
  toys::TwoPitchforks problem(0.5);
  TracerOptions options = upTo(0.8);
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
          "[branch_tree]") {
  toys::ManyPitchforks problem(5, 0.1);  // branch points at λ = 0, 0.1, …, 0.4 on u = 0
  TracerOptions options = upTo(0.6);
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
          "[branch_tree]") {
  toys::ManyPitchforks problem(5, 0.1);
  TracerOptions options = upTo(0.6);
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
