// Control inputs as the path parameter (control_path.h, equilibrium_problem.h with a control
// direction; issue 29): the exact λ-derivatives against finite differences, a point of a control
// path against the same chain reached by loading it (the equilibrium does not depend on the
// route), a fold of a dL0 path on the two-parameter fold curve in (dL0, load) traced from another
// fold, and the same path in scaled units.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/derivative_check.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/critical_curves.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/branch_report.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/stiffness_extremum.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "fixed_lambda_newton.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The example: the default segment under the payload Fx = Fy = −0.3 (k b units).
const Eigen::Vector3d kPayload(-0.3, -0.3, 0.0);

Chain defaultChain(int n, double L = 1.0, double k = 1.0) {
  return Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L));
}

cont::TracerOptions tracerOptions(double lambdaMin, double lambdaMax) {
  cont::TracerOptions o;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = lambdaMax;
  o.maxPoints = 5000;
  o.detection.stability = true;
  o.corrector.tolerance = 1e-12;
  return o;
}

// The chain under `load` reached from the unloaded shape by loading it along λ·load, λ: 0 → 1.
Eigen::VectorXd loaded(const Chain& chain, const Eigen::Vector3d& load) {
  const UnloadedShape shape = unloadedShape(chain);
  REQUIRE(shape.allFound);
  EquilibriumProblem ramp(chain, EndCondition::freeEnd(), load);
  const cont::Branch b = cont::trace(ramp, shape.q, 0.0, cont::InitialDirection::increasingLambda(),
                                     tracerOptions(-1.0, 1.0));
  REQUIRE(b.stopReason == cont::StopReason::LambdaRange);
  REQUIRE(b.specialPointsOfType(cont::SpecialPointType::Fold).empty());  // no snap on the way
  REQUIRE(b.points.back().lambda == Approx(1.0).margin(1e-14));
  return b.points.back().u;
}

// Newton at fixed λ on F_u (dense): the equilibrium polished to rounding.
Eigen::VectorXd polish(EquilibriumProblem& p, const Eigen::VectorXd& u, double lambda) {
  return buckle::test::polishAtFixedLambda(p, u, lambda);
}

}  // namespace

TEST_CASE("control path: named directions, input values and the chain at lambda", "[control_path]") {
  const ControlDirection all = ControlDirection::named(3, ControlInput::dL0);
  CHECK(all.rates.rows() == 3);
  for (int i = 0; i < 3; ++i) {
    CHECK(all.rates(i, 0) == 0.5);
    CHECK(all.rates(i, 1) == -0.5);
  }
  const ControlDirection one = ControlDirection::named(3, ControlInput::L0, 1);
  CHECK(one.rates.row(0).isZero());
  CHECK(one.rates.row(2).isZero());
  CHECK(one.rates(1, 0) == 1.0);
  CHECK(one.rates(1, 1) == 1.0);
  CHECK_THROWS_WITH(ControlDirection::named(3, ControlInput::L1_0, 3), Catch::Contains("out of range 1..3"));
  for (ControlInput c : {ControlInput::L1_0, ControlInput::L2_0, ControlInput::L0, ControlInput::dL0}) {
    ControlInput parsed;
    REQUIRE(parseControlInput(controlInputName(c), parsed));
    CHECK(parsed == c);
  }
  ControlInput parsed;
  CHECK_FALSE(parseControlInput("L3_0", parsed));

  // Along each named direction λ − origin is the change of that input, the other mode kept.
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.L1_0 = 2.4;
  p.L2_0 = 2.0;
  const Chain chain = Chain::uniform(2, p);
  for (ControlInput c : {ControlInput::L1_0, ControlInput::L2_0, ControlInput::L0, ControlInput::dL0}) {
    INFO(controlInputName(c));
    ControlDirection d = ControlDirection::named(2, c, 1);
    d.origin = controlInputValue(chain, c, 1);
    const Chain moved = chainWithControls(chain, d, d.origin + 0.125);
    CHECK(controlInputValue(moved, c, 1) == Approx(d.origin + 0.125).epsilon(1e-15));
    CHECK(controlInputValue(moved, c, 0) == controlInputValue(chain, c, 0));  // segment 1 untouched
    if (c == ControlInput::dL0) CHECK(controlInputValue(moved, ControlInput::L0, 1) == Approx(2.2).epsilon(1e-15));
    if (c == ControlInput::L0) CHECK(controlInputValue(moved, ControlInput::dL0, 1) == Approx(0.4).epsilon(1e-15));
  }
  CHECK(controlInputValue(chain, ControlInput::dL0) == Approx(0.4).epsilon(1e-15));
  CHECK_THROWS_WITH(chainWithControls(chain, ControlDirection::named(2, ControlInput::L2_0), -2.0),
                    Catch::Contains("segment 1: L2_0"));
}

