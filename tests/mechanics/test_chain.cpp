#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/chain.h"

#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::randomAngles;
using testing::randomChain;
using testing::rejection;

// Jᵀ F as a function of q.
Vector jtF(const Chain& chain, const Vector& q, const Wrench& F) {
  ChainData d(chain);
  forwardKinematics(chain, q, d);
  Matrix J(3, chain.size());
  endJacobian(d, J);
  return J.transpose() * F;
}

}  // namespace

TEST_CASE("end pose of three identical segments is eq 5", "[chain]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> Q(-1.2, 1.2), B(0.5, 2.0);
  for (int trial = 0; trial < 30; ++trial) {
    const double b = B(rng);
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.4 * b, b, 1.0, 2.3 * b));
    const Vector q = Vector::NullaryExpr(3, [&](Eigen::Index) { return Q(rng); });
    const double q1 = q[0], q12 = q[0] + q[1], q123 = q12 + q[2];
    const Pose p = endPose(chain, q);
    CHECK(p[0] == Approx(b + 2 * b * std::cos(q1) + 2 * b * std::cos(q12) + b * std::cos(q123)).margin(1e-13));
    CHECK(p[1] == Approx(2 * b * std::sin(q1) + 2 * b * std::sin(q12) + b * std::sin(q123)).margin(1e-13));
    CHECK(p[2] == Approx(q123).margin(1e-15));
  }
  const Chain straight = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  CHECK(endPose(straight, Vector::Zero(3))[0] == Approx(6.0).margin(1e-15));
  CHECK(straight.length() == Approx(6.0).margin(1e-15));
}

TEST_CASE("a long curled chain's end position is exact to a fraction of eps times its length", "[chain]") {
  // A spiral of 1.3 turns: the end comes back near the base, so the link terms of x and y cancel
  // and their plain running sums keep their rounding. Reference: the same sums in long double
  // (64-bit mantissa); beside it the plain double sums, to show the test can tell.
  double plainWorst = 0.0;
  for (int n : {10000, 100000}) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = 2.0 * M_PI * 1.3 / n * (1.0 + 0.3 * std::sin(0.37 * i));
    long double t = 0.0L, x = chain.linkLengths()[0], y = 0.0L;
    double tp = 0.0, xp = chain.linkLengths()[0], yp = 0.0;
    for (int i = 0; i < n; ++i) {
      const double l = chain.linkLengths()[i + 1];
      t += q[i];
      x += l * std::cos(t);
      y += l * std::sin(t);
      tp += q[i];
      xp += l * std::cos(tp);
      yp += l * std::sin(tp);
    }
    const double epsL = std::numeric_limits<double>::epsilon() * chain.length();
    const Pose pose = endPose(chain, q);
    INFO("n = " << n);
    CHECK(std::abs(pose.x() - double(x)) <= epsL);
    CHECK(std::abs(pose.y() - double(y)) <= epsL);
    plainWorst = std::max({plainWorst, std::abs(xp - double(x)) / epsL, std::abs(yp - double(y)) / epsL});
  }
  CHECK(plainWorst > 3.0);  // plain sums miss by several eps·L here
}

