// The report of a traced branch (mechanics/branch_report.h): physical quantities, the
// displacement-controlled stability of a branch traced through a reaction (against an
// independent dense projected Hessian), the range filter, KMIN's deep-minimum rule, and the
// classification table of docs/mechanics.md.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/unloaded_shape.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// Independent: inertia of K_q − K_g(F) on the kernel of the rows of J that `end` holds, from
// the dense Hessian of the total potential.
int denseHeldNegative(const Chain& chain, const Eigen::VectorXd& q, const Wrench& F, const EndCondition& end) {
  const int n = chain.size();
  Matrix H(n, n);
  totalPotentialHessian(chain, q, F, H);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  const std::vector<int> held = end.heldIndices();
  Matrix C(held.size(), n);
  for (size_t k = 0; k < held.size(); ++k) C.row(Eigen::Index(k)) = J.row(held[k]);
  return cont::projectedInertia(H, C, 1e-10 * std::max(1.0, H.norm())).negative;
}

// Fx from 0 to −3 (past the U branch's fold and joint limits), the first branch points switched.
EquilibriumBranchOptions fxToMinus3() {
  EquilibriumBranchOptions opt;
  opt.tracer.lambdaMin = -3.0;
  opt.tracer.lambdaMax = 0.5;
  opt.tracer.step.maxStep = 0.05;
  opt.tree.branchSwitching = 1;
  return opt;
}

}  // namespace

TEST_CASE("traced through the reaction, a branch is reported against the held coordinate", "[branch_report]") {
  // The paper's chain with its end on the x-axis (y held), x driven through its reaction Fx:
  // the report must read as the chain with x held as well.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const EndCondition traced = EndCondition::clampedPinned(0.0);
  EndCondition held = traced;
  held.control[0] = Control::Held;
  EquilibriumProblem problem(chain, traced, Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions opt;
  opt.tracer.lambdaMin = -2.5;
  opt.tracer.lambdaMax = 0.0;
  opt.tracer.step.maxStep = 0.05;
  opt.tree.branchSwitching = 1;
  opt.report.heldCoordinate = 0;
  const double x0 = endPose(chain, Eigen::VectorXd::Zero(3))[0];
  opt.report.rangeLow = x0 - 1.0;  // the end moved in by at most one b
  opt.report.rangeHigh = x0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), opt);
  REQUIRE(r.tree.branches.size() >= 3);  // the straight branch, U and Z (both sides)
  int compared = 0, filtered = 0;
  for (size_t b = 0; b < r.tree.branches.size(); ++b) {
    const BranchReport& rep = r.reports[b];
    filtered += int(r.tree.branches[b].points.size()) - int(rep.points.size());
    for (const PointReport& p : rep.points) {
      const cont::ContinuationPoint& tp = r.tree.branches[b].points[size_t(p.index)];
      CHECK(p.q == tp.u.head(3));
      CHECK(p.F == problem.wrench(tp.u, tp.lambda));
      CHECK(p.parameter == endPose(chain, p.q)[0]);
      CHECK(p.parameter >= opt.report.rangeLow - 1e-9);
      CHECK(p.parameter <= opt.report.rangeHigh + 1e-9);
      CHECK(p.negative == denseHeldNegative(chain, p.q, p.F, held));
      CHECK(p.stable == (p.negative == 0));
      ++compared;
    }
    for (const SpecialPointReport& s : rep.specialPoints) {
      CHECK(s.parameter >= opt.report.rangeLow - 1e-9);
      CHECK(s.parameter <= opt.report.rangeHigh + 1e-9);
      // a fold of the traced reaction is no fold of the held coordinate
      if (s.source >= 0) CHECK(s.type != EventType::Fold);
    }
  }
  CHECK(compared > 50);
  CHECK(filtered > 0);  // the tree goes beyond the range: the filter had something to do
}

TEST_CASE("a fold with a stable side is a jump, between unstable parts no event", "[branch_report]") {
  // Fig 8 setting: a nearly non-monotonic segment chain folds under Fx.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const EquilibriumBranchOptions opt = fxToMinus3();
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), opt);
  int folds = 0;
  for (const BranchReport& rep : r.reports)
    for (const SpecialPointReport& s : rep.specialPoints) {
      CHECK(std::string(label(s.type)) != "?");
      CHECK(s.stabilityBefore == stabilityLabel(s.negativeBefore));
      if (s.type == EventType::BranchPoint) CHECK(s.phenomenon == Phenomenon::Buckling);
      if (s.type != EventType::Fold) continue;
      ++folds;
      const bool stableSide = s.negativeBefore == 0 || s.negativeAfter == 0;
      CHECK(s.phenomenon == (stableSide ? Phenomenon::Jumping : Phenomenon::None));
      CHECK(s.jumps == stableSide);
    }
  CHECK(folds >= 1);  // the U branch folds back (Fx ≈ −1.755) before its joint limit
}

