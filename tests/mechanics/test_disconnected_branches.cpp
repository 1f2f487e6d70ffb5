// Disconnected branches (disconnected_branches.h) on the imperfect U pitchfork: the paper's
// three-segment chain, clamped-pinned, its unloaded shape the symmetric U imperfection
// q0 = (θ, −2θ, θ), compressed by Fx. Continuation from the unloaded shape bends into the U on
// the imperfection's side; the U bent the other way is on a separate branch born at a fold. The
// checks are independent of the library's tracing: the fold against brute-force equilibrium
// counts on both sides of it, the branch points against the chain's own gradient, the crossings
// at λ* by this file's Newton against the equilibrium list.
#include <catch2/catch.hpp>

#include <cmath>

#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/disconnected_branches.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "fixed_lambda_newton.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The chain in units scaled by `length` and `stiffness` (forces by length·stiffness).
struct Setup {
  double length, force;
  Chain chain;
  EndCondition end;
  double lambdaStar, lambdaEnd;
};
Setup imperfectU(double length = 1.0, double stiffness = 1.0) {
  const double theta = 0.05;
  const SegmentParameters p = SegmentParameters::symmetric(0.5 * length, length, stiffness, 2.25 * length);
  const Eigen::Vector3d q0(theta, -2.0 * theta, theta);
  const Chain chain(preloadsForShape(std::vector<SegmentParameters>(3, p), q0));
  return {length, length * stiffness, chain, EndCondition::clampedPinned(0.0), -1.0 * length * stiffness,
          -1.5 * length * stiffness};
}

EquilibriumBranchOptions treeOptions(const Setup& s) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = s.lambdaEnd;
  o.tracer.lambdaMax = 0.0;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 1;
  return o;
}

EquilibriumProblem pathProblem(const Setup& s) { return EquilibriumProblem(s.chain, s.end, Eigen::Vector3d(1, 0, 0)); }

AllEquilibria equilibriaAt(const Setup& s, double lambda) {
  EndCondition e = s.end;
  e.value[0] = lambda;
  return allEquilibria(s.chain, e);
}

// This file's own crossings of a branch with λ*: the bracketing chord's interpolant polished by
// Newton at fixed λ* on the problem's equations.
std::vector<Eigen::VectorXd> crossingsAt(EquilibriumProblem& problem, const cont::Branch& b, double lambda) {
  std::vector<Eigen::VectorXd> out;
  const int N = problem.dimension();
  for (size_t i = 0; i + 1 < b.points.size(); ++i) {
    const double da = b.points[i].lambda - lambda, db = b.points[i + 1].lambda - lambda;
    if (da * db > 0.0 || da == db) continue;
    const Eigen::VectorXd u = buckle::test::polishAtFixedLambda(
        problem, b.points[i].u + (da / (da - db)) * (b.points[i + 1].u - b.points[i].u), lambda, 20);
    Eigen::VectorXd F(N);
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
    REQUIRE(F.cwiseQuotient(problem.scales().residuals).lpNorm<Eigen::Infinity>() < 1e-11);
    out.push_back(u.head(problem.segments()));
  }
  return out;
}

int findIn(const std::vector<Eigen::VectorXd>& list, const Eigen::VectorXd& q, double tol) {
  for (size_t k = 0; k < list.size(); ++k)
    if ((list[k] - q).lpNorm<Eigen::Infinity>() <= tol) return int(k);
  return -1;
}

struct Traced {
  Setup s;
  EquilibriumBranches tree;
  AllEquilibria found;
  std::vector<Eigen::VectorXd> q;
  std::vector<bool> stable;
  DisconnectedBranches d;
};
Traced traceAll(double length = 1.0, double stiffness = 1.0) {
  Traced t{imperfectU(length, stiffness), {}, {}, {}, {}, {}};
  EquilibriumProblem problem = pathProblem(t.s);
  t.tree = traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(),
                           treeOptions(t.s));
  t.found = equilibriaAt(t.s, t.s.lambdaStar);
  for (const FoundEquilibrium& e : t.found.equilibria) {
    t.q.push_back(e.q);
    t.stable.push_back(e.stable);
  }
  DisconnectedBranchOptions o;
  o.branches = treeOptions(t.s);
  t.d = traceDisconnectedBranches(problem, t.q, t.s.lambdaStar, t.stable, t.tree.tree.branches, o);
  return t;
}

}  // namespace

