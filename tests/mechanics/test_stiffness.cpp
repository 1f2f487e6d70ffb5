#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/unloaded_shape.h"

#include "random_segments.h"

using namespace buckle::mechanics;

namespace {

SegmentParameters randomStableSegment(std::mt19937& rng) {
  std::uniform_real_distribution<double> A(0.1, 0.7), B(0.7, 1.3), K(0.5, 3.0), L(2.3, 3.0);
  SegmentParameters p;
  p.a1 = A(rng); p.a2 = A(rng);
  p.b1 = B(rng); p.b2 = B(rng);
  p.k1 = K(rng); p.k2 = K(rng);
  p.L1_0 = L(rng) * p.b1; p.L2_0 = L(rng) * p.b2;
  return p;
}

Matrix jacobian(const Chain& chain, const Vector& q) {
  ChainData d(chain);
  forwardKinematics(chain, q, d);
  Matrix J(3, chain.size());
  endJacobian(d, J);
  return J;
}

// Position compliance with the end rotation held, from an explicit null-space basis of J_φ.
Eigen::Matrix2d heldRotationCompliance(const Matrix& H, const Matrix& J) {
  const Eigen::Index n = H.rows();
  const Eigen::HouseholderQR<Matrix> qr(J.row(2).transpose());
  const Matrix Z = (qr.householderQ() * Matrix::Identity(n, n)).rightCols(n - 1);
  const Matrix P = Z * (Z.transpose() * H * Z).inverse() * Z.transpose();
  return J.topRows(2) * P * J.topRows(2).transpose();
}

// Equilibrium under the end condition at (q guess), by Newton on the EquilibriumProblem.
Vector solve(const Chain& chain, const EndCondition& end, const Vector& qGuess) {
  EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero());
  const PolishResult r = polishEquilibrium(problem, qGuess, 0.0);
  REQUIRE(r.converged);
  return r.u;
}

}  // namespace

TEST_CASE("unloaded stiffness: eq 21 equals the eq 23 closed form, symmetric positive definite", "[stiffness]") {
  std::mt19937 rng(7);
  for (int n : {3, 6, 40}) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < n; ++i) segs.push_back(randomStableSegment(rng));
    const Chain chain(segs);
    for (int trial = 0; trial < 5; ++trial) {
      Vector q(n);
      std::uniform_real_distribution<double> Q(-0.5, 0.5);
      for (int i = 0; i < n; ++i) q[i] = Q(rng);
      Vector kq(n);
      jointStiffness(chain, q, kq);
      REQUIRE(kq.minCoeff() > 0.0);
      const Matrix J = jacobian(chain, q);
      // eq 23: C = Σ_i J_{·i} J_{·i}ᵀ / K_qi
      Eigen::Matrix2d C23 = Eigen::Matrix2d::Zero();
      for (int i = 0; i < n; ++i) {
        C23(0, 0) += J(0, i) * J(0, i) / kq[i];
        C23(1, 1) += J(1, i) * J(1, i) / kq[i];
        C23(0, 1) += J(0, i) * J(1, i) / kq[i];
      }
      C23(1, 0) = C23(0, 1);
      // eq 21 literally
      const Eigen::Matrix2d K21 = (J.topRows(2) * kq.cwiseInverse().asDiagonal() * J.topRows(2).transpose()).inverse();
      const CartesianStiffness s = unloadedStiffness(chain, q);
      REQUIRE_FALSE(s.singular);
      REQUIRE_FALSE(s.rigid);
      CHECK((s.compliance - C23).lpNorm<Eigen::Infinity>() < 1e-12 * C23.lpNorm<Eigen::Infinity>());
      CHECK((s.stiffness - K21).lpNorm<Eigen::Infinity>() < 1e-9 * K21.lpNorm<Eigen::Infinity>());
      CHECK(s.stiffness(0, 1) == s.stiffness(1, 0));
      CHECK(s.positiveDefinite);
      CHECK(s.negativeDirections == 0);
      CHECK(s.smallestEigenvalue == Approx(kq.minCoeff()).epsilon(1e-12));
      CHECK((s.stiffness * s.compliance - Eigen::Matrix2d::Identity()).lpNorm<Eigen::Infinity>() < 1e-9);
      // rotation held: independent null-space formula
      const CartesianStiffness sh = unloadedStiffness(chain, q, true);
      Matrix H = kq.asDiagonal();
      const Eigen::Matrix2d Ch = heldRotationCompliance(H, J);
      CHECK((sh.compliance - Ch).lpNorm<Eigen::Infinity>() < 1e-10 * Ch.lpNorm<Eigen::Infinity>());
      CHECK(sh.positiveDefinite);
      // holding the rotation can only stiffen: C_free − C_held is positive semidefinite
      CHECK(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s.compliance - sh.compliance).eigenvalues()[0] >
            -1e-12 * s.compliance.norm());
    }
  }
}

