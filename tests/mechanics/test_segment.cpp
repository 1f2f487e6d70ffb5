#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "buckle/mechanics/segment.h"

#include "random_segments.h"

using namespace buckle::mechanics;

namespace {

// b in [0.8, 1.4]: away from degenerate geometry.
const testing::SegmentRanges kNarrow{0.1, 0.9, 0.8, 1.4, 0.5, 3.0, 1.5, 2.8};

double central(const std::function<double(double)>& f, double x, double h = 1e-5) {
  return (f(x + h) - f(x - h)) / (2 * h);
}

}  // namespace

TEST_CASE("segment torque derivatives match finite differences", "[segment]") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Segment s(testing::randomSegment(rng, kNarrow));
    std::uniform_real_distribution<double> Q(0.8 * s.geometricLowerLimit(), 0.8 * s.geometricUpperLimit());
    const double q = Q(rng);
    CHECK(s.torque(q) == Approx(-central([&](double x) { return s.energy(x); }, q)).margin(1e-8));
    CHECK(s.torqueDerivative(q) == Approx(central([&](double x) { return s.torque(x); }, q)).margin(1e-7));
    CHECK(s.torqueSecondDerivative(q) ==
          Approx(central([&](double x) { return s.torqueDerivative(x); }, q)).margin(1e-7));
    CHECK(s.stiffness(q) == Approx(-s.torqueDerivative(q)).margin(1e-14));
  }
}

TEST_CASE("general torque (eq 1) equals the symmetric closed forms (eq 3, 10, 19)", "[segment]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> A(0.1, 1.2), B(0.8, 1.4), K(0.5, 3.0), L(1.0, 3.0), Q(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double a = A(rng), b = B(rng), k = K(rng), L0 = L(rng), q = Q(rng);
    const Segment s(SegmentParameters::symmetric(a, b, k, L0));
    // eq 1 literally: M = k1(1 − L1⁰/L1) c² sin θ1 − k2(1 − L2⁰/L2) c² sin θ2
    const double c = std::hypot(a, b), beta = 2 * std::atan(a / b);
    const double L1 = std::sqrt(2 * c * c + 2 * c * c * std::cos(beta + q));
    const double L2 = std::sqrt(2 * c * c + 2 * c * c * std::cos(beta - q));
    const double eq1 = k * (1 - L0 / L1) * c * c * std::sin(beta + q) - k * (1 - L0 / L2) * c * c * std::sin(beta - q);
    // eq 3
    const double eq3 = 2 * c * k * (c * std::cos(beta) * std::sin(q) - L0 * std::cos(beta / 2) * std::sin(q / 2));
    const double eq3d = c * k * (2 * c * std::cos(beta) * std::cos(q) - L0 * std::cos(beta / 2) * std::cos(q / 2));
    // eq 10
    const double eq10 = 2 * k * ((b * b - a * a) * std::sin(q) - b * L0 * std::sin(q / 2));
    CHECK(s.torque(q) == Approx(eq1).margin(1e-12));
    CHECK(s.torque(q) == Approx(eq3).margin(1e-12));
    CHECK(s.torque(q) == Approx(eq10).margin(1e-12));
    CHECK(s.torqueDerivative(q) == Approx(eq3d).margin(1e-12));
    // spring lengths, docs/mechanics.md "Conventions": 2(b cos(q/2) ∓ a sin(q/2))
    CHECK(s.spring1(q).value == Approx(2 * (b * std::cos(q / 2) - a * std::sin(q / 2))).margin(1e-13));
    CHECK(s.spring2(q).value == Approx(2 * (b * std::cos(q / 2) + a * std::sin(q / 2))).margin(1e-13));
  }
  // eq 19: unequal preloads, symmetric geometry
  for (int trial = 0; trial < 50; ++trial) {
    SegmentParameters p = SegmentParameters::symmetric(A(rng), B(rng), K(rng), 2.0);
    p.L1_0 = L(rng);
    p.L2_0 = L(rng);
    const Segment s(p);
    const double a = p.a1, b = p.b1, k = p.k1, q = Q(rng);
    const double eq19 = 2 * k * (b * b - a * a) * std::sin(q) - k * p.L1_0 * (a * std::cos(q / 2) + b * std::sin(q / 2)) +
                        k * p.L2_0 * (a * std::cos(q / 2) - b * std::sin(q / 2));
    CHECK(s.torque(q) == Approx(eq19).margin(1e-12));
  }
}

