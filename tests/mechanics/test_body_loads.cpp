// Body loads (body_loads.h): the torques and generator of the weight against the independent
// GravityPotential (absolute positions, gravity.h), point loads against central differences of the
// potential (B1), a load at the end against the end wrench (eq 11, 27), and the rate dγ (B5)
// against differences of γ, in the paper's units and scaled ones (lengths ×1e-4, stiffness ×1e8).
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <random>

#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/gravity.h"
#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::randomAngles;

// A random chain with lengths ×L and stiffnesses ×k.
Chain scaledChain(std::mt19937& rng, int n, double L, double k) {
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < n; ++i) {
    SegmentParameters p = testing::randomSegment(rng);
    p.a1 *= L, p.a2 *= L, p.b1 *= L, p.b2 *= L, p.L1_0 *= L, p.L2_0 *= L, p.k1 *= k, p.k2 *= k;
    segs.push_back(p);
  }
  return Chain(segs);
}

InertiaData unevenMasses(const Chain& chain, double massScale) {
  InertiaData data;
  for (int i = 0; i < chain.size(); ++i)
    data.links.push_back({massScale * (0.7 + 0.3 * i), 0.0,
                          i % 2 == 0 ? 0.3 * chain.linkLengths()[i + 1] : std::numeric_limits<double>::quiet_NaN()});
  return data;
}

struct Terms {
  Vector tau, gamma;
  double V = 0.0;
};

Terms termsAt(const Chain& chain, BodyLoadTerms& terms, const Vector& q, double lambda) {
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  terms.update(data);
  Terms t;
  t.tau.resize(chain.size());
  t.gamma.resize(chain.size());
  terms.torques(lambda, t.tau);
  terms.generator(lambda, t.gamma);
  t.V = terms.potential(data, lambda);
  return t;
}

}  // namespace

TEST_CASE("body loads: the weight's torques, generator and potential equal GravityPotential's", "[body_loads]") {
  std::mt19937 rng(31);
  for (double L : {1.0, 1e-4}) {
    const double k = L == 1.0 ? 1.0 : 1e8, force = k * L;  // masses scale with the force unit (g fixed)
    for (int n : {1, 4, 12}) {
      const Chain chain = scaledChain(rng, n, L, k);
      const InertiaData inertia = unevenMasses(chain, force);
      const Eigen::Vector2d g0(0.7, -9.81), rate(-0.2, 0.5);
      const double lambda = 0.8;
      BodyLoadTerms terms(chain, BodyLoads::weight(chain, inertia, g0, rate));
      REQUIRE(terms.active());
      GravityPotential V(chain, inertia, g0 + lambda * rate);
      for (int trial = 0; trial < 3; ++trial) {
        const Vector q = randomAngles(rng, chain, 0.7);
        const Terms t = termsAt(chain, terms, q, lambda);
        Vector grad(n), gamma(n);
        V.gradient(q, grad);
        V.hessianGenerator(q, gamma);
        const double scale = force * (g0 + lambda * rate).norm() * chain.length() * n;
        INFO("L = " << L << ", n = " << n);
        CHECK((t.tau + grad).cwiseAbs().maxCoeff() <= 1e-13 * scale);
        CHECK((t.gamma - gamma).cwiseAbs().maxCoeff() <= 1e-13 * scale);
        CHECK(std::abs(t.V - V.value(q)) <= 1e-13 * scale);
      }
    }
  }
}

TEST_CASE("body loads: point loads at joints, torques and generator by central differences of V, dgamma of gamma",
          "[body_loads]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  for (double L : {1.0, 1e-4}) {
    const double k = L == 1.0 ? 1.0 : 1e8, force = k * L;
    for (int n : {1, 3, 9}) {
      const Chain chain = scaledChain(rng, n, L, k);
      BodyLoads loads = BodyLoads::weight(chain, unevenMasses(chain, force), {0.3, -1.0}, {0.1, -0.4});
      for (int j = 1; j <= n + 1; j += 2)
        loads.points.push_back({j, force * Eigen::Vector2d(W(rng), W(rng)), force * Eigen::Vector2d(W(rng), W(rng))});
      BodyLoadTerms terms(chain, loads);
      const double lambda = 0.6, scale = force * chain.length() * (n + 2);
      INFO("L = " << L << ", n = " << n);
      const Vector q = randomAngles(rng, chain, 0.7);
      const Terms t = termsAt(chain, terms, q, lambda);
      const double h = 1e-5;
      for (int j = 0; j < n; ++j) {
        Vector e = Vector::Zero(n);
        e[j] = h;
        const Terms p = termsAt(chain, terms, q + e, lambda), m = termsAt(chain, terms, q - e, lambda);
        CHECK(std::abs(-(p.V - m.V) / (2 * h) - t.tau[j]) <= 1e-8 * scale);  // eq (B2)
        for (int i = 0; i < n; ++i)  // ∂²V/∂q_i∂q_j = γ_max(i,j), eq (B3)
          CHECK(std::abs(-(p.tau[i] - m.tau[i]) / (2 * h) - t.gamma[std::max(i, j)]) <= 1e-8 * scale);
      }
      // the λ derivatives: ∂V/∂λ by differences, τ' and γ' as the differences of τ and γ
      Vector tauRate(n), gammaRate(n);
      const Terms lp = termsAt(chain, terms, q, lambda + h), lm = termsAt(chain, terms, q, lambda - h);
      tauRate = terms.rateTorques();
      gammaRate = terms.rateGenerator();
      CHECK(((lp.tau - lm.tau) / (2 * h) - tauRate).cwiseAbs().maxCoeff() <= 1e-8 * scale);
      CHECK(((lp.gamma - lm.gamma) / (2 * h) - gammaRate).cwiseAbs().maxCoeff() <= 1e-8 * scale);
      // dγ along (dq, dλ), eq (B5)
      Vector dq(n);
      for (int i = 0; i < n; ++i) dq[i] = W(rng);
      const double dl = W(rng);
      termsAt(chain, terms, q, lambda);
      Vector dgamma(n);
      terms.generatorDerivative(lambda, dq, dl, dgamma);
      const Terms sp = termsAt(chain, terms, q + h * dq, lambda + h * dl);
      const Terms sm = termsAt(chain, terms, q - h * dq, lambda - h * dl);
      CHECK(((sp.gamma - sm.gamma) / (2 * h) - dgamma).cwiseAbs().maxCoeff() <= 1e-7 * scale);
    }
  }
}