TEST_CASE("loaded stiffness tends to the unloaded one as F -> 0 and equals eq 29", "[stiffness]") {
  std::mt19937 rng(9);
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < 5; ++i) segs.push_back(randomStableSegment(rng));
  const Chain chain(segs);
  const Vector q = (Vector(5) << 0.2, -0.3, 0.1, 0.25, -0.15).finished();
  const Wrench F(-0.4, 0.3, 0.1);
  const CartesianStiffness K0 = unloadedStiffness(chain, q);
  double prev = 1e300;
  for (double eps : {1e-1, 1e-2, 1e-3, 1e-4}) {
    const CartesianStiffness K = loadedStiffness(chain, q, eps * F);
    const double diff = (K.stiffness - K0.stiffness).lpNorm<Eigen::Infinity>();
    CHECK(diff < 5.0 * eps * K0.stiffness.lpNorm<Eigen::Infinity>());
    CHECK(diff < prev);
    prev = diff;
    // eq 29 literally
    Matrix H(5, 5);
    totalPotentialHessian(chain, q, eps * F, H);
    const Matrix J = jacobian(chain, q);
    const Eigen::Matrix2d K29 = (J.topRows(2) * H.inverse() * J.topRows(2).transpose()).inverse();
    CHECK((K.stiffness - K29).lpNorm<Eigen::Infinity>() < 1e-9 * K29.lpNorm<Eigen::Infinity>());
  }
  CHECK(prev < 1e-3 * K0.stiffness.lpNorm<Eigen::Infinity>());
}

TEST_CASE("loaded compliance equals the finite difference of the equilibrium force-deflection map", "[stiffness]") {
  std::mt19937 rng(13);
  // The paper's non-straight start (docs/mechanics.md, "What the physics does"):
  // q⁰ = (θ, −2θ, θ), cos θ = 7/8, made unloaded by preloads,
  // and a random asymmetric 6-segment chain with a random unloaded shape.
  const double theta = std::acos(7.0 / 8.0);
  std::vector<std::pair<std::vector<SegmentParameters>, Vector>> cases;
  cases.emplace_back(preloadsForShape(std::vector<SegmentParameters>(3, SegmentParameters::symmetric(0.75, 1.0, 1.0, 2.25)),
                                      Eigen::Vector3d(theta, -2 * theta, theta)),
                     Eigen::Vector3d(theta, -2 * theta, theta));
  {
    std::vector<SegmentParameters> segs;
    Vector q0(6);
    std::uniform_real_distribution<double> Q(-0.3, 0.3);
    for (int i = 0; i < 6; ++i) {
      segs.push_back(randomStableSegment(rng));
      q0[i] = Q(rng);
    }
    cases.emplace_back(preloadsForShape(segs, q0), q0);
  }
  for (const auto& [segs, q0] : cases) {
    const Chain chain(segs);
    const int n = chain.size();
    INFO("n = " << n);
    // loads at a fraction of the first (cantilever) critical load of the unloaded shape
    const double Pc = std::abs(linearBuckling(chain, q0, EndCondition::freeEnd()).modes.at(0).lambda);
    for (const Eigen::Vector2d& Fp : {Eigen::Vector2d(-0.5 * Pc, 0.2 * Pc), Eigen::Vector2d(0.4 * Pc, -0.6 * Pc)}) {
      for (bool rotationHeld : {false, true}) {
        INFO("rotation held: " << rotationHeld << ", F = " << Fp.transpose());
        EndCondition end = EndCondition::freeEnd(Eigen::Vector3d(Fp[0], Fp[1], 0.0));
        if (rotationHeld) {
          end.control[2] = Control::Held;
          end.value[2] = endPose(chain, q0)[2];
        }
        const Vector u = solve(chain, end, q0);
        EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero());
        const Wrench W = problem.wrench(u, 0.0);
        const CartesianStiffness s = loadedStiffness(chain, u.head(n), W, end);
        REQUIRE_FALSE(s.singular);
        REQUIRE_FALSE(s.rigid);
        CHECK(s.negativeDirections == 0);
        CHECK(s.positiveDefinite);
        const double h = 1e-5;
        Eigen::Matrix2d Cfd;
        for (int c = 0; c < 2; ++c) {
          EndCondition ep = end, em = end;
          ep.value[c] += h;
          em.value[c] -= h;
          const Vector up = solve(chain, ep, u.head(n)), um = solve(chain, em, u.head(n));
          Cfd.col(c) = (endPose(chain, up.head(n)) - endPose(chain, um.head(n))).head(2) / (2 * h);
        }
        CHECK((s.compliance - Cfd).lpNorm<Eigen::Infinity>() < 1e-6 * Cfd.lpNorm<Eigen::Infinity>());
        if (rotationHeld) {
          CHECK(std::isnan(s.rotationalStiffness));
        } else {
          // the end's rotational compliance: δφ/δMe with the forces unchanged, by the same differences
          EndCondition ep = end, em = end;
          ep.value[2] += h;
          em.value[2] -= h;
          const Vector up = solve(chain, ep, u.head(n)), um = solve(chain, em, u.head(n));
          const double cpp = (endPose(chain, up.head(n))[2] - endPose(chain, um.head(n))[2]) / (2 * h);
          CHECK(s.rotationalCompliance == Approx(cpp).epsilon(1e-6));
          CHECK(s.rotationalStiffness == Approx(1.0 / cpp).epsilon(1e-6));
        }
        // the load changes the stiffness (the check above is not just the unloaded one)
        const CartesianStiffness s0 = unloadedStiffness(chain, u.head(n), rotationHeld);
        CHECK((s0.compliance - Cfd).lpNorm<Eigen::Infinity>() > 1e-3 * Cfd.lpNorm<Eigen::Infinity>());
      }
    }
  }
}

