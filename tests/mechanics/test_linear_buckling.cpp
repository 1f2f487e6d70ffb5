#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/unloaded_shape.h"

#include "random_segments.h"
#include "sanitized_build.h"

using namespace buckle::mechanics;

namespace {

double relErr(double a, double b) { return std::abs(a - b) / std::max(1e-300, std::abs(b)); }

// Projected Hessian of Π at the straight / unloaded q0 under F = λ d, on ker of the held rows.
buckle::continuation::StabilityInfo inertiaAt(const Chain& chain, const Vector& q0, const EndCondition& end,
                                              const Eigen::Vector3d& d, double lambda) {
  const int n = chain.size();
  Matrix H(n, n);
  totalPotentialHessian(chain, q0, Wrench(lambda * d[0], lambda * d[1], 0.0), H);
  ChainData data(chain);
  forwardKinematics(chain, q0, data);
  Matrix J(3, n);
  endJacobian(data, J);
  const std::vector<int> held = end.heldIndices();
  Matrix C(int(held.size()), n);
  for (size_t k = 0; k < held.size(); ++k) C.row(int(k)) = J.row(held[k]);
  return buckle::continuation::projectedInertia(H, C);
}

// Full spectrum of H on ker C (independent of the library: null space from a full QR of Cᵀ).
Vector projectedSpectrum(const Matrix& H, const Matrix& C) {
  const Eigen::Index n = H.cols();
  Matrix Z = Matrix::Identity(n, n);
  if (C.rows() > 0) {
    const Eigen::HouseholderQR<Matrix> qr(C.transpose());
    Z = (qr.householderQ() * Matrix::Identity(n, n)).rightCols(n - C.rows());
  }
  return Eigen::SelfAdjointEigenSolver<Matrix>(Z.transpose() * H * Z, Eigen::EigenvaluesOnly).eigenvalues();
}

constexpr double kBetaClampedPinned = 4.493409457909064;  // tan β = β: P = β² EI / L²

}  // namespace

TEST_CASE("n = 3 clamped-pinned: critical loads, mode ratios and mu match eq 15, 17, 18", "[buckling]") {
  int checked = 0;
  for (double b : {1.0, 2.5})
    for (double k : {1.0, 3.0})
      for (double aOverB : {0.2, 0.5, 0.75, 0.9, 1.1})
        for (double L0OverB : {1.2, 1.8, 2.25, 3.0}) {
          const double a = aOverB * b, L0 = L0OverB * b;
          const AnalyticBuckling3 an = analyticClampedPinned3(a, b, k, L0);
          if (std::abs(an.kappa) < 1e-6 * k * b * b) continue;
          INFO("a/b = " << aOverB << ", L0/b = " << L0OverB << ", b = " << b << ", k = " << k);
          const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0));
          const LinearBucklingResult r = linearBuckling(chain, Vector::Zero(3), EndCondition::clampedPinned(0.0));
          REQUIRE(r.modes.size() == 2);
          CHECK(r.constrainedDimension == 2);
          CHECK(r.unloadedStable == (an.kappa > 0));
          CHECK(chain.segment(0).straightStiffness() == Approx(an.kappa).epsilon(1e-13));
          const BucklingMode &U = r.modes[0], &Z = r.modes[1];
          CHECK(U.shape == "U");
          CHECK(Z.shape == "Z");
          CHECK(relErr(U.lambda, an.FxU) < 1e-12);
          CHECK(relErr(Z.lambda, an.FxZ) < 1e-12);
          CHECK(std::abs(U.alpha1 - an.alpha1U) < 1e-12);
          CHECK(std::abs(U.alpha3 - an.alpha3U) < 1e-12);
          CHECK(std::abs(Z.alpha1 - an.alpha1Z) < 1e-12);
          CHECK(std::abs(Z.alpha3 - an.alpha3Z) < 1e-12);
          CHECK(std::abs(U.mu - an.muU) < 1e-12);
          CHECK(std::abs(Z.mu - an.muZ) < 1e-12);
          // compression (Fx < 0) exactly when the straight chain is stable (eq 17 remark)
          CHECK((U.lambda < 0) == (an.kappa > 0));
          CHECK(U.mode.norm() == Approx(1.0).epsilon(1e-14));
          // the shortening is the real second-order kinematics: (x0 − x(εz)) / ε²
          for (const BucklingMode* m : {&U, &Z}) {
            const double eps = 1e-4;
            const Pose p = endPose(chain, eps * m->mode);
            CHECK(std::abs((6 * b - p[0]) / (eps * eps) - m->shortening) < 1e-6 * b);
            CHECK(std::abs(p[1]) < 1e-10 * b);  // y held to first order
          }
          ++checked;
        }
  CHECK(checked >= 70);
}