TEST_CASE("stability condition (eq 4) is the sign of K_q at q = 0", "[segment]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> A(0.05, 1.3), B(0.5, 2.0), L(0.3, 4.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double a = A(rng), b = B(rng), L0 = L(rng);
    const Segment s(SegmentParameters::symmetric(a, b, 1.0, L0));
    const bool eq4 = L0 > 2 * b * (1 - (a / b) * (a / b));
    const double kappa = b * L0 - 2 * (b * b - a * a);
    CHECK(s.straightStiffness() == Approx(kappa).margin(1e-12));
    if (std::abs(kappa) > 1e-9) CHECK((s.straightStiffness() > 0) == eq4);
  }
}

TEST_CASE("geometric joint limit: closing spring reaches zero length at pi - beta12", "[segment]") {
  const Segment s(SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const double qmax = s.geometricUpperLimit();
  CHECK(qmax == Approx(2 * std::atan(1.0 / 0.5)).epsilon(1e-14));
  CHECK(s.spring1(qmax).value == Approx(0.0).margin(1e-7));
  CHECK(s.spring2(-qmax).value == Approx(0.0).margin(1e-7));
  CHECK(s.spring1(0.99 * qmax).value > 0.0);
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.qMaxUser = 1.0;
  CHECK(Segment(p).upperLimit() == 1.0);
  CHECK(Segment(p).lowerLimit() == Approx(-qmax));
}

TEST_CASE("spring jets stay accurate up to the geometric limit (no cancellation in L)", "[segment]") {
  // Reference: eq 1 in long double from the same double inputs (q, β12). Near the limit L → 0 (or
  // √Δ), L² = c1² + c2² + 2c1c2 cos θ evaluated naively in double would lose half the digits
  // (absolute error ~1e-8 in L); the half-angle form keeps absolute errors at a few ulp. dL/dq is
  // bounded there but d²L/dq² grows like P/√Δ for nearly equal triangles (Δ = (c1 − c2)² → 0), so
  // the derivatives are checked relative to max(1, |reference|).
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst[3] = {0, 0, 0};
  for (int trial = 0; trial < 400; ++trial) {
    SegmentParameters p = testing::randomSegment(rng, kNarrow);
    if (trial % 2) {  // symmetric triangles: L itself → 0 at the limit
      p.a2 = p.a1;
      p.b2 = p.b1;
    }
    const Segment s(p);
    const long double c1 = std::hypot((long double)p.a1, (long double)p.b1);
    const long double c2 = std::hypot((long double)p.a2, (long double)p.b2);
    const long double P = c1 * c2, delta = (c1 - c2) * (c1 - c2);
    for (int side = 0; side < 2; ++side) {
      const double d = std::pow(10.0, -12.0 * U(rng));  // relative distance to the limit, 1e-12 … 1
      const double q = side == 0 ? s.geometricUpperLimit() * (1.0 - d) : s.geometricLowerLimit() * (1.0 - d);
      for (int spring = 0; spring < 2; ++spring) {
        const long double sign = spring == 0 ? 1.0L : -1.0L;
        const long double theta = (long double)s.beta12() + sign * (long double)q;
        const long double ch = std::cos(0.5L * theta);
        const long double L = std::sqrt(delta + 4.0L * P * ch * ch);
        const long double d1 = -sign * P * std::sin(theta) / L;
        const long double d2 = -(P * std::cos(theta) * delta + 4.0L * P * P * ch * ch * ch * ch) / (L * L * L);
        const Jet3 got = spring == 0 ? s.spring1(q) : s.spring2(q);
        worst[0] = std::max(worst[0], double(std::abs(got.value - L)));
        worst[1] = std::max(worst[1], double(std::abs(got.d1 - d1) / std::max(1.0L, std::abs(d1))));
        worst[2] = std::max(worst[2], double(std::abs(got.d2 - d2) / std::max(1.0L, std::abs(d2))));
      }
    }
  }
  INFO("worst errors: L " << worst[0] << ", dL/dq " << worst[1] << ", d2L/dq2 " << worst[2]);
  // (measured: L 7.8e-16, dL/dq 1.0e-13, d²L/dq² 6.0e-14; the previous full-angle form gave
  // 7.2e-16, 1.4e-13, 1.6e-13: the derivative errors come from cos(θ/2) near 0 itself, i.e. from q)
  CHECK(worst[0] < 2e-15);
  CHECK(worst[1] < 5e-13);
  CHECK(worst[2] < 5e-13);
}

TEST_CASE("spring jets keep their relative accuracy as L -> 0, at the limit and past it", "[segment]") {
  // Reference in long double from the distance to the (double) limit δ = q_max − q, exact in
  // double near the limit: c = cos(θ/2) = sin(δ/2), s_h = cos(δ/2). For identical triangles
  // L = 2√P c → 0 with δ, smooth and signed past the limit (its analytic continuation); the jet
  // must keep relative accuracy down to δ = 1e-15 and be finite at δ = 0 (no 0/0).
  std::mt19937 rng(23);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    SegmentParameters p = testing::randomSegment(rng, kNarrow);
    if (trial % 2) {
      p.a2 = p.a1;
      p.b2 = p.b1;
    }
    const Segment s(p);
    const long double c1 = std::hypot((long double)p.a1, (long double)p.b1);
    const long double c2 = std::hypot((long double)p.a2, (long double)p.b2);
    const long double P = c1 * c2, delta = (long double)((double(c1) - double(c2)) * (double(c1) - double(c2)));
    for (int k = -3; k <= 16; ++k) {
      // k = 16: at the limit; k < 0: past it by 10^k
      const double d = k == 16 ? 0.0 : (k < 0 ? -std::pow(10.0, double(k)) : std::pow(10.0, -double(k)));
      for (int spring = 0; spring < 2; ++spring) {
        const double q = spring == 0 ? s.geometricUpperLimit() - d : s.geometricLowerLimit() + d;
        const long double sign = spring == 0 ? 1.0L : -1.0L;
        const long double h = 0.5L * (spring == 0 ? (long double)s.geometricUpperLimit() - q
                                                  : q - (long double)s.geometricLowerLimit());
        const long double c = std::sin(h), sh = std::cos(h), cosT = c * c - sh * sh;
        long double L, d1, d2;
        if (delta > 0) {
          L = std::sqrt(delta + 4.0L * P * c * c);
          d1 = -2.0L * sign * P * sh * c / L;
          d2 = -(P * cosT * delta + 4.0L * P * P * c * c * c * c) / (L * L * L);
        } else {
          L = 2.0L * std::sqrt(P) * c;
          d1 = -sign * std::sqrt(P) * sh;
          d2 = -0.5L * std::sqrt(P) * c;
        }
        const Jet3 got = spring == 0 ? s.spring1(q) : s.spring2(q);
        REQUIRE(std::isfinite(got.value));
        REQUIRE(std::isfinite(got.d1));
        REQUIRE(std::isfinite(got.d2));
        REQUIRE(std::isfinite(got.d3));
        const auto rel = [](double x, long double ref) {
          return ref == 0 ? double(std::abs(x)) : double(std::abs(x - ref) / std::abs(ref));
        };
        worst = std::max({worst, rel(got.value, L), rel(got.d1, d1), rel(got.d2, d2)});
        if (delta == 0 && d == 0.0) CHECK(got.value == 0.0);  // exactly zero length at the limit
      }
    }
  }
  INFO("worst relative error of L, L', L'' near the limit: " << worst);
  CHECK(worst < 1e-13);
}