TEST_CASE("Disconnected branches: the other U of an imperfect pitchfork, stable, unreachable from the start",
          "[disconnected]") {
  const Traced t = traceAll();
  const Setup& s = t.s;
  EquilibriumProblem problem = pathProblem(s);
  // three equilibria beyond the fold of an imperfect pitchfork: two stable U shapes, one unstable
  REQUIRE(t.found.equilibria.size() == 3);
  int stableCount = 0;
  for (const FoundEquilibrium& e : t.found.equilibria) stableCount += e.stable;
  REQUIRE(stableCount == 2);

  // The tree from the unloaded shape: one branch (no branch point), through one of them only.
  REQUIRE(t.tree.tree.branches.size() == 1);
  std::vector<Eigen::VectorXd> onTree = crossingsAt(problem, t.tree.tree.branches[0], s.lambdaStar);
  REQUIRE(onTree.size() == 1);
  const int reached = findIn(t.q, onTree[0], 1e-8);
  REQUIRE(reached >= 0);
  CHECK(t.found.equilibria[size_t(reached)].stable);
  // the other stable one is far from every point the tree traced near λ*
  int other = -1;
  for (size_t k = 0; k < t.q.size(); ++k)
    if (t.stable[k] && int(k) != reached) other = int(k);
  REQUIRE(other >= 0);
  double nearest = INFINITY;
  for (const cont::ContinuationPoint& p : t.tree.tree.branches[0].points)
    if (std::abs(p.lambda - s.lambdaStar) <= 0.2 * s.force) nearest = std::min(nearest, (p.u.head(3) - t.q[size_t(other)]).lpNorm<Eigen::Infinity>());
  CHECK(nearest > 0.5);

  // What the library says: the reached one is on the tree's branch, the two others on new ones,
  // traced once from the stable one (the unstable one lies on its branch: no second seed).
  const DisconnectedBranches& d = t.d;
  REQUIRE(d.firstId == 1);
  CHECK(d.onBranch[size_t(reached)] == 0);
  CHECK(d.onBranch[size_t(other)] >= d.firstId);
  REQUIRE(d.seeds == std::vector<int>{other});
  const auto& branches = d.traced.tree.branches;
  REQUIRE(branches.size() == 2);  // both directions from the seed
  for (size_t b = 0; b < branches.size(); ++b) {
    CHECK(branches[b].id == d.firstId + int(b));
    CHECK(branches[b].parentId < 0);
    CHECK(branches[b].stopReason == cont::StopReason::LambdaRange);
    CHECK(d.joined[b] == -1);
  }

  // Every traced point is an equilibrium: the chain's own gradient of Π with the end wrench, and
  // the held end on y = 0 (relative to the chain's torque and length units).
  const double torque = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  for (const cont::Branch& b : branches)
    for (const cont::ContinuationPoint& p : b.points) {
      Eigen::VectorXd g(3);
      totalPotentialGradient(s.chain, p.u.head(3), problem.wrench(p.u, p.lambda), g);
      CHECK(g.lpNorm<Eigen::Infinity>() < 1e-9 * torque);
      CHECK(std::abs(endPose(s.chain, p.u.head(3))[1]) < 1e-9 * problem.lengthUnit());
      CHECK(p.lambda >= s.lambdaEnd * (1 + 1e-12));
      CHECK(p.lambda <= 0.0);
    }

  // The crossings of the new branches with λ* are the equilibria the tree misses, no more.
  std::vector<Eigen::VectorXd> crossed;
  for (const cont::Branch& b : branches)
    for (const Eigen::VectorXd& q : crossingsAt(problem, b, s.lambdaStar))
      if (findIn(crossed, q, 1e-8) < 0) crossed.push_back(q);
  REQUIRE(crossed.size() == 2);
  for (size_t k = 0; k < t.q.size(); ++k) {
    CHECK((findIn(crossed, t.q[k], 1e-8) >= 0) == (int(k) != reached));
    if (int(k) != reached) CHECK(d.onBranch[k] >= d.firstId);
  }

  // One fold on the new branches; brute force on each side of it: three equilibria beyond, one
  // short of it (the branch is born there).
  std::vector<const cont::SpecialPoint*> folds;
  for (const cont::Branch& b : branches)
    for (const cont::SpecialPoint* f : b.specialPointsOfType(cont::SpecialPointType::Fold)) folds.push_back(f);
  REQUIRE(folds.size() == 1);
  const double fold = folds[0]->lambda;
  CHECK(fold > s.lambdaStar);
  CHECK(fold < 0.0);
  CHECK(equilibriaAt(s, fold - 0.01 * s.force).equilibria.size() == 3);
  CHECK(equilibriaAt(s, fold + 0.01 * s.force).equilibria.size() == 1);

  // Stability along the new branch: stable from the seed to the fold and beyond the seed, one
  // negative eigenvalue past the fold (where the unstable equilibrium is crossed).
  for (const cont::Branch& b : branches) {
    const auto f = b.specialPointsOfType(cont::SpecialPointType::Fold);
    for (size_t i = 0; i < b.points.size(); ++i)
      CHECK(b.points[i].stability.negative == (!f.empty() && int(i) > f[0]->index ? 1 : 0));
  }
}