TEST_CASE("singular cases: bordered solves where K_q - K_g alone is singular", "[stiffness]") {
  const int n = 4;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Vector straight = Vector::Zero(n);
  // Straight chain at the first cantilever load: K_q − K_g is singular.
  const LinearBucklingResult lb = linearBuckling(chain, straight, EndCondition::freeEnd());
  const Wrench Fc(lb.modes[0].lambda, 0.0, 0.0);
  Matrix H(n, n);
  totalPotentialHessian(chain, straight, Fc, H);
  REQUIRE(std::abs(Eigen::SelfAdjointEigenSolver<Matrix>(H).eigenvalues()[0]) < 1e-12);
  const CartesianStiffness free = loadedStiffness(chain, straight, Fc, false);
  CHECK(free.singular);
  CHECK(std::isnan(free.compliance(0, 0)));
  // With the rotation held the constrained problem is regular: finite compliance, equal to the
  // null-space formula; the end cannot move along x to first order (rigid).
  const CartesianStiffness held = loadedStiffness(chain, straight, Fc, true);
  CHECK_FALSE(held.singular);
  CHECK(held.rigid);
  const Eigen::Matrix2d Ch = heldRotationCompliance(H, jacobian(chain, straight));
  CHECK((held.compliance - Ch).lpNorm<Eigen::Infinity>() < 1e-9 * Ch.lpNorm<Eigen::Infinity>());
  CHECK(held.compliance(1, 1) > 0.0);
  CHECK(held.negativeDirections == 0);
  // Unloaded straight chain: axially rigid.
  const CartesianStiffness u0 = unloadedStiffness(chain, straight);
  CHECK(u0.rigid);
  CHECK(u0.compliance(0, 0) == 0.0);
  CHECK(u0.compliance(1, 1) > 0.0);

  // A bent chain at the load where K_q − K_g becomes singular (a force-control limit): the
  // compliance is infinite, K_F stays finite, singular, and is the limit of the regular K_F.
  const Vector q = (Vector(n) << 0.3, -0.2, 0.4, 0.1).finished();
  ChainData d(chain);
  forwardKinematics(chain, q, d);
  Matrix G(n, n);
  loadMatrix(d, Wrench(1.0, 0.0, 0.0), G);
  Vector kq(n);
  jointStiffness(chain, q, kq);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> ges(G, Matrix(kq.asDiagonal()));
  const Eigen::Index last = n - 1;
  const double mu = std::abs(ges.eigenvalues()[0]) > std::abs(ges.eigenvalues()[last]) ? ges.eigenvalues()[0]
                                                                                        : ges.eigenvalues()[last];
  const Wrench Fs(1.0 / mu, 0.0, 0.0);
  const CartesianStiffness at = loadedStiffness(chain, q, Fs);
  CHECK(at.singular);
  REQUIRE(at.stiffness.allFinite());
  CHECK(std::abs(at.stiffness.determinant()) < 1e-8 * at.stiffness.squaredNorm());
  const CartesianStiffness near = loadedStiffness(chain, q, Wrench(Fs[0] * (1 + 1e-7), 0.0, 0.0));
  CHECK_FALSE(near.singular);
  CHECK((near.stiffness - at.stiffness).lpNorm<Eigen::Infinity>() < 1e-5 * at.stiffness.lpNorm<Eigen::Infinity>());
  // beyond it the force-controlled equilibrium has one negative direction
  CHECK(loadedStiffness(chain, q, Wrench(Fs[0] * 1.01, 0.0, 0.0)).negativeDirections == 1);
}

