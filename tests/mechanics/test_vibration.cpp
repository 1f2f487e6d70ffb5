// Natural frequencies about an equilibrium (vibration.h): closed form for one segment, a dense
// generalized eigen-solve on an independent kernel basis, Sylvester's law at located branch
// points and folds, the period of the integrated inertial model (dynamics.h) against 2π/ω₁,
// the mass and unit scaling laws and the count under held end coordinates.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/gravity.h"
#include "buckle/mechanics/vibration.h"
#include "buckle/mechanics/wall_contact.h"

#include "test_chains.h"
#include "relative_error.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::stiffChain;

constexpr double kPi = 3.14159265358979323846;

using buckle::test::relativeError;

// Equilibrium of the free end under F by Newton on ∂Π/∂q with the dense Hessian, from q = 0.
Vector freeEquilibrium(const Chain& chain, const Wrench& F) {
  const int n = chain.size();
  Vector q = Vector::Zero(n), g(n);
  Matrix H(n, n);
  for (int it = 0; it < 50; ++it) {
    totalPotentialGradient(chain, q, F, g);
    totalPotentialHessian(chain, q, F, H);
    q -= H.ldlt().solve(g);
  }
  totalPotentialGradient(chain, q, F, g);
  REQUIRE(g.norm() <= 1e-13 * chain.segment(0).straightStiffness());
  return q;
}

// Reference: Z from an LU kernel orthonormalised by QR (not the reflectors of vibration.cpp), the
// pencil (ZᵀHZ, ZᵀMZ) by Eigen's generalized solver with all vectors.
struct DenseReference {
  Vector values;
  Matrix shapes;  // n × dimension, M-orthonormal
};
DenseReference denseReference(VibrationAnalysis& va, const Vector& q, const Wrench& F, const std::vector<int>& held,
                              const std::vector<int>& locked, const Matrix* extraHessian = nullptr,
                              const Matrix* extraRows = nullptr) {
  const int n = va.chain().size();
  Matrix H(n, n), M(n, n);
  totalPotentialHessian(va.chain(), q, F, H);
  if (extraHessian) H += *extraHessian;
  va.massMatrix(q, M);
  Matrix C = va.constraintRows(q, held, locked);
  if (extraRows) {
    C.conservativeResize(C.rows() + extraRows->rows(), n);
    C.bottomRows(extraRows->rows()) = *extraRows;
  }
  Matrix Z = Matrix::Identity(n, n);
  if (C.rows() > 0) {
    Eigen::FullPivLU<Matrix> lu(C);
    lu.setThreshold(1e-10);
    if (lu.rank() == n) return {Vector(0), Matrix(n, 0)};  // kernel() gives one zero column then
    const Matrix K = lu.kernel();
    Z = Eigen::HouseholderQR<Matrix>(K).householderQ() * Matrix::Identity(n, K.cols());
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> es(Z.transpose() * H * Z, Z.transpose() * M * Z);
  REQUIRE(es.info() == Eigen::Success);
  return {es.eigenvalues(), Z * es.eigenvectors()};
}

// Links of masses 0.5 … 0.9 (period 5), small rotary inertia, centres at 0.3 of each link.
InertiaData variedLinks(const Chain& chain) {
  InertiaData inertia;
  for (int i = 0; i < chain.size(); ++i)
    inertia.links.push_back({0.5 + 0.1 * (i % 5), 0.01, 0.3 * chain.linkLengths()[i + 1]});
  return inertia;
}

// Joint angles uniform in ±1.8/n: a chain bent by a total of up to ±1.8 rad.
Vector bentAngles(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  Vector q(n);
  for (int i = 0; i < n; ++i) q[i] = U(rng) * 3.0 / n;
  return q;
}

// Times where s(t) = v₁ᵀ M (q − q*) changes sign, by a cubic Hermite interpolant on (s, ṡ) between
// consecutive recorded steps (bisection on the cubic).
std::vector<double> zeroCrossings(const DynamicsResult& r, const Vector& weight, const Vector& qStar) {
  std::vector<double> out;
  for (size_t i = 0; i + 1 < r.trajectory.size(); ++i) {
    const TrajectorySample& a = r.trajectory[i];
    const TrajectorySample& b = r.trajectory[i + 1];
    const double s0 = weight.dot(a.q - qStar), s1 = weight.dot(b.q - qStar);
    if (!(s0 * s1 < 0.0)) continue;
    const double h = b.t - a.t, d0 = weight.dot(a.qdot) * h, d1 = weight.dot(b.qdot) * h;
    const auto cubic = [&](double x) {
      const double x2 = x * x, x3 = x2 * x;
      return (2 * x3 - 3 * x2 + 1) * s0 + (x3 - 2 * x2 + x) * d0 + (-2 * x3 + 3 * x2) * s1 + (x3 - x2) * d1;
    };
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      if ((cubic(mid) < 0.0) == (s0 < 0.0)) lo = mid; else hi = mid;
    }
    out.push_back(a.t + 0.5 * (lo + hi) * h);
  }
  return out;
}