TEST_CASE("Disconnected branches: a branch that comes onto a traced one is cut there", "[disconnected]") {
  const Traced t = traceAll();
  EquilibriumProblem problem = pathProblem(t.s);
  const auto& newBranches = t.d.traced.tree.branches;
  // the seed's branch that does not pass the fold (decreasing Fx from the stable seed)
  const cont::Branch* plain = nullptr;
  for (const cont::Branch& b : newBranches)
    if (b.specialPointsOfType(cont::SpecialPointType::Fold).empty()) plain = &b;
  REQUIRE(plain != nullptr);

  SECTION("from the unstable equilibrium: round the fold onto the known stable part") {
    std::vector<cont::Branch> known{t.tree.tree.branches[0], *plain};
    known[1].id = 7;
    int unstable = -1;
    for (size_t k = 0; k < t.q.size(); ++k)
      if (!t.stable[k]) unstable = int(k);
    REQUIRE(unstable >= 0);
    DisconnectedBranchOptions o;
    o.branches = treeOptions(t.s);
    const DisconnectedBranches d =
        traceDisconnectedBranches(problem, {t.q[size_t(unstable)]}, t.s.lambdaStar, {false}, known, o);
    REQUIRE(d.firstId == 8);
    REQUIRE(d.seeds == std::vector<int>{0});
    REQUIRE(d.traced.tree.branches.size() == 2);
    int joined = -1;
    for (size_t b = 0; b < 2; ++b)
      if (d.traced.tree.branches[b].stopReason == cont::StopReason::Joined) joined = int(b);
    REQUIRE(joined >= 0);
    const cont::Branch& j = d.traced.tree.branches[size_t(joined)];
    CHECK(d.joined[size_t(joined)] == 7);
    CHECK(j.specialPointsOfType(cont::SpecialPointType::Fold).size() == 1);
    // it ends just past the stable equilibrium where the known branch starts: within a few steps
    // of λ*, on the stable side, and never far down the known branch
    const cont::ContinuationPoint& last = j.points.back();
    CHECK(last.lambda < t.s.lambdaStar);
    CHECK(last.lambda > t.s.lambdaStar - 0.1 * t.s.force);
    CHECK(last.stability.negative == 0);
    // the other direction runs to the end of the range
    CHECK(d.traced.tree.branches[size_t(1 - joined)].stopReason == cont::StopReason::LambdaRange);
  }

  SECTION("every equilibrium on a traced branch: nothing is traced") {
    std::vector<cont::Branch> known{t.tree.tree.branches[0]};
    for (cont::Branch b : newBranches) known.push_back(b);
    DisconnectedBranchOptions o;
    o.branches = treeOptions(t.s);
    const DisconnectedBranches d = traceDisconnectedBranches(problem, t.q, t.s.lambdaStar, t.stable, known, o);
    CHECK(d.seeds.empty());
    CHECK(d.traced.tree.branches.empty());
    for (int id : d.onBranch) CHECK((id >= 0 && id < d.firstId));
  }
}

TEST_CASE("Disconnected branches: the same in scaled units (lengths x1e-4, stiffness x1e8)", "[disconnected]") {
  const Traced a = traceAll(), b = traceAll(1e-4, 1e8);
  const double force = b.s.force;
  REQUIRE(a.q.size() == b.q.size());
  CHECK(a.d.onBranch == b.d.onBranch);
  CHECK(a.d.seeds == b.d.seeds);
  REQUIRE(a.d.traced.tree.branches.size() == b.d.traced.tree.branches.size());
  for (size_t k = 0; k < a.d.traced.tree.branches.size(); ++k) {
    const auto fa = a.d.traced.tree.branches[k].specialPointsOfType(cont::SpecialPointType::Fold);
    const auto fb = b.d.traced.tree.branches[k].specialPointsOfType(cont::SpecialPointType::Fold);
    REQUIRE(fa.size() == fb.size());
    for (size_t f = 0; f < fa.size(); ++f) CHECK(fb[f]->lambda / force == Approx(fa[f]->lambda).epsilon(1e-8));
  }
}
