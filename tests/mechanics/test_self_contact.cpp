// Self contact's gap and its derivatives (self_contact.h) against the test's own geometry: the
// gap from wall_statics.h's vertices, its gradient and Hessian by central differences of that
// gap; the touching pair against a brute-force scan of every vertex–edge distance.
#include <catch2/catch.hpp>

#include <random>

#include "buckle/mechanics/self_contact.h"
#include "random_segments.h"
#include "wall_statics.h"

namespace mech = buckle::mechanics;
using Eigen::Vector2d;
using Eigen::VectorXd;

namespace {

// The gap n_e·(p_v − p_e0) from the test's own vertices.
double testGap(const mech::Chain& chain, const VectorXd& q, const mech::SelfContact& c) {
  const int s = c.edge.segment;
  const Vector2d e0 = buckle::test::vertexAt(chain, q, {s, c.edge.corner(0)});
  const Vector2d e1 = buckle::test::vertexAt(chain, q, {s, c.edge.corner(1)});
  const Vector2d third = buckle::test::vertexAt(chain, q, {s, c.edge.corner(2)});
  Vector2d n(e1.y() - e0.y(), e0.x() - e1.x());
  n.normalize();
  if (n.dot(third - e0) > 0.0) n = -n;
  return n.dot(buckle::test::vertexAt(chain, q, c.vertex) - e0);
}

mech::Chain randomChain(std::mt19937& rng, int n) {
  std::vector<mech::SegmentParameters> p;
  for (int i = 0; i < n; ++i) p.push_back(mech::testing::randomSegment(rng));
  return mech::Chain(p);
}

}  // namespace

TEST_CASE("self contact: gap, gradient and Hessian against the test's own geometry", "[self_contact]") {
  std::mt19937 rng(20261207);
  const int n = 7;
  const mech::Chain chain = randomChain(rng, n);
  using V = mech::WallVertex;
  using E = mech::TriangleEdge;
  // the vertex's body distal (σ = +1) and proximal (σ = −1), the clamped triangle's corner, a joint
  const std::vector<mech::SelfContact> contacts = {
      {V{5, 3}, E{1, true, 0}}, {V{6, 4}, E{2, false, 1}}, {V{1, 3}, E{5, false, 2}}, {V{0, 1}, E{4, true, 1}},
      {V{5, 0}, E{2, true, 2}}, {V{2, 2}, E{6, true, 0}}};
  for (int trial = 0; trial < 4; ++trial) {
    const VectorXd q = mech::testing::randomState(rng, chain, n);
    const Eigen::Matrix2Xd P = mech::jointPositions(chain, q);
    for (const mech::SelfContact& c : contacts) {
      INFO(c.label() << ", trial " << trial);
      REQUIRE_NOTHROW(mech::checkSelfContact(c, n));
      const mech::SelfContactGap g = mech::selfContactGap(chain, q, P, c);
      CHECK(g.gap == Approx(testGap(chain, q, c)).margin(1e-13));
      VectorXd grad(n), gen(n), coupling(n), weights(n);
      mech::selfContactDerivatives(P, c, g, grad, gen, coupling, weights);
      // −∂²g assembled from the generator form and the rank-2 term
      Eigen::MatrixXd minusHessian(n, n);
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          minusHessian(j, k) = gen[std::max(j, k)] - coupling[j] * weights[k] - weights[j] * coupling[k];
      const double h = 1e-5, h2 = 1e-3;
      double gradError = 0.0, hessError = 0.0;
      for (int j = 0; j < n; ++j) {
        VectorXd qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        gradError = std::max(gradError, std::abs(grad[j] - (testGap(chain, qp, c) - testGap(chain, qm, c)) / (2 * h)));
        for (int k = 0; k < n; ++k) {
          VectorXd a = q, b = q, cc = q, d = q;
          a[j] += h2, a[k] += h2;
          b[j] += h2, b[k] -= h2;
          cc[j] -= h2, cc[k] += h2;
          d[j] -= h2, d[k] -= h2;
          const double fd = (testGap(chain, a, c) - testGap(chain, b, c) - testGap(chain, cc, c) + testGap(chain, d, c)) /
                            (4 * h2 * h2);
          hessError = std::max(hessError, std::abs(-minusHessian(j, k) - fd));
        }
      }
      CHECK(gradError < 1e-8);
      CHECK(hessError < 1e-5);
      // the joints that move both bodies or neither do not enter
      const int lo = std::min(c.vertex.lastJoint(), c.edge.lastJoint());
      const int hi = std::max(c.vertex.lastJoint(), c.edge.lastJoint());
      for (int j = 0; j < n; ++j)
        if (j <= lo || j > hi) CHECK(grad[j] == 0.0);
    }
  }
}

