// Certified counting (spectral_monitor.h): crossings the inertia count cannot see, on problems
// whose eigenvalues are known in closed form.
#include "buckle/continuation/internal/spectral_monitor.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

using namespace buckle::continuation;

namespace {

/// [(λ − 1)u₁ − u₁³, (c − λ)u₂ − u₂³] with c > 1, H = −F_u: on u = 0 the eigenvalues are 1 − λ
/// (through zero downwards at λ = 1) and λ − c (upwards at λ = c). For λ < 1 and λ > c one of them
/// is negative, between them both: one step over [1, c] sees ν = 1 at both ends and no
/// determinant sign change.
class OppositeCrossings : public Problem {
 public:
  explicit OppositeCrossings(double c) : c_(c) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = (lambda - 1.0) * u[0] - u[0] * u[0] * u[0];
    F[1] = (c_ - lambda) * u[1] - u[1] * u[1] * u[1];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setZero();
    Fu(0, 0) = lambda - 1.0 - 3.0 * u[0] * u[0];
    Fu(1, 1) = c_ - lambda - 3.0 * u[1] * u[1];
    Fl << u[0], -u[1];
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return toys::negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  double c_;
};

/// [−(λ − 1)²u₁ − u₁³, −u₂], H = −F_u: on u = 0 the eigenvalue (λ − 1)² reaches zero at λ = 1 and
/// turns back; no branch crosses there (u₁² = −(λ − 1)² has no other real solution).
class Touch : public Problem {
 public:
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
    F[0] = -(lambda - 1.0) * (lambda - 1.0) * u[0] - u[0] * u[0] * u[0];
    F[1] = -u[1];
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setZero();
    Fu(0, 0) = -(lambda - 1.0) * (lambda - 1.0) - 3.0 * u[0] * u[0];
    Fu(1, 1) = -1.0;
    Fl << -2.0 * (lambda - 1.0) * u[0], 0.0;
    return true;
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return toys::negatedJacobian(*this, ws, u, lambda, H, C);
  }
};

/// OppositeCrossings with its exact rate bound: H = diag(1 − λ + 3u₁², λ − c + 3u₂²) moves by
/// dH = diag(−dλ + 6u₁du₁, dλ + 6u₂du₂), and |dμ_i| ≤ ‖dH‖₂ = the larger |entry| (Weyl). Counts
/// the eigenvalue evaluations.
class BoundedOppositeCrossings : public OppositeCrossings {
 public:
  BoundedOppositeCrossings(double c, bool offerBound) : OppositeCrossings(c), offerBound_(offerBound) {}
  bool stabilityEigenvalues(ProblemWorkspace &ws, ConstVectorRef u, double lambda, int first,
                            VectorRef values) const override {
    ++evaluations;
    return Problem::stabilityEigenvalues(ws, u, lambda, first, values);
  }
  bool stabilityRateBound(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef du, double dlambda,
                          double &bound) const override {
    if (!offerBound_) return false;
    bound = std::max(std::abs(-dlambda + 6.0 * u[0] * du[0]), std::abs(dlambda + 6.0 * u[1] * du[1]));
    return true;
  }
  mutable int evaluations = 0;  // a probe of this single-threaded test

 private:
  bool offerBound_;
};

// Big fixed steps so that one step spans the whole event.
TracerOptions bigSteps(double lambdaMax, bool certified) {
  TracerOptions o;
  o.step.initialStep = o.step.maxStep = 0.1;
  o.lambdaMax = lambdaMax;
  o.detection.certifiedCounting = certified;
  return o;
}

}  // namespace

TEST_CASE("the monitor records the eigenvalues next to zero and their rates along the branch") {
  OppositeCrossings problem(1.02);
  ContinuationPoint p;
  p.u = Vector::Zero(2);
  p.lambda = 0.96;
  p.tangent = Vector::Unit(3, 2);  // the trivial branch, λ increasing
  REQUIRE(BoundProblem(problem).stability(p.u, p.lambda, 2, p.stability));
  REQUIRE(p.stability.negative == 1);
  REQUIRE(measureNearZeroSpectrum(problem, p));
  CHECK(p.spectrum.first == 0);
  CHECK(p.spectrum.count == 2);
  // μ₀ = λ − c, μ₁ = 1 − λ, slopes +1 and −1 (forward difference of linear functions: exact to rounding)
  CHECK(p.spectrum.values[0] == Approx(0.96 - 1.02).margin(1e-14));
  CHECK(p.spectrum.values[1] == Approx(1.0 - 0.96).margin(1e-14));
  CHECK(p.spectrum.slopes[0] == Approx(1.0).margin(1e-8));
  CHECK(p.spectrum.slopes[1] == Approx(-1.0).margin(1e-8));
}