// Period of the first mode from the integrated undamped inertial model, released at rest from
// q* + ε v₁ (ε relative to the mode's largest joint angle).
double integratedPeriod(const Chain& chain, const EndCondition& end, const InertiaData& inertia, const Vector& qStar,
                        const Vector& v1, double omega1) {
  const int n = chain.size();
  InertialModel model(chain, end, inertia, {}, 0.0, qStar);
  Matrix M(n, n);
  model.massMatrix(qStar, M);
  const double period = 2 * kPi / omega1;
  IntegrationOptions opt;
  opt.absoluteTolerance = 1e-14;
  opt.relativeTolerance = 1e-12;
  opt.maxTime = 10.25 * period / model.timeUnit();
  opt.maxStep = period / 64 / model.timeUnit();
  opt.velocityTolerance = 1e-300;  // never at rest: the oscillation is undamped
  opt.residualTolerance = 1e-300;
  opt.contact = false;
  const Vector q0 = qStar + 1e-5 * v1 / v1.cwiseAbs().maxCoeff();
  const DynamicsResult r = simulate(model, q0, Vector::Zero(n), opt);
  REQUIRE(r.reason == IntegrationStop::MaxTime);
  const std::vector<double> t = zeroCrossings(r, M * v1, qStar);
  REQUIRE(t.size() >= 19);
  return 2.0 * (t.back() - t.front()) / double(t.size() - 1);
}

}  // namespace

TEST_CASE("vibration: one segment, free end, oscillates at omega^2 = K / I (I = m l^2 / 3 of a rod about its joint)",
          "[vibration]") {
  for (double L : {1.0, 1e4}) {
    const Chain chain = stiffChain(1, L, 1.0);
    const double rho = 2.5;
    VibrationAnalysis va(chain, InertiaData::uniformRods(chain, rho));
    const Vector q = Vector::Zero(1);  // unloaded equilibrium of the symmetric segment
    Vector K(1);
    jointStiffness(chain, q, K);
    const double l = chain.linkLengths()[1], I = rho * l * l * l / 3.0;
    const VibrationModes m = va.modes(q, Wrench::Zero(), {}, {}, 3);
    REQUIRE(m.dimension == 1);
    REQUIRE(m.omegaSquared.size() == 1);
    CHECK(relativeError(m.omegaSquared[0], K[0] / I) <= 1e-13);
    CHECK(relativeError(m.shapes(0, 0), 1.0 / std::sqrt(I)) <= 1e-13);  // vᵀMv = 1, positive
    // its end pinned in y: no mode left
    CHECK(va.modes(q, Wrench::Zero(), {1}, {}, 3).dimension == 0);
  }
}

