#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/critical_curves.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/post_buckling.h"

#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::kAxial;

std::vector<SegmentParameters> paperChain(int n, double a, double b, double k, double L0) {
  return std::vector<SegmentParameters>(size_t(n), SegmentParameters::symmetric(a, b, k, L0));
}

CriticalCurveOptions curveOptions(double muMin, double muMax) {
  CriticalCurveOptions o;
  o.muMin = muMin;
  o.muMax = muMax;
  o.tracer.step.maxStep = 0.05;
  o.tracer.maxPoints = 400;
  o.tracer.corrector.tolerance = 1e-12;
  return o;
}

// Every point of a clamped–pinned three-segment curve on eq 17: Fx_U = λ_U κ/b.
void checkEq17(const CriticalCurve& c, const ChainParameterProblem& p) {
  const SegmentParameters s0 = p.segments()[0];
  REQUIRE(c.points.size() > 20);
  for (const CriticalPoint& q : c.points) {
    double a = s0.a1, b = s0.b1, k = s0.k1, L0 = s0.L1_0;
    switch (p.parameter().kind) {
      case SecondParameter::Kind::A: a = q.mu; break;
      case SecondParameter::Kind::B: b = q.mu; break;
      case SecondParameter::Kind::K: k = q.mu; break;
      case SecondParameter::Kind::L0: L0 = q.mu; break;
      default: FAIL("unexpected parameter");
    }
    const AnalyticBuckling3 an = analyticClampedPinned3(a, b, k, L0);
    CHECK(std::abs(q.lambda - an.FxU) <= 1e-12 * k * b);
    CHECK(std::abs(q.kappa - an.kappa) <= 1e-12 * k * b * b);
  }
}
}  // namespace

TEST_CASE("chain second-parameter derivatives match central differences for every kind", "[critical_curves]") {
  std::mt19937 rng(5);
  const testing::SegmentRanges ranges{0.2, 0.7, 0.8, 1.3, 0.5, 2.0, 1.6, 2.6};
  struct Case {
    const char* kind;
    int segment;
  };
  const Case cases[] = {{"a", -1}, {"b", -1}, {"k", -1}, {"L0", -1}, {"dL0", -1}, {"a", 1},
                        {"b", 2},  {"b", 0},  {"L0", 3}, {"x", -1}, {"y", -1}, {"phi", -1}};
  const EndCondition ends[] = {EndCondition::clampedPinned(-0.3), EndCondition::heldPosition(5.0, 0.4),
                               EndCondition::freeEnd(Eigen::Vector3d(-0.2, 0.1, 0.05))};
  for (const EndCondition& end : ends) {
    for (const Case& cs : cases) {
      std::vector<SegmentParameters> segs;
      for (int i = 0; i < 4; ++i) segs.push_back(testing::randomSegment(rng, ranges));
      ChainParameterProblem p(segs, end, Eigen::Vector3d(0.7, -0.2, 0.1), SecondParameter::parse(cs.kind, cs.segment));
      const int N = p.dimension();
      std::uniform_real_distribution<double> U(-0.3, 0.3);
      Vector u(N), v(N);
      for (int i = 0; i < N; ++i) {
        u[i] = U(rng);
        v[i] = U(rng);
      }
      const double lambda = 0.4, mu = p.secondParameter();
      Vector Fmu(N), FuMuV(N);
      REQUIRE(p.secondParameterDerivatives(*p.createWorkspace(), u, lambda, v, Fmu, FuMuV));
      const double h = 1e-6 * std::max(1.0, std::abs(mu));
      Vector Fp(N), Fm(N), Fl(N);
      Matrix Jp(N, N), Jm(N, N);
      REQUIRE(p.setSecondParameter(mu + h));
      REQUIRE(buckle::continuation::BoundProblem(p).residual(u, lambda, Fp));
      REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, lambda, Jp, Fl));
      REQUIRE(p.setSecondParameter(mu - h));
      REQUIRE(buckle::continuation::BoundProblem(p).residual(u, lambda, Fm));
      REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, lambda, Jm, Fl));
      REQUIRE(p.setSecondParameter(mu));
      INFO(cs.kind << " segment " << cs.segment);
      CHECK(((Fp - Fm) / (2 * h) - Fmu).norm() <= 1e-7 * (1.0 + Fmu.norm()));
      CHECK(((Jp - Jm) * v / (2 * h) - FuMuV).norm() <= 1e-7 * (1.0 + FuMuV.norm()));
      // (∂F_u/∂λ)·v, exact, against central differences of the dense Jacobian in λ
      Vector FuLv(N);
      REQUIRE(p.parameterJacobianApply(*p.createWorkspace(), u, lambda, v, FuLv));
      REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, lambda + h, Jp, Fl));
      REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, lambda - h, Jm, Fl));
      CHECK(((Jp - Jm) * v / (2 * h) - FuLv).norm() <= 1e-7 * (1.0 + FuLv.norm()));
    }
  }
}

