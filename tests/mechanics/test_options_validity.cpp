// Every options struct of the mechanics layer validates itself as the core's do
// (continuation/options_validity.h): the defaults are valid, a bad field is named by its path
// inside the struct it was set through, and each entry point throws std::invalid_argument
// "<Struct>: <path> ..." before computing anything (docs/continuation.md, "Errors").
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/critical_curves.h"
#include "buckle/mechanics/disconnected_branches.h"
#include "buckle/mechanics/energy_landscape.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/load_history.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/stiffness_extremum.h"
#include "buckle/mechanics/task_path_trace.h"
#include "buckle/mechanics/unloaded_shape.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;
using Catch::Matchers::StartsWith;

namespace {

const SegmentParameters kSegment = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);

Chain chain3() { return Chain::uniform(3, kSegment); }

EquilibriumProblem pinned(const Chain& chain) {
  return EquilibriumProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
}

// `call` throws std::invalid_argument starting with `expected` ("<Struct>: <path>").
void refuses(const std::function<void()>& call, const std::string& expected) {
  INFO(expected);
  CHECK_THROWS_MATCHES(call(), std::invalid_argument, Catch::Matchers::Predicate<std::invalid_argument>(
                                                          [&](const std::invalid_argument& e) {
                                                            return std::string(e.what()).rfind(expected, 0) == 0;
                                                          },
                                                          "message starts with " + expected));
}

}  // namespace

TEST_CASE("mechanics options: every default is valid", "[options_validity]") {
  CHECK(StiffnessOptions().validate(3).empty());
  CHECK(StiffnessExtremumOptions().validate().empty());
  CHECK(LinearBucklingOptions().validate().empty());
  CHECK(DisconnectedBranchOptions().validate().empty());
  CHECK(EquilibriumBranchOptions().validate().empty());
  CHECK(ReportOptions().validate().empty());
  CHECK(EquilibriumOptions().validate().empty());
  CHECK(LandscapeOptions().validate().empty());
  CHECK(AllEquilibriaOptions().validate(3).empty());
  CHECK(UnloadedShapeOptions().validate().empty());
  CHECK(CriticalCurveOptions().validate().empty());
  CHECK(TaskPathOptions().validate().empty());
  CHECK(IntegrationOptions().validate().empty());
  const Chain chain = chain3();
  EquilibriumProblem problem = pinned(chain);
  CHECK(JumpOptions().validate(problem).empty());
  CHECK(SuddenLoadOptions().validate(chain).empty());
  CHECK(LoadHistoryOptions().validate(problem).empty());
}

TEST_CASE("mechanics options: a nested setting is named by its whole path", "[options_validity]") {
  EquilibriumBranchOptions branches;
  branches.tracer.step.maxStep = -1.0;
  CHECK_THAT(branches.validate(), StartsWith("tracer.step.maxStep"));
  branches = EquilibriumBranchOptions();
  branches.tree.switching.amplitude = -1.0;
  CHECK_THAT(branches.validate(), StartsWith("tree.switching.amplitude"));
  branches = EquilibriumBranchOptions();
  branches.report.deepStiffnessRatio = 0.0;
  CHECK_THAT(branches.validate(), StartsWith("report.deepStiffnessRatio"));

  DisconnectedBranchOptions disconnected;
  disconnected.branches.maxContactTorque = 0.0;
  CHECK_THAT(disconnected.validate(), StartsWith("branches.maxContactTorque"));

  const Chain chain = chain3();
  EquilibriumProblem problem = pinned(chain);
  LoadHistoryOptions history;
  history.jump.integration.maxSteps = 0;
  CHECK_THAT(history.validate(problem), StartsWith("jump.integration.maxSteps"));
  history = LoadHistoryOptions();
  history.jump.polish.tolerance = -1.0;
  CHECK_THAT(history.validate(problem), StartsWith("jump.polish.tolerance"));
  history = LoadHistoryOptions();
  history.tracer.corrector.maxIterations = 0;
  CHECK_THAT(history.validate(problem), StartsWith("tracer.corrector.maxIterations"));

  TaskPathOptions task;
  task.tracer.location.tolerance = 0.0;
  std::string why;
  CHECK_FALSE(task.IsValid(&why));
  CHECK_THAT(why, StartsWith("tracer.location.tolerance"));
}