TEST_CASE("segment: the energy jet with given free lengths and its control rate", "[control_path]") {
  SegmentParameters p = SegmentParameters::symmetric(0.4, 1.1, 1.3, 2.25);
  p.k2 = 0.7;
  const Segment s(p);
  for (double q : {-1.2, -0.3, 0.0, 0.7, 1.5}) {
    INFO("q = " << q);
    SegmentParameters moved = p;
    moved.L1_0 = 2.6;
    moved.L2_0 = 1.9;
    const Jet3 reference = Segment(moved).energyJet(q);
    Jet3 rate;
    const Jet3 e = s.energyJet(q, std::sin(0.5 * q), std::cos(0.5 * q), 2.6, 1.9, 0.3, -1.1, rate);
    // the same sums: bit for bit the segment with those free lengths
    CHECK(e.value == reference.value);
    CHECK(e.d1 == reference.d1);
    CHECK(e.d2 == reference.d2);
    CHECK(e.d3 == reference.d3);
    // the rate against the forward-mode parameter derivative at those free lengths
    SegmentParameterDirection dp;
    dp.L1_0 = 0.3;
    dp.L2_0 = -1.1;
    const Jet3 exact = Segment(moved).energyJetParameterDerivative(q, dp);
    const double scale = 1.3 * 2.6 * 1.1;
    CHECK(std::abs(rate.value - exact.value) <= 1e-13 * scale);
    CHECK(std::abs(rate.d1 - exact.d1) <= 1e-13 * scale);
    CHECK(std::abs(rate.d2 - exact.d2) <= 1e-13 * scale);
    CHECK(std::abs(rate.d3 - exact.d3) <= 1e-13 * scale);
  }
}

TEST_CASE("equilibrium problem: control derivatives match finite differences", "[control_path]") {
  struct Case {
    ControlInput input;
    int segment;
    EndCondition end;
    Eigen::Vector3d loadDirection;
  };
  const std::vector<Case> cases = {
      {ControlInput::dL0, -1, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero()},
      {ControlInput::L0, -1, EndCondition::freeEnd(Eigen::Vector3d(-0.2, 0.1, 0.05)), Eigen::Vector3d::Zero()},
      {ControlInput::L1_0, 1, EndCondition::heldPosition(2.5, 2.0), Eigen::Vector3d::Zero()},
      {ControlInput::L2_0, 2, EndCondition::clampedPinned(-0.3, 0.4), Eigen::Vector3d(0.0, 0.2, 0.0)},
      {ControlInput::dL0, 0, EndCondition::freeEnd(kPayload), Eigen::Vector3d(0.1, 0.0, -0.2)},
  };
  for (int n : {3, 12}) {
    for (size_t k = 0; k < cases.size(); ++k) {
      INFO("n = " << n << ", case " << k);
      const Case& cs = cases[k];
      ControlDirection d = ControlDirection::named(n, cs.input, cs.segment);
      d.origin = 0.2;
      EquilibriumProblem problem(defaultChain(n), cs.end, cs.loadDirection, {}, d);
      Eigen::VectorXd u(problem.dimension());
      for (int i = 0; i < u.size(); ++i) u[i] = i < n ? 0.3 * std::sin(1.7 * i + 0.4) : 0.2 + 0.1 * i;
      const cont::DerivativeCheck check = cont::checkDerivatives(problem, u, 0.55);
      INFO(check.message);
      CHECK(check.success);
      for (const char* name : {"F_lambda", "jacobianApply", "jacobianTransposeApply"}) {
        INFO(name);
        const cont::DerivativeComparison* c = check.find(name);
        REQUIRE(c != nullptr);
        CHECK(c->evaluated);
      }
      // the residual is the chain's with its free lengths at λ, bit for bit
      EquilibriumProblem atLambda(problem.chainAt(0.55), cs.end, cs.loadDirection);
      Eigen::VectorXd F(problem.dimension()), G(problem.dimension());
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, 0.55, F));
      REQUIRE(buckle::continuation::BoundProblem(atLambda).residual(u, 0.55, G));
      CHECK((F - G).cwiseAbs().maxCoeff() == 0.0);
    }
  }
  // a free length driven through zero is refused, not evaluated
  EquilibriumProblem problem(defaultChain(3), EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {},
                             ControlDirection::named(3, ControlInput::L1_0, 0));
  Eigen::VectorXd F(3);
  CHECK(buckle::continuation::BoundProblem(problem).residual(Eigen::VectorXd::Zero(3), -1.0, F));
  CHECK_FALSE(buckle::continuation::BoundProblem(problem).residual(Eigen::VectorXd::Zero(3), -2.25, F));
  ControlDirection wrong = ControlDirection::named(2, ControlInput::L0);
  CHECK_THROWS_WITH(EquilibriumProblem(defaultChain(3), EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {}, wrong),
                    Catch::Contains("rates for 2 segments, the chain has 3"));
}