TEST_CASE("second parameter: names, parsing and refused values", "[critical_curves]") {
  CHECK(SecondParameter::parse("L0").name() == "L0");
  CHECK(SecondParameter::parse("a", 1).name() == "a[2]");
  CHECK(SecondParameter::parse("y").component == 1);
  CHECK_THROWS_WITH(SecondParameter::parse("c"), Catch::Matchers::Contains("\"c\""));
  CHECK_THROWS_WITH(SecondParameter::parse("y", 2), Catch::Matchers::Contains("no segment"));
  CHECK_THROWS_WITH(ChainParameterProblem(paperChain(3, 0.5, 1, 1, 2.25), EndCondition::clampedPinned(0.0), kAxial,
                                          SecondParameter::parse("a", 3)),
                    Catch::Matchers::Contains("segment 4"));
  ChainParameterProblem p(paperChain(3, 0.5, 1, 1, 2.25), EndCondition::clampedPinned(0.0), kAxial,
                          SecondParameter::parse("k"));
  CHECK(p.secondParameter() == 1.0);
  CHECK_FALSE(p.setSecondParameter(-1.0));  // k must be > 0
  CHECK(p.secondParameter() == 1.0);
  CHECK_FALSE(p.setSecondParameter(std::nan("")));
}

TEST_CASE("BP curve of the n = 3 clamped-pinned chain is eq 17 in L0, a, b and k", "[critical_curves]") {
  struct Case {
    const char* kind;
    double muMin, muMax;
  };
  for (const Case& cs : {Case{"L0", 1.2, 3.0}, Case{"a", 0.1, 0.8}, Case{"b", 0.8, 1.3}, Case{"k", 0.3, 3.0}}) {
    INFO(cs.kind);
    ChainParameterProblem p(paperChain(3, 0.5, 1.0, 1.0, 1.8), EndCondition::clampedPinned(0.0), kAxial,
                            SecondParameter::parse(cs.kind));
    const CriticalCurve c = branchPointCurve(p, 0, curveOptions(cs.muMin, cs.muMax));
    CHECK(c.type == "BP");
    CHECK(c.points.front().mu == Approx(cs.muMin).epsilon(1e-12));
    CHECK(c.points.back().mu == Approx(cs.muMax).epsilon(1e-12));
    checkEq17(c, p);
  }
}

TEST_CASE("the kappa = 0 line: the BP curve passes zero load where b L0 = 2(b^2 - a^2)", "[critical_curves]") {
  // in L0 at a = 0.5, b = 1: L0* = 1.5; in a at L0 = 1.8: a* = √0.1
  struct Case {
    const char* kind;
    double muMin, muMax, expected;
  };
  for (const Case& cs : {Case{"L0", 1.2, 3.0, 1.5}, Case{"a", 0.1, 0.8, std::sqrt(0.1)}}) {
    INFO(cs.kind);
    ChainParameterProblem p(paperChain(3, 0.5, 1.0, 1.0, 1.8), EndCondition::clampedPinned(0.0), kAxial,
                            SecondParameter::parse(cs.kind));
    const CriticalCurve c = branchPointCurve(p, 0, curveOptions(cs.muMin, cs.muMax));
    int found = 0;
    for (const Codim2Point& s : c.special)
      if (s.label == "K0") {
        ++found;
        CHECK(s.converged);
        CHECK(std::abs(s.mu - cs.expected) <= 1e-11);
        CHECK(std::abs(s.lambda) <= 1e-11);
      }
    CHECK(found == 1);
  }
}

TEST_CASE("BP curve in scaled units (lengths x 1e-3, stiffness x 1e6) is the same curve", "[critical_curves]") {
  const double ls = 1e-3, ks = 1e6;
  ChainParameterProblem p(paperChain(3, 0.5, 1.0, 1.0, 1.8), EndCondition::clampedPinned(0.0), kAxial,
                          SecondParameter::parse("L0"));
  ChainParameterProblem ps(paperChain(3, 0.5 * ls, ls, ks, 1.8 * ls), EndCondition::clampedPinned(0.0), kAxial,
                           SecondParameter::parse("L0"));
  const CriticalCurve c = branchPointCurve(p, 0, curveOptions(1.2, 3.0));
  const CriticalCurve cs = branchPointCurve(ps, 0, curveOptions(1.2 * ls, 3.0 * ls));
  REQUIRE(c.points.size() == cs.points.size());
  for (size_t i = 0; i < c.points.size(); ++i) {
    CHECK(cs.points[i].mu == Approx(c.points[i].mu * ls).epsilon(1e-10));
    CHECK(std::abs(cs.points[i].lambda - c.points[i].lambda * ks * ls) <= 1e-10 * ks * ls);
    // Koiter b: λ in force units, ξ in radians
    CHECK(std::abs(cs.points[i].koiterB - c.points[i].koiterB * ks * ls) <= 1e-6 * ks * ls);
  }
  checkEq17(cs, ps);
}

namespace {
// λ on the bifurcated branch at modal amplitude ξ = zᵀq (z the unit joint-angle mode): Newton on
// F(u, λ) = 0, zᵀq = ξ from the linearised guess, independent of the Lyapunov–Schmidt formulas.
double lambdaAtAmplitude(ChainParameterProblem& p, const Vector& z, double lambdaC, double xi) {
  const int N = p.dimension(), n = int(z.size());
  Vector x = Vector::Zero(N + 1);
  x.head(n) = xi * z;
  x[N] = lambdaC;
  Vector R(N + 1), F(N), Fl(N);
  Matrix J(N + 1, N + 1), Fu(N, N);
  for (int it = 0; it < 30; ++it) {
    REQUIRE(buckle::continuation::BoundProblem(p).residual(x.head(N), x[N], F));
    REQUIRE(buckle::continuation::BoundProblem(p).jacobian(x.head(N), x[N], Fu, Fl));
    R << F, z.dot(x.head(n)) - xi;
    J.setZero();
    J.topLeftCorner(N, N) = Fu;
    J.block(0, N, N, 1) = Fl;
    J.block(N, 0, 1, n) = z.transpose();
    const Vector dx = J.fullPivLu().solve(R);
    x -= dx;
    if (dx.norm() < 1e-15) break;
  }
  return x[N];
}
}  // namespace