TEST_CASE("mechanics options: each entry point refuses a bad setting before computing", "[options_validity]") {
  const Chain chain = chain3();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(3);

  EquilibriumOptions equilibrium;
  equilibrium.heldRange = {1, 0.5, -0.5};
  refuses([&] { EquilibriumProblem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0), equilibrium); },
          "EquilibriumOptions: heldRange.low");

  EquilibriumProblem problem = pinned(chain);
  EquilibriumBranchOptions branches;
  branches.tree.branchSwitching = -1;
  refuses([&] { traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), branches); },
          "EquilibriumBranchOptions: tree.branchSwitching");

  DisconnectedBranchOptions disconnected;
  disconnected.joinCosine = 0.0;
  refuses([&] { traceDisconnectedBranches(problem, {q0}, 0.0, {true}, {}, disconnected); },
          "DisconnectedBranchOptions: joinCosine");

  ReportOptions report;
  report.heldCoordinate = 3;
  const cont::Branch empty;
  refuses([&] { reportBranch(problem, empty, report); }, "ReportOptions: heldCoordinate");

  StiffnessOptions stiffness;
  stiffness.bodyGenerator = Eigen::VectorXd::Zero(2);
  refuses([&] { loadedStiffness(chain, q0, Wrench::Zero(), false, stiffness); }, "StiffnessOptions: bodyGenerator");
  stiffness = StiffnessOptions();
  stiffness.singularTolerance = 0.0;
  Eigen::Matrix2d K, dK;
  refuses([&] { loadedStiffnessDerivative(chain, q0, Wrench::Zero(), false, q0, Wrench::Zero(), K, dK, stiffness); },
          "StiffnessOptions: singularTolerance");

  StiffnessExtremumOptions extremum;
  extremum.maxEvaluations = 0;
  cont::ContinuationPoint a, b;
  a.u = b.u = Eigen::VectorXd::Zero(problem.dimension());
  refuses([&] { locateStiffnessMinimum(problem, a, b, StiffnessMeasure::Kxx, extremum); },
          "StiffnessExtremumOptions: maxEvaluations");

  LinearBucklingOptions buckling;
  buckling.direction = Eigen::Vector3d(1, std::nan(""), 0);
  refuses([&] { linearBuckling(chain, q0, EndCondition::clampedPinned(0.0), buckling); },
          "LinearBucklingOptions: direction");

  LandscapeOptions landscape;
  landscape.q1Min = 0.5;
  landscape.q1Max = -0.5;
  refuses([&] { energyLandscape(chain, 2.5, 0.0, landscape); }, "LandscapeOptions: q1Min");

  AllEquilibriaOptions all;
  all.starts = {Eigen::VectorXd::Zero(2)};
  refuses([&] { allEquilibria(chain, EndCondition::heldPosition(2.5, 0.0), all); }, "AllEquilibriaOptions: starts[0]");

  UnloadedShapeOptions unloaded;
  unloaded.tolerance = 0.0;
  refuses([&] { unloadedShape(chain, unloaded); }, "UnloadedShapeOptions: tolerance");

  CriticalCurveOptions curve;
  curve.muMin = 2.0;
  curve.muMax = 1.0;
  ChainParameterProblem parametric(std::vector<SegmentParameters>(3, kSegment), EndCondition::clampedPinned(0.0),
                                   Eigen::Vector3d(1, 0, 0), SecondParameter::parse("k"));
  refuses([&] { branchPointCurve(parametric, 0, curve); }, "CriticalCurveOptions: muMin");

  JumpOptions jump;
  jump.perturbation = -1.0;
  refuses([&] { simulateJump(problem, q0, 0.0, jump); }, "JumpOptions: perturbation");

  LoadHistoryOptions history;
  history.overshoot = 0.0;
  refuses([&] { followLoadHistory(problem, q0, {0.0, -0.1}, history); }, "LoadHistoryOptions: overshoot");
}
