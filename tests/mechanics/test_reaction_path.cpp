// Displacement control traced through the reaction (reaction_path.h, EquilibriumOptions::heldRange):
// the derived load limit against the paper's closed-form critical loads (eq 17), and the branches
// ending exactly where the held coordinate leaves the path's range, checked by an independent
// displacement-controlled Newton solve, in three unit systems.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/reaction_path.h"
#include "fixed_lambda_newton.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {
// End held at (x, 0), rotation free: the path's own end condition (x the driven coordinate).
EndCondition heldX(double x) { return EndCondition::heldPosition(x, 0.0); }
}  // namespace

TEST_CASE("the derived load limit is the margin times the critical reaction (eq 17)", "[reaction_path]") {
  for (const auto& [L, K] : {std::pair{1.0, 1.0}, std::pair{1e-4, 1e8}, std::pair{1e4, 1e-8}}) {
    for (double L0 : {2.0, 2.25, 2.5}) {
      const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, K, L0 * L));
      const AnalyticBuckling3 a = analyticClampedPinned3(0.5 * L, L, K, L0 * L);
      const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(3);
      const double x0 = endPose(chain, q0)[0];
      const ReactionLimit one = reactionLimit(chain, q0, heldX(x0), 0, 1);
      CHECK(one.modesFound == 1);
      CHECK(one.firstCritical == Approx(a.FxU).epsilon(1e-12));
      CHECK(one.governing == Approx(a.FxU).epsilon(1e-12));
      CHECK(one.limit == Approx(kReactionLimitMargin * std::abs(a.FxU)).epsilon(1e-12));
      const ReactionLimit two = reactionLimit(chain, q0, heldX(x0), 0, 2);
      CHECK(two.modesFound == 2);
      CHECK(two.firstCritical == Approx(a.FxU).epsilon(1e-12));
      CHECK(two.governing == Approx(a.FxZ).epsilon(1e-12));
      // asking for more than exist: the last one governs (two finite critical reactions with y held)
      const ReactionLimit many = reactionLimit(chain, q0, heldX(x0), 0, 5);
      CHECK(many.modesFound == 2);
      CHECK(many.limit == two.limit);
    }
  }
}

TEST_CASE("no load limit is derived where none exists", "[reaction_path]") {
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(3);
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const double x0 = endPose(chain, q0)[0];
  CHECK_THROWS_AS(reactionLimit(chain, q0, EndCondition::clampedPinned(0.0), 0), std::invalid_argument);  // x not held
  CHECK_THROWS_AS(reactionLimit(chain, q0, heldX(x0), 0, 0), std::invalid_argument);
  // κ = 0 (b L0 = 2(b² − a²)): K_q vanishes, every critical reaction is 0
  const Chain flat = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5));
  CHECK_THROWS_AS(reactionLimit(flat, q0, heldX(endPose(flat, q0)[0]), 0), std::invalid_argument);
}

TEST_CASE("traced through the reaction, a branch ends exactly at the held coordinate's range end",
          "[reaction_path]") {
  for (const auto& [L, K] : {std::pair{1.0, 1.0}, std::pair{1e-4, 1e8}, std::pair{1e4, 1e-8}}) {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, K, 2.25 * L));
    const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(3);
    const double x0 = endPose(chain, q0)[0];
    const double xEnd = x0 - 1.5 * L;  // Fig 6: x from 6 b down to 4.5 b
    const ReactionLimit rl = reactionLimit(chain, q0, heldX(x0), 0, 2);
    EquilibriumOptions eo;
    eo.heldRange = {0, xEnd, x0};
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0), eo);
    REQUIRE(problem.boundaryCount() == 2 * 3 + 2);
    EquilibriumBranchOptions opt;
    opt.tracer.lambdaMin = -rl.limit;
    opt.tracer.lambdaMax = 0.0;
    opt.tree.branchSwitching = 1;
    opt.report.heldCoordinate = 0;
    opt.report.rangeLow = xEnd;
    opt.report.rangeHigh = x0;
    const EquilibriumBranches r = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), opt);
    REQUIRE(r.tree.branches.size() >= 3);
    int atRangeEnd = 0;
    for (size_t b = 0; b < r.tree.branches.size(); ++b) {
      const cont::Branch& br = r.tree.branches[b];
      const BranchReport& rep = r.reports[b];
      for (const SpecialPointReport& s : rep.specialPoints) CHECK(s.type != EventType::Boundary);
      // every traced point is in the range: the branch stops where it leaves it
      CHECK(rep.points.size() == br.points.size());
      if (br.stopReason != cont::StopReason::Boundary) {
        if (b == 0) CHECK(rep.stopReason == "load limit");  // the straight branch never moves x
        continue;
      }
      REQUIRE(problem.isRangeBoundary(br.specialPoints.back().boundaryName));
      CHECK(rep.stopReason == cont::toString(cont::StopReason::LambdaRange));
      CHECK(rep.finished);
      ++atRangeEnd;
      const cont::ContinuationPoint& last = br.points.back();
      const Eigen::VectorXd q = last.u.head(3);
      CHECK(std::abs(endPose(chain, q)[0] - xEnd) <= 1e-9 * L);
      // independent: the equilibrium with the end held at (xEnd, 0), polished from it
      EquilibriumProblem held(chain, heldX(xEnd), Eigen::Vector3d::Zero());
      Eigen::VectorXd u(5);
      u << q, last.lambda, problem.wrench(last.u, last.lambda)[1];
      const Eigen::VectorXd polished = buckle::test::polishAtFixedLambda(held, u, 0.0);
      CHECK((polished.head(3) - q).norm() <= 1e-8);
      CHECK(std::abs(polished[3] - last.lambda) <= 1e-8 * K * L);
    }
    CHECK(atRangeEnd >= 2);  // the U branch, both sides (the Z branch may reach the load limit first)
  }
}
