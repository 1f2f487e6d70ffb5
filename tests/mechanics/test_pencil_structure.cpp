// The vibration pencil's O(n) structure (pencil_structure.h): the quasiseparable LDLᵀ against a
// dense LDLᵀ of T − σM_θ (pivots, inertia, determinant and its derivative), the solves and the mass
// product against dense algebra, the mass generators against the dense mass matrix, the counts with
// held rows against a dense generalized eigen-solve, and a shift where a pivot is exactly zero.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/pencil_structure.h"

using namespace buckle::mechanics;

namespace {

// A random pencil: T tridiagonal (indefinite for a load), M_θ from random link angles and masses.
PencilStructure randomPencil(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  PencilStructure ws(n);
  ws.n = n;
  for (int i = 0; i < n; ++i) {
    ws.t[i] = 2.0 + U(rng);
    if (i + 1 < n) ws.e[i] = -0.8 + 0.3 * U(rng);
    const double theta = 0.7 * U(rng), w = 0.5 + 0.2 * U(rng), l = 1.0 + 0.3 * U(rng);
    ws.p(i, 0) = w * std::cos(theta);
    ws.p(i, 1) = w * std::sin(theta);
    ws.r(i, 0) = l * std::cos(theta);
    ws.r(i, 1) = l * std::sin(theta);
    ws.a[i] = 2.0 * w * l * (n - i) + 0.5;  // diagonally large enough for a positive definite M_θ
  }
  ws.scale = 1.0;
  return ws;
}

Matrix denseT(const PencilStructure& ws) {
  Matrix T = Matrix::Zero(ws.n, ws.n);
  for (int i = 0; i < ws.n; ++i) {
    T(i, i) = ws.t[i];
    if (i + 1 < ws.n) T(i + 1, i) = T(i, i + 1) = ws.e[i];
  }
  return T;
}

Matrix denseMass(const PencilStructure& ws) {
  Matrix M(ws.n, ws.n);
  for (int i = 0; i < ws.n; ++i) {
    M(i, i) = ws.a[i];
    for (int j = 0; j < i; ++j) M(i, j) = M(j, i) = ws.p.row(i).dot(ws.r.row(j));
  }
  return M;
}

// Unpivoted dense LDLᵀ pivots (the reference for the recursion).
Vector densePivots(Matrix G) {
  const int n = int(G.rows());
  Vector d(n);
  for (int k = 0; k < n; ++k) {
    d[k] = G(k, k);
    for (int i = k + 1; i < n; ++i) {
      const double l = G(i, k) / d[k];
      for (int j = k + 1; j <= i; ++j) G(i, j) -= l * G(j, k);
    }
  }
  return d;
}

int countBelowDense(const Matrix& A, const Matrix& M, double sigma) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> es(A, M, Eigen::EigenvaluesOnly);
  int c = 0;
  for (int i = 0; i < es.eigenvalues().size(); ++i) c += es.eigenvalues()[i] < sigma ? 1 : 0;
  return c;
}

}  // namespace

TEST_CASE("pencil structure: the recursion's pivots, inertia and determinant are those of a dense LDLt of T - sigma M_theta",
          "[pencil_structure]") {
  std::mt19937 rng(3);
  for (int n : {1, 2, 7, 40}) {
    PencilStructure ws = randomPencil(n, rng);
    const Matrix T = denseT(ws), M = denseMass(ws);
    REQUIRE(Eigen::LLT<Matrix>(M).info() == Eigen::Success);
    REQUIRE(pencilMassPositive(ws));
    for (double sigma : {-0.3, 0.0, 0.01, 0.05, 0.2}) {
      INFO("n = " << n << ", sigma = " << sigma);
      const Matrix G = T - sigma * M;
      factorizePencil(ws, sigma);
      const Vector d = densePivots(G);
      if (ws.twoByTwo == 0)  // (with 2×2 pivots the pivots differ; inertia and determinant do not)
        for (int i = 0; i < n; ++i) CHECK(std::abs(ws.d[i] - d[i]) <= 1e-11 * std::max(1.0, std::abs(d[i])));
      CHECK(ws.negative == countBelowDense(T, M, sigma));  // Sylvester: eigenvalues of the pencil below σ
      const double logDet = d.array().abs().log().sum();
      CHECK(std::abs(ws.logAbsDet - logDet) <= 1e-10 * std::max(1.0, std::abs(logDet)));
      int sign = 1;
      for (int i = 0; i < n; ++i) sign *= d[i] < 0 ? -1 : 1;
      CHECK(ws.detSign == sign);
      // d log|det G_σ|/dσ = −tr(G⁻¹M)
      const double dLog = -(G.lu().solve(M)).trace();
      if (ws.twoByTwo == 0) CHECK(std::abs(ws.dLogAbsDet - dLog) <= 1e-9 * std::max(1.0, std::abs(dLog)));
      else CHECK(std::isnan(ws.dLogAbsDet));
      // the solve and the mass product
      Vector b = Vector::LinSpaced(n, -1.0, 2.0), y = b;
      solvePencil(ws, y);
      CHECK((G * y - b).norm() <= 1e-10 * G.norm() * y.norm());
      Vector Mb(n);
      applyPencilMass(ws, b, Mb);
      CHECK((Mb - M * b).norm() <= 1e-13 * M.norm() * b.norm());
    }
  }
}

