#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <random>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/energy_landscape.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/gravity.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/unloaded_shape.h"

using namespace buckle::mechanics;

namespace {

const std::vector<LandscapeSample>& branchSamples(const EnergyLandscape& L, int branch) {
  return branch > 0 ? L.positive : L.negative;
}

// Hessian of Π projected on ker J_p (1-D for three joints), independent of the landscape code.
double projectedHessian(const Chain& chain, const Eigen::Vector3d& q, const Wrench& F) {
  Matrix H(3, 3);
  totalPotentialHessian(chain, q, F, H);
  ChainData d(chain);
  forwardKinematics(chain, q, d);
  Matrix J(3, 3);
  endJacobian(d, J);
  const Eigen::HouseholderQR<Matrix> qr(J.topRows(2).transpose());
  const Vector t = (qr.householderQ() * Matrix::Identity(3, 3)).col(2);
  return t.dot(H * t);
}

void checkLandscapeConsistency(const Chain& chain, const EnergyLandscape& L) {
  int withIk = 0;
  for (int branch : {+1, -1})
    for (const LandscapeSample& s : branchSamples(L, branch)) {
      if (s.status == LandscapeStatus::NoInverseKinematics) {
        CHECK(std::isnan(s.energy));
        continue;
      }
      ++withIk;
      const Pose p = endPose(chain, s.q);
      CHECK(std::abs(p[0] - L.x) < 1e-12 * chain.length());
      CHECK(std::abs(p[1] - L.y) < 1e-12 * chain.length());
      CHECK(s.q[0] == s.q1);
      CHECK(branch * s.q[2] >= 0.0);
      CHECK(s.energy == Approx(energy(chain, s.q)).epsilon(1e-14));
      bool inside = true;
      int first = -1;
      for (int i = 0; i < 3; ++i)
        if (s.q[i] < chain.lowerLimits()[i] || s.q[i] > chain.upperLimits()[i]) {
          inside = false;
          if (first < 0) first = i + 1;
        }
      CHECK((s.status == LandscapeStatus::Feasible) == inside);
      if (!inside) CHECK(s.violatedJoint == first);
    }
  CHECK(withIk > 0);
}

}  // namespace

TEST_CASE("landscape: IK branches keep the end at (x, y), derivatives along the branch", "[landscape]") {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> A(0.2, 0.9), B(0.7, 1.3), K(0.5, 3.0), L(2.2, 3.0);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < 3; ++i) {
      SegmentParameters p;
      p.a1 = A(rng); p.a2 = A(rng); p.b1 = B(rng); p.b2 = B(rng); p.k1 = K(rng); p.k2 = K(rng);
      p.L1_0 = L(rng); p.L2_0 = L(rng);
      segs.push_back(p);
    }
    const Chain chain(segs);
    const double x = 0.85 * chain.length(), y = 0.1 * chain.length();
    LandscapeOptions opt;
    opt.samples = 201;
    const EnergyLandscape land = energyLandscape(chain, x, y, opt);
    checkLandscapeConsistency(chain, land);
    // dE/dq1, d²E/dq1² vs finite differences on the branch; dE/dq1 = (1 + t2 + t3)·Me
    const double h = 1e-6;
    int checked = 0;
    for (int branch : {+1, -1})
      for (const LandscapeSample& s : branchSamples(land, branch)) {
        if (s.status != LandscapeStatus::Feasible || std::abs(std::sin(s.q[1])) < 0.05 || std::abs(s.q[2]) < 0.05) continue;
        const LandscapeSample p = landscapeSample(chain, x, y, s.q1 + h, branch);
        const LandscapeSample m = landscapeSample(chain, x, y, s.q1 - h, branch);
        CHECK(std::abs(s.dEdq1 - (p.energy - m.energy) / (2 * h)) < 1e-6 * std::max(1.0, std::abs(s.dEdq1)));
        CHECK(std::abs(s.d2Edq1 - (p.dEdq1 - m.dEdq1) / (2 * h)) < 1e-5 * std::max(1.0, std::abs(s.d2Edq1)));
        const double tphi = 1.0 + (p.q[1] - m.q[1]) / (2 * h) + (p.q[2] - m.q[2]) / (2 * h);
        CHECK(std::abs(s.dEdq1 - tphi * s.endTorque) < 1e-6 * std::max(1.0, std::abs(s.dEdq1)));
        ++checked;
      }
    CHECK(checked > 20);
    // every located stationary point is an equilibrium of the held-position problem
    for (const LandscapeEquilibrium& e : land.equilibria) {
      CHECK(e.residual < 1e-10);
      EquilibriumProblem problem(chain, EndCondition::heldPosition(x, y), Eigen::Vector3d::Zero());
      Vector u(5), F(5);
      u << e.q, e.F[0], e.F[1];
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, 0.0, F));
      CHECK(F.lpNorm<Eigen::Infinity>() < 1e-10);
      const double Hp = projectedHessian(chain, e.q, e.F);
      CHECK((Hp > 0) == e.stable);
    }
  }
  CHECK_THROWS_WITH(energyLandscape(Chain::uniform(4, SegmentParameters{}), 7.0, 0.0), Catch::Contains("3 segments"));
  CHECK_THROWS_WITH(energyLandscape(Chain::uniform(3, SegmentParameters{}), std::nan(""), 0.0), Catch::Contains("x"));
}