TEST_CASE("vibration: the lowest modes equal a dense generalized eigen-solve on an independent kernel basis",
          "[vibration]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  for (int n : {3, 20, 150}) {
    const Chain chain = stiffChain(n);
    InertiaData inertia;
    for (int i = 0; i < n; ++i) inertia.links.push_back({0.5 + 0.1 * (i % 5), 0.01 + 0.002 * i, 0.3 * chain.linkLengths()[i + 1]});
    VibrationAnalysis va(chain, inertia);
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = U(rng) * 3.0 / n;
    const Wrench F(-0.3, 0.2, 0.1);
    for (const std::vector<int>& held : {std::vector<int>{}, {1}, {0, 1}, {0, 1, 2}}) {
      const std::vector<int> locked = n > 3 ? std::vector<int>{n / 2} : std::vector<int>{};
      INFO("n = " << n << ", held " << held.size() << ", locked " << locked.size());
      const int k = std::min(4, n - int(held.size() + locked.size()));
      const VibrationModes m = va.modes(q, F, held, locked, k);
      const DenseReference ref = denseReference(va, q, F, held, locked);
      REQUIRE(m.dimension == ref.values.size());
      REQUIRE(m.omegaSquared.size() == k);
      if (k == 0) continue;
      const double scale = ref.values.cwiseAbs().maxCoeff();
      Matrix M(n, n), H(n, n);
      va.massMatrix(q, M);
      totalPotentialHessian(chain, q, F, H);
      const Matrix C = va.constraintRows(q, held, locked);
      for (int j = 0; j < k; ++j) {
        CHECK(std::abs(m.omegaSquared[j] - ref.values[j]) <= 1e-11 * scale);
        const Vector v = m.shapes.col(j);
        CHECK((C * v).norm() <= 1e-12 * v.norm() * std::max(1.0, C.norm()));
        // the reference mode up to its sign (the eigenvalues are simple here)
        Vector w = ref.shapes.col(j);
        if (w.dot(M * v) < 0) w = -w;
        CHECK((v - w).norm() <= 1e-8 * w.norm());
      }
      const Matrix G = m.shapes.transpose() * M * m.shapes;
      CHECK((G - Matrix::Identity(k, k)).norm() <= 1e-10);
      // the mode equation on ker C: H v − ω² M v ⟂ ker C
      const Matrix R = H * m.shapes - M * m.shapes * m.omegaSquared.asDiagonal();
      const Matrix Z = Eigen::FullPivLU<Matrix>(C.rows() ? C : Matrix::Zero(1, n)).kernel();
      CHECK((Z.transpose() * R).norm() <= 1e-10 * H.norm() * Z.norm() * m.shapes.norm());
    }
  }
}

TEST_CASE("vibration: held end coordinates and locked joints remove modes, one constraint interlaces the frequencies",
          "[vibration]") {
  const int n = 6;
  const Chain chain = stiffChain(n);
  VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
  Vector q = Vector::LinSpaced(n, 0.1, -0.2);
  const Wrench F(-0.1, 0.05, 0.0);
  const VibrationModes free = va.modes(q, F, {}, {}, n);
  CHECK(free.dimension == n);
  CHECK(va.modes(q, F, {1}, {}, n).dimension == n - 1);
  CHECK(va.modes(q, F, {0, 1}, {}, n).dimension == n - 2);
  CHECK(va.modes(q, F, {0, 1, 2}, {}, n).dimension == n - 3);
  CHECK(va.modes(q, F, {0, 1, 2}, {0, 4}, n).dimension == n - 5);
  // the straight chain: x does not move to first order (J_x = 0), so holding it removes nothing
  CHECK(va.modes(Vector::Zero(n), Wrench::Zero(), {0, 1}, {}, n).dimension == n - 1);
  // Cauchy interlacing of the pencil under one constraint: ω²_i ≤ ω̃²_i ≤ ω²_{i+1}
  for (const std::vector<int>& one : {std::vector<int>{1}, {2}}) {
    const VibrationModes c = va.modes(q, F, one, {}, n);
    REQUIRE(c.omegaSquared.size() == n - 1);
    const double tol = 1e-12 * free.omegaSquared.cwiseAbs().maxCoeff();
    for (int i = 0; i < n - 1; ++i) {
      CHECK(free.omegaSquared[i] <= c.omegaSquared[i] + tol);
      CHECK(c.omegaSquared[i] <= free.omegaSquared[i + 1] + tol);
    }
  }
  CHECK_THROWS_AS(va.modes(q, F, {3}, {}, 2), std::invalid_argument);
  CHECK_THROWS_AS(va.modes(q, F, {}, {n}, 2), std::invalid_argument);
  CHECK_THROWS_AS(va.modes(Vector::Zero(n + 1), F, {}, {}, 2), std::invalid_argument);
}