TEST_CASE("KMIN: a deep local minimum of Kxx along a stable stretch, scale-free", "[branch_report]") {
  // Fig 9/10: the non-straight chain a/b = 0.75 under Fx quasi-buckles.
  const double theta = std::acos(7.0 / 8.0);
  Eigen::VectorXd q0(3);
  q0 << theta, -2.0 * theta, theta;
  for (double unit : {1.0, 1e-3, 1e3}) {  // lengths in b; stiffness 1: the same minimum, scaled
    const SegmentParameters p = SegmentParameters::symmetric(0.75 * unit, unit, 1.0, 2.25 * unit);
    const Chain chain(preloadsForShape(std::vector<SegmentParameters>(3, p), q0));
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
    EquilibriumBranchOptions opt;
    opt.tracer.lambdaMin = -2.0 * unit;
    opt.tracer.lambdaMax = 0.0;
    opt.tree.branchSwitching = 0;
    opt.report.stiffness = true;
    const EquilibriumBranches r =
        traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), opt);
    const BranchReport& rep = r.reports.front();
    REQUIRE(rep.points.size() >= 3);
    const double k0 = rep.points.front().K(0, 0);
    int kmin = 0;
    for (const SpecialPointReport& s : rep.specialPoints) {
      if (s.type != EventType::StiffnessMinimum) continue;
      ++kmin;
      CHECK(s.phenomenon == Phenomenon::QuasiBuckling);
      // Located between the traced points index and index + 1, below both.
      size_t i = 0;
      while (i < rep.points.size() && rep.points[i].index != s.index) ++i;
      REQUIRE(i + 1 < rep.points.size());
      REQUIRE(s.refined);
      const double km = loadedStiffness(chain, s.q, s.F, problem.endCondition()).stiffness(0, 0);
      CHECK(km < opt.report.deepStiffnessRatio * k0);
      CHECK(km <= rep.points[i].K(0, 0));
      CHECK(km <= rep.points[i + 1].K(0, 0));
      CHECK(rep.points[i].stable);
      CHECK(rep.points[i + 1].stable);
    }
    CHECK(kmin == 1);
  }
}

TEST_CASE("after an interrupt the report skips the post-buckling refinements and says so", "[branch_report]") {
  // The paper's chain: two BPs on the straight branch, each with Koiter's coefficients. Reported
  // again with an interrupt already requested, each BP keeps its location and its stability
  // counts but has no coefficients, and its note names the reason.
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25)),
                             EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o;
  o.tracer.lambdaMin = -1.6;
  o.tracer.step.maxStep = 0.05;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const cont::Branch& straight = r.tree.branches.at(0);
  std::atomic<bool> stop{true};
  ReportOptions late;
  late.interrupt.watch(&stop, "SIGTERM received");
  const BranchReport full = reportBranch(problem, straight, ReportOptions());
  const BranchReport cut = reportBranch(problem, straight, late);
  REQUIRE(full.specialPoints.size() == cut.specialPoints.size());
  int bps = 0;
  for (size_t s = 0; s < full.specialPoints.size(); ++s) {
    if (full.specialPoints[s].type != EventType::BranchPoint) continue;
    ++bps;
    CHECK(full.specialPoints[s].koiter.valid);
    CHECK(!cut.specialPoints[s].koiter.valid);
    CHECK(cut.specialPoints[s].imperfections.empty());
    CHECK(cut.specialPoints[s].parameter == full.specialPoints[s].parameter);
    CHECK(cut.specialPoints[s].negativeAfter == full.specialPoints[s].negativeAfter);
    CHECK(cut.specialPoints[s].note.find("post-buckling coefficients not computed: SIGTERM received") !=
          std::string::npos);
  }
  CHECK(bps == 2);
  // what was left out is on the report itself (the run counts it as interrupted)
  CHECK(full.skipped.empty());
  CHECK(cut.skipped == "not computed: post-buckling coefficients (SIGTERM received)");
}