TEST_CASE("straight start pushed by dx > 0: U minima, Z maxima, eq 12 force, buckling limits", "[landscape]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0));
  const AnalyticBuckling3 an = analyticClampedPinned3(a, b, k, L0);
  double prevFxU = 0.0, prevErrU = 1e300;
  for (double delta : {0.02, 0.005, 0.001}) {
    INFO("delta = " << delta);
    LandscapeOptions opt;
    opt.samples = 2001;
    const EnergyLandscape land = energyLandscape(chain, 6 * b - delta, 0.0, opt);
    checkLandscapeConsistency(chain, land);
    int U = 0, Z = 0;
    double EU = 0, EZ = 0, FxU = 0;
    for (const LandscapeEquilibrium& e : land.equilibria) {
      // eq 12 closed form at the stationary point: Me = 0 and ∂E/∂q = J_pᵀ (Fx, Fy)
      const double S1 = std::sin(e.q[0]), C1 = std::cos(e.q[0]), S2 = std::sin(e.q[1]), S3 = std::sin(e.q[2]);
      const double S12 = std::sin(e.q[0] + e.q[1]), C12 = std::cos(e.q[0] + e.q[1]), S23 = std::sin(e.q[1] + e.q[2]);
      Eigen::Matrix3d JmT;
      JmT << C12, -C1 - C12, C1, S12, -S1 - S12, S1, b * S3, -b * S23 - b * S3, 2 * b * S2 + b * S23;
      JmT /= 2 * b * S2;
      Vector M(3);
      jointTorques(chain, e.q, M);
      const Eigen::Vector3d F = -JmT * Eigen::Vector3d(M);
      CHECK(std::abs(F[2]) < 1e-9 * F.head(2).norm());
      Vector res(3);
      totalPotentialGradient(chain, e.q, Wrench(F[0], F[1], 0.0), res);
      CHECK(res.lpNorm<Eigen::Infinity>() < 1e-10 * M.lpNorm<Eigen::Infinity>());
      CHECK(F[0] == Approx(e.F[0]).epsilon(1e-8));
      if (e.shape == "U") {
        ++U;
        CHECK(e.stable);
        EU = e.energy;
        FxU = e.F[0];
        // δx = μ_U b q2² to leading order (eq 18, docs/mechanics.md erratum 3)
        CHECK(std::abs(an.muU * b * e.q[1] * e.q[1] / delta - 1.0) < 2.0 * delta);
      } else if (e.shape == "Z") {
        ++Z;
        CHECK_FALSE(e.stable);
        EZ = e.energy;
        CHECK(e.F[0] == Approx(an.FxZ).epsilon(2.0 * delta));
        CHECK(std::abs(an.muZ * b * e.q[1] * e.q[1] / delta - 1.0) < 2.0 * delta);
      } else {
        FAIL("unexpected equilibrium shape " << e.shape << " at q = " << e.q.transpose());
      }
    }
    CHECK(U == 2);  // mirror images
    CHECK(Z == 2);
    CHECK(EU < EZ);
    // Fx on the U branch tends to the first critical load, and rises in magnitude (supercritical)
    const double errU = std::abs(FxU / an.FxU - 1.0);
    CHECK(errU < 2.0 * delta);
    CHECK(errU < prevErrU);
    CHECK(std::abs(FxU) > std::abs(an.FxU));
    if (prevFxU != 0.0) CHECK(std::abs(FxU) < std::abs(prevFxU));
    prevFxU = FxU;
    prevErrU = errU;
  }
  // the straight chain with its end held at (6b, 0): stable below the first critical reaction, unstable beyond
  EquilibriumProblem held(chain, EndCondition::heldPosition(6 * b, 0.0), Eigen::Vector3d::Zero());
  for (double factor : {0.99, 1.01}) {
    Vector u(5);
    u << 0, 0, 0, factor * an.FxU, 0;
    buckle::continuation::StabilityInfo info;
    REQUIRE(buckle::continuation::BoundProblem(held).stability(u, 0.0, 3, info));
    CHECK(info.stable() == (factor < 1.0));
  }
  // pulled (x > 6b): out of reach, no equilibria
  const EnergyLandscape pulled = energyLandscape(chain, 6 * b + 0.01, 0.0);
  CHECK(pulled.equilibria.empty());
  for (const LandscapeSample& s : pulled.positive) CHECK(s.status == LandscapeStatus::NoInverseKinematics);
}