TEST_CASE("body loads: a force at the end is the end wrench (torques J^T F, generator -h of eq 27)", "[body_loads]") {
  std::mt19937 rng(3);
  const int n = 6;
  const Chain chain = scaledChain(rng, n, 1.0, 1.0);
  const Eigen::Vector2d f(0.8, -1.3);
  BodyLoads loads;
  loads.points.push_back({n + 1, f, Eigen::Vector2d::Zero()});
  BodyLoadTerms terms(chain, loads);
  const Vector q = randomAngles(rng, chain, 0.7);
  const Terms t = termsAt(chain, terms, q, 0.0);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  Vector h(n);
  const Wrench F(f.x(), f.y(), 0.0);
  loadHessianGenerator(data, F, h);
  const double scale = f.norm() * chain.length();
  CHECK((t.tau - J.transpose() * F).cwiseAbs().maxCoeff() <= 1e-14 * scale);
  CHECK((t.gamma + h).cwiseAbs().maxCoeff() <= 1e-14 * scale);
  CHECK(std::abs(t.V + f.dot(data.pose.head<2>())) <= 1e-14 * scale);
}

TEST_CASE("body loads: a payload added to the end link (withPayload) weighs as the rods plus a point load m_p g at the "
          "end", "[body_loads]") {
  std::mt19937 rng(5);
  const int n = 5;
  const Chain chain = scaledChain(rng, n, 1.0, 1.0);
  const InertiaData rods = InertiaData::uniformRods(chain, 0.8);
  const double mp = 0.3;
  const Eigen::Vector2d g(0.4, -2.0);
  const InertiaData withEnd = withPayload(chain, rods, mp);
  // the end link: total mass, centre of mass and the parallel-axis inertia about that centre
  const double l = chain.linkLengths()[n], m = rods.links.back().mass;
  const LinkInertia& L = withEnd.links.back();
  CHECK(L.mass == Approx(m + mp).epsilon(1e-15));
  CHECK(L.comOffset == Approx((m * 0.5 * l + mp * l) / (m + mp)).epsilon(1e-15));
  CHECK(L.inertia == Approx(m * l * l / 12 + m * std::pow(0.5 * l - L.comOffset, 2) + mp * std::pow(l - L.comOffset, 2))
                         .epsilon(1e-14));
  BodyLoads split = BodyLoads::weight(chain, rods, g, Eigen::Vector2d::Zero());
  split.points.push_back({n + 1, mp * g, Eigen::Vector2d::Zero()});
  BodyLoadTerms a(chain, split), b(chain, BodyLoads::weight(chain, withEnd, g, Eigen::Vector2d::Zero()));
  const Vector q = randomAngles(rng, chain, 0.7);
  const Terms ta = termsAt(chain, a, q, 0.0), tb = termsAt(chain, b, q, 0.0);
  const double scale = (m * n + mp) * g.norm() * chain.length();
  CHECK((ta.tau - tb.tau).cwiseAbs().maxCoeff() <= 1e-14 * scale);
  CHECK((ta.gamma - tb.gamma).cwiseAbs().maxCoeff() <= 1e-14 * scale);
  CHECK_THROWS_WITH(withPayload(chain, rods, -1.0), Catch::Contains("payload mass"));
}

TEST_CASE("body loads: bad input is refused naming the value", "[body_loads]") {
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  BodyLoads loads;
  loads.points.push_back({5, {1.0, 0.0}, {0.0, 0.0}});
  CHECK_THROWS_WITH(BodyLoadTerms(chain, loads), Catch::Contains("joints are 1"));
  loads.points.clear();
  loads.mass = Vector::Ones(2);
  loads.centre = Vector::Zero(2);
  CHECK_THROWS_WITH(BodyLoadTerms(chain, loads), Catch::Contains("2 link masses"));
  loads.mass = Vector::Ones(3);
  loads.centre = Vector::Constant(3, 10.0);
  CHECK_THROWS_WITH(BodyLoadTerms(chain, loads), Catch::Contains("centre of mass"));
  loads.centre = Vector::Zero(3);
  loads.gravity = {std::nan(""), 0.0};
  CHECK_THROWS_WITH(BodyLoadTerms(chain, loads), Catch::Contains("gravity"));
  loads.gravity = {0.0, 0.0};
  CHECK_FALSE(BodyLoadTerms(chain, loads).active());  // masses without gravity: no load
}