TEST_CASE("after an interrupt the report leaves the remaining stiffness and the minima out and says so",
          "[branch_report]") {
  // The quasi-buckling chain of Fig 9/10 (one KMIN): reported again with an interrupt already
  // requested, no point has K (NaN, haveStiffness false), no KMIN is claimed from the missing
  // values, and `skipped` counts the points left out.
  const double theta = std::acos(7.0 / 8.0);
  Eigen::VectorXd q0(3);
  q0 << theta, -2.0 * theta, theta;
  const SegmentParameters p = SegmentParameters::symmetric(0.75, 1.0, 1.0, 2.25);
  const Chain chain(preloadsForShape(std::vector<SegmentParameters>(3, p), q0));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions opt;
  opt.tracer.lambdaMin = -2.0;
  opt.tracer.lambdaMax = 0.0;
  opt.tree.branchSwitching = 0;
  const EquilibriumBranches r = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), opt);
  const cont::Branch& branch = r.tree.branches.at(0);
  ReportOptions asked;
  asked.stiffness = true;
  const BranchReport full = reportBranch(problem, branch, asked);
  std::atomic<bool> stop{true};
  ReportOptions late = asked;
  late.interrupt.watch(&stop, "SIGINT received");
  const BranchReport cut = reportBranch(problem, branch, late);
  REQUIRE(full.points.size() == cut.points.size());
  REQUIRE(full.points.size() >= 3);
  auto kmins = [](const BranchReport& rep) {
    return std::count_if(rep.specialPoints.begin(), rep.specialPoints.end(),
                         [](const SpecialPointReport& s) { return s.type == EventType::StiffnessMinimum; });
  };
  CHECK(kmins(full) == 1);
  CHECK(kmins(cut) == 0);
  for (size_t i = 0; i < full.points.size(); ++i) {
    CHECK(full.points[i].haveStiffness);
    CHECK(!cut.points[i].haveStiffness);
    CHECK(std::isnan(cut.points[i].K(0, 0)));
    CHECK(cut.points[i].parameter == full.points[i].parameter);  // the points themselves are kept
  }
  CHECK(full.skipped.empty());
  // the chain curls through its base on this branch: that contact, detected only, is not located either
  const bool touches = std::any_of(full.specialPoints.begin(), full.specialPoints.end(), [](const SpecialPointReport& s) {
    return s.type == EventType::BaseContact || s.type == EventType::SelfContact;
  });
  CHECK(cut.skipped == "not computed: the loaded stiffness at " + std::to_string(full.points.size()) + " of " +
                           std::to_string(full.points.size()) + " points, the stiffness minima" +
                           (touches ? ", the location of base and self contacts" : "") + " (SIGINT received)");
}

TEST_CASE("steps that collapse next to a user's stop are no joint limit: the branch is unfinished", "[branch_report]") {
  // Only a geometric limit (the closing spring at zero length, where the smooth model ends) ends a
  // collapsing branch regularly. A user's stop inside the geometric range is held by the contact
  // model (or located as a boundary without it): the U and Z branches of the paper's chain with
  // |q| ≤ 1.5 lock joints on it and go on to the path's end. The same points ending with the
  // steps collapsed instead, a joint on its stop, must read as a failure, not as a joint limit.
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.qMinUser = -1.5;
  p.qMaxUser = 1.5;
  const Chain chain = Chain::uniform(3, p);
  REQUIRE(chain.segment(0).geometricUpperLimit() > 1.5 + 0.1);
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const EquilibriumBranchOptions opt = fxToMinus3();
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), opt);
  REQUIRE(r.contact.size() == r.tree.branches.size());
  int checked = 0;
  for (size_t k = 0; k < r.tree.branches.size(); ++k) {
    cont::Branch b = r.tree.branches[k];
    if (b.points.empty() || std::abs(b.points.back().u.head(3).cwiseAbs().maxCoeff() - 1.5) > 1e-9) continue;
    CHECK(r.reports[k].finished);  // a joint on its stop at the path's end
    b.stopReason = cont::StopReason::StepSizeTooSmall;
    b.stopMessage = "step size below minimum";
    const BranchReport collapsed = reportBranch(problem, b, opt.report, r.contact[k]);
    CHECK_FALSE(collapsed.finished);
    CHECK(collapsed.stopReason == cont::toString(cont::StopReason::StepSizeTooSmall));
    // no collapsed limit added to the points the branch located itself
    const auto limits = [](const BranchReport& rep) {
      return std::count_if(rep.specialPoints.begin(), rep.specialPoints.end(),
                           [](const SpecialPointReport& s) { return s.type == EventType::JointLimit; });
    };
    CHECK(limits(collapsed) == limits(r.reports[k]));
    ++checked;
  }
  CHECK(checked >= 2);  // U and Z
}
