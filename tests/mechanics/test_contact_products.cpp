// ContactProblem's O(n) second derivative F_xx[x, z] (mechanics/contact_products.cpp) against the
// problem's own dense directional derivative of its Jacobian applied to z (Problem's default
// secondDerivativeApply), at random points of a chain past the dense routes: locked joints only
// (the base problem's exact product, to rounding), and with a wall vertex and a self contact
// (central differences of the O(n) products, to the differences' accuracy).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "contact_cases.h"
#include "random_segments.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

TEST_CASE("contact products: the O(n) second derivative equals the dense one's product", "[contact_products]") {
  const int n = 150;
  std::mt19937 rng(150);
  const Chain chain(testing::randomSegments(rng, n));
  const auto [distalOnProximal, proximalOnDistal] = testing::crossingSelfContacts(n);
  (void)proximalOnDistal;
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.3, 0.3);
  const std::vector<testing::ContactCase> cases = {
      {"free end, locked joints only", EndCondition::freeEnd(), false, {}},
      {"clamped-pinned, locked joints only", EndCondition::clampedPinned(0.0), false, {}},
      {"clamped-pinned, a wall vertex and a self contact", EndCondition::clampedPinned(0.0), true, {distalOnProximal}}};
  testing::forEachContactCase(rng, chain, cases, {{4, LimitSide::Upper}, {70, LimitSide::Lower}, {120, LimitSide::Upper}},
                              [&](const testing::ContactCase& k, const ContactProblem& contact) {
    INFO(k.name);
    const ContactSet& locked = contact.contacts();
    const int N = contact.dimension();
    Eigen::VectorXd u(N), x(N + 1), z(N + 1);
    for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : W(rng);
    for (int i = 0; i <= N; ++i) x[i] = W(rng), z[i] = W(rng);
    const double lambda = W(rng);
    auto ws = contact.createWorkspace();
    Eigen::VectorXd fast(N), dense(N);
    REQUIRE(contact.secondDerivativeApply(*ws, u, lambda, x, z, fast));
    REQUIRE(contact.cont::Problem::secondDerivativeApply(*ws, u, lambda, x, z, dense));
    const double size = dense.norm();
    REQUIRE(size > 0.0);
    // exact against exact to rounding; differences against differences (other steps of the same
    // truncation order) to their accuracy
    const double tolerance = locked.gapCount() == 0 ? 1e-12 : 1e-8;
    CHECK((fast - dense).norm() <= tolerance * size);
  });
}