TEST_CASE("two eigenvalues crossing zero in opposite directions inside one step are two branch points") {
  const double c = 1.02;
  OppositeCrossings problem(c);
  // Without certified counting the step [0.96, 1.06] hides both: ν = 1 and det of one sign at both ends.
  const Branch blind = trace(problem, Vector::Zero(2), 0.96, InitialDirection::increasingLambda(), bigSteps(1.3, false));
  REQUIRE(blind.points.size() >= 3);
  CHECK(blind.points[1].lambda == Approx(1.06).margin(1e-9));
  CHECK(blind.specialPointsOfType(SpecialPointType::BranchPoint).empty());

  const Branch branch = trace(problem, Vector::Zero(2), 0.96, InitialDirection::increasingLambda(), bigSteps(1.3, true));
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  // closed form: λ = 1 (eigenvalue 1 − λ) and λ = c (eigenvalue λ − c), both within one step
  CHECK(std::abs(bps[0]->lambda - 1.0) <= 1e-10);
  CHECK(std::abs(bps[1]->lambda - c) <= 1e-10);
  CHECK(bps[0]->index == 0);
  CHECK(bps[1]->index == 0);
  CHECK(bps[0]->inertiaBefore == 1);
  CHECK(bps[0]->inertiaAfter == 2);
  CHECK(bps[1]->inertiaBefore == 2);
  CHECK(bps[1]->inertiaAfter == 1);
  // the kernel direction of each is its own coordinate
  REQUIRE(bps[0]->nullVectors.cols() == 2);
  CHECK(std::abs(bps[0]->nullVectors.col(1)[0]) == Approx(1.0).margin(1e-6));
  CHECK(std::abs(bps[1]->nullVectors.col(1)[1]) == Approx(1.0).margin(1e-6));
  CHECK(branch.specialPointsOfType(SpecialPointType::EigenvalueTouch).empty());
}

TEST_CASE("an eigenvalue touching zero without crossing is reported as an eigenvalue touch") {
  Touch problem;
  const Branch blind = trace(problem, Vector::Zero(2), 0.95, InitialDirection::increasingLambda(), bigSteps(1.3, false));
  CHECK(blind.specialPointsOfType(SpecialPointType::EigenvalueTouch).empty());
  CHECK(blind.specialPointsOfType(SpecialPointType::BranchPoint).empty());

  const Branch branch = trace(problem, Vector::Zero(2), 0.95, InitialDirection::increasingLambda(), bigSteps(1.3, true));
  const auto touches = branch.specialPointsOfType(SpecialPointType::EigenvalueTouch);
  REQUIRE(touches.size() == 1);
  const SpecialPoint &t = *touches[0];
  // closed form: (λ − 1)² = 0 at λ = 1, the count 0 on both sides
  CHECK(std::abs(t.lambda - 1.0) <= 1e-6);
  CHECK(std::abs(t.lambda - 1.0) <= t.lambdaAccuracy + 1e-12);
  CHECK(t.lambdaAccuracy <= 1e-6);
  CHECK(t.testFunctionValue >= 0.0);
  CHECK(t.testFunctionValue <= 1e-12);
  CHECK(t.inertiaBefore == 0);
  CHECK(t.inertiaAfter == 0);
  CHECK(std::string(label(t.type)) == "ET");
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
}

TEST_CASE("a dip of an eigenvalue that stays clear of zero is not a touch") {
  // μ = (λ − 1)² + d with d well above the touch tolerance: the monitor may suspect it (its tangent
  // lines meet below zero), the minimisation finds μ_min = d > 0 and reports nothing.
  class Dip : public Touch {
   public:
    bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
      Touch::stabilityOperator(ws, u, lambda, H, C);
      H(0, 0) += 1e-4;
      return true;
    }
  } problem;
  const Branch branch = trace(problem, Vector::Zero(2), 0.95, InitialDirection::increasingLambda(), bigSteps(1.3, true));
  CHECK(branch.specialPointsOfType(SpecialPointType::EigenvalueTouch).empty());
  CHECK(branch.specialPointsOfType(SpecialPointType::BranchPoint).empty());
}

TEST_CASE("suspectHiddenCrossings needs an interior extremum reaching zero") {
  ContinuationPoint a, b;
  a.stability.negative = b.stability.negative = 0;
  a.spectrum.first = b.spectrum.first = 0;
  a.spectrum.count = b.spectrum.count = 1;
  a.spectrum.slopesMeasured = b.spectrum.slopesMeasured = true;
  a.spectrum.values[0] = b.spectrum.values[0] = 0.04;
  a.spectrum.slopes[0] = -1.0;
  b.spectrum.slopes[0] = 1.0;
  // tangent lines meet at s = 0.05 with value 0.04 − 0.05 < 0: suspected
  auto s = suspectHiddenCrossings(a, b, 0.1);
  REQUIRE(s.size() == 1);
  CHECK(s[0].predictedS == Approx(0.05));
  CHECK(s[0].predictedValue == Approx(-0.01));
  // moving the same way at both ends: no interior extremum
  b.spectrum.slopes[0] = -1.0;
  CHECK(suspectHiddenCrossings(a, b, 0.1).empty());
  // a shallow dip: the lines meet far above zero
  b.spectrum.slopes[0] = 0.1;
  a.spectrum.slopes[0] = -0.1;
  CHECK(suspectHiddenCrossings(a, b, 0.1).empty());
  // different counts at the ends are the count's business
  b.stability.negative = 1;
  CHECK(suspectHiddenCrossings(a, b, 0.1).empty());
}