TEST_CASE("Koiter coefficients of the straight chain against the branch at fixed modal amplitude",
          "[critical_curves]") {
  // the paper's chain (supercritical) and a tall-triangle one (subcritical)
  for (double a : {0.5, 2.5}) {
    const double L0 = a < 1 ? 2.25 : 0.5;
    INFO("a = " << a);
    ChainParameterProblem p(paperChain(3, a, 1.0, 1.0, L0), EndCondition::clampedPinned(0.0), kAxial,
                            SecondParameter::parse("L0"));
    CriticalCurveOptions o = curveOptions(L0, L0 + 1e-3);
    o.bothDirections = false;
    const CriticalCurve c = branchPointCurve(p, 0, o);
    const CriticalPoint& cp = c.points.front();
    REQUIRE(cp.mu == L0);
    CHECK(cp.koiterA == 0.0);  // symmetric pitchfork (E even in q)
    const double xi = 0.01;
    auto R = [&](double x) { return (lambdaAtAmplitude(p, cp.mode, cp.lambda, x) - cp.lambda) / (x * x); };
    const double bfd = (4.0 * R(0.5 * xi) - R(xi)) / 3.0;  // Richardson: error O(ξ⁴)
    CHECK(std::abs(cp.koiterB - bfd) <= 1e-6);
    CHECK(std::abs(R(-xi) - R(xi)) <= 1e-9);  // even in ξ
    const FirstBuckling fb = firstBuckling(p.equilibrium().chain(), EndCondition::clampedPinned(0.0), kAxial,
                                           Vector::Zero(3));
    CHECK(cp.kind == fb.kind);
    CHECK(cp.kind == (a < 1 ? PostBuckling::Supercritical : PostBuckling::Subcritical));
  }
}

TEST_CASE("degenerate pitchfork: b changes sign where the atlas' classification flips", "[critical_curves]") {
  // L0/b = 0.5: the first (U) mode turns subcritical for tall triangles, a/b ≈ 1.85
  ChainParameterProblem p(paperChain(3, 1.2, 1.0, 1.0, 0.5), EndCondition::clampedPinned(0.0), kAxial,
                          SecondParameter::parse("a"));
  const CriticalCurve c = branchPointCurve(p, 0, curveOptions(0.9, 3.0));
  std::vector<Codim2Point> dp;
  for (const Codim2Point& s : c.special)
    if (s.label == "DP") dp.push_back(s);
  REQUIRE(dp.size() == 1);
  CHECK(dp[0].converged);
  const double aStar = dp[0].mu;
  CHECK(aStar > 1.5);
  CHECK(aStar < 2.2);
  // on the curve: b < 0 before, > 0 after, and the kinds agree with the atlas' firstBuckling
  int compared = 0;
  for (size_t i = 0; i < c.points.size(); i += 7) {
    const CriticalPoint& q = c.points[i];
    if (std::abs(q.mu - aStar) < 1e-3) continue;
    CHECK((q.koiterB > 0.0) == (q.mu > aStar));
    REQUIRE(p.setSecondParameter(q.mu));
    const FirstBuckling fb = firstBuckling(p.equilibrium().chain(), EndCondition::clampedPinned(0.0), kAxial,
                                           Vector::Zero(3));
    INFO("a = " << q.mu);
    CHECK(fb.kind == q.kind);
    CHECK(fb.kind == (q.mu < aStar ? PostBuckling::Supercritical : PostBuckling::Subcritical));
    ++compared;
  }
  CHECK(compared >= 5);
  // b at the located point vanishes to the location accuracy
  const auto near = std::min_element(c.points.begin(), c.points.end(), [&](const CriticalPoint& x, const CriticalPoint& y) {
    return std::abs(x.mu - aStar) < std::abs(y.mu - aStar);
  });
  CHECK(std::abs(near->koiterB) <= 0.1 * std::abs(near->mu - aStar) + 1e-12);
}

namespace {
// The first fold of the chain under an end torque Me (the eccentricity), traced from zero load.
cont::Branch imperfectPath(ChainParameterProblem& p) {
  cont::TracerOptions to;
  to.step.maxStep = 0.05;
  to.lambdaMin = -20;
  to.maxPoints = 400;
  const Vector u0 = p.equilibrium().initialGuess(Vector::Zero(3), 0.0);
  return cont::trace(p, u0, 0.0, cont::InitialDirection::decreasingLambda(), to);
}
}  // namespace

