// The loaded stiffness of a chain holding contacts in O(n) (structuredContactStiffness) against
// the dense route (denseContactStiffness: an eigen-solve of ZᵀHZ) at random points of long chains,
// with locked joints, a wall vertex, self contacts pushing and pulling, the rotation free and held;
// its singular route (K_F from the position-held system) against loadedStiffness's at a guided
// chain's critical load by linear buckling.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/unloaded_shape.h"

#include "contact_cases.h"
#include "random_segments.h"

using namespace buckle::mechanics;

namespace {

// Lengths ×sL, stiffnesses ×sK.
SegmentParameters scaled(SegmentParameters p, double sL, double sK) {
  p.a1 *= sL, p.b1 *= sL, p.a2 *= sL, p.b2 *= sL, p.L1_0 *= sL, p.L2_0 *= sL;
  p.k1 *= sK, p.k2 *= sK;
  return p;
}

EndCondition guided(double Fx) {  // x loaded, y free, φ held at 0
  EndCondition e = EndCondition::freeEnd(Eigen::Vector3d(Fx, 0.0, 0.0));
  e.control[2] = Control::Held;
  e.value[2] = 0.0;
  return e;
}

}  // namespace

TEST_CASE("contact stiffness: the O(n) route equals the dense eigen-solve (locked joints, wall, self contacts, "
          "rotation free and held)",
          "[contact_stiffness]") {
  const int n = 120;
  std::mt19937 rng(2026);
  const std::vector<SegmentParameters> segs = testing::randomSegments(rng, n);
  const Chain chain(segs);
  const auto [a, b] = testing::crossingSelfContacts(n);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.3, 0.3);
  const std::vector<testing::ContactCase> cases = {
      {"free end, no contact", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))), false, {}, 1.0},
      {"free end, a self contact pushing", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))), false, {a}, 1.0},
      {"free end, two, one pulling", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))), false, {a, b}, -1.0},
      {"guided, wall and a self contact", guided(0.3 * W(rng)), true, {b}, 1.0},
      {"held position, wall", EndCondition::heldPosition(0.6 * chain.length(), 0.2), true, {}, 1.0}};
  for (const testing::ContactCase& k : cases) {
    for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e-4, 1e8}}) {
      INFO(k.name << ", lengths x" << sL << ", stiffnesses x" << sK);
      std::vector<SegmentParameters> units;
      for (const SegmentParameters& p : segs) units.push_back(scaled(p, sL, sK));
      const Chain c(units);
      EquilibriumProblem problem(c, k.end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      const ContactSet locked =
          testing::caseContacts(k, {{3, LimitSide::Upper}, {70, LimitSide::Lower}}, WallVertex{1, 3});
      const ContactProblem contact(problem, locked);
      const int N = contact.dimension();
      const double force = c.segment(0).parameters().k1 * c.segment(0).parameters().b1;
      Eigen::VectorXd u(N);
      for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : 0.5 * force * std::abs(W(rng));
      if (!k.self.empty()) u[N - 1] *= k.lastForceSign;
      const double lambda = 0.2 * force * W(rng);
      const CartesianStiffness dense = denseContactStiffness(contact, u, lambda);
      CartesianStiffness fast;
      REQUIRE(structuredContactStiffness(contact, u, lambda, fast));
      CHECK(fast.negativeDirections == dense.negativeDirections);
      CHECK(fast.smallestEigenvalue == Approx(dense.smallestEigenvalue).epsilon(1e-9));
      CHECK(fast.singular == dense.singular);
      CHECK(fast.rigid == dense.rigid);
      CHECK(fast.rotationHeld == dense.rotationHeld);
      CHECK(fast.positiveDefinite == dense.positiveDefinite);
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          CHECK(fast.compliance(i, j) == Approx(dense.compliance(i, j)).epsilon(1e-8).margin(4 * dense.complianceAccuracy(i, j)));
          CHECK(fast.complianceAccuracy(i, j) == Approx(dense.complianceAccuracy(i, j)).epsilon(1e-3));
          CHECK(fast.stiffness(i, j) == Approx(dense.stiffness(i, j)).epsilon(1e-7).margin(1e-7 * dense.stiffness.norm()));
        }
      if (!k.end.isHeld(EndCoordinate::Phi))
        CHECK(fast.rotationalCompliance == Approx(dense.rotationalCompliance).epsilon(1e-8));
    }
  }
}

TEST_CASE("contact stiffness: at a guided chain's critical load the O(n) route is singular and gives the "
          "position-held K_F of the dense loadedStiffness",
          "[contact_stiffness]") {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> U(0.8, 1.2);
  const int n = 80;
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < n; ++i) segs.push_back(SegmentParameters::symmetric(0.4 * U(rng), U(rng), U(rng), 2.25 * U(rng)));
  // bent when unloaded (J_x ≠ 0: the straight chain's position-held system is singular in x)
  Eigen::VectorXd q(n);
  for (int i = 0; i < n; ++i) q[i] = 0.02 * (U(rng) - 1.0) + 0.01;
  const Chain chain(preloadsForShape(segs, q));
  const LinearBucklingResult lb = linearBuckling(chain, q, guided(0.0));
  double critical = 0.0;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0.0) {
      critical = m.lambda;
      break;
    }
  REQUIRE(critical < 0.0);
  EquilibriumProblem problem(chain, guided(0.0), Eigen::Vector3d(1.0, 0.0, 0.0));
  const ContactProblem contact(problem, ContactSet());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(contact.dimension());
  u.head(n) = q;
  CartesianStiffness fast;
  REQUIRE(structuredContactStiffness(contact, u, critical, fast));
  CHECK(fast.singular);
  const CartesianStiffness dense = loadedStiffness(chain, q, Wrench(critical, 0.0, 0.0), true);
  REQUIRE(dense.singular);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      CHECK(fast.stiffness(i, j) == Approx(dense.stiffness(i, j)).epsilon(1e-8).margin(1e-8 * dense.stiffness.norm()));
  // a step off the critical load: regular, and K_F there approaches the singular point's
  CartesianStiffness near;
  REQUIRE(structuredContactStiffness(contact, u, critical * (1 + 1e-7), near));
  CHECK_FALSE(near.singular);
}