TEST_CASE("vibration: masses x s divide every omega by sqrt(s), lengths x1e4 and stiffness x1e-8 scale omega^2 by k / L",
          "[vibration]") {
  const int n = 8;
  const Chain chain = stiffChain(n);
  const Vector q = freeEquilibrium(chain, Wrench(-0.2, 0.1, 0.0));
  const VibrationModes ref =
      VibrationAnalysis(chain, InertiaData::uniformRods(chain, 1.0)).modes(q, Wrench(-0.2, 0.1, 0.0), {1}, {}, 4);
  for (double s : {1e-3, 7.0}) {
    const VibrationModes m =
        VibrationAnalysis(chain, InertiaData::uniformRods(chain, s)).modes(q, Wrench(-0.2, 0.1, 0.0), {1}, {}, 4);
    for (int j = 0; j < 4; ++j) CHECK(relativeError(m.omegaSquared[j], ref.omegaSquared[j] / s) <= 1e-12);
    CHECK((m.shapes * std::sqrt(s) - ref.shapes).norm() <= 1e-10 * ref.shapes.norm());
  }
  const double L = 1e4, k = 1e-8;
  const Chain scaled = stiffChain(n, L, k);
  // the same angles are the equilibrium under the loads scaled by k L (eq 17)
  const Wrench Fs(-0.2 * k * L, 0.1 * k * L, 0.0);
  const VibrationModes m = VibrationAnalysis(scaled, InertiaData::uniformRods(scaled, 1.0)).modes(q, Fs, {1}, {}, 4);
  // ω² = stiffness / inertia: the joint stiffness scales as k L², the rods' μ_ij as ρ L³
  for (int j = 0; j < 4; ++j) CHECK(relativeError(m.omegaSquared[j], ref.omegaSquared[j] * k / L) <= 1e-9);
  CHECK((m.shapes * std::sqrt(L * L * L) - ref.shapes).norm() <= 1e-8 * ref.shapes.norm());
}

TEST_CASE("vibration: the period of the integrated inertial model released along the first mode is 2 pi / omega_1",
          "[vibration]") {
  SECTION("free end under a load, uneven links") {
    const Chain chain = stiffChain(3);
    InertiaData inertia;
    for (int i = 0; i < 3; ++i) inertia.links.push_back({0.7 + 0.3 * i, 0.05 + 0.02 * i, 0.4 * chain.linkLengths()[i + 1]});
    const Wrench F(-0.15, 0.08, 0.02);
    const Vector q = freeEquilibrium(chain, F);
    VibrationAnalysis va(chain, inertia);
    const VibrationModes m = va.modes(q, F, {}, {}, 1);
    REQUIRE(m.omegaSquared[0] > 0.0);
    const double omega = std::sqrt(m.omegaSquared[0]);
    const double T = integratedPeriod(chain, EndCondition::freeEnd(F), inertia, q, m.shapes.col(0), omega);
    CHECK(relativeError(T, 2 * kPi / omega) <= 1e-5);
  }
  SECTION("clamped-pinned column, straight and compressed (y held by the reaction)") {
    const Chain chain = stiffChain(4);
    const InertiaData inertia = InertiaData::uniformRods(chain, 1.3);
    const Wrench F(-0.2, 0.0, 0.0);
    const Vector q = Vector::Zero(4);
    VibrationAnalysis va(chain, inertia);
    const VibrationModes m = va.modes(q, F, {1}, {}, 1);
    REQUIRE(m.omegaSquared[0] > 0.0);
    const double omega = std::sqrt(m.omegaSquared[0]);
    const double T =
        integratedPeriod(chain, EndCondition::clampedPinned(-0.2), inertia, q, m.shapes.col(0), omega);
    CHECK(relativeError(T, 2 * kPi / omega) <= 1e-5);
  }
}