TEST_CASE("chain derivatives match central finite differences", "[chain]") {
  std::mt19937 rng(17);
  const double h = 1e-6;
  for (int n : {1, 3, 17, 200}) {
    INFO("n = " << n);
    const Chain chain = randomChain(rng, n);
    REQUIRE(chain.size() == n);
    for (int trial = 0; trial < (n > 50 ? 1 : 4); ++trial) {
      const Vector q = randomAngles(rng, chain);
      std::uniform_real_distribution<double> W(-2.0, 2.0);
      const Wrench F(W(rng), W(rng), W(rng));
      ChainData data(chain);
      forwardKinematics(chain, q, data);
      Matrix J(3, n), Kg(n, n), H(n, n);
      endJacobian(data, J);
      loadMatrix(data, F, Kg);
      totalPotentialHessian(chain, q, F, H);
      Vector g(n), kq(n), dkq(n), gradPi(n), M(n);
      energyGradient(chain, q, g);
      jointStiffness(chain, q, kq);
      jointStiffnessDerivative(chain, q, dkq);
      totalPotentialGradient(chain, q, F, gradPi);
      jointTorques(chain, q, M);
      CHECK((M + g).lpNorm<Eigen::Infinity>() < 1e-14 * std::max(1.0, g.lpNorm<Eigen::Infinity>()));
      const double scale = chain.length();
      double errJ = 0, errKg = 0, errG = 0, errKq = 0, errH = 0, errGradPi = 0, errDkq = 0;
      for (int j = 0; j < n; ++j) {
        Vector qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        const Pose dp = (endPose(chain, qp) - endPose(chain, qm)) / (2 * h);
        errJ = std::max(errJ, (J.col(j) - dp).lpNorm<Eigen::Infinity>());
        const Vector dJtF = (jtF(chain, qp, F) - jtF(chain, qm, F)) / (2 * h);
        errKg = std::max(errKg, (Kg.col(j) - dJtF).lpNorm<Eigen::Infinity>());
        errG = std::max(errG, std::abs(g[j] - (energy(chain, qp) - energy(chain, qm)) / (2 * h)));
        Vector gp(n), gm(n), kp(n), km(n), Gp(n), Gm(n);
        energyGradient(chain, qp, gp);
        energyGradient(chain, qm, gm);
        // ∂²E/∂q²: diagonal K_q, no coupling between joints
        Vector col = (gp - gm) / (2 * h);
        errKq = std::max(errKq, std::abs(col[j] - kq[j]));
        col[j] = 0;
        errKq = std::max(errKq, col.lpNorm<Eigen::Infinity>());
        jointStiffness(chain, qp, kp);
        jointStiffness(chain, qm, km);
        errDkq = std::max(errDkq, std::abs((kp[j] - km[j]) / (2 * h) - dkq[j]));
        totalPotentialGradient(chain, qp, F, Gp);
        totalPotentialGradient(chain, qm, F, Gm);
        errH = std::max(errH, (H.col(j) - (Gp - Gm) / (2 * h)).lpNorm<Eigen::Infinity>());
        errGradPi = std::max(errGradPi, std::abs(gradPi[j] - (totalPotential(chain, qp, F) - totalPotential(chain, qm, F)) / (2 * h)));
      }
      const double tol = 1e-7 * std::max(1.0, scale);  // FD truncation ~h², round-off ~eps·|f|/h
      CHECK(errJ < tol);
      CHECK(errKg < tol);
      CHECK(errG < tol);
      CHECK(errKq < tol);
      CHECK(errDkq < tol);
      CHECK(errH < tol);
      CHECK(errGradPi < tol);
      // the Hessian of Π is K_q − K_g
      Matrix expected = -Kg;
      expected.diagonal() += kq;
      CHECK((H - expected).lpNorm<Eigen::Infinity>() < 1e-12 * std::max(1.0, H.lpNorm<Eigen::Infinity>()));
      CHECK((H - H.transpose()).lpNorm<Eigen::Infinity>() == 0.0);
    }
  }
}

TEST_CASE("K_g(i, j) depends on max(i, j) only and Me does not enter", "[chain]") {
  std::mt19937 rng(23);
  const Chain chain = randomChain(rng, 9);
  const Vector q = randomAngles(rng, chain);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix Kg(9, 9), Kg2(9, 9);
  loadMatrix(data, Wrench(1.3, -0.7, 0.0), Kg);
  loadMatrix(data, Wrench(1.3, -0.7, 5.0), Kg2);
  CHECK((Kg - Kg2).lpNorm<Eigen::Infinity>() == 0.0);
  Vector h(9);
  loadHessianGenerator(data, Wrench(1.3, -0.7, 0.0), h);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) CHECK(Kg(i, j) == h[std::max(i, j)]);
  // different max index → different entries (the pattern is not trivially constant)
  CHECK(Kg(0, 3) != Kg(0, 4));
}

TEST_CASE("eq 12: closed-form J^-T of three identical segments equals the numerical inverse", "[chain]") {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> Q(-1.1, 1.1), B(0.5, 2.0);
  int checked = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const double b = B(rng);
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.3 * b, b, 1.0, 2.2 * b));
    const Vector q = Vector::NullaryExpr(3, [&](Eigen::Index) { return Q(rng); });
    if (std::abs(std::sin(q[1])) < 0.05) continue;  // J3 singular at sin q2 = 0 (docs/mechanics.md erratum 7)
    ChainData data(chain);
    forwardKinematics(chain, q, data);
    Matrix J(3, 3);
    endJacobian(data, J);
    const double S1 = std::sin(q[0]), C1 = std::cos(q[0]), S2 = std::sin(q[1]), S3 = std::sin(q[2]);
    const double S12 = std::sin(q[0] + q[1]), C12 = std::cos(q[0] + q[1]), S23 = std::sin(q[1] + q[2]);
    Eigen::Matrix3d closed;
    closed << C12, -C1 - C12, C1,  //
        S12, -S1 - S12, S1,        //
        b * S3, -b * S23 - b * S3, 2 * b * S2 + b * S23;
    closed /= 2 * b * S2;
    const Eigen::Matrix3d numeric = Eigen::Matrix3d(J).transpose().inverse();
    CHECK((closed - numeric).lpNorm<Eigen::Infinity>() < 1e-10 * numeric.lpNorm<Eigen::Infinity>());
    // F = −J⁻ᵀ M (eq 12) satisfies M + Jᵀ F = 0 (eq 9)
    Vector M(3);
    jointTorques(chain, q, M);
    const Eigen::Vector3d F = -closed * Eigen::Vector3d(M);
    CHECK((M + J.transpose() * F).lpNorm<Eigen::Infinity>() < 1e-11 * std::max(1.0, M.lpNorm<Eigen::Infinity>()));
    ++checked;
  }
  CHECK(checked > 30);
}