TEST_CASE("pencil structure: the mass generators give the inertial model's mass matrix M = U M_theta U^T",
          "[pencil_structure]") {
  const int n = 9;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  InertiaData inertia;
  for (int i = 0; i < n; ++i) inertia.links.push_back({0.5 + 0.1 * i, 0.02 * i, 0.3 + 0.05 * i});
  const MassGenerators gen = massGenerators(chain, inertia);
  const Vector q = Vector::LinSpaced(n, 0.3, -0.4);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  PencilStructure ws(n);
  ws.n = n;
  for (int i = 0; i < n; ++i) {
    ws.a[i] = gen.diagonal[i];
    ws.p.row(i) << gen.weight[i] * std::cos(data.theta[i]), gen.weight[i] * std::sin(data.theta[i]);
    ws.r.row(i) << gen.length[i] * std::cos(data.theta[i]), gen.length[i] * std::sin(data.theta[i]);
  }
  Matrix U = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i) U.row(i).tail(n - i).setOnes();
  Matrix M(n, n);
  InertialModel(chain, EndCondition::freeEnd(), inertia, {}, 1.0, Vector::Zero(n)).massMatrix(q, M);
  CHECK((U * denseMass(ws) * U.transpose() - M).norm() <= 1e-13 * M.norm());
}

TEST_CASE("pencil structure: counts on the kernel of held rows equal a dense generalized eigen-solve on that kernel",
          "[pencil_structure]") {
  std::mt19937 rng(5);
  const int n = 30;
  PencilStructure ws = randomPencil(n, rng);
  Matrix U = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i) U.row(i).tail(n - i).setOnes();
  const Matrix H = U * denseT(ws) * U.transpose(), M = U * denseMass(ws) * U.transpose();
  std::uniform_real_distribution<double> V(-1.0, 1.0);
  for (int m : {1, 2, 3}) {
    Matrix C(m, n);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < n; ++j) C(i, j) = V(rng);
    REQUIRE(setPencilConstraints(ws, C) == m);
    const Matrix Z = Eigen::FullPivLU<Matrix>(C).kernel();
    const Matrix Zo = Eigen::HouseholderQR<Matrix>(Z).householderQ() * Matrix::Identity(n, Z.cols());
    Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> es(Zo.transpose() * H * Zo, Zo.transpose() * M * Zo,
                                                        Eigen::EigenvaluesOnly);
    const Vector mu = es.eigenvalues();
    for (int i = 0; i + 1 < int(mu.size()) && i < 8; ++i) {
      const double sigma = 0.5 * (mu[i] + mu[i + 1]);
      CHECK(pencilCountBelow(ws, sigma) == i + 1);
    }
    Vector out(5);
    REQUIRE(pencilEigenvalues(ws, 0, 5, out, 1e-14) == 5);
    for (int i = 0; i < 5; ++i) CHECK(std::abs(out[i] - mu[i]) <= 1e-11 * mu.cwiseAbs().maxCoeff());
  }
}

TEST_CASE("pencil structure: an exactly zero leading pivot (sigma = t_0 / a_0) takes a 2x2 pivot: exact count and solve",
          "[pencil_structure]") {
  std::mt19937 rng(11);
  const int n = 12;
  PencilStructure ws = randomPencil(n, rng);
  ws.t[0] = 0.75;
  ws.a[0] = 3.0;  // G_σ(0, 0) = t_0 − σ a_0 = 0 exactly at σ = 0.25
  const Matrix T = denseT(ws), M = denseMass(ws);
  const double sigma = 0.25;
  factorizePencil(ws, sigma);
  CHECK(ws.twoByTwo >= 1);
  CHECK_FALSE(ws.singular);
  REQUIRE(std::abs(countBelowDense(T, M, sigma * (1 - 1e-9)) - countBelowDense(T, M, sigma * (1 + 1e-9))) == 0);
  CHECK(ws.negative == countBelowDense(T, M, sigma));
  const Matrix G = T - sigma * M;
  const double logDet = std::log(std::abs(G.determinant()));
  CHECK(std::abs(ws.logAbsDet - logDet) <= 1e-10 * std::max(1.0, std::abs(logDet)));
  CHECK(ws.detSign == (G.determinant() < 0 ? -1 : 1));
  Vector b = Vector::LinSpaced(n, 1.0, -2.0), y = b;
  solvePencil(ws, y);
  CHECK((G * y - b).norm() <= 1e-12 * G.norm() * y.norm());
  // and near it: a tiny (not zero) leading pivot, where the unpivoted recursion lost the count
  for (double rel : {1e-13, 1e-9, 1e-6}) {
    INFO("sigma = 0.25 (1 + " << rel << ")");
    factorizePencil(ws, sigma * (1 + rel));
    CHECK(ws.negative == countBelowDense(T, M, sigma * (1 + rel)));
    Vector z = b;
    solvePencil(ws, z);
    const Matrix Gr = T - sigma * (1 + rel) * M;
    CHECK((Gr * z - b).norm() <= 1e-12 * Gr.norm() * z.norm());
  }
}
