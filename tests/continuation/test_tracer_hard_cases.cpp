// Hard cases of the tracer (issue 33, docs/continuation.md "Hard cases"): a branch point reached
// along its bifurcated branch, at the branch's tip, is one branch point, located once, in both
// directions and at every step setting; never a fold as well.
#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace buckle::continuation;

namespace {

/// The side branch u₁² = λ of TwoPitchforks at u₁ = s (u₂ = 0).
Vector sideBranch(double s) { return (Vector(2) << s, 0.0).finished(); }

}  // namespace

TEST_CASE("A pitchfork reached along its side branch: one BP at the tip, both ways, no fold", "[tracer][hard]") {
  // F = (λu₁ − u₁³, (λ − c)u₂ − u₂³): the side branch λ = u₁² turns in λ at the branch point
  // (0, 0), where it touches the trivial branch u = 0 without crossing; H = −F_u = diag(2λ, c − λ)
  // on it, stable on both sides (the zero eigenvalue touches zero, ν does not change).
  toys::TwoPitchforks problem(1.0);
  for (const double start : {0.6, -0.6})
    for (const double maxStep : {0.013, 0.05, 0.1, 0.2, 0.3, 0.6}) {
      TracerOptions options;
      options.step.maxStep = maxStep;
      options.step.initialStep = std::min(0.02, maxStep);
      options.lambdaMax = 0.5;
      // through the tip: λ decreases to 0 at u₁ = 0, then grows again on the other side
      const Branch branch = trace(problem, sideBranch(start), start * start, InitialDirection::decreasingLambda(), options);
      INFO("start " << start << " maxStep " << maxStep);
      CHECK(branch.stopReason == StopReason::LambdaRange);
      CHECK(branch.points.back().u[0] * start < 0.0);  // it passed to the other side
      CHECK(branch.specialPointsOfType(SpecialPointType::Fold).empty());
      const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
      REQUIRE(bps.size() == 1);
      const SpecialPoint &bp = *bps[0];
      CHECK(std::abs(bp.lambda) <= 1e-12);
      CHECK(std::abs(bp.u[0]) <= 1e-6);
      CHECK(bp.refined);
      CHECK(bp.inertiaBefore == 0);  // stable on both sides
      CHECK(bp.inertiaAfter == 0);
      INFO(bp.note);
      // the other branch through it, the trivial one, is the one to switch to: λ moves along it
      Vector direction;
      std::string how;
      REQUIRE(bifurcatingDirection(problem, bp, direction, &how));
      CHECK(std::abs(direction[2]) >= 0.999 * direction.norm());
    }
}