TEST_CASE("kappa = 0: every critical load is 0, G = 0 directions are dropped", "[buckling]") {
  // b L0 = 2 (b² − a²) with a = 0.5, b = 1, L0 = 1.5
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5));
  CHECK(std::abs(chain.segment(0).straightStiffness()) < 1e-14);
  const LinearBucklingResult r = linearBuckling(chain, Vector::Zero(3), EndCondition::clampedPinned(0.0));
  CHECK(r.degenerate);
  CHECK_FALSE(r.unloadedStable);
  REQUIRE(r.modes.size() == 2);
  for (const auto& m : r.modes) CHECK(m.lambda == 0.0);

  const Chain stiff = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  LinearBucklingOptions lateral;
  lateral.direction = Eigen::Vector3d(0.0, 1.0, 0.0);  // ∂²y = −S_max = 0 at the straight chain
  const LinearBucklingResult rl = linearBuckling(stiff, Vector::Zero(5), EndCondition::freeEnd(), lateral);
  CHECK(rl.modes.empty());
  CHECK(rl.droppedInfinite == 5);
  LinearBucklingOptions torque;
  torque.direction = Eigen::Vector3d(0.0, 0.0, 1.0);
  CHECK(linearBuckling(stiff, Vector::Zero(5), EndCondition::freeEnd(), torque).modes.empty());
  // An axial load on the free end: n finite modes, all compressive for a stable chain.
  const LinearBucklingResult rf = linearBuckling(stiff, Vector::Zero(5), EndCondition::freeEnd());
  CHECK(rf.modes.size() == 5);
  CHECK(rf.droppedInfinite == 0);
  for (const auto& m : rf.modes) CHECK(m.lambda < 0.0);
  // count limits the output
  LinearBucklingOptions two;
  two.count = 2;
  CHECK(linearBuckling(stiff, Vector::Zero(5), EndCondition::freeEnd(), two).modes.size() == 2);
}

TEST_CASE("a non-equilibrium q0 or a wrong size is rejected", "[buckling]") {
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  CHECK_THROWS_WITH(linearBuckling(chain, Vector::Constant(3, 0.2), EndCondition::clampedPinned(0.0)),
                    Catch::Contains("not an unloaded equilibrium"));
  CHECK_THROWS_WITH(linearBuckling(chain, Vector::Zero(4), EndCondition::clampedPinned(0.0)), Catch::Contains("q0"));
  CHECK_THROWS_WITH(analyticClampedPinned3(0.5, -1.0, 1.0, 2.25), Catch::Contains("b"));
}