TEST_CASE("fold curve of the imperfect subcritical chain: pointwise folds, the cusp at eq 17, joint limits",
          "[critical_curves]") {
  const double a = 2.5, L0 = 0.5;
  EndCondition end = EndCondition::clampedPinned(0.0);
  end.value[2] = 0.01;  // Me
  ChainParameterProblem p(paperChain(3, a, 1.0, 1.0, L0), end, kAxial, SecondParameter::parse("phi"));
  const cont::Branch path = imperfectPath(p);
  const auto folds = path.specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(!folds.empty());
  CriticalCurveOptions o = curveOptions(-1.0, 1.0);
  const CriticalCurve c = foldCurve(p, *folds.front(), o);
  CHECK(c.type == "LP");
  REQUIRE(c.points.size() > 20);
  // the fold curve against the tracer's own fold location at a few μ
  int compared = 0;
  for (size_t i = 0; i < c.points.size(); i += 5) {
    const CriticalPoint& q = c.points[i];
    // near μ = 0 the fold is at λc itself; for |Me| ≳ 0.2 the path meets a joint limit first
    if (std::abs(q.mu) < 1e-3 || std::abs(q.mu) > 0.15) continue;
    EndCondition e = end;
    e.value[2] = q.mu;
    ChainParameterProblem pi(paperChain(3, a, 1.0, 1.0, L0), e, kAxial, SecondParameter::parse("phi"));
    const cont::Branch b = imperfectPath(pi);
    const auto f = b.specialPointsOfType(cont::SpecialPointType::Fold);
    REQUIRE(!f.empty());
    INFO("Me = " << q.mu);
    CHECK(std::abs(f.front()->lambda - q.lambda) <= 1e-10);
    CHECK((f.front()->u - q.u).lpNorm<Eigen::Infinity>() <= 1e-6);
    ++compared;
  }
  CHECK(compared >= 4);
  // the perfect chain's pitchfork is the cusp of the imperfect folds: μ = 0, λ = Fx_U (eq 17)
  const AnalyticBuckling3 an = analyticClampedPinned3(a, 1.0, 1.0, L0);
  int cusps = 0, limits = 0;
  for (const Codim2Point& s : c.special) {
    if (s.label == "CP") {
      ++cusps;
      CHECK(s.converged);
      CHECK(std::abs(s.mu) <= 1e-12);
      CHECK(std::abs(s.lambda - an.FxU) <= 1e-10);
    } else if (s.label == "BD") {
      ++limits;
      CHECK(s.note.find("joint 2") != std::string::npos);
    }
  }
  CHECK(cusps == 1);
  CHECK(limits == 2);  // mirror images: ±Me reach the upper / lower limit of the middle joint
  // the knockdown follows Koiter's 2/3 law near the cusp: λc − λ_fold ∝ |Me|^(2/3)
  std::vector<std::pair<double, double>> small;
  for (const CriticalPoint& q : c.points)
    if (q.mu > 1e-6 && q.mu < 1e-3) small.push_back({std::log(q.mu), std::log(q.lambda - an.FxU)});
  REQUIRE(small.size() >= 2);
  const double slope = (small.back().second - small.front().second) / (small.back().first - small.front().first);
  CHECK(std::abs(slope - 2.0 / 3.0) <= 0.05);
}

// ---- the chain's O(n) structure for long chains (structuredFromDimension) ----------------------

namespace {
// The first compressive critical load of the straight clamped-pinned chain (O(n) for long chains).
double linearCritical(ChainParameterProblem& p, double mu) {
  REQUIRE(p.setSecondParameter(mu));
  LinearBucklingOptions lbo;
  lbo.count = 2;
  const LinearBucklingResult lb =
      linearBuckling(p.equilibrium().chain(), Vector::Zero(p.equilibrium().segments()), EndCondition::clampedPinned(0.0), lbo);
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0.0) return m.lambda;
  FAIL("no compressive mode");
  return 0.0;
}

CriticalCurveOptions forced(CriticalCurveOptions o, bool structured) {
  o.tracer.linearAlgebra =
      structured ? cont::TracerOptions::LinearAlgebra::Structured : cont::TracerOptions::LinearAlgebra::Dense;
  return o;
}
}  // namespace

TEST_CASE("BP curve: the structured path is the dense one (n = 40, 200) and linear buckling (n = 1000)",
          "[critical_curves]") {
  for (int n : {40, 200, 1000}) {
    INFO("n = " << n);
    ChainParameterProblem p(paperChain(n, 0.5, 1.0, 1.0, 2.25), EndCondition::clampedPinned(0.0), kAxial,
                            SecondParameter::parse("L0"));
    CriticalCurveOptions o = curveOptions(2.25, 4.0);
    o.bothDirections = false;
    o.coefficients = false;  // Koiter coefficients are dense (O(n³) per point)
    o.tracer.maxPoints = 60;
    const CriticalCurve s = branchPointCurve(p, 0, forced(o, true));
    REQUIRE(s.points.size() >= 30);
    if (n <= 200) {
      const CriticalCurve d = branchPointCurve(p, 0, forced(o, false));
      REQUIRE(d.points.size() == s.points.size());
      for (size_t i = 0; i < s.points.size(); ++i) {
        CHECK(std::abs(s.points[i].mu - d.points[i].mu) <= 1e-10 * std::abs(d.points[i].mu));
        CHECK(std::abs(s.points[i].lambda - d.points[i].lambda) <= 1e-10 * std::abs(d.points[i].lambda));
        CHECK((s.points[i].mode - d.points[i].mode).norm() <= 1e-8);
      }
    }
    for (size_t i = 0; i < s.points.size(); i += 6) {
      const double lc = linearCritical(p, s.points[i].mu);
      CHECK(std::abs(s.points[i].lambda - lc) <= 1e-12 * std::abs(lc));
    }
    REQUIRE(p.setSecondParameter(2.25));
    // Automatic: structured from structuredFromDimension on
    CriticalCurveOptions a = o;
    a.tracer.maxPoints = 3;
    const CriticalCurve c = branchPointCurve(p, 0, a);
    REQUIRE(c.points.size() == 3);
    CHECK(std::abs(c.points[2].lambda - s.points[2].lambda) <= 1e-10 * std::abs(s.points[2].lambda));
  }
}

