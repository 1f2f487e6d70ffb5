#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <limits>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/imperfection_sensitivity.h"

#include "unequal_springs.h"
#include "test_chains.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::kAxial;

/// The first branch point of the straight clamped–pinned chain under compression.
cont::SpecialPoint firstBranchPoint(EquilibriumProblem& p, double lambdaMin) {
  cont::TracerOptions o;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = 1.0;
  o.corrector.tolerance = 1e-12;
  const cont::Branch b =
      cont::trace(p, Eigen::VectorXd::Zero(p.dimension()), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = b.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  return *bps.front();
}

/// λ of the first fold on the imperfect chain's path (NaN: none before lambdaMin), the chain
/// `chain` with end `end` compressed along x: traced in fine steps (at most `step`) from its
/// nearly straight equilibrium at lambdaStart (found by Newton at fixed λ from q = 0), so that
/// the sharp turn of the path near the perfect branch point (of size |ε|^{1/3} in ξ for a
/// symmetric point, |ε|^{1/2} for an asymmetric one) is followed, not cut.
double imperfectFold(const Chain& chain, const EndCondition& end, double lambdaStart, double lambdaMin,
                     double step = 0.002) {
  EquilibriumProblem p(chain, end, kAxial);
  cont::TracerOptions o;
  o.lambdaMin = std::min(lambdaMin, lambdaStart);
  o.lambdaMax = std::max(lambdaMin, lambdaStart);
  o.step.initialStep = 0.5 * step;
  o.step.maxStep = step;
  o.maxPoints = 8000;
  o.corrector.tolerance = 1e-12;
  o.detection.branchPoints = false;
  const cont::Branch b = cont::trace(p, p.initialGuess(Eigen::VectorXd::Zero(chain.size()), lambdaStart),
                                     lambdaStart, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(!b.points.empty());
  INFO("imperfect path: " << cont::toString(b.stopReason) << " " << b.stopMessage << ", " << b.points.size()
                          << " points, last λ " << b.points.back().lambda);
  const auto folds = b.specialPointsOfType(cont::SpecialPointType::Fold);
  return folds.empty() ? std::numeric_limits<double>::quiet_NaN() : folds.front()->lambda;
}

/// Tall triangles, short preload: the straight chain's first (U) branch point is subcritical.
/// The chain, its problem, that point and its Koiter coefficients (checked subcritical).
struct SubcriticalChain {
  Chain chain = Chain::uniform(3, SegmentParameters::symmetric(2.5, 1.0, 1.0, 0.5));
  EquilibriumProblem p{chain, EndCondition::clampedPinned(0.0), kAxial};
  cont::SpecialPoint bp = firstBranchPoint(p, -12.0);
  KoiterCoefficients k = koiterCoefficients(p, bp);

  SubcriticalChain() {
    REQUIRE(k.valid);
    REQUIRE(k.kind == KoiterKind::Subcritical);
  }
  SubcriticalChain(const SubcriticalChain&) = delete;
  SubcriticalChain& operator=(const SubcriticalChain&) = delete;
};

/// The same for an imperfection ε of end coordinate c of the clamped–pinned chain.
double imperfectFold(const Chain& chain, int c, double eps, double lambdaStart, double lambdaMin) {
  EndCondition end = EndCondition::clampedPinned(0.0);
  end.value[c] = eps;
  return imperfectFold(chain, end, lambdaStart, lambdaMin);
}

/// The exponent of |Δλ| = C|ε|^p from the knockdowns at ε and 4ε, and the ratio of the traced
/// knockdown at the smallest ε to the predicted one.
void checkLaw(const ImperfectionSensitivity& s, const std::vector<double>& eps, const std::vector<double>& traced,
              double exponent) {
  INFO("predicted " << knockdown(s, eps[0]) << ", traced " << traced[0]);
  CHECK(std::abs(traced[0] / knockdown(s, eps[0]) - 1.0) <= 0.01);
  const double measured = std::log(traced[1] / traced[0]) / std::log(eps[1] / eps[0]);
  INFO("exponent " << measured);
  CHECK(std::abs(measured - exponent) <= 1e-2);
}

}  // namespace

TEST_CASE("Koiter's 2/3 law: knockdown of a subcritical chain by an end moment, against the traced imperfect path",
          "[imperfection_sensitivity]") {
  SubcriticalChain c;
  const Chain& chain = c.chain;
  EquilibriumProblem& p = c.p;
  const cont::SpecialPoint& bp = c.bp;
  const KoiterCoefficients& k = c.k;
  const ImperfectionSensitivity s = imperfectionSensitivity(p, bp, k, 2);  // an end moment Me = ε
  REQUIRE(s.valid);
  CHECK(s.name == "Me");
  CHECK(s.exponent == 2.0 / 3.0);
  CHECK(s.sign == 0);
  const std::vector<double> eps{1e-6, 4e-6, 1.6e-5};
  std::vector<double> traced;
  for (double e : eps) {
    const double fold = imperfectFold(chain, 2, e, 0.95 * bp.lambda, 1.05 * bp.lambda);
    INFO("eps " << e);
    REQUIRE(std::isfinite(fold));
    traced.push_back(std::abs(fold - bp.lambda));
    // both signs of ε knock the load down by the same amount (the chain's mirror symmetry)
    CHECK(std::abs(std::abs(imperfectFold(chain, 2, -e, 0.95 * bp.lambda, 1.05 * bp.lambda) - bp.lambda) - traced.back()) <=
          1e-8 * std::abs(bp.lambda));
  }
  checkLaw(s, eps, traced, 2.0 / 3.0);
}

TEST_CASE("A supercritical chain has no limit point near its critical load when imperfect",
          "[imperfection_sensitivity]") {
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  const cont::SpecialPoint bp = firstBranchPoint(p, -1.0);
  const KoiterCoefficients k = koiterCoefficients(p, bp);
  REQUIRE(k.valid);
  REQUIRE(k.kind == KoiterKind::Supercritical);
  const ImperfectionSensitivity s = imperfectionSensitivity(p, bp, k, 2);
  REQUIRE(s.valid);
  CHECK(s.coupling != 0.0);
  CHECK(s.exponent == 0.0);
  CHECK(knockdown(s, 1e-3) == 0.0);
  // the imperfect path passes the critical load smoothly (no fold up to 1.3 λc)
  CHECK(std::isnan(imperfectFold(chain, 2, 1e-4, 0.9 * bp.lambda, 1.3 * bp.lambda)));
  // the load's own direction does not couple (ψᵀF_λ = 0 at a branch point)
  CHECK(imperfectionSensitivity(p, bp, k, 0).coupling == 0.0);
  CHECK_FALSE(imperfectionSensitivity(p, bp, k, 3).valid);
}

TEST_CASE("Koiter's 2/3 law for a preload asymmetry (dL0), against the traced imperfect path",
          "[imperfection_sensitivity]") {
  SubcriticalChain c;
  const Chain& chain = c.chain;
  EquilibriumProblem& p = c.p;
  const cont::SpecialPoint& bp = c.bp;
  const KoiterCoefficients& k = c.k;
  // every segment's springs apart by ε, and the middle segment's alone
  for (int segment : {-1, 1}) {
    INFO("segment " << segment);
    const ImperfectionSensitivity s = preloadImperfectionSensitivity(p, bp, k, segment);
    REQUIRE(s.valid);
    CHECK(s.name == "dL0");
    CHECK(s.segment == segment);
    CHECK(s.coupling != 0.0);
    CHECK(s.exponent == 2.0 / 3.0);
    // F_ε against central differences of the residual in the free lengths
    const double h = 1e-6;
    EquilibriumProblem plus(preloadAsymmetric(chain, segment, h), p.endCondition(), kAxial);
    EquilibriumProblem minus(preloadAsymmetric(chain, segment, -h), p.endCondition(), kAxial);
    cont::Vector Fp(p.dimension()), Fm(p.dimension());
    REQUIRE(buckle::continuation::BoundProblem(plus).residual(bp.u, bp.lambda, Fp));
    REQUIRE(buckle::continuation::BoundProblem(minus).residual(bp.u, bp.lambda, Fm));
    CHECK(std::abs(k.psi.dot(Fp - Fm) / (2.0 * h) - s.coupling) <= 1e-7 * std::abs(s.coupling));
    const std::vector<double> eps{1e-6, 4e-6};
    std::vector<double> traced;
    for (double e : eps) {
      INFO("eps " << e);
      const double fold =
          imperfectFold(preloadAsymmetric(chain, segment, e), p.endCondition(), 0.95 * bp.lambda, 1.05 * bp.lambda);
      REQUIRE(std::isfinite(fold));
      traced.push_back(std::abs(fold - bp.lambda));
      // a mirror image for −ε (springs swapped): the same knockdown
      const double mirror =
          imperfectFold(preloadAsymmetric(chain, segment, -e), p.endCondition(), 0.95 * bp.lambda, 1.05 * bp.lambda);
      CHECK(std::abs(std::abs(mirror - bp.lambda) - traced.back()) <= 1e-8 * std::abs(bp.lambda));
    }
    checkLaw(s, eps, traced, 2.0 / 3.0);
  }
  CHECK_FALSE(preloadImperfectionSensitivity(p, bp, k, 3).valid);
  CHECK(mostSensitivePreloadSegment(p, bp, k) >= 0);
  CHECK_THROWS_AS(preloadAsymmetric(chain, 0, -1.0), std::invalid_argument);  // L2_0 = 0
}

TEST_CASE("The asymmetric 1/2 law: a chain with unequal springs, against the traced imperfect path",
          "[imperfection_sensitivity]") {
  const Chain chain = Chain::uniform(3, testing::unequalSprings());
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  const cont::SpecialPoint bp = firstBranchPoint(p, -1.0);
  const KoiterCoefficients k = koiterCoefficients(p, bp);
  REQUIRE(k.valid);
  INFO("a = " << k.a << ", b = " << k.b);
  REQUIRE(k.kind == KoiterKind::Asymmetric);
  // an end moment Me = ε and a preload asymmetry of every segment
  for (int which : {0, 1}) {
    const ImperfectionSensitivity s =
        which == 0 ? imperfectionSensitivity(p, bp, k, 2) : preloadImperfectionSensitivity(p, bp, k, -1);
    INFO(s.name);
    REQUIRE(s.valid);
    CHECK(s.exponent == 0.5);
    REQUIRE(s.sign != 0);
    auto fold = [&](double e) {
      if (which == 1)
        return imperfectFold(preloadAsymmetric(chain, -1, e), p.endCondition(), 0.95 * bp.lambda, 1.05 * bp.lambda,
                             5e-4);
      EndCondition end = EndCondition::clampedPinned(0.0);
      end.value[2] = e;
      return imperfectFold(chain, end, 0.95 * bp.lambda, 1.05 * bp.lambda, 5e-4);
    };
    const std::vector<double> eps{s.sign * 1e-6, s.sign * 4e-6};
    std::vector<double> traced;
    for (double e : eps) {
      INFO("eps " << e);
      const double f = fold(e);
      REQUIRE(std::isfinite(f));
      traced.push_back(std::abs(f - bp.lambda));
    }
    checkLaw(s, eps, traced, 0.5);
    // the other sign passes the critical load without a limit point
    CHECK(knockdown(s, -eps[0]) == 0.0);
    CHECK(std::isnan(fold(-eps[0])));
  }
}