TEST_CASE("critical loads make K_q - K_g singular on the null space of the held rows", "[buckling]") {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> A(0.1, 0.7), B(0.7, 1.3), K(0.5, 2.0), L(2.2, 2.9), dL(-0.3, 0.3);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < 7; ++i) {
      SegmentParameters p;
      p.a1 = A(rng); p.a2 = A(rng); p.b1 = B(rng); p.b2 = B(rng); p.k1 = K(rng); p.k2 = K(rng);
      const double base = L(rng) * 0.5 * (p.b1 + p.b2);
      p.L1_0 = base + dL(rng);
      p.L2_0 = base + dL(rng);
      segs.push_back(p);
    }
    const Chain chain(segs);
    const UnloadedShape shape = unloadedShape(chain);
    REQUIRE(shape.allFound);
    REQUIRE(shape.allStable);
    for (const EndCondition& end : {EndCondition::clampedPinned(0.0), EndCondition::freeEnd(),
                                    EndCondition::heldPosition(0.0, 0.0)}) {
      const Eigen::Vector3d d(1.0, 0.0, 0.0);
      const LinearBucklingResult r = linearBuckling(chain, shape.q, end);
      REQUIRE(!r.modes.empty());
      CHECK(r.unloadedStable);
      const double l1 = r.modes[0].lambda;
      // stable before the first critical load, one negative direction past it, none at λ = 0
      CHECK(inertiaAt(chain, shape.q, end, d, 0.0).negative == 0);
      CHECK(inertiaAt(chain, shape.q, end, d, 0.99 * l1).negative == 0);
      CHECK(inertiaAt(chain, shape.q, end, d, 1.01 * l1).negative == 1);
      CHECK(int(r.modes.size()) == r.constrainedDimension);
      ChainData data(chain);
      forwardKinematics(chain, shape.q, data);
      Matrix J(3, 7);
      endJacobian(data, J);
      Matrix Crows(int(end.heldIndices().size()), 7);
      for (int k = 0; k < Crows.rows(); ++k) Crows.row(k) = J.row(end.heldIndices()[size_t(k)]);
      for (size_t im = 0; im < r.modes.size(); ++im) {
        const BucklingMode& m = r.modes[im];
        Matrix H(7, 7);
        totalPotentialHessian(chain, shape.q, Wrench(m.lambda, 0.0, 0.0), H);
        const Vector spectrum = projectedSpectrum(H, Crows);
        CHECK(spectrum.cwiseAbs().minCoeff() < 1e-9 * std::max(1.0, spectrum.cwiseAbs().maxCoeff()));
        // all critical loads are compressive here: the k-th one is where the k-th eigenvalue crosses 0
        CHECK(m.lambda < 0.0);
        CHECK(std::abs(spectrum[Eigen::Index(im)]) < 1e-9 * std::max(1.0, spectrum.cwiseAbs().maxCoeff()));
        for (int c : end.heldIndices()) CHECK(std::abs(J.row(c).dot(m.mode)) < 1e-12 * chain.length());
        // H z is a combination of the held rows (Lagrange multipliers)
        Vector Hz = H * m.mode;
        const std::vector<int> held = end.heldIndices();
        if (!held.empty()) {
          Matrix Ch(7, int(held.size()));
          for (size_t k = 0; k < held.size(); ++k) Ch.col(int(k)) = J.row(held[k]).transpose();
          Hz -= Ch * Ch.colPivHouseholderQr().solve(Hz);
        }
        CHECK(Hz.lpNorm<Eigen::Infinity>() < 1e-9 * std::max(1.0, H.lpNorm<Eigen::Infinity>()));
      }
    }
  }
}