TEST_CASE("BP curve of a long chain in scaled units (lengths x 1e-3, stiffness x 1e6) is the same curve",
          "[critical_curves]") {
  const double ls = 1e-3, ks = 1e6;
  const int n = 300;
  ChainParameterProblem p(paperChain(n, 0.5, 1.0, 1.0, 1.8), EndCondition::clampedPinned(0.0), kAxial,
                          SecondParameter::parse("L0"));
  ChainParameterProblem ps(paperChain(n, 0.5 * ls, ls, ks, 1.8 * ls), EndCondition::clampedPinned(0.0), kAxial,
                           SecondParameter::parse("L0"));
  CriticalCurveOptions o = curveOptions(1.8, 3.0), os = curveOptions(1.8 * ls, 3.0 * ls);
  o.coefficients = os.coefficients = false;
  o.bothDirections = os.bothDirections = false;
  o.tracer.maxPoints = os.tracer.maxPoints = 40;
  const CriticalCurve c = branchPointCurve(p, 0, forced(o, true));
  const CriticalCurve cs = branchPointCurve(ps, 0, forced(os, true));
  REQUIRE(c.points.size() == cs.points.size());
  for (size_t i = 0; i < c.points.size(); ++i) {
    CHECK(cs.points[i].mu == Approx(c.points[i].mu * ls).epsilon(1e-10));
    CHECK(std::abs(cs.points[i].lambda - c.points[i].lambda * ks * ls) <= 1e-10 * std::abs(c.points[i].lambda) * ks * ls);
  }
}

namespace {
// A free-end chain of slightly different paper segments (a_i = 0.5(1 + 0.05 sin 1.3i), L0 = 2.25)
// under an end torque λ with an axial end force Fx = μ: the flat triangles snap, so the torque
// path has a fold.
ChainParameterProblem snappingChain(int n, double Fx) {
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < n; ++i) segs.push_back(SegmentParameters::symmetric(0.5 * (1 + 0.05 * std::sin(1.3 * i)), 1.0, 1.0, 2.25));
  return ChainParameterProblem(segs, EndCondition::freeEnd(Eigen::Vector3d(Fx, 0.0, 0.0)), Eigen::Vector3d(0, 0, 1),
                               SecondParameter::parse("x"));
}

// The first fold of the torque path, located by the tracer (structured above its crossover).
cont::SpecialPoint firstFold(ChainParameterProblem& p) {
  cont::TracerOptions to;
  to.step.maxStep = 0.1;
  to.lambdaMax = 10.0;
  to.maxPoints = 3000;
  to.detection.lowestEigenvalues = 0;
  to.onStep = [](const cont::StepInfo& step) {
    for (const cont::SpecialPoint& sp : step.specialPoints)
      if (sp.type == cont::SpecialPointType::Fold) return cont::StepAction::Stop;
    return cont::StepAction::Continue;
  };
  const int n = p.equilibrium().segments();
  const cont::Branch path = cont::trace(p.equilibrium(), p.equilibrium().initialGuess(Vector::Zero(n), 0.0), 0.0,
                                        cont::InitialDirection::increasingLambda(), to);
  const auto folds = path.specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(!folds.empty());
  return *folds.front();
}

// The fold near (u, λ) (null vector v) located pointwise by the tracer: an equilibrium just below
// (or above) λ from u ± εv (off the singular point), traced toward λ until the tracer locates the fold.
cont::SpecialPoint foldNear(ChainParameterProblem& p, const Vector& u, double lambda, const Vector& v) {
  cont::TracerOptions to;
  to.step.maxStep = 0.01;
  to.maxPoints = 200;
  to.detection.lowestEigenvalues = 0;
  to.onStep = [](const cont::StepInfo& step) {
    for (const cont::SpecialPoint& sp : step.specialPoints)
      if (sp.type == cont::SpecialPointType::Fold) return cont::StepAction::Stop;
    return cont::StepAction::Continue;
  };
  const double delta = 1e-5 * std::max(1.0, std::abs(lambda));
  for (int side : {-1, 1})
    for (double eps : {0.0, 1e-2, -1e-2}) {
      const cont::Branch path = cont::trace(p.equilibrium(), u + eps * v, lambda + side * delta,
                                            side < 0 ? cont::InitialDirection::increasingLambda()
                                                     : cont::InitialDirection::decreasingLambda(),
                                            to);
      const auto folds = path.specialPointsOfType(cont::SpecialPointType::Fold);
      if (!folds.empty() && (folds.front()->u - u).norm() < 0.1) return *folds.front();
    }
  FAIL("no fold near the curve point");
  return {};
}
}  // namespace