TEST_CASE("a state along a dL0 path is the equilibrium reached by loading the chain at those inputs",
          "[control_path]") {
  for (int n : {3, 5}) {
    INFO("n = " << n);
    const Chain chain = defaultChain(n);
    const Eigen::VectorXd start = loaded(chain, kPayload);
    EquilibriumProblem actuated(chain, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero(), {},
                                ControlDirection::named(n, ControlInput::dL0));
    // dL0 > 0 bends the unloaded chain the way the payload does (no second equilibrium the
    // loading could end on; towards dL0 < 0 this path snaps, see below)
    const double target = 1.5;
    const cont::Branch b = cont::trace(actuated, start, 0.0, cont::InitialDirection::increasingLambda(),
                                       tracerOptions(-1.0, target));
    REQUIRE(b.stopReason == cont::StopReason::LambdaRange);
    REQUIRE(b.points.back().lambda == target);
    const Eigen::VectorXd viaControls = polish(actuated, b.points.back().u, target);

    // the same inputs set first, then the payload applied from the unloaded shape
    const Chain set = actuated.chainAt(target);
    CHECK(controlInputValue(set, ControlInput::dL0) == Approx(target).epsilon(1e-15));
    EquilibriumProblem atInputs(set, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero());
    const Eigen::VectorXd viaLoad = polish(atInputs, loaded(set, kPayload), 0.0);
    CHECK((viaControls - viaLoad).cwiseAbs().maxCoeff() <= 1e-12 * viaLoad.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("a fold of the dL0 path lies on the fold curve in (dL0, load) traced from another fold", "[control_path]") {
  const int n = 3;
  const Chain chain = defaultChain(n);
  EquilibriumProblem actuated(chain, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero(), {},
                              ControlDirection::named(n, ControlInput::dL0));
  const cont::Branch b = cont::trace(actuated, loaded(chain, kPayload), 0.0,
                                     cont::InitialDirection::decreasingLambda(), tracerOptions(-3.0, 3.0));
  const auto folds = b.specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(!folds.empty());
  const cont::SpecialPoint& fold = *folds.front();  // snap-through under actuation
  CHECK(fold.inertiaBefore == 0);
  CHECK(fold.inertiaAfter == 1);

  // A regular point of the same branch before the fold, at dL0 = μ0: the chain there, loaded
  // along λ·payload (λ = 1 at the point), has a fold in λ nearby; its fold curve in μ = dL0,
  // traced up to μ = dL0 of the actuation fold, must arrive at λ = 1 (the payload) and q there.
  const cont::ContinuationPoint& before = b.points[size_t(std::max(0, fold.index - 1))];
  const double mu0 = before.lambda;
  REQUIRE(mu0 > fold.lambda);
  ChainParameterProblem two(std::vector<SegmentParameters>(size_t(n), actuated.chainAt(mu0).segment(0).parameters()),
                            EndCondition::freeEnd(), kPayload, SecondParameter::parse("dL0"));
  REQUIRE(two.secondParameter() == Approx(mu0).epsilon(1e-14));
  cont::TracerOptions to = tracerOptions(0.0, 2.0);
  to.detection.stability = true;
  const cont::Branch loadPath = cont::trace(two, before.u, 1.0, cont::InitialDirection::increasingLambda(), to);
  const cont::Branch loadBack = cont::trace(two, before.u, 1.0, cont::InitialDirection::decreasingLambda(), to);
  const cont::SpecialPoint* loadFold = nullptr;
  for (const cont::Branch* lb : {&loadPath, &loadBack})
    for (const cont::SpecialPoint* sp : lb->specialPointsOfType(cont::SpecialPointType::Fold))
      if (!loadFold || std::abs(sp->lambda - 1.0) < std::abs(loadFold->lambda - 1.0)) loadFold = sp;
  REQUIRE(loadFold != nullptr);
  CHECK(std::abs(loadFold->lambda - 1.0) > 1e-4);  // a different fold of the two-parameter family

  CriticalCurveOptions co;
  co.muMin = fold.lambda;
  co.muMax = mu0 + 1.0;
  co.tracer.step.maxStep = 0.05;
  co.tracer.maxPoints = 2000;
  co.tracer.corrector.tolerance = 1e-12;
  const CriticalCurve curve = foldCurve(two, *loadFold, co);
  REQUIRE(curve.type == "LP");
  const CriticalPoint* at = nullptr;
  for (const CriticalPoint& cp : curve.points)
    if (cp.mu == Approx(fold.lambda).epsilon(1e-12)) at = &cp;
  REQUIRE(at != nullptr);  // the curve reached μ = dL0 of the fold (its range end)
  CHECK(std::abs(at->lambda - 1.0) <= 1e-8);
  CHECK((at->u.head(n) - fold.u.head(n)).cwiseAbs().maxCoeff() <= 1e-7);
}

TEST_CASE("a dL0 path in scaled units (lengths x 1e4, stiffness x 1e-8) is the same path", "[control_path]") {
  const int n = 3;
  const auto folds = [n](double L, double k) {
    const Chain chain = defaultChain(n, L, k);
    const Eigen::Vector3d payload = k * L * kPayload;
    EquilibriumProblem actuated(chain, EndCondition::freeEnd(payload), Eigen::Vector3d::Zero(), {},
                                ControlDirection::named(n, ControlInput::dL0));
    const cont::Branch b = cont::trace(actuated, loaded(chain, payload), 0.0, cont::InitialDirection::decreasingLambda(),
                                       tracerOptions(-3.0 * L, 3.0 * L));
    std::vector<cont::SpecialPoint> out;
    for (const cont::SpecialPoint* sp : b.specialPointsOfType(cont::SpecialPointType::Fold)) out.push_back(*sp);
    return out;
  };
  const std::vector<cont::SpecialPoint> reference = folds(1.0, 1.0);
  const std::vector<cont::SpecialPoint> scaled = folds(1e4, 1e-8);
  REQUIRE(!reference.empty());
  REQUIRE(scaled.size() == reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    CHECK(std::abs(scaled[i].lambda - 1e4 * reference[i].lambda) <= 1e-10 * 1e4 * std::abs(reference[i].lambda));
    CHECK((scaled[i].u.head(n) - reference[i].u.head(n)).cwiseAbs().maxCoeff() <= 1e-9);
  }
}

TEST_CASE("an actuation history snaps at the dL0 fold and lands on an equilibrium of the actuated chain",
          "[control_path]") {
  const int n = 3;
  const Chain chain = defaultChain(n);
  EquilibriumProblem actuated(chain, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero(), {},
                              ControlDirection::named(n, ControlInput::dL0));
  LoadHistoryOptions options;
  options.tracer = tracerOptions(-3.0, 3.0);
  const LoadHistoryResult h = followLoadHistory(actuated, loaded(chain, kPayload), {0.0, -3.0, 3.0}, options);
  CHECK(h.success);
  REQUIRE(!h.jumps.empty());
  const JumpRecord& j = h.jumps.front();
  CHECK(j.trigger == JumpTrigger::Fold);
  REQUIRE(j.success);
  // the landing: an equilibrium of the chain with its inputs at the release value, of lower
  // potential (E of the free lengths there, minus the payload's work)
  EquilibriumProblem there(actuated.chainAt(j.lambda), EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero());
  Eigen::VectorXd F(n);
  REQUIRE(buckle::continuation::BoundProblem(there).residual(j.to, 0.0, F));
  CHECK(F.norm() <= 1e-9);
  const Chain released = actuated.chainAt(j.lambda);
  CHECK(j.energyReleased ==
        Approx(totalPotential(released, j.from.head(n), kPayload) - totalPotential(released, j.to.head(n), kPayload))
            .epsilon(1e-9));
  CHECK(j.energyReleased > 0.0);
}

TEST_CASE("stiffness along a control path: K_F of the free lengths at the point, its rate by differences",
          "[control_path]") {
  const int n = 3;
  const Chain chain = defaultChain(n);
  EquilibriumProblem actuated(chain, EndCondition::freeEnd(kPayload), Eigen::Vector3d::Zero(), {},
                              ControlDirection::named(n, ControlInput::dL0));
  const cont::Branch b = cont::trace(actuated, loaded(chain, kPayload), 0.0, cont::InitialDirection::increasingLambda(),
                                     tracerOptions(-1.0, 2.0));
  ReportOptions ro;
  ro.stiffness = true;
  const BranchReport r = reportBranch(actuated, b, ro);
  REQUIRE(r.points.size() > 5);
  for (const PointReport& p : r.points) {
    REQUIRE(p.haveStiffness);
    const double lambda = b.points[size_t(p.index)].lambda;
    const Eigen::Matrix2d K = loadedStiffness(actuated.chainAt(lambda), p.q, p.F).stiffness;
    CHECK((p.K - K).norm() <= 1e-12 * K.norm());
  }
  // the rate of each measure along the tangent against central differences of K_F(q, F, λ)
  const cont::ContinuationPoint& p = b.points[b.points.size() / 2];
  const int N = actuated.dimension();
  for (StiffnessMeasure m : {StiffnessMeasure::Kxx, StiffnessMeasure::Kyy, StiffnessMeasure::MinEigenvalue}) {
    INFO(toString(m));
    const StiffnessRate sr = stiffnessRate(actuated, p.u, p.lambda, p.tangent.head(N), p.tangent[N], m);
    REQUIRE(sr.valid);
    const double h = 1e-5;
    double at[2];
    for (int s = 0; s < 2; ++s) {
      const double sign = s == 0 ? 1.0 : -1.0;
      const Eigen::VectorXd u = p.u + sign * h * p.tangent.head(N);
      const double lambda = p.lambda + sign * h * p.tangent[N];
      at[s] = stiffnessMeasure(loadedStiffness(actuated.chainAt(lambda), u.head(n), actuated.wrench(u, lambda)).stiffness, m);
    }
    CHECK(sr.rate == Approx((at[0] - at[1]) / (2.0 * h)).epsilon(1e-6).margin(1e-9 * std::abs(sr.value)));
  }
}

TEST_CASE("the straight column under a fixed Fx buckles along an L0 path where eq 17 gives that Fx, the "
          "buckled branch is switched to", "[control_path]") {
  // Fx_U = λ_U κ/b with κ = k(b L0 − 2(b² − a²)) (eq 17) is affine in L0: the L0 where it equals Fx
  const double Fx = -0.5;
  const double f1 = analyticClampedPinned3(0.5, 1.0, 1.0, 2.0).FxU, f2 = analyticClampedPinned3(0.5, 1.0, 1.0, 2.5).FxU;
  const double L0c = 2.0 + (Fx - f1) * 0.5 / (f2 - f1);
  REQUIRE(analyticClampedPinned3(0.5, 1.0, 1.0, L0c).FxU == Approx(Fx).epsilon(1e-12));
  REQUIRE(L0c < 2.25);
  ControlDirection d = ControlDirection::named(3, ControlInput::L0);
  d.origin = 2.25;
  EquilibriumProblem actuated(defaultChain(3), EndCondition::clampedPinned(Fx), Eigen::Vector3d::Zero(), {}, d);
  cont::Tracer tracer(actuated, tracerOptions(1.6, 2.25));
  const cont::Branch straight =
      tracer.trace(actuated.initialGuess(Eigen::VectorXd::Zero(3), 2.25), 2.25, cont::InitialDirection::decreasingLambda());
  const auto bps = straight.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  CHECK(std::abs(bps[0]->lambda - L0c) <= 1e-10);
  CHECK(bps[0]->u.head(3).cwiseAbs().maxCoeff() <= 1e-12);  // on the straight branch
  CHECK(bps[0]->inertiaBefore == 0);
  CHECK(bps[0]->inertiaAfter == 1);
  Eigen::VectorXd direction;
  REQUIRE(cont::bifurcatingDirection(actuated, *bps[0], direction));
  const cont::Branch u = cont::switchBranch(tracer, *bps[0], direction, 1);
  REQUIRE(u.points.size() > 3);
  // bent, and an equilibrium of the chain with its free lengths at that L0
  const cont::ContinuationPoint& far = u.points.back();
  CHECK(far.u.head(3).cwiseAbs().maxCoeff() > 1e-2);
  EquilibriumProblem there(actuated.chainAt(far.lambda), EndCondition::clampedPinned(Fx), Eigen::Vector3d::Zero());
  Eigen::VectorXd F(4);
  REQUIRE(buckle::continuation::BoundProblem(there).residual(far.u, 0.0, F));
  CHECK(F.norm() <= 1e-9);
}