TEST_CASE("clamped-pinned and cantilever chains converge to the Euler elastica loads", "[buckling][euler]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  const double kappa = k * (b * L0 - 2 * (b * b - a * a));
  const double EI = kappa * 2 * b;  // rotational spring per link length
  double prevPinned = 1e300, prevFree = 1e300;
  for (int n : {10, 20, 40, 80}) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(a, b, k, L0));
    const double L = 2 * n * b;
    REQUIRE(chain.length() == Approx(L).epsilon(1e-14));
    LinearBucklingOptions opt;
    opt.count = 1;
    const LinearBucklingResult pinned = linearBuckling(chain, Vector::Zero(n), EndCondition::clampedPinned(0.0), opt);
    const LinearBucklingResult cantilever = linearBuckling(chain, Vector::Zero(n), EndCondition::freeEnd(), opt);
    REQUIRE(pinned.modes.size() == 1);
    REQUIRE(cantilever.modes.size() == 1);
    const double Ppinned = kBetaClampedPinned * kBetaClampedPinned * EI / (L * L);
    const double Pfree = M_PI * M_PI * EI / (4 * L * L);
    const double ePinned = relErr(-pinned.modes[0].lambda, Ppinned);
    const double eFree = relErr(-cantilever.modes[0].lambda, Pfree);
    WARN("n = " << n << ": clamped-pinned Fx = " << pinned.modes[0].lambda << " (Euler " << -Ppinned
                << ", rel err " << ePinned << "), cantilever Fx = " << cantilever.modes[0].lambda << " (Euler "
                << -Pfree << ", rel err " << eFree << ")");
    CHECK(pinned.modes[0].shape == "mode 1");
    CHECK(cantilever.modes[0].shape == "mode 0");
    // the rigid-link discretisation converges as 1/n² (observed ≈ 1.5/n² and 0.2/n²)
    CHECK(ePinned < 2.0 / (n * n));
    CHECK(eFree < 0.3 / (n * n));
    CHECK(ePinned < prevPinned);
    CHECK(eFree < prevFree);
    prevPinned = ePinned;
    prevFree = eFree;
  }
}

TEST_CASE("shape names: Table I sign patterns, straight, other, sign changes for general n", "[buckling][shape]") {
  CHECK(shapeName(Eigen::Vector3d(-0.1, 0.2, 0.3)) == "U");
  CHECK(shapeName(Eigen::Vector3d(0.1, -0.2, -0.3)) == "U");
  CHECK(shapeName(Eigen::Vector3d(-0.1, 0.2, -0.3)) == "Z");
  CHECK(shapeName(Eigen::Vector3d(0.1, -0.2, 0.3)) == "Z");
  CHECK(shapeName(Eigen::Vector3d(0.1, 0.2, 0.3)) == "other");
  CHECK(shapeName(Eigen::Vector3d(-0.1, -0.2, 0.3)) == "other");
  CHECK(shapeName(Eigen::Vector3d(0.0, 0.2, 0.3)) == "other");
  CHECK(shapeName(Eigen::Vector3d(1e-12, -1e-11, 0.0)) == "straight");
  CHECK(modeShapeName(Eigen::Vector3d(-1e-12, 2e-12, 3e-12)) == "U");  // scale-free
  // general n: sign changes of the link angles θ = cumulative sums of q
  CHECK(shapeName((Vector(4) << 0.1, 0.1, 0.1, 0.1).finished()) == "mode 0");
  CHECK(shapeName((Vector(4) << 0.1, -0.3, 0.0, 0.0).finished()) == "mode 1");   // θ = (0.1, −0.2, −0.2, −0.2)
  CHECK(shapeName((Vector(4) << 0.1, -0.3, 0.4, 0.0).finished()) == "mode 2");   // θ = (0.1, −0.2, 0.2, 0.2)
  CHECK(signChanges((Vector(5) << 1, 0, -1, 1e-20, 2).finished(), 1e-15) == 2);
}