TEST_CASE("fold curve: the structured path is the dense one (n = 40) and the pointwise folds (n = 40, 1000)",
          "[critical_curves]") {
  for (int n : {40, 1000}) {
    INFO("n = " << n);
    const double mu0 = -0.01;
    ChainParameterProblem p = snappingChain(n, mu0);
    const cont::SpecialPoint fold = firstFold(p);
    REQUIRE(fold.lambda > 0.0);
    CriticalCurveOptions o = curveOptions(-0.05, 0.05);
    o.tracer.maxPoints = 25;
    const CriticalCurve s = foldCurve(p, fold, forced(o, true));
    REQUIRE(s.points.size() == 49);
    CHECK(s.type == "LP");
    REQUIRE(s.points[24].mu == mu0);  // the start; before it the decreasing-μ half, reversed
    int compared = 0;
    // more compression (μ < μ0): the fold load rises, away from the cusp where λ → 0
    for (size_t i = 2; i < 24; i += 7) {
      const CriticalPoint& q = s.points[i];
      INFO("mu = " << q.mu);
      REQUIRE(q.mu < mu0);
      REQUIRE(q.lambda > fold.lambda);
      ChainParameterProblem pi = snappingChain(n, q.mu);
      const cont::SpecialPoint f = foldNear(pi, q.u, q.lambda, q.mode);
      CHECK(std::abs(f.lambda - q.lambda) <= 1e-10 * std::abs(q.lambda));
      CHECK((f.u - q.u).lpNorm<Eigen::Infinity>() <= 1e-6);
      if (n <= 40) {
        // the dense (2N+1)-system traced from the same fold down to exactly this μ
        CriticalCurveOptions d = forced(o, false);
        d.muMin = q.mu;
        d.muMax = mu0 + 1e-9;
        d.tracer.maxPoints = 2000;
        const CriticalCurve dc = foldCurve(p, fold, d);
        const CriticalPoint& e = dc.points.front();
        REQUIRE(e.mu == Approx(q.mu).epsilon(1e-13));
        CHECK(std::abs(e.lambda - q.lambda) <= 1e-10 * std::abs(q.lambda));
        CHECK((e.u - q.u).lpNorm<Eigen::Infinity>() <= 1e-8);
        CHECK((e.mode - q.mode).norm() <= 1e-8);
      }
      ++compared;
    }
    CHECK(compared == 4);
  }
}

// ---- certified counting on a chain: two folds inside one step, and the touch at the cusp --------

namespace {
// The hysteresis chain (data/scenes/hysteresis.json: κ = −0.3 < 0, free end) under the end torque
// Me = λ, with the axial tension Fx = μ as the second parameter. At Fx = 0.29 the Me path through
// the straight state has a small Z: two folds at ±Me_f (mirror images, (q, Me) → (−q, −Me)), the
// stretch between them one eigenvalue less stable. Its fold curve in μ has cusps (two folds meet);
// beyond a cusp the eigenvalue only touches zero where the folds merged.
ChainParameterProblem hysteresisChain(double tension) {
  return ChainParameterProblem(paperChain(3, 0.5, 1.0, 1.0, 1.2), EndCondition::freeEnd(Eigen::Vector3d(tension, 0, 0)),
                               Eigen::Vector3d(0, 0, 1), SecondParameter::parse("x"));
}

// One step of the tracer from the path's point `a` (tangent oriented by `direction`) whose length
// lands on the path's point `b`.
cont::Branch stepTo(ChainParameterProblem& p, const cont::ContinuationPoint& a, const Vector& direction,
                    const Vector& b, bool certified) {
  cont::TracerOptions o;
  const Vector t = a.tangent.dot(direction) >= 0.0 ? a.tangent : Vector(-a.tangent);
  o.step.maxStep = o.step.initialStep = t.dot(b - a.state());
  o.step.minStep = 1e-6 * o.step.maxStep;
  o.maxPoints = 2;  // the start and the one step
  o.lambdaMin = -1.0;
  o.lambdaMax = 1.0;
  o.detection.certifiedCounting = certified;
  return cont::trace(p, a.u, a.lambda, cont::InitialDirection::along(t), o);
}

cont::Branch stepToMirror(ChainParameterProblem& p, const cont::ContinuationPoint& a, const Vector& direction,
                          bool certified) {
  Vector mirror(a.u.size() + 1);
  mirror << -a.u, -a.lambda;
  return stepTo(p, a, direction, mirror, certified);
}

// The Me path from the straight state at Me = 0 in small steps, towards increasing Me, stopping
// at Me = `stop` (< 0: after the Z's fold it comes back down).
cont::Branch finePath(ChainParameterProblem& p, double stop, int lambdaSign) {
  cont::TracerOptions o;
  o.step.maxStep = 2e-3;
  o.step.initialStep = 1e-3;
  o.lambdaMin = lambdaSign > 0 ? stop : -1.0;
  o.lambdaMax = lambdaSign > 0 ? 1.0 : stop;
  o.maxPoints = 2000;
  const Vector u0 = p.equilibrium().initialGuess(Vector::Zero(3), 0.0);
  return cont::trace(p, u0, 0.0,
                     lambdaSign > 0 ? cont::InitialDirection::increasingLambda() : cont::InitialDirection::decreasingLambda(), o);
}
// The Z's upper fold on the fine Me path at μ = 0.29 and, from the fold curve through it, the
// cusp nearest μ = 0.3 (where the two folds meet).
struct ZAndCusp {
  cont::Branch path;
  cont::SpecialPoint fold;
  Codim2Point cusp;
};

ZAndCusp zAndCusp(ChainParameterProblem& p) {
  ZAndCusp z;
  z.path = finePath(p, -0.05, +1);
  const auto refFolds = z.path.specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(!refFolds.empty());
  z.fold = *refFolds.front();  // the Z's upper fold, Me_f > 0 small
  REQUIRE(z.fold.refined);
  REQUIRE(z.fold.lambda > 0.0);
  REQUIRE(z.fold.lambda < 0.01);
  CriticalCurveOptions co = curveOptions(0.2, 0.4);
  co.tracer.step.maxStep = 0.01;
  co.tracer.maxPoints = 200;
  const CriticalCurve curve = foldCurve(p, z.fold, co);
  const Codim2Point* cusp = nullptr;
  for (const Codim2Point& s : curve.special)
    if (s.label == "CP" && (!cusp || std::abs(s.mu - 0.3) < std::abs(cusp->mu - 0.3))) cusp = &s;
  REQUIRE(cusp);
  REQUIRE(cusp->converged);
  z.cusp = *cusp;
  INFO("cusp at Fx = " << cusp->mu << ", Me = " << cusp->lambda);
  CHECK(std::abs(cusp->lambda) <= 1e-12);  // Me = 0, by the mirror symmetry
  return z;
}
}  // namespace

