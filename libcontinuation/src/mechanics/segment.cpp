#include "buckle/mechanics/segment.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/validation.h"

namespace buckle::mechanics {

SegmentParameters SegmentParameters::symmetric(double a, double b, double k, double L0) {
  SegmentParameters p;
  p.a1 = p.a2 = a;
  p.b1 = p.b2 = b;
  p.k1 = p.k2 = k;
  p.L1_0 = p.L2_0 = L0;
  return p;
}

Segment::Segment(const SegmentParameters& p) : p_(p) {
  requireNonNegative("a1", p.a1);
  requireNonNegative("a2", p.a2);
  requirePositive("b1", p.b1);
  requirePositive("b2", p.b2);
  requirePositive("k1", p.k1);
  requirePositive("k2", p.k2);
  // A free length <= 0 is a spring that would have to pass through zero length: no preload
  // can produce it on the real mechanism.
  requirePositive("L1_0", p.L1_0);
  requirePositive("L2_0", p.L2_0);
  if (std::isnan(p.qMinUser)) throw std::invalid_argument("qMinUser must not be NaN");
  if (std::isnan(p.qMaxUser)) throw std::invalid_argument("qMaxUser must not be NaN");
  c1_ = std::hypot(p.a1, p.b1);
  c2_ = std::hypot(p.a2, p.b2);
  c1c2_ = c1_ * c2_;
  sqrtP_ = std::sqrt(c1c2_);
  beta12_ = std::atan(p.a1 / p.b1) + std::atan(p.a2 / p.b2);
  delta_ = (c1_ - c2_) * (c1_ - c2_);
  cosHalfBeta_ = std::cos(0.5 * beta12_);
  sinHalfBeta_ = std::sin(0.5 * beta12_);
  if (!(lowerLimit() < upperLimit())) {
    std::ostringstream os;
    os << "joint limits are empty: qMinUser=" << p.qMinUser << ", qMaxUser=" << p.qMaxUser
       << ", geometric range (" << geometricLowerLimit() << ", " << geometricUpperLimit() << ")";
    throw std::invalid_argument(os.str());
  }
}

// θ = β12 + s·q (s = +1: spring 1, s = −1: spring 2), L² = c1² + c2² + 2c1c2 cos θ (eq 1).
// Near the geometric limit (θ → π) that form cancels catastrophically, so everything is written
// with the half angle, 1 + cos θ = 2cos²(θ/2) (exact to rounding): with P = c1c2, Δ = (c1 − c2)²,
// c = cos(θ/2), s_h = sin(θ/2), r = c/L,
//   L² = Δ + 4P c²,   dL/dq = −s P sin θ / L = −2s P s_h r,
//   d²L/dq² = −[P cos θ Δ + 4P²c⁴] / L³ = L·g,  g = −P cos θ Δ/L⁴ − 4P² r⁴,
//   d³L/dq³ = −dL/dq − 3 (dL/dq)(d²L/dq²)/L = −dL/dq (1 + 3g),   cos θ = c² − s_h².
// Near the limit, written with r and g, nothing is 0/0 where L → 0: for identical triangles
// (Δ = 0) L = 2√P c and r = 1/(2√P) exactly, so L, L′, L″, L‴ are the smooth functions of q they are on the
// admissible side, up to and at the limit itself (c = 0, L = 0), and continue analytically
// beyond it (c < 0, L < 0: what the boundary location of the tracer needs to bracket the limit;
// equilibrium_problem.cpp). For Δ > 0, L ≥ √Δ > 0 is smooth through the limit anyway.
// Both springs share one sincos of q/2: θ/2 = β12/2 ± q/2, so by the addition theorems
//   cos(θ/2) = cos(β12/2)cos(q/2) ∓ sin(β12/2)sin(q/2),  sin(θ/2) = sin(β12/2)cos(q/2) ± cos(β12/2)sin(q/2).
// cos(θ/2) → 0 at the limit loses its relative accuracy in that difference (absolute error of
// a few ulp), so near the limit (|c| < kNearLimit) c and s_h come from the distance to the limit
// instead, δ = q_max − q (exact by Sterbenz there): c = sin(δ/2), s_h = cos(δ/2) — relative
// accuracy to the end, and c = 0 exactly at q = geometricUpperLimit() (the double limit).
namespace {
constexpr double kNearLimit = 0.25;

// Away from the limit (|c| ≥ kNearLimit, L ≥ 2√P·kNearLimit): the direct forms.
inline Jet3 springFromHalfAngle(double c, double sh, double sign, double P, double delta) {
  const double c2 = c * c;
  Jet3 L;
  L.value = std::sqrt(delta + 4.0 * P * c2);
  const double inv = 1.0 / L.value;
  L.d1 = -2.0 * sign * P * sh * c * inv;
  L.d2 = -(P * (c2 - sh * sh) * delta + 4.0 * P * P * c2 * c2) * (inv * inv * inv);
  L.d3 = -L.d1 - 3.0 * L.d1 * L.d2 * inv;
  return L;
}

// Near the limit: the same quantities through r = c/L and g = L″/L, never 0/0.
inline Jet3 springNearLimit(double c, double sh, double sign, double P, double delta, double sqrtP) {
  Jet3 L;
  double r, w;
  if (delta > 0.0) {
    L.value = std::sqrt(delta + 4.0 * P * c * c);
    const double inv = 1.0 / L.value;
    r = c * inv;
    w = delta * (inv * inv) * (inv * inv);
  } else {  // identical triangles: L = 2√P c, signed (its analytic continuation through c = 0)
    L.value = 2.0 * sqrtP * c;
    r = 0.5 / sqrtP;
    w = 0.0;
  }
  const double r2 = r * r;
  const double g = -P * (c * c - sh * sh) * w - 4.0 * P * P * r2 * r2;
  L.d1 = -2.0 * sign * P * sh * r;
  L.d2 = g * L.value;
  L.d3 = -L.d1 * (1.0 + 3.0 * g);
  return L;
}
}  // namespace

void Segment::springs(double q, double sq, double cq, Jet3& L1, Jet3& L2) const {
  const double cc = cosHalfBeta_ * cq, ss = sinHalfBeta_ * sq;
  const double sc = sinHalfBeta_ * cq, cs = cosHalfBeta_ * sq;
  const double c1 = cc - ss, c2 = cc + ss;
  if (std::abs(c1) < kNearLimit) {  // spring 1 near its limit q_max = π − β12
    const double h = 0.5 * (geometricUpperLimit() - q);
    L1 = springNearLimit(std::sin(h), std::cos(h), +1.0, c1c2_, delta_, sqrtP_);
  } else {
    L1 = springFromHalfAngle(c1, sc + cs, +1.0, c1c2_, delta_);
  }
  if (std::abs(c2) < kNearLimit) {  // spring 2 near q_min = β12 − π
    const double h = 0.5 * (q - geometricLowerLimit());
    L2 = springNearLimit(std::sin(h), std::cos(h), -1.0, c1c2_, delta_, sqrtP_);
  } else {
    L2 = springFromHalfAngle(c2, sc - cs, -1.0, c1c2_, delta_);
  }
}

Jet3 Segment::spring1(double q) const {
  Jet3 L1, L2;
  springs(q, std::sin(0.5 * q), std::cos(0.5 * q), L1, L2);
  return L1;
}
Jet3 Segment::spring2(double q) const {
  Jet3 L1, L2;
  springs(q, std::sin(0.5 * q), std::cos(0.5 * q), L1, L2);
  return L2;
}

Jet3 Segment::energyJet(double q) const {
  return energyJet(q, std::sin(0.5 * q), std::cos(0.5 * q));  // one sincos call at -O2
}

namespace {
// One spring's term of E = Σ ½k(L − L⁰)² (eq 7) and its q-derivatives, added to E; the stretch
// L − L⁰ returned (both energy jets share this, so their sums are the same bit for bit).
inline double addSpring(const Jet3& L, double k, double L0, Jet3& E) {
  const double stretch = L.value - L0;
  E.value += 0.5 * k * stretch * stretch;
  E.d1 += k * stretch * L.d1;
  E.d2 += k * (L.d1 * L.d1 + stretch * L.d2);
  E.d3 += k * (3.0 * L.d1 * L.d2 + stretch * L.d3);
  return stretch;
}
}  // namespace

Jet3 Segment::energyJet(double q, double sinHalf, double cosHalf) const {
  Jet3 L1, L2;
  springs(q, sinHalf, cosHalf, L1, L2);
  Jet3 E;
  addSpring(L1, p_.k1, p_.L1_0, E);
  addSpring(L2, p_.k2, p_.L2_0, E);
  return E;
}

Jet3 Segment::energyJet(double q, double sinHalf, double cosHalf, double L1_0, double L2_0, double r1, double r2,
                        Jet3& rate) const {
  Jet3 Ls[2];
  springs(q, sinHalf, cosHalf, Ls[0], Ls[1]);
  const double k[2] = {p_.k1, p_.k2};
  const double L0[2] = {L1_0, L2_0};
  const double r[2] = {r1, r2};
  Jet3 E;
  rate = Jet3{};
  for (int i = 0; i < 2; ++i) {
    const Jet3& L = Ls[i];
    const double stretch = addSpring(L, k[i], L0[i], E);
    const double kr = k[i] * r[i];  // E = ½k(L − L⁰)²: ∂/∂L⁰ of each term is −k(·)
    rate.value -= kr * stretch;
    rate.d1 -= kr * L.d1;
    rate.d2 -= kr * L.d2;
    rate.d3 -= kr * L.d3;
  }
  return E;
}

double Segment::energy(double q) const { return energyJet(q).value; }
double Segment::torque(double q) const { return -energyJet(q).d1; }
double Segment::torqueDerivative(double q) const { return -energyJet(q).d2; }
double Segment::torqueSecondDerivative(double q) const { return -energyJet(q).d3; }
double Segment::stiffness(double q) const { return energyJet(q).d2; }

double Segment::geometricUpperLimit() const { return M_PI - beta12_; }
double Segment::geometricLowerLimit() const { return beta12_ - M_PI; }
double Segment::upperLimit() const { return std::min(geometricUpperLimit(), p_.qMaxUser); }
double Segment::lowerLimit() const { return std::max(geometricLowerLimit(), p_.qMinUser); }

}  // namespace buckle::mechanics