TEST_CASE("the third derivative of L is continuous through the geometric limit", "[segment]") {
  // Identical triangles: L = 2√P sin(δ/2), so L‴ = √P s_h/4·(sign) stays bounded and continuous
  // where L = 0; finite differences of L″ on both sides agree with it.
  const Segment s(SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const double qmax = s.geometricUpperLimit(), h = 1e-5;
  for (double q : {qmax - 1e-3, qmax, qmax + 1e-3}) {
    const double fd = (s.spring1(q + h).d2 - s.spring1(q - h).d2) / (2 * h);
    CHECK(std::abs(s.spring1(q).d3 - fd) <= 1e-8);
  }
  CHECK(std::abs(s.spring1(qmax).d3 - std::sqrt(std::hypot(0.5, 1.0) * std::hypot(0.5, 1.0)) / 4) <= 1e-15);
}

TEST_CASE("bad segment parameters are rejected naming the parameter", "[segment]") {
  auto message = [](SegmentParameters p) {
    try {
      Segment s(p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  SegmentParameters p;
  p.b1 = 0;
  CHECK_THAT(message(p), Catch::Contains("b1"));
  p = {};
  p.k2 = -1;
  CHECK_THAT(message(p), Catch::Contains("k2"));
  p = {};
  p.a1 = -0.1;
  CHECK_THAT(message(p), Catch::Contains("a1"));
  p = {};
  p.L1_0 = -2;
  CHECK_THAT(message(p), Catch::Contains("L1_0"));
  p = {};
  p.a2 = std::numeric_limits<double>::quiet_NaN();
  CHECK_THAT(message(p), Catch::Contains("a2"));
  p = {};
  p.k1 = std::numeric_limits<double>::infinity();
  CHECK_THAT(message(p), Catch::Contains("k1"));
  p = {};
  p.qMinUser = 1.0;
  p.qMaxUser = 0.5;
  CHECK_THAT(message(p), Catch::Contains("joint limits"));
  CHECK(message(SegmentParameters{}) == "accepted");
}

TEST_CASE("energy jet parameter derivatives match finite differences in every parameter", "[segment]") {
  std::mt19937 rng(11);
  // one unit direction per parameter, then a mixed one
  std::vector<SegmentParameterDirection> dirs(9);
  dirs[0].a1 = 1;
  dirs[1].b1 = 1;
  dirs[2].a2 = 1;
  dirs[3].b2 = 1;
  dirs[4].k1 = 1;
  dirs[5].k2 = 1;
  dirs[6].L1_0 = 1;
  dirs[7].L2_0 = 1;
  dirs[8] = {0.3, -0.2, 0.5, 0.7, 1.1, -0.4, 0.5, -0.5};
  for (int trial = 0; trial < 10; ++trial) {
    const SegmentParameters p = testing::randomSegment(rng, kNarrow);
    const Segment s(p);
    std::uniform_real_distribution<double> Q(0.7 * s.geometricLowerLimit(), 0.7 * s.geometricUpperLimit());
    const double q = Q(rng);
    for (const SegmentParameterDirection& d : dirs) {
      auto moved = [&](double h) {
        SegmentParameters m = p;
        m.a1 += h * d.a1;
        m.b1 += h * d.b1;
        m.a2 += h * d.a2;
        m.b2 += h * d.b2;
        m.k1 += h * d.k1;
        m.k2 += h * d.k2;
        m.L1_0 += h * d.L1_0;
        m.L2_0 += h * d.L2_0;
        return Segment(m).energyJet(q);
      };
      const double h = 1e-5;
      const Jet3 plus = moved(h), minus = moved(-h);
      const Jet3 exact = s.energyJetParameterDerivative(q, d);
      CHECK(exact.value == Approx((plus.value - minus.value) / (2 * h)).margin(1e-8));
      CHECK(exact.d1 == Approx((plus.d1 - minus.d1) / (2 * h)).margin(1e-8));
      CHECK(exact.d2 == Approx((plus.d2 - minus.d2) / (2 * h)).margin(1e-8));
      CHECK(exact.d3 == Approx((plus.d3 - minus.d3) / (2 * h)).margin(1e-7));
    }
  }
  // symmetric closed form: κ = k(b L0 − 2(b² − a²)), so ∂κ/∂a = 4ka, ∂κ/∂b = k(L0 − 4b), ∂κ/∂L0 = kb
  const Segment sym(SegmentParameters::symmetric(0.4, 1.1, 2.0, 2.3));
  SegmentParameterDirection da, db, dL;
  da.a1 = da.a2 = 1;
  db.b1 = db.b2 = 1;
  dL.L1_0 = dL.L2_0 = 1;
  CHECK(sym.energyJetParameterDerivative(0.0, da).d2 == Approx(4 * 2.0 * 0.4).epsilon(1e-13));
  CHECK(sym.energyJetParameterDerivative(0.0, db).d2 == Approx(2.0 * (2.3 - 4 * 1.1)).epsilon(1e-13));
  CHECK(sym.energyJetParameterDerivative(0.0, dL).d2 == Approx(2.0 * 1.1).epsilon(1e-13));
}