TEST_CASE("certified counting on a chain: two folds of a Z inside one step, below the fold curve's cusp",
          "[critical_curves]") {
  ChainParameterProblem p = hysteresisChain(0.29);
  const ZAndCusp z = zAndCusp(p);
  const cont::Branch& reference = z.path;
  const cont::SpecialPoint& fold = z.fold;

  SECTION("below the cusp: the Z's two folds in one step, counts unchanged at its ends") {
    REQUIRE(p.setSecondParameter(0.29));
    // From the lower arm of the Z at twice the fold's distance from the straight state, to its mirror.
    const double sFold = fold.arclength - reference.points.front().arclength;
    const cont::ContinuationPoint* start = nullptr;
    for (const cont::ContinuationPoint& q : reference.points)
      if (q.arclength - reference.points.front().arclength >= 2.0 * sFold) {
        start = &q;
        break;
      }
    REQUIRE(start);
    const Vector back = -start->tangent;  // towards the fold and the straight state
    const cont::Branch blind = stepToMirror(p, *start, back, false);
    REQUIRE(blind.points.size() == 2);
    CHECK(blind.points[0].stability.negative == blind.points[1].stability.negative);
    CHECK(blind.points[0].foldTest * blind.points[1].foldTest > 0.0);
    CHECK(blind.specialPointsOfType(cont::SpecialPointType::Fold).empty());  // what the count misses
    const cont::Branch step = stepToMirror(p, *start, back, true);
    REQUIRE(step.points.size() == 2);
    const auto folds = step.specialPointsOfType(cont::SpecialPointType::Fold);
    REQUIRE(folds.size() == 2);
    CHECK(step.specialPointsOfType(cont::SpecialPointType::BranchPoint).empty());
    for (const cont::SpecialPoint* f : folds) {
      INFO(f->note);
      CHECK(f->index == 0);
      CHECK(f->refined);
      CHECK(f->note.find("certified counting") != std::string::npos);
      CHECK(std::abs(std::abs(f->lambda) - fold.lambda) <= 1e-12);  // the fine path's fold and its mirror
      CHECK(std::abs(f->inertiaAfter - f->inertiaBefore) == 1);
    }
    CHECK(folds[0]->lambda * folds[1]->lambda < 0.0);
  }
}