TEST_CASE("bad chain parameters are rejected naming the parameter and the segment", "[chain]") {
  CHECK_THAT(rejection([] { Chain c(std::vector<SegmentParameters>{}); }), Catch::Contains("n (segment count)"));
  CHECK_THAT(rejection([] { Chain::uniform(0, SegmentParameters{}); }), Catch::Contains("n (segment count)"));
  CHECK_THAT(rejection([] { Chain::uniform(-3, SegmentParameters{}); }), Catch::Contains("-3"));
  std::vector<SegmentParameters> s(4);
  s[1].b1 = 0.0;
  CHECK_THAT(rejection([&] { Chain c(s); }), Catch::Contains("segment 2") && Catch::Contains("b1"));
  s[1] = {};
  s[3].k2 = -1.0;
  CHECK_THAT(rejection([&] { Chain c(s); }), Catch::Contains("segment 4") && Catch::Contains("k2"));
  s[3] = {};
  s[0].L1_0 = std::nan("");
  CHECK_THAT(rejection([&] { Chain c(s); }), Catch::Contains("segment 1") && Catch::Contains("L1_0"));
  s[0] = {};
  CHECK(rejection([&] { Chain c(s); }) == "accepted");
}

TEST_CASE("joint positions: links of the chain's lengths, ending at the end pose", "[chain]") {
  std::mt19937 rng(11);
  for (int n : {1, 3, 40}) {
    const Chain chain = randomChain(rng, n);
    const Vector q = randomAngles(rng, chain);
    const Eigen::Matrix2Xd P = jointPositions(chain, q);
    REQUIRE(P.cols() == n + 2);
    CHECK(P.col(0).norm() == 0.0);
    CHECK(P(1, 1) == 0.0);  // the first link lies along the clamp's x-axis
    const double L = chain.length();
    for (int i = 0; i <= n; ++i)
      CHECK((P.col(i + 1) - P.col(i)).norm() == Approx(chain.linkLengths()[i]).margin(1e-14 * L));
    const Pose end = endPose(chain, q);
    CHECK(P(0, n + 1) == Approx(end[0]).margin(1e-13 * L));
    CHECK(P(1, n + 1) == Approx(end[1]).margin(1e-13 * L));
    CHECK_THROWS_AS(jointPositions(chain, Vector::Zero(n + 1)), std::invalid_argument);
  }
}

TEST_CASE("endMovesAlong: the straight chain cannot move its end along x, in any units", "[chain]") {
  for (double unit : {1e-3, 1.0, 1e3}) {
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5 * unit, unit, 1.0, 2.25 * unit));
    const Vector straight = Vector::Zero(3);
    CHECK_FALSE(endMovesAlong(chain, straight, 0));
    CHECK(endMovesAlong(chain, straight, 1));
    CHECK(endMovesAlong(chain, straight, 2));
    const Vector bent = Vector::Constant(3, 1e-3);  // a small bend moves x to first order
    CHECK(endMovesAlong(chain, bent, 0));
  }
}

TEST_CASE("forward kinematics from the springs' half angles agrees with one sincos per link", "[chain]") {
  // The overload rotates each link direction by its joint angle from sin(q/2), cos(q/2) (the
  // springs' own sincos) and takes sincos(θ) itself every 16th link: a few ulp per rotation
  // between re-anchors, scaled by the sums they enter. θ is the same prefix sum, bit for bit.
  std::mt19937 rng(11);
  const double eps = std::numeric_limits<double>::epsilon();
  for (const int n : {1, 3, 17, 50, 1000}) {
    for (const double L : {1.0, 1e-3, 1e3}) {
      std::vector<SegmentParameters> s;
      for (int i = 0; i < n; ++i) {
        SegmentParameters p = testing::randomSegment(rng);
        p.a1 *= L, p.a2 *= L, p.b1 *= L, p.b2 *= L, p.L1_0 *= L, p.L2_0 *= L;
        s.push_back(p);
      }
      const Chain chain(s);
      for (const double fraction : {0.0, 0.01, 0.9}) {  // straight, nearly straight, coiled
        const Vector q = fraction == 0.0 ? Vector(Vector::Zero(n)) : randomAngles(rng, chain, fraction);
        Vector sh(n), ch(n);
        for (int i = 0; i < n; ++i) {
          sh[i] = std::sin(0.5 * q[i]);
          ch[i] = std::cos(0.5 * q[i]);
        }
        ChainData plain(chain), half(chain);
        forwardKinematics(chain, q, plain);
        forwardKinematics(chain, q, sh.data(), ch.data(), half);
        CHECK(half.theta == plain.theta);
        const double tol = 64.0 * eps * chain.length();  // ≤ 16 rotations of a few ulp, summed over ℓ
        CHECK((half.S - plain.S).cwiseAbs().maxCoeff() <= tol);
        CHECK((half.C - plain.C).cwiseAbs().maxCoeff() <= tol);
        CHECK((half.pose - plain.pose).head<2>().cwiseAbs().maxCoeff() <= tol);
        CHECK(half.pose[2] == plain.pose[2]);
        if (fraction == 0.0) {  // q = 0: every rotation is by (1, 0), exactly the sincos route
          CHECK(half.S == plain.S);
          CHECK(half.C == plain.C);
        }
      }
    }
  }
}