TEST_CASE("self contact: contacts between the same or adjacent links are refused", "[self_contact]") {
  using V = mech::WallVertex;
  using E = mech::TriangleEdge;
  const int n = 5;
  CHECK_THROWS_AS(mech::checkSelfContact({V{2, 3}, E{2, true, 0}}, n), std::invalid_argument);   // the same triangle
  CHECK_THROWS_AS(mech::checkSelfContact({V{2, 3}, E{3, true, 0}}, n), std::invalid_argument);   // adjacent links
  CHECK_THROWS_AS(mech::checkSelfContact({V{3, 0}, E{2, true, 1}}, n), std::invalid_argument);   // joint 4 is on link 3
  CHECK_THROWS_AS(mech::checkSelfContact({V{7, 3}, E{0, true, 0}}, n), std::invalid_argument);   // no segment 8
  CHECK_THROWS_AS(mech::checkSelfContact({V{4, 3}, E{0, true, 5}}, n), std::invalid_argument);   // no edge 5
  CHECK_NOTHROW(mech::checkSelfContact({V{3, 3}, E{1, true, 0}}, n));
  CHECK(mech::SelfContact{V{3, 3}, E{1, true, 1}}.label() == "4d+ on 2d[j,+]");
}

TEST_CASE("self contact: the touching pair is the nearest vertex over an edge (brute force)", "[self_contact]") {
  std::mt19937 rng(7);
  const int n = 6;
  const mech::Chain chain = randomChain(rng, n);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd q = mech::testing::randomState(rng, chain, n);
    const int a = 1, b = 4;
    // every corner of link a's and link b's triangles against every edge of the other's, by the test's geometry
    double best = std::numeric_limits<double>::infinity();
    const auto triangles = [&](int link) {
      std::vector<std::pair<int, bool>> t;
      if (link >= 1) t.push_back({link - 1, true});
      if (link <= n - 1) t.push_back({link, false});
      return t;
    };
    for (const auto& [vl, el] : {std::pair{a, b}, std::pair{b, a}})
      for (const auto& [vs, vd] : triangles(vl))
        for (const int corner : vd ? std::vector<int>{0, 3, 4} : std::vector<int>{0, 1, 2})
          for (const auto& [es, ed] : triangles(el))
            for (int edge = 0; edge < 3; ++edge) {
              const mech::SelfContact c{{vs, corner}, {es, ed, edge}};
              const Vector2d p = buckle::test::vertexAt(chain, q, c.vertex);
              const Vector2d e0 = buckle::test::vertexAt(chain, q, {es, c.edge.corner(0)});
              const Vector2d e1 = buckle::test::vertexAt(chain, q, {es, c.edge.corner(1)});
              const double t = (p - e0).dot(e1 - e0) / (e1 - e0).squaredNorm();
              if (t < 0.0 || t > 1.0) continue;
              best = std::min(best, std::abs(testGap(chain, q, c)));
            }
    INFO("trial " << trial);
    if (!std::isfinite(best)) {  // no vertex over an edge of the other link
      CHECK_THROWS_AS(mech::touchingPair(chain, q, a, b), std::invalid_argument);
      continue;
    }
    const mech::SelfContact found = mech::touchingPair(chain, q, a, b);
    INFO(found.label());
    CHECK(std::abs(testGap(chain, q, found)) == Approx(best).margin(1e-12));
  }
  CHECK_THROWS_AS(mech::touchingPair(chain, VectorXd::Zero(n), 2, 3), std::invalid_argument);
}