TEST_CASE("vibration: the crossing omega^2 is zero at the located branch points and folds, omega_1^2 has the sign of the stability "
          "operator's lowest eigenvalue at every traced point",
          "[vibration]") {
  cont::TracerOptions o;
  o.step.initialStep = 0.01;
  o.step.maxStep = 0.05;
  o.step.minStep = 1e-4;
  o.maxPoints = 20000;
  const auto check = [](EquilibriumProblem& problem, const cont::Branch& br, cont::SpecialPointType type,
                        size_t expected) {
    const int n = problem.segments();
    VibrationAnalysis va(problem.chain(), InertiaData::uniformRods(problem.chain(), 1.0));
    const std::vector<int> held = problem.endCondition().heldIndices();
    const auto omega2 = [&](const Vector& u, double lambda, int index = 0) {
      return va.modes(u.head(n), problem.wrench(u, lambda), held, {}, index + 1, false).omegaSquared[index];
    };
    const double scale = va.modes(br.points.front().u.head(n), problem.wrench(br.points.front().u, br.points.front().lambda),
                                  held, {}, n, false)
                             .omegaSquared.cwiseAbs()
                             .maxCoeff();
    int compared = 0;
    for (const cont::ContinuationPoint& p : br.points) {
      cont::StabilityInfo info;
      REQUIRE(buckle::continuation::BoundProblem(problem).stability(p.u, p.lambda, 1, info));
      const double w = omega2(p.u, p.lambda);
      if (std::abs(info.smallest) > 1e-6) {
        CHECK((w > 0) == (info.smallest > 0));
        ++compared;
      }
    }
    CHECK(compared > 10);
    const auto located = br.specialPointsOfType(type);
    REQUIRE(located.size() == expected);
    for (const cont::SpecialPoint* sp : located) {
      // the eigenvalue crossing there is number min(inertia before, after) (0-based) of the
      // stability operator, so (Sylvester) the same ω² of the pencil
      INFO("located at lambda = " << sp->lambda << ", inertia " << sp->inertiaBefore << " -> " << sp->inertiaAfter);
      REQUIRE(sp->inertiaBefore >= 0);
      REQUIRE(std::abs(sp->inertiaBefore - sp->inertiaAfter) == 1);
      CHECK(std::abs(omega2(sp->u, sp->lambda, std::min(sp->inertiaBefore, sp->inertiaAfter))) <= 1e-10 * scale);
    }
    return located;
  };
  SECTION("branch points of the compressed clamped-pinned column: omega_1^2 linear in the load through them") {
    EquilibriumProblem problem(stiffChain(3), EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
    o.lambdaMin = -2.5;
    o.lambdaMax = 0.0;
    const cont::Branch br = cont::trace(problem, Vector::Zero(4), 0.0, cont::InitialDirection::decreasingLambda(), o);
    const auto bps = check(problem, br, cont::SpecialPointType::BranchPoint, 2);
    // on the straight branch M is constant and H affine in λ: ω²(λ* ± δ) = ∓c δ + O(δ²)
    VibrationAnalysis va(problem.chain(), InertiaData::uniformRods(problem.chain(), 1.0));
    const double lambda = bps[0]->lambda, delta = 1e-4 * std::abs(lambda);
    const auto w = [&](double l) { return va.modes(Vector::Zero(3), Wrench(l, 0, 0), {1}, {}, 1, false).omegaSquared[0]; };
    const double up = w(lambda + delta), down = w(lambda - delta);
    CHECK(up > 0.0);
    CHECK(down < 0.0);
    CHECK(std::abs(up + down) <= 1e-3 * std::abs(up - down));
  }
  SECTION("the fold of the free end under a lateral force") {
    EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5)),
                               EndCondition::freeEnd(Eigen::Vector3d(0, 0.01, 0)), Eigen::Vector3d(1, 0, 0));
    o.lambdaMin = -3.0;
    o.lambdaMax = 3.0;
    const cont::Branch br = cont::trace(problem, Vector::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
    check(problem, br, cont::SpecialPointType::Fold, 1);
  }
}