namespace {

// ‖P (K_q − λG) z‖ / (‖K_q z‖ + |λ| ‖G z‖) with P the projector onto ker C: the pencil's relative
// residual on the null space of the held rows. G z from its entries G(i, j) = g_max(i,j) (eq 27)
// as (G z)_i = g_i Σ_{j≤i} z_j + Σ_{j>i} g_j z_j, O(n) and independent of the factored route.
// The pencil's data at q0 for d = (1, 0): end Jacobian J, K_q diagonal, load generator g.
struct PencilData {
  Matrix J;
  Vector kq, g;
  PencilData(const Chain& chain, const Vector& q0) : J(3, chain.size()), kq(chain.size()), g(chain.size()) {
    ChainData data(chain);
    forwardKinematics(chain, q0, data);
    endJacobian(data, J);
    jointStiffness(chain, q0, kq);
    loadHessianGenerator(data, Wrench(1.0, 0.0, 0.0), g);
  }
};

double pencilResidual(const Chain& chain, const Vector& q0, const EndCondition& end, const BucklingMode& m) {
  const int n = chain.size();
  const PencilData pd(chain, q0);
  const Matrix& J = pd.J;
  const Vector &kq = pd.kq, &g = pd.g;
  const Vector Kz = kq.cwiseProduct(m.mode);
  Vector Gz(n);
  double head = 0.0, tail = 0.0;
  for (int i = 0; i < n; ++i) {
    head += m.mode[i];
    Gz[i] = g[i] * head;
  }
  for (int i = n - 1; i >= 0; --i) {
    Gz[i] += tail;
    tail += g[i] * m.mode[i];
  }
  Vector r = Kz - m.lambda * Gz;
  const std::vector<int> held = end.heldIndices();
  if (!held.empty()) {
    Matrix Ch(n, int(held.size()));
    for (size_t k = 0; k < held.size(); ++k) Ch.col(int(k)) = J.row(held[k]).transpose();
    r -= Ch * Ch.colPivHouseholderQr().solve(r);
  }
  return r.norm() / (Kz.norm() + std::abs(m.lambda) * Gz.norm());
}

// Free-end uniform straight chain (links b, 2b, …, 2b, b): in link angles θ the pencil is
// κ A θ = −λ b E θ with A = tridiag(−1, 2, −1) (last diagonal 1), E = diag(2, …, 2, 1); θ_m =
// sin((m + 1)φ) solves it when cos(nφ) = 0, so λ_k = −(2κ/b) sin²((2k − 1)π/(4n)) exactly.
double cantileverLoad(double kappa, double b, int n, int k) {
  const double s = std::sin((2 * k - 1) * M_PI / (4.0 * n));
  return -2.0 * kappa / b * s * s;
}

}  // namespace

TEST_CASE("Long chains: the O(n) path equals the dense pencil to rounding (loads, modes, shapes)",
          "[linear_buckling]") {
  std::mt19937 rng(4242);
  int compared = 0;
  double worst = 0.0;
  std::vector<int> sizes{kStructuredBucklingFrom + 1, 300};
  if (!buckle::test::kSanitizedBuild) sizes.push_back(1000);  // (sanitized_build.h)
  for (int n : sizes) {
    for (bool uniform : {true, false}) {
      std::vector<SegmentParameters> segs;
      for (int i = 0; i < n; ++i)
        segs.push_back(uniform ? SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25) : testing::randomSegment(rng));
      const Chain chain(segs);
      const UnloadedShape shape = unloadedShape(chain);
      REQUIRE(shape.allFound);
      const Vector q0 = shape.q;
      for (const auto& [name, end] : std::vector<std::pair<std::string, EndCondition>>{
               {"free", EndCondition::freeEnd()},
               {"clamped-pinned", EndCondition::clampedPinned(0.0)},
               {"held position", EndCondition::heldPosition(0.0, 0.0)}}) {
        INFO("n = " << n << (uniform ? ", uniform, " : ", random, ") << name);
        LinearBucklingOptions few;
        few.count = 5;
        const LinearBucklingResult fast = linearBuckling(chain, q0, end, few);
        LinearBucklingOptions all;  // count = −1: the dense pencil
        const LinearBucklingResult dense = linearBuckling(chain, q0, end, all);
        REQUIRE(fast.unloadedStable == dense.unloadedStable);
        if (!dense.unloadedStable) continue;
        ++compared;
        CHECK(fast.constrainedDimension == dense.constrainedDimension);
        CHECK(fast.droppedInfinite == dense.droppedInfinite);
        REQUIRE(fast.modes.size() == std::min<std::size_t>(5, dense.modes.size()));
        for (std::size_t k = 0; k < fast.modes.size(); ++k) {
          const BucklingMode &a = fast.modes[k], &b = dense.modes[k];
          const double e = relErr(a.lambda, b.lambda);
          worst = std::max(worst, e);
          CHECK(e <= 1e-14);
          // modes: both unit; up to sign (a tie for the largest component leaves it open)
          CHECK(std::min((a.mode - b.mode).norm(), (a.mode + b.mode).norm()) <= 1e-12);
          CHECK(a.shape == b.shape);
          CHECK(std::abs(a.shortening - b.shortening) <= 1e-12 * std::abs(b.shortening));
          CHECK(pencilResidual(chain, q0, end, a) <= 1e-13);
        }
      }
    }
  }
  WARN("largest relative difference O(n) vs dense: " << worst);
  CHECK(compared >= 5 * int(sizes.size()));  // at least five comparisons per chain length
}

