// The links' weight as a potential (gravity.h): its value against the inertial model's centres of
// mass, gradient and Hessian against central differences, the K_g pattern against the end-load
// formulas of a chain whose mass sits at its end, and the sag of a horizontal cantilever against
// the small-deflection closed form.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/gravity.h"
#include "heavy_newton.h"
#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::stiffChain;
using testing::unevenInertia;

}  // namespace

TEST_CASE("gravity: V = -sum m g.r with the inertial model's centres of mass, gradient and Hessian by differences",
          "[gravity]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int n : {1, 4, 12}) {
    const Chain chain = stiffChain(n);
    const InertiaData inertia = unevenInertia(chain);
    const Eigen::Vector2d g(0.7, -9.81);
    GravityPotential V(chain, inertia, g);
    InertialModel model(chain, EndCondition::freeEnd(), inertia, {}, 1.0, Vector::Zero(n));
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = U(rng);
    Eigen::Matrix2Xd r(2, n);
    model.centresOfMass(q, r);
    double expected = 0.0;
    for (int i = 0; i < n; ++i) expected -= inertia.links[size_t(i)].mass * g.dot(r.col(i));
    CHECK(std::abs(V.value(q) - expected) <= 1e-13 * std::abs(expected));

    Vector grad(n), gp(n), gm(n);
    V.gradient(q, grad);
    Matrix G(n, n);
    V.hessian(q, G);
    const double h = 1e-6, scale = g.norm() * inertia.links[0].mass * chain.linkLengths().sum();
    for (int j = 0; j < n; ++j) {
      Vector e = Vector::Zero(n);
      e[j] = h;
      CHECK(std::abs((V.value(q + e) - V.value(q - e)) / (2 * h) - grad[j]) <= 1e-8 * scale);
      V.gradient(q + e, gp);
      V.gradient(q - e, gm);
      CHECK(((gp - gm) / (2 * h) - G.col(j)).cwiseAbs().maxCoeff() <= 1e-8 * scale);
    }
  }
}

TEST_CASE("gravity: all the mass at the end is an end force m g (gradient -J^T F, Hessian -K_g(F))", "[gravity]") {
  const int n = 5;
  const Chain chain = stiffChain(n);
  InertiaData inertia;
  const double M = 2.5, tiny = 1e-13 * M;  // the other links nearly massless (masses must be > 0)
  for (int i = 0; i < n; ++i) inertia.links.push_back({tiny, 0.0, std::numeric_limits<double>::quiet_NaN()});
  inertia.links.back() = {M, 0.0, chain.linkLengths()[n]};  // centre of mass at the end
  const Eigen::Vector2d g(1.5, -9.81);
  GravityPotential V(chain, inertia, g);
  const Vector q = Vector::LinSpaced(n, 0.4, -0.9);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n), Kg(n, n), G(n, n);
  endJacobian(data, J);
  const Wrench F(M * g.x(), M * g.y(), 0.0);
  loadMatrix(data, F, Kg);
  Vector grad(n);
  V.gradient(q, grad);
  V.hessian(q, G);
  const double scale = M * g.norm() * chain.linkLengths().sum();
  CHECK((grad + J.transpose() * F).cwiseAbs().maxCoeff() <= 1e-11 * scale);
  CHECK((G + Kg).cwiseAbs().maxCoeff() <= 1e-11 * scale);
  CHECK(std::abs(V.value(q) + F.head(2).dot(data.pose.head(2))) <= 1e-11 * scale);
}

TEST_CASE("gravity: a horizontal cantilever sags as the small-deflection closed form, the relative error O(g^2)", "[gravity]") {
  const int n = 8;
  const Chain chain = stiffChain(n);
  const InertiaData inertia = InertiaData::uniformRods(chain, 1.0);
  Vector kappa(n);
  jointStiffness(chain, Vector::Zero(n), kappa);  // q = 0 is the unloaded equilibrium
  const Eigen::Matrix2Xd P = jointPositions(chain, Vector::Zero(n));
  const double xEnd = P(0, n + 1);
  const auto sag = [&](double g) {
    GravityPotential V(chain, inertia, Eigen::Vector2d(0.0, -g));
    // independent minimisation of E + V: Newton with the dense Hessian from the unloaded shape
    const Vector q = testing::heavyNewton(chain, inertia, Eigen::Vector2d(0.0, -g), Vector::Zero(n), 40);
    Vector grad(n), gv(n);
    energyGradient(chain, q, grad);
    V.gradient(q, gv);
    REQUIRE((grad + gv).norm() <= 1e-12 * kappa.maxCoeff());
    const double tip = endPose(chain, q)[1];
    // closed form, first order in g: joint j carries the moment of the weight beyond it,
    // q_j = −(g/κ_j) Σ_{i≥j} m_i (x_i − x_j), and the tip drops by Σ_j q_j (x_end − x_j)
    const Eigen::Matrix2Xd r = V.centresOfMass(Vector::Zero(n));
    double linear = 0.0;
    for (int j = 0; j < n; ++j) {
      double moment = 0.0;
      for (int i = j; i < n; ++i) moment += inertia.links[size_t(i)].mass * (r(0, i) - P(0, j + 1));
      linear += -(g / kappa[j]) * moment * (xEnd - P(0, j + 1));
    }
    return std::abs(tip / linear - 1.0);
  };
  // the sag is odd in g (the springs are even in q): the next term is O(g³), the relative error O(g²)
  const double e1 = sag(1e-4), e2 = sag(5e-5);
  CHECK(e1 <= 1e-3);
  CHECK(e1 / e2 == Approx(4.0).epsilon(0.02));
}