TEST_CASE("vibration: with the links' weight the modes are those of K_q - K_g + the weight's Hessian (GravityPotential)",
          "[vibration][body_loads]") {
  std::mt19937 rng(17);
  for (int n : {3, 25}) {
    const Chain chain = stiffChain(n);
    const InertiaData inertia = variedLinks(chain);
    VibrationAnalysis va(chain, inertia);
    const Vector q = bentAngles(rng, n);
    const Wrench F(-0.1, 0.05, 0.0);
    const Eigen::Vector2d g(0.3, -2.0);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(F), Eigen::Vector3d::Zero(), {}, {},
                               BodyLoads::weight(chain, inertia, g, Eigen::Vector2d::Zero()));
    Matrix G(n, n);
    GravityPotential(chain, inertia, g).hessian(q, G);  // the independent dense Hessian of V
    for (const std::vector<int>& held : {std::vector<int>{}, {1}}) {
      INFO("n = " << n << ", held " << held.size());
      const VibrationModes m = va.modes(q, F, held, {}, 3, false, problem.bodyLoadGenerator(q, 0.0));
      const DenseReference ref = denseReference(va, q, F, held, {}, &G);
      const DenseReference without = denseReference(va, q, F, held, {});
      const double scale = ref.values.cwiseAbs().maxCoeff();
      REQUIRE(m.omegaSquared.size() == std::min<Eigen::Index>(3, ref.values.size()));
      for (int j = 0; j < m.omegaSquared.size(); ++j) CHECK(std::abs(m.omegaSquared[j] - ref.values[j]) <= 1e-11 * scale);
      CHECK(std::abs(without.values[0] - ref.values[0]) > 1e-3 * std::abs(ref.values[0]));  // the weight matters
    }
  }
}

