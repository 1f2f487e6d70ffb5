#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/imperfection_sensitivity.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {
const Eigen::Vector3d kAxial(1.0, 0.0, 0.0);

/// The first branch point of the straight clamped–pinned chain under compression.
cont::SpecialPoint firstBranchPoint(EquilibriumProblem& p, double lambdaMin) {
  cont::TracerOptions o;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = 1.0;
  o.newtonTolerance = 1e-12;
  const cont::Branch b =
      cont::trace(p, Eigen::VectorXd::Zero(p.dimension()), 0.0, cont::InitialDirection::decreasingLambda(), o);
  const auto bps = b.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  return *bps.front();
}

/// λ of the first fold on the imperfect chain's path (NaN: none before lambdaMin), the
/// imperfection ε on end coordinate c: traced in fine steps from its nearly straight equilibrium
/// at lambdaStart (found by Newton at fixed λ from q = 0), so that the sharp turn of the path
/// near the perfect branch point (of size |ε|^{1/3} in ξ) is followed, not cut.
double imperfectFold(const Chain& chain, int c, double eps, double lambdaStart, double lambdaMin) {
  EndCondition end = EndCondition::clampedPinned(0.0);
  end.value[c] = eps;
  EquilibriumProblem p(chain, end, kAxial);
  cont::TracerOptions o;
  o.lambdaMin = lambdaMin;
  o.lambdaMax = 0.0;
  o.initialStep = 0.001;
  o.maxStep = 0.002;
  o.maxPoints = 4000;
  o.newtonTolerance = 1e-12;
  o.detectBranchPoints = false;
  const cont::Branch b = cont::trace(p, p.initialGuess(Eigen::VectorXd::Zero(chain.size()), lambdaStart),
                                     lambdaStart, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(!b.points.empty());
  INFO("imperfect path: " << cont::toString(b.stopReason) << " " << b.stopMessage << ", " << b.points.size()
                          << " points, last λ " << b.points.back().lambda);
  const auto folds = b.specialPointsOfType(cont::SpecialPointType::Fold);
  return folds.empty() ? std::numeric_limits<double>::quiet_NaN() : folds.front()->lambda;
}
}  // namespace

TEST_CASE("Koiter's 2/3 law: knockdown of a subcritical chain by an end moment, against the traced imperfect path",
          "[imperfection_sensitivity]") {
  // tall triangles, short preload: the straight chain's first (U) point is subcritical
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(2.5, 1.0, 1.0, 0.5));
  EquilibriumProblem p(chain, EndCondition::clampedPinned(0.0), kAxial);
  const cont::SpecialPoint bp = firstBranchPoint(p, -12.0);
  const KoiterCoefficients k = koiterCoefficients(p, bp);
  REQUIRE(k.valid);
  REQUIRE(k.kind == KoiterKind::Subcritical);
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
  INFO("predicted " << knockdown(s, eps[0]) << ", traced " << traced[0]);
  CHECK(std::abs(traced[0] / knockdown(s, eps[0]) - 1.0) <= 0.01);
  const double exponent = std::log(traced[1] / traced[0]) / std::log(eps[1] / eps[0]);
  INFO("exponent " << exponent);
  CHECK(std::abs(exponent - 2.0 / 3.0) <= 1e-2);
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