namespace buckle::mechanics {

namespace {
// A number with one directional derivative (forward mode), for the parameter derivatives.
struct Dual {
  double v = 0, d = 0;
};
inline Dual operator+(Dual x, Dual y) { return {x.v + y.v, x.d + y.d}; }
inline Dual operator-(Dual x, Dual y) { return {x.v - y.v, x.d - y.d}; }
inline Dual operator-(Dual x) { return {-x.v, -x.d}; }
inline Dual operator*(Dual x, Dual y) { return {x.v * y.v, x.d * y.v + x.v * y.d}; }
inline Dual operator*(double s, Dual x) { return {s * x.v, s * x.d}; }
inline Dual operator/(Dual x, Dual y) { return {x.v / y.v, (x.d * y.v - x.v * y.d) / (y.v * y.v)}; }
inline Dual sqrtD(Dual x) {
  const double r = std::sqrt(x.v);
  return {r, 0.5 * x.d / r};
}
inline Dual cosD(Dual x) { return {std::cos(x.v), -std::sin(x.v) * x.d}; }
inline Dual sinD(Dual x) { return {std::sin(x.v), std::cos(x.v) * x.d}; }
inline Dual atanRatio(Dual a, Dual b) {  // atan(a/b), b > 0
  return {std::atan(a.v / b.v), (b.v * a.d - a.v * b.d) / (a.v * a.v + b.v * b.v)};
}

struct DualJet {
  Dual value, d1, d2, d3;
};
}  // namespace

Jet3 Segment::energyJetParameterDerivative(double q, const SegmentParameterDirection& dp) const {
  const Dual a1{p_.a1, dp.a1}, b1{p_.b1, dp.b1}, a2{p_.a2, dp.a2}, b2{p_.b2, dp.b2};
  const Dual cc1 = a1 * a1 + b1 * b1, cc2 = a2 * a2 + b2 * b2;  // c1², c2²
  const Dual P = sqrtD(cc1 * cc2);                                // c1 c2
  const Dual beta = atanRatio(a1, b1) + atanRatio(a2, b2);        // β12
  const Dual k[2] = {{p_.k1, dp.k1}, {p_.k2, dp.k2}};
  const Dual L0[2] = {{p_.L1_0, dp.L1_0}, {p_.L2_0, dp.L2_0}};
  const double sign[2] = {1.0, -1.0};
  DualJet E;
  for (int i = 0; i < 2; ++i) {
    // θ = β12 ± q; L² = c1² + c2² + 2c1c2 cos θ (eq 1); q-derivatives from L L′ = ∓P sin θ.
    const Dual theta = beta + Dual{sign[i] * q, 0.0};
    const Dual cosT = cosD(theta), sinT = sinD(theta);
    DualJet L;
    L.value = sqrtD(cc1 + cc2 + 2.0 * (P * cosT));
    L.d1 = -sign[i] * (P * sinT) / L.value;
    L.d2 = -(P * cosT + L.d1 * L.d1) / L.value;
    L.d3 = (sign[i] * (P * sinT) - 3.0 * (L.d1 * L.d2)) / L.value;
    const Dual stretch = L.value - L0[i];
    E.value = E.value + 0.5 * (k[i] * stretch * stretch);
    E.d1 = E.d1 + k[i] * stretch * L.d1;
    E.d2 = E.d2 + k[i] * (L.d1 * L.d1 + stretch * L.d2);
    E.d3 = E.d3 + k[i] * (3.0 * (L.d1 * L.d2) + stretch * L.d3);
  }
  Jet3 out;
  out.value = E.value.d;
  out.d1 = E.d1.d;
  out.d2 = E.d2.d;
  out.d3 = E.d3.d;
  return out;
}

}  // namespace buckle::mechanics