TEST_CASE("vibration: vertices held on the base wall add their rows grad x_v to C_h and -mu d2x_v to H "
          "(central differences of the vertex's x), on both routes",
          "[vibration][wall]") {
  std::mt19937 rng(29);
  for (int n : {6, 40}) {
    const Chain chain = stiffChain(n);
    VibrationAnalysis va(chain, variedLinks(chain));
    const Vector q = bentAngles(rng, n);
    const Wrench F(-0.1, 0.05, 0.0);
    ContactSet contacts;
    contacts.touch(WallVertex{2, 3});
    contacts.touch(WallVertex{n - 2, 0});
    contacts.lock(1, LimitSide::Upper);
    const Vector mu = (Vector(2) << 0.4, 0.7).finished();
    // the reference's rows and Hessian term from x_v(q) alone, by central differences
    auto x = [&](const Vector& angles, const WallVertex& v) {
      return wallVertexPoint(chain, angles, jointPositions(chain, angles), v).x();
    };
    Matrix rows(2, n), wallHessian = Matrix::Zero(n, n);
    const double h1 = 1e-6, h2 = 1e-4;
    for (int k = 0; k < 2; ++k) {
      const WallVertex& v = contacts.wall()[size_t(k)];
      for (int i = 0; i < n; ++i) {
        Vector p = q, m = q;
        p[i] += h1;
        m[i] -= h1;
        rows(k, i) = (x(p, v) - x(m, v)) / (2 * h1);
        for (int j = 0; j < n; ++j) {
          Vector pp = q, pm = q, mp = q, mm = q;
          pp[i] += h2, pp[j] += h2, pm[i] += h2, pm[j] -= h2, mp[i] -= h2, mp[j] += h2, mm[i] -= h2, mm[j] -= h2;
          wallHessian(i, j) -= mu[k] * (x(pp, v) - x(pm, v) - x(mp, v) + x(mm, v)) / (4 * h2 * h2);
        }
      }
    }
    Matrix H(n, n), M(n, n);
    totalPotentialHessian(chain, q, F, H);
    H += wallHessian;
    va.massMatrix(q, M);
    for (const std::vector<int>& held : {std::vector<int>{}, {1}, {0, 1}}) {
      INFO("n = " << n << ", held " << held.size());
      const DenseReference ref = denseReference(va, q, F, held, {1}, &wallHessian, &rows);
      const DenseReference unheld = denseReference(va, q, F, held, {1});
      const DenseReference forceless = denseReference(va, q, F, held, {1}, nullptr, &rows);
      const double scale = ref.values.cwiseAbs().maxCoeff();
      for (VibrationRoute route : {VibrationRoute::Dense, VibrationRoute::Structured}) {
        va.setRoute(route);
        const int dimension = n - 1 - 2 - int(held.size()), count = std::min(4, dimension);
        const VibrationModes m = va.modes(q, F, held, contacts, mu, count, true);
        // the structured route borders at most three rows: two held and two wall rows go dense
        CHECK(m.route == (route == VibrationRoute::Structured && held.size() < 2 ? VibrationRoute::Structured
                                                                                 : VibrationRoute::Dense));
        CHECK(m.fallback.empty() == (route == VibrationRoute::Dense || held.size() < 2));
        REQUIRE(m.dimension == dimension);
        REQUIRE(m.omegaSquared.size() == count);
        for (int j = 0; j < count; ++j) CHECK(std::abs(m.omegaSquared[j] - ref.values[j]) <= 1e-6 * scale);
        // each shape keeps the vertices on the wall and the locked joint still, M-orthonormal, and
        // its Rayleigh quotient on the reference's H is its ω²
        REQUIRE(m.shapes.cols() == count);
        CHECK((rows * m.shapes).norm() <= 1e-6 * rows.norm() * m.shapes.norm());
        CHECK(m.shapes.row(1).norm() <= 1e-12 * m.shapes.norm());
        CHECK((m.shapes.transpose() * M * m.shapes - Matrix::Identity(count, count)).norm() <= 1e-8);
        for (int j = 0; j < count; ++j)
          CHECK(std::abs(m.shapes.col(j).dot(H * m.shapes.col(j)) - ref.values[j]) <= 1e-6 * scale);
      }
      va.setRoute(VibrationRoute::Automatic);
      // the wall matters, its rows and its forces' Hessian both
      CHECK(std::abs(unheld.values[0] - ref.values[0]) > 1e-3 * std::abs(ref.values[0]));
      CHECK(std::abs(forceless.values[0] - ref.values[0]) > 1e-4 * scale);
    }
    CHECK_THROWS_AS(va.modes(q, F, {}, contacts, Vector(1), 2, false), std::invalid_argument);
    // in other units, lengths x1e4 and stiffness x1e-8: the same angles under the end load and
    // the wall forces x k L, omega^2 x k / L (rods of the same mass per length, as above)
    const double L = 1e4, k = 1e-8;
    const Chain scaled = stiffChain(n, L, k);
    VibrationAnalysis rods(chain, InertiaData::uniformRods(chain, 1.0));
    VibrationAnalysis scaledRods(scaled, InertiaData::uniformRods(scaled, 1.0));
    const VibrationModes a = rods.modes(q, F, {1}, contacts, mu, 2, false);
    const VibrationModes b = scaledRods.modes(q, Wrench(F.x() * k * L, F.y() * k * L, 0.0), {1}, contacts, mu * k * L, 2, false);
    for (int j = 0; j < 2; ++j) CHECK(relativeError(b.omegaSquared[j], a.omegaSquared[j] * k / L) <= 1e-9);
  }
}