TEST_CASE("non-straight start (5.5b, 0): the unloaded shape is a stable stationary point, joint limits marked",
          "[landscape]") {
  const double theta = std::acos(7.0 / 8.0);
  const Eigen::Vector3d q0(theta, -2 * theta, theta);
  const Chain chain(preloadsForShape(std::vector<SegmentParameters>(3, SegmentParameters::symmetric(0.75, 1.0, 1.0, 2.25)), q0));
  const EnergyLandscape land = energyLandscape(chain, 5.5, 0.0);
  checkLandscapeConsistency(chain, land);
  int found = 0;
  for (const LandscapeEquilibrium& e : land.equilibria)
    if ((e.q - q0).norm() < 1e-9) {
      ++found;
      CHECK(e.stable);
      CHECK(e.F.norm() < 1e-9);
      CHECK(e.energy == Approx(energy(chain, q0)).epsilon(1e-12));
    }
  CHECK(found == 1);
  // tight user limits: samples beyond them are marked with the first violated joint
  std::vector<SegmentParameters> segs(3, SegmentParameters::symmetric(0.75, 1.0, 1.0, 2.25));
  segs[0].qMinUser = -0.45;
  segs[0].qMaxUser = 0.2;
  segs[1].qMinUser = -0.9;
  segs[1].qMaxUser = 0.9;
  segs[2].qMinUser = -1.0;
  segs[2].qMaxUser = 1.0;
  const Chain limited(segs);
  LandscapeOptions opt;
  opt.q1Min = -1.0;
  opt.q1Max = 1.0;
  const EnergyLandscape lim = energyLandscape(limited, 5.5, 0.0, opt);
  checkLandscapeConsistency(limited, lim);
  int marked[4] = {0, 0, 0, 0};
  for (int branch : {+1, -1})
    for (const LandscapeSample& s : branchSamples(lim, branch))
      if (s.status == LandscapeStatus::JointLimit) ++marked[s.violatedJoint];
  CHECK(marked[1] > 0);  // q1 in (0.2, 0.5): reachable but beyond joint 1
  CHECK(marked[2] > 0);  // negative branch near q1 = −0.4: q2 ≈ 0.96
  CHECK(marked[3] > 0);  // positive branch near q1 = 0: q3 ≈ 1.25
  for (const LandscapeEquilibrium& e : lim.equilibria)
    for (int i = 0; i < 3; ++i) {
      CHECK(e.q[i] >= limited.lowerLimits()[i]);
      CHECK(e.q[i] <= limited.upperLimits()[i]);
    }
}