TEST_CASE("Long chains: cantilever loads equal the discrete closed form at any n", "[linear_buckling]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  for (int n : {kStructuredBucklingFrom + 1, 1000, 20000, 100000}) {
    INFO("n = " << n);
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(a, b, k, L0));
    const double kappa = chain.segment(0).straightStiffness();
    LinearBucklingOptions opt;
    opt.count = 5;
    const LinearBucklingResult r = linearBuckling(chain, Vector::Zero(n), EndCondition::freeEnd(), opt);
    REQUIRE(r.modes.size() == 5);
    for (int j = 1; j <= 5; ++j) {
      const BucklingMode& m = r.modes[size_t(j - 1)];
      // to rounding where a dense solve is feasible; beyond, the Rayleigh quotient's own
      // rounding floor (≈ 1e-14 at n = 1e5) sets the limit
      CHECK(relErr(m.lambda, cantileverLoad(kappa, b, n, j)) <= (n <= 3000 ? 1e-14 : 5e-14));
      CHECK(m.shape == "mode " + std::to_string(j - 1));
      CHECK(pencilResidual(chain, Vector::Zero(n), EndCondition::freeEnd(), m) <= 1e-13);
    }
  }
}

TEST_CASE("Long chains: clamped-pinned loads are Sturm-isolated, residual-small, Euler-convergent",
          "[linear_buckling]") {
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  for (int n : {20000, 100000}) {
    INFO("n = " << n);
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(a, b, k, L0));
    const Vector q0 = Vector::Zero(n);
    const EndCondition end = EndCondition::clampedPinned(0.0);
    LinearBucklingOptions opt;
    opt.count = 5;
    const LinearBucklingResult r = linearBuckling(chain, q0, end, opt);
    REQUIRE(r.modes.size() == 5);
    REQUIRE(r.unloadedStable);
    // Independent count: the projected Hessian K_q − λG through the chain structure, on the
    // held row J_y, just below and above each load (the count's own rounding is ≈ ε n² relative).
    const PencilData pd(chain, q0);
    const Matrix& J = pd.J;
    ChainStructure ws(n);
    auto countAt = [&](double lambda) {
      assemble(pd.kq, lambda * pd.g, ws);
      return constrainedInertia(ws, J.row(1), 0.0).negative;
    };
    const double delta = 1e-5;
    for (int j = 1; j <= 5; ++j) {
      const BucklingMode& m = r.modes[size_t(j - 1)];
      CHECK(m.lambda < 0.0);
      CHECK(countAt(m.lambda * (1.0 - delta)) == j - 1);
      CHECK(countAt(m.lambda * (1.0 + delta)) == j);
      CHECK(std::abs(J.row(1).dot(m.mode)) <= 1e-13 * J.row(1).norm());
      CHECK(pencilResidual(chain, q0, end, m) <= 1e-13);
      CHECK(m.shape == "mode " + std::to_string(j));
    }
    // Euler clamped–pinned: P = β² EI / L², EI = 2 b κ, L = 2 n b; the discretisation error is O(1/n²)
    const double kappa = chain.segment(0).straightStiffness();
    const double L = 2.0 * n * b;
    CHECK(relErr(-r.modes[0].lambda, kBetaClampedPinned * kBetaClampedPinned * 2.0 * b * kappa / (L * L)) <
          2.0 / (double(n) * n));
  }
}