TEST_CASE("with a rate bound, the slopes are skipped only where no eigenvalue can come near zero") {
  const double c = 1.02;
  // Far from both crossings (λ ∈ [0, 0.6]: μ = 1 − λ ≥ 0.4 and λ − c ≤ −0.42, |dμ/ds| ≤ 1 over
  // steps of 0.1): the bound excludes every step. The values come with the point's stability
  // (lowestEigenvalues = 3), so the only eigenvalue evaluations are the slopes' off-branch ones:
  // one per point without the bound, none with it.
  BoundedOppositeCrossings measured(c, false), bounded(c, true);
  const Branch a = trace(measured, Vector::Zero(2), 0.0, InitialDirection::increasingLambda(), bigSteps(0.6, true));
  const Branch b = trace(bounded, Vector::Zero(2), 0.0, InitialDirection::increasingLambda(), bigSteps(0.6, true));
  REQUIRE(a.points.size() == b.points.size());
  REQUIRE(a.points.size() >= 6);
  CHECK(measured.evaluations == int(a.points.size()));
  CHECK(bounded.evaluations == 0);
  for (size_t i = 0; i < a.points.size(); ++i) {
    CHECK(a.points[i].lambda == b.points[i].lambda);
    CHECK(b.points[i].spectrum.rateBound == Approx(1.0));
    CHECK_FALSE(b.points[i].spectrum.slopesMeasured);
  }

  // Across both crossings the bound cannot exclude the step: slopes measured, both branch points found.
  BoundedOppositeCrossings across(c, true);
  const Branch branch = trace(across, Vector::Zero(2), 0.96, InitialDirection::increasingLambda(), bigSteps(1.3, true));
  const auto bps = branch.specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  CHECK(std::abs(bps[0]->lambda - 1.0) <= 1e-10);
  CHECK(std::abs(bps[1]->lambda - c) <= 1e-10);
  CHECK(branch.points[0].spectrum.slopesMeasured);
}

TEST_CASE("rateBoundsExcludeCrossing: no slopes within the bounds make suspectHiddenCrossings flag an excluded step") {
  ContinuationPoint a, b;
  a.stability.negative = b.stability.negative = 1;
  for (ContinuationPoint *p : {&a, &b}) {
    p->spectrum.first = 0;
    p->spectrum.count = 2;
    p->spectrum.slopesMeasured = true;
  }
  // The closed case: μ = 0.04 at both ends, slopes ∓1 reach −0.01 at s = 0.05 (suspected above).
  a.spectrum.values[0] = b.spectrum.values[0] = -0.5;
  a.spectrum.values[1] = b.spectrum.values[1] = 0.04;
  a.spectrum.rateBound = b.spectrum.rateBound = 1.0;
  CHECK_FALSE(rateBoundsExcludeCrossing(a, b, 0.1));
  // With |dμ/ds| ≤ 0.1 the lines meet no lower than 0.04 − 0.005 > 0.25·0.04: excluded.
  a.spectrum.rateBound = b.spectrum.rateBound = 0.1;
  CHECK(rateBoundsExcludeCrossing(a, b, 0.1));
  // No bound offered: never excluded.
  b.spectrum.rateBound = std::numeric_limits<double>::infinity();
  CHECK_FALSE(rateBoundsExcludeCrossing(a, b, 0.1));

  // Property: random values, bounds and step lengths; whenever the step is excluded, slopes
  // anywhere in [−D, D] (including the extremes) give no suspect.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1.0, 1.0), P(0.0, 1.0);
  int excluded = 0, kept = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const double L = 0.5 * P(rng);
    for (ContinuationPoint *p : {&a, &b}) {
      p->spectrum.values[0] = -std::pow(10.0, -3.0 * P(rng));
      p->spectrum.values[1] = std::pow(10.0, -3.0 * P(rng));
      p->spectrum.rateBound = std::pow(10.0, 2.0 * U(rng));
    }
    if (!rateBoundsExcludeCrossing(a, b, L)) {
      ++kept;
      continue;
    }
    ++excluded;
    for (int draw = 0; draw < 8; ++draw) {
      for (int k = 0; k < 2; ++k) {
        a.spectrum.slopes[k] = (draw < 4 ? (draw & 1 ? 1.0 : -1.0) : U(rng)) * a.spectrum.rateBound;
        b.spectrum.slopes[k] = (draw < 4 ? (draw & 2 ? 1.0 : -1.0) : U(rng)) * b.spectrum.rateBound;
      }
      INFO("trial " << trial << ", draw " << draw);
      REQUIRE(suspectHiddenCrossings(a, b, L).empty());
    }
  }
  CHECK(excluded > 1000);  // both outcomes occur: the property is not vacuous
  CHECK(kept > 1000);
}