TEST_CASE("landscape with the links' weight: E + V, its derivatives along the branch, equilibria of the weighted "
          "chain by an independent potential",
          "[landscape][body_loads]") {
  // the paper's chain as uniform rods under g at 30° below the horizontal, heavy enough to tilt it
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const InertiaData rods = InertiaData::uniformRods(chain, 0.05);
  const Eigen::Vector2d g(0.5, -0.866);
  const double x = 5.5, y = 0.4;
  LandscapeOptions opt;
  opt.samples = 401;
  opt.body = BodyLoads::weight(chain, rods, g, Eigen::Vector2d::Zero());
  const EnergyLandscape heavy = energyLandscape(chain, x, y, opt);
  const GravityPotential V(chain, rods, g);  // gravity.h: an independent formulation of V
  BodyLoadTerms terms(chain, opt.body);
  const double h = 1e-6;
  int checked = 0;
  for (int branch : {+1, -1})
    for (const LandscapeSample& s : branchSamples(heavy, branch)) {
      if (s.status != LandscapeStatus::Feasible || std::abs(std::sin(s.q[1])) < 0.05 || std::abs(s.q[2]) < 0.05) continue;
      CHECK(s.energy == Approx(energy(chain, s.q) + V.value(s.q)).epsilon(1e-12).margin(1e-13));
      const LandscapeSample p = landscapeSample(chain, x, y, s.q1 + h, branch, &terms);
      const LandscapeSample m = landscapeSample(chain, x, y, s.q1 - h, branch, &terms);
      CHECK(std::abs(s.dEdq1 - (p.energy - m.energy) / (2 * h)) < 1e-6 * std::max(1.0, std::abs(s.dEdq1)));
      CHECK(std::abs(s.d2Edq1 - (p.dEdq1 - m.dEdq1) / (2 * h)) < 1e-5 * std::max(1.0, std::abs(s.d2Edq1)));
      ++checked;
    }
  CHECK(checked > 40);
  // each stationary point balances the springs, the weight and the end reaction: ∇E + ∇V = Jᵀ F with
  // Me = 0, and its stability is that of (K_q − K_g(F) + ∇²V) on ker J_p
  LandscapeOptions weightless;
  weightless.samples = 401;
  const EnergyLandscape light = energyLandscape(chain, x, y, weightless);
  REQUIRE(!heavy.equilibria.empty());
  double moved = 0.0;
  for (const LandscapeEquilibrium& e : heavy.equilibria) {
    Vector grad(3), gradV(3), q = e.q;
    energyGradient(chain, q, grad);
    V.gradient(q, gradV);
    ChainData data(chain);
    forwardKinematics(chain, q, data);
    Matrix J(3, 3);
    endJacobian(data, J);
    CHECK((grad + gradV - J.transpose() * e.F).lpNorm<Eigen::Infinity>() < 1e-10);
    CHECK(e.F[2] == 0.0);
    Matrix H(3, 3), G(3, 3);
    totalPotentialHessian(chain, q, e.F, H);
    V.hessian(q, G);
    const Eigen::HouseholderQR<Matrix> qr(J.topRows(2).transpose());
    const Vector t = (qr.householderQ() * Matrix::Identity(3, 3)).col(2);  // ker J_p
    CHECK(((t.transpose() * (H + G) * t)(0, 0) > 0.0) == e.stable);
    double nearest = INFINITY;
    for (const LandscapeEquilibrium& f : light.equilibria) nearest = std::min(nearest, (f.q - e.q).cwiseAbs().maxCoeff());
    moved = std::max(moved, nearest);
  }
  CHECK(moved > 1e-3);  // the weight moved the equilibria: it is in the sums, not beside them
}
