// Every options struct of the core says what is wrong with it the same way (options_validity.h):
// validate() names the bad field by its path inside the struct it was set through, IsValid is the
// same answer, and each entry point refuses invalid options before computing anything.
#include "buckle/continuation/options_validity.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/curve_zeros.h"
#include "buckle/continuation/derivative_check.h"
#include "buckle/continuation/internal/locator.h"
#include "buckle/continuation/numeric_diff.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

using namespace buckle::continuation;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

using toys::vec1;

// The residual of a circle only: its derivatives by differences.
class DifferencedCircle : public NumericDiffProblem {
 public:
  using NumericDiffProblem::NumericDiffProblem;
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace&, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = u[0] * u[0] + lambda * lambda - 1.0;
    return true;
  }
};

}  // namespace

TEST_CASE("options validity: the rules name the field after its path", "[options_validity]") {
  CHECK(require(true, "tree.", "branchSwitching", "must be >= 0").empty());
  CHECK(require(false, "tree.", "branchSwitching", "must be >= 0") == "tree.branchSwitching must be >= 0");
  CHECK(requirePositive("", "tolerance", 1e-300).empty());
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL})
    CHECK(requirePositive("a.", "tolerance", bad) == "a.tolerance must be positive and finite");
  CHECK(firstProblem({"", "second", "third"}) == "second");
  CHECK(firstProblem({"", ""}).empty());
  std::string why = "unset";
  CHECK(reportValidity("", &why));
  CHECK(why.empty());
  CHECK_FALSE(reportValidity("x must be y", &why));
  CHECK(why == "x must be y");
  CHECK_FALSE(reportValidity("x must be y", nullptr));
}

TEST_CASE("options validity: every default of the core is valid", "[options_validity]") {
  CHECK(TracerOptions().validate().empty());
  CHECK(LocatorOptions().validate().empty());
  CHECK(TreeOptions().validate().empty());
  CHECK(BranchSwitchingOptions().validate().empty());
  CHECK(CurveZeroOptions().validate().empty());
  CHECK(NumericDiffOptions().validate().empty());
  CHECK(DerivativeCheckOptions().validate(3).empty());
}

TEST_CASE("options validity: a nested struct's path is prefixed by where it sits", "[options_validity]") {
  TracerOptions t;
  t.corrector.tolerance = -1.0;
  CHECK(t.validate() == "corrector.tolerance must be positive and finite");
  CHECK(t.validate("tracer.") == "tracer.corrector.tolerance must be positive and finite");
  t = TracerOptions();
  t.maxPoints = 1;
  CHECK_THAT(t.validate("childTracer."), StartsWith("childTracer.maxPoints"));

  LocatorOptions lo;
  lo.location.maxIterations = 0;
  CHECK_THAT(lo.validate(), StartsWith("location.maxIterations"));
  lo = LocatorOptions();
  lo.minSampleCosine = 1.5;
  std::string why;
  CHECK_FALSE(lo.IsValid(&why));
  CHECK_THAT(why, StartsWith("minSampleCosine"));
}

TEST_CASE("options validity: traceTree refuses an invalid tree in its first branch", "[options_validity]") {
  auto refused = [](const TreeOptions& tree, const std::string& field) {
    INFO(field);
    CHECK_THAT(tree.validate(), StartsWith(field));
    toys::TwoPitchforks problem(0.5);
    const BranchTree result =
        traceTree(problem, Vector::Zero(2), -0.3, {InitialDirection::increasingLambda()}, TracerOptions(), tree);
    REQUIRE(result.branches.size() == 1);
    CHECK(result.branches[0].stopReason == StopReason::InvalidOptions);
    CHECK_THAT(result.branches[0].stopMessage, StartsWith("TreeOptions: " + field));
    CHECK(result.branches[0].points.empty());
  };
  TreeOptions tree;
  tree.branchSwitching = -1;
  refused(tree, "branchSwitching");
  tree = TreeOptions();
  tree.switching.minOffBranchFraction = 1.0;
  refused(tree, "switching.minOffBranchFraction");
  tree = TreeOptions();
  TracerOptions child;
  child.step.maxStep = -1.0;
  tree.childTracer = child;
  refused(tree, "childTracer.step.maxStep");
}

TEST_CASE("options validity: curve zeros, numeric differences and derivative checks refuse bad options",
          "[options_validity]") {
  CurveZeroOptions zeros;
  zeros.corrector.tolerance = 0.0;
  CHECK_THAT(zeros.validate(), StartsWith("corrector.tolerance"));
  toys::Circle circle;
  Branch branch = trace(circle, vec1(1.0), 0.0, InitialDirection::increasingLambda(), TracerOptions());
  REQUIRE(branch.points.size() >= 2);
  const CurveTest g = [](ConstVectorRef u, double, double& out) {
    out = u[0];
    return true;
  };
  CHECK_THROWS_WITH(locateCurveZeros(circle, branch, g, zeros), StartsWith("CurveZeroOptions: corrector.tolerance"));
  zeros = CurveZeroOptions();
  zeros.maxIterations = 0;
  CHECK_THROWS_WITH(locateCurveZeros(circle, branch, g, zeros), Contains("maxIterations must be at least 1"));
  CHECK_FALSE(locateCurveZeros(circle, branch, g).empty());  // the circle crosses u = 0 on its way round

  NumericDiffOptions steps;
  steps.secondRelativeStep = 0.5;
  CHECK_THROWS_WITH(DifferencedCircle(steps), StartsWith("NumericDiffOptions: secondRelativeStep"));
  CHECK_NOTHROW(DifferencedCircle(NumericDiffOptions()));

  DerivativeCheckOptions check;
  check.steps.relativeStep = -1.0;
  const DerivativeCheck result = checkDerivatives(circle, vec1(0.6), 0.8, check);
  CHECK_FALSE(result.success);
  CHECK_THAT(result.message, StartsWith("DerivativeCheckOptions: steps.relativeStep"));
  std::string why;
  CHECK_FALSE(check.IsValid(1, &why));
  CHECK(why == check.validate(1));
}