TEST_CASE("the lateral compliance of the free chain vanishes at the clamped-pinned critical load", "[stiffness]") {
  // The end held laterally (y) makes [[H, J_yᵀ], [J_y, 0]] singular exactly where the free chain's
  // J_y H⁻¹ J_yᵀ = C_yy is zero (H regular there): the pinned critical loads are the zeros of C_yy
  // and the poles of 1/C_yy, and C_F reports them as an exact 0 (the rounding left of them is
  // below complianceAccuracy), in any units.
  const int n = 6;
  for (const double scale : {1.0, 1e-4, 1e4}) {
    const double stiffnessScale = scale == 1.0 ? 1.0 : 1.0 / (scale * scale * 1e4);
    const Chain chain =
        Chain::uniform(n, SegmentParameters::symmetric(0.5 * scale, scale, stiffnessScale, 2.25 * scale));
    const Vector straight = Vector::Zero(n);
    const EndCondition pinned = EndCondition::clampedPinned(0.0);
    const LinearBucklingResult lb = linearBuckling(chain, straight, pinned);
    REQUIRE_FALSE(lb.modes.empty());
    const double Fc = lb.modes[0].lambda;
    const CartesianStiffness at = loadedStiffness(chain, straight, Wrench(Fc, 0.0, 0.0), false);
    REQUIRE_FALSE(at.singular);
    CHECK(at.compliance(1, 1) == 0.0);
    CHECK(at.compliance(0, 0) == 0.0);  // the straight chain's axial rigidity
    // either side of it C_yy is finite and of opposite signs, |C_yy| growing linearly away from it
    const CartesianStiffness before = loadedStiffness(chain, straight, Wrench(Fc * (1 - 1e-6), 0.0, 0.0), false);
    const CartesianStiffness after = loadedStiffness(chain, straight, Wrench(Fc * (1 + 1e-6), 0.0, 0.0), false);
    const CartesianStiffness further = loadedStiffness(chain, straight, Wrench(Fc * (1 + 2e-6), 0.0, 0.0), false);
    CHECK(before.compliance(1, 1) * after.compliance(1, 1) < 0.0);
    CHECK(std::abs(before.compliance(1, 1)) > 1e3 * before.complianceAccuracy(1, 1));
    CHECK(further.compliance(1, 1) / after.compliance(1, 1) == Approx(2.0).epsilon(1e-4));
  }
}