namespace {
// The straight state (q = 0, Me = 0: an equilibrium for every Fx, by the mirror symmetry): the
// second-lowest eigenvalue of its stability operator (the dense 3×3 eigen-solve, not the tracer's
// Sturm counts) and its eigenvector's load by the end moment, |vᵀ ∂φ/∂q| = |Σ v_i|. Where that
// eigenvalue vanishes with a loaded eigenvector the straight state is a fold of the Me path whose
// two sides are mirror images: a cusp (an unloaded one would make it a branch point).
struct StraightMode {
  double eigenvalue = 0.0, load = 0.0;
};

StraightMode straightSecondMode(ChainParameterProblem& p, double tension) {
  REQUIRE(p.setSecondParameter(tension));
  Matrix H, C;
  REQUIRE(buckle::continuation::BoundProblem(p).stabilityOperator(p.equilibrium().initialGuess(Vector::Zero(3), 0.0),
                                                                  0.0, H, C));
  REQUIRE(C.rows() == 0);  // free end
  const Eigen::SelfAdjointEigenSolver<Matrix> es(H);
  return {es.eigenvalues()[1], std::abs(es.eigenvectors().col(1).sum())};
}

// The Me path at tension Fx = μ through the straight state: traced from the straight state at
// Me = 0 (without certified counting) to |Me| = 0.0123 — at the cusp itself the straight state is
// the path's singular point and the tangent has dMe = 0, so either side — then back through it to
// the other side's |Me| = 0.03 in steps of up to 0.05, with or without certified counting. The
// touch, if any, lies inside one of its steps.
cont::Branch pathThroughStraight(ChainParameterProblem& p, double tension, bool certified) {
  REQUIRE(p.setSecondParameter(tension));
  cont::TracerOptions o;
  o.step.maxStep = 0.05;
  o.step.initialStep = 0.01;
  o.lambdaMin = -0.0123;
  o.lambdaMax = 0.0123;
  o.maxPoints = 400;
  const Vector u0 = p.equilibrium().initialGuess(Vector::Zero(3), 0.0);
  const cont::Branch out = cont::trace(p, u0, 0.0, cont::InitialDirection::decreasingLambda(), o);
  REQUIRE(!out.points.empty());
  const cont::ContinuationPoint& start = out.points.back();
  REQUIRE(std::abs(start.lambda) == Approx(0.0123).margin(1e-12));
  o.detection.certifiedCounting = certified;
  o.lambdaMin = -0.03;
  o.lambdaMax = 0.03;
  return cont::trace(p, start.u, start.lambda,
                     start.lambda > 0.0 ? cont::InitialDirection::decreasingLambda() : cont::InitialDirection::increasingLambda(), o);
}
}  // namespace

TEST_CASE("certified counting on a chain: at the fold curve's cusp an eigenvalue touches zero without crossing",
          "[critical_curves]") {
  // At the cusp the Z's two folds merge into the straight state: along the Me path the eigenvalue
  // of K_q − K_g that the end moment loads reaches zero there and turns back (μ ∝ s² in the cusp's normal form
  // Π = ¼ g a⁴ − Me a), no fold, no branch point, the count 0 on both sides.
  ChainParameterProblem p = hysteresisChain(0.29);
  const ZAndCusp z = zAndCusp(p);
  const double cusp = z.cusp.mu;
  // Independent: where the straight state's second eigenvalue vanishes (secant in Fx; at 0.29 the
  // Z's stretch has two negative eigenvalues, beyond the cusp one).
  double a = 0.29, b = 0.31, fa = straightSecondMode(p, a).eigenvalue, fb = straightSecondMode(p, b).eigenvalue;
  REQUIRE(fa * fb < 0.0);
  for (int it = 0; it < 50 && fb != 0.0 && std::abs(b - a) > 1e-15 * b; ++it) {
    const double c = b - fb * (b - a) / (fb - fa);
    a = b;
    fa = fb;
    b = c;
    fb = straightSecondMode(p, b).eigenvalue;
  }
  const double marginal = b;
  INFO("cusp Fx = " << cusp << ", the straight state's second eigenvalue vanishes at Fx = " << marginal);
  CHECK(std::abs(cusp - marginal) <= 1e-10 * marginal);
  CHECK(straightSecondMode(p, marginal).load >= 0.1);  // the end moment loads the mode: a cusp, not a branch point

  SECTION("at the cusp's tension: one eigenvalue touch at the straight state") {
    const cont::Branch blind = pathThroughStraight(p, cusp, false);
    CHECK(blind.specialPointsOfType(cont::SpecialPointType::EigenvalueTouch).empty());
    CHECK(blind.specialPointsOfType(cont::SpecialPointType::Fold).empty());
    const cont::Branch branch = pathThroughStraight(p, cusp, true);
    const auto touches = branch.specialPointsOfType(cont::SpecialPointType::EigenvalueTouch);
    REQUIRE(touches.size() == 1);
    const cont::SpecialPoint& t = *touches[0];
    INFO(t.note);
    CHECK(branch.specialPointsOfType(cont::SpecialPointType::Fold).empty());
    CHECK(branch.specialPointsOfType(cont::SpecialPointType::BranchPoint).empty());
    // at the cusp: Me = 0 and the straight state, relative to the Z's fold moment at Fx = 0.29
    CHECK(std::abs(t.lambda - z.cusp.lambda) <= 1e-6 * z.fold.lambda);
    CHECK(t.u.cwiseAbs().maxCoeff() <= 1e-3);
    CHECK(std::abs(t.testFunctionValue) <= 1e-8);
    // the count is unchanged across the touch: 1, the straight state's lowest mode, which the end
    // moment does not load (its own zero is at a higher tension)
    CHECK(t.inertiaBefore == 1);
    CHECK(t.inertiaAfter == 1);
    CHECK(std::abs(straightSecondMode(p, cusp).eigenvalue) <= 1e-12);
  }
  SECTION("the touch belongs to the cusp's tension: a dip clear of zero above it, the Z's two folds below") {
    const cont::Branch above = pathThroughStraight(p, cusp * (1.0 + 1e-4), true);
    CHECK(above.specialPointsOfType(cont::SpecialPointType::EigenvalueTouch).empty());
    CHECK(above.specialPointsOfType(cont::SpecialPointType::Fold).empty());
    const cont::Branch below = pathThroughStraight(p, cusp * (1.0 - 1e-4), true);
    CHECK(below.specialPointsOfType(cont::SpecialPointType::EigenvalueTouch).empty());
    CHECK(below.specialPointsOfType(cont::SpecialPointType::Fold).size() == 2);
  }
}