TEST_CASE("with the links' weight the loaded compliance is the difference quotient of the force-deflection map, and dK_F "
          "that of K_F", "[stiffness][body_loads]") {
  const int n = 6;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const BodyLoads weight =
      BodyLoads::weight(chain, InertiaData::uniformRods(chain, 0.005), {0.2, -1.0}, Eigen::Vector2d::Zero());
  const auto heavy = [&](const Eigen::Vector2d& F, const Vector& guess) {
    EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(F[0], F[1], 0.0)), Eigen::Vector3d::Zero(),
                               {}, {}, weight);
    const PolishResult r = polishEquilibrium(problem, guess, 0.0);
    REQUIRE(r.converged);
    return Vector(r.u.head(n));
  };
  const Eigen::Vector2d F0(0.05, 0.3);
  const Vector q = heavy(F0, Vector::Zero(n));
  const EndCondition end = EndCondition::freeEnd(Eigen::Vector3d(F0[0], F0[1], 0.0));
  EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero(), {}, {}, weight);
  StiffnessOptions so;
  so.bodyGenerator = problem.bodyLoadGenerator(q, 0.0);
  const CartesianStiffness s = loadedStiffness(chain, q, problem.wrench(q, 0.0), end, so);
  INFO("singular " << s.singular << ", rigid " << s.rigid << ", C = " << s.compliance);
  REQUIRE(s.positiveDefinite);
  const double h = 1e-5;
  Eigen::Matrix2d Cfd;
  for (int c = 0; c < 2; ++c) {
    Eigen::Vector2d e = Eigen::Vector2d::Zero();
    e[c] = h;
    Cfd.col(c) = (endPose(chain, heavy(F0 + e, q)) - endPose(chain, heavy(F0 - e, q))).head(2) / (2 * h);
  }
  CHECK((s.compliance - Cfd).lpNorm<Eigen::Infinity>() < 1e-6 * Cfd.lpNorm<Eigen::Infinity>());
  const CartesianStiffness weightless = loadedStiffness(chain, q, problem.wrench(q, 0.0), end);
  CHECK((weightless.compliance - Cfd).lpNorm<Eigen::Infinity>() > 1e-3 * Cfd.lpNorm<Eigen::Infinity>());
  // dK_F along (dq, dF) with γ moving with q (eq B5) against central differences of K_F
  const Vector dq = Vector::LinSpaced(n, 0.3, -0.5);
  const Wrench W = problem.wrench(q, 0.0), dW(0.2, -0.1, 0.0);
  Eigen::Matrix2d K, dK;
  so.bodyGeneratorRate = problem.bodyLoadGeneratorRate(q, 0.0, dq, 0.0);
  REQUIRE(loadedStiffnessDerivative(chain, q, W, false, dq, dW, K, dK, so));
  StiffnessOptions plus, minus;
  plus.bodyGenerator = problem.bodyLoadGenerator(q + h * dq, 0.0);
  minus.bodyGenerator = problem.bodyLoadGenerator(q - h * dq, 0.0);
  const Eigen::Matrix2d Kp = loadedStiffness(chain, q + h * dq, W + h * dW, false, plus).stiffness;
  const Eigen::Matrix2d Km = loadedStiffness(chain, q - h * dq, W - h * dW, false, minus).stiffness;
  CHECK((dK - (Kp - Km) / (2 * h)).lpNorm<Eigen::Infinity>() < 1e-6 * K.lpNorm<Eigen::Infinity>());
}

TEST_CASE("the O(n) stiffness and its rate equal loadedStiffnessDerivative's dense solves (rotation free and held, "
          "body loads, any units)",
          "[stiffness]") {
  std::mt19937 rng(64);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.4, 0.4);
  for (int n : {70, 300}) {
    for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}}) {
      std::vector<SegmentParameters> segs;
      for (int i = 0; i < n; ++i) {
        SegmentParameters p = testing::randomSegment(rng);
        p.a1 *= sL, p.b1 *= sL, p.a2 *= sL, p.b2 *= sL, p.L1_0 *= sL, p.L2_0 *= sL, p.k1 *= sK, p.k2 *= sK;
        segs.push_back(p);
      }
      const Chain chain(segs);
      const double force = sK * sL, moment = sK * sL * sL;
      Eigen::VectorXd q(n), dq(n);
      for (int i = 0; i < n; ++i) q[i] = Q(rng), dq[i] = W(rng);
      const Wrench F(0.3 * force * W(rng) / n, 0.3 * force * W(rng) / n, moment * W(rng));
      const Wrench dF(force * W(rng), force * W(rng), moment * W(rng));
      for (bool rotationHeld : {false, true})
        for (bool body : {false, true}) {
          INFO("n = " << n << ", lengths x" << sL << ", rotation held " << rotationHeld << ", body loads " << body);
          StiffnessOptions o;
          if (body) {  // a generator of the body loads' kind (any γ: the formulas do not care)
            o.bodyGenerator = o.bodyGeneratorRate = Eigen::VectorXd(n);
            for (int i = 0; i < n; ++i)
              o.bodyGenerator[i] = 0.1 * moment * W(rng) / n, o.bodyGeneratorRate[i] = moment * W(rng) / n;
          }
          Eigen::Matrix2d K1, dK1, K2, dK2, K3;
          REQUIRE(loadedStiffnessDerivative(chain, q, F, rotationHeld, dq, dF, K1, dK1, o));
          REQUIRE(structuredStiffnessDerivative(chain, q, F, rotationHeld, dq, dF, K2, &dK2, o));
          REQUIRE(structuredStiffnessDerivative(chain, q, F, rotationHeld, dq, dF, K3, nullptr, o));
          CHECK((K2 - K1).norm() <= 1e-9 * K1.norm());
          CHECK((dK2 - dK1).norm() <= 1e-8 * dK1.norm());
          CHECK(K3 == K2);
        }
    }
  }
}
