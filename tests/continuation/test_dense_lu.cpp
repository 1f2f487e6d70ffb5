#include "buckle/continuation/internal/dense_lu.h"

#include <sundials/sundials_dense.h>

#include <Eigen/LU>
#include <Eigen/QR>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

using namespace buckle::continuation;

namespace {

Matrix randomMatrix(int n, std::mt19937 &rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix A(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) A(i, j) = uniform(rng);
  return A;
}

Matrix randomOrthogonal(int n, std::mt19937 &rng) {
  Eigen::HouseholderQR<Matrix> qr(randomMatrix(n, rng));
  return qr.householderQ() * Matrix::Identity(n, n);
}

// Every entry the same double, bit for bit (copies: any Eigen expression converts to Matrix).
bool bitwiseEqual(const Matrix &a, const Matrix &b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  return std::memcmp(a.data(), b.data(), sizeof(double) * std::size_t(a.size())) == 0;
}

}  // namespace

TEST_CASE("DenseLU with Divide rounding is Eigen's PartialPivLU bit for bit up to size 8", "[dense_lu]") {
  std::mt19937 rng(17);
  for (int n = 1; n <= 12; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      const Matrix A = randomMatrix(n, rng);
      const Vector b = randomMatrix(n, rng).col(0);
      Eigen::PartialPivLU<Matrix> eigen(A);
      DenseLU lu(n, DenseLU::Rounding::Divide);
      lu.matrix() = A;
      REQUIRE(lu.factor());
      // Eigen factors sizes ≤ 16 unblocked: the factors agree at every size here.
      CHECK(bitwiseEqual(Matrix(lu.factors()), eigen.matrixLU()));
      CHECK(lu.permutationSign() == (eigen.permutationP().determinant() > 0 ? 1 : -1));
      Vector x = b;
      lu.solveInPlace(x);
      const Vector xe = eigen.solve(b);
      if (n <= DenseLU::kEigenIdenticalSize) {
        CHECK(bitwiseEqual(x, xe));
      } else {
        CHECK((x - xe).norm() <= 1e-12 * xe.norm() * (1.0 + A.norm() * A.inverse().norm()));
      }
      CHECK((A * x - b).norm() <= 1e-13 * A.norm() * x.norm() * n);
    }
  }
}

TEST_CASE("DenseLU with Reciprocal rounding is SUNDIALS' dense GETRF/GETRS bit for bit", "[dense_lu]") {
  std::mt19937 rng(23);
  for (int n : {1, 2, 4, 5, 8, 9, 15}) {
    for (int trial = 0; trial < 20; ++trial) {
      Matrix A = randomMatrix(n, rng);
      if (trial % 4 == 0 && n > 1) A.col(n - 1).head(n / 2).setZero();  // the zero-skipping branch
      const Vector b = randomMatrix(n, rng).col(0);
      // SUNDIALS' reference on a column-pointer copy of A.
      Matrix ref = A;
      std::vector<sunrealtype *> columns(static_cast<std::size_t>(n));
      for (int j = 0; j < n; ++j) columns[std::size_t(j)] = ref.col(j).data();
      std::vector<sunindextype> pivots(static_cast<std::size_t>(n));
      REQUIRE(SUNDlsMat_denseGETRF(columns.data(), n, n, pivots.data()) == 0);
      Vector xr = b;
      SUNDlsMat_denseGETRS(columns.data(), n, pivots.data(), xr.data());

      DenseLU lu(n, DenseLU::Rounding::Reciprocal);
      lu.matrix() = A;
      REQUIRE(lu.factor());
      CHECK(bitwiseEqual(Matrix(lu.factors()), ref));
      Vector x = b;
      lu.solveInPlace(x);
      CHECK(bitwiseEqual(x, xr));
    }
  }
}

TEST_CASE("DenseLU: determinant sign and log|det| of near-singular and badly scaled matrices", "[dense_lu]") {
  std::mt19937 rng(5);
  for (int n : {2, 3, 5, 8, 11}) {
    for (double smallest : {1.0, 1e-8, 1e-14, -1e-14, -1e-200}) {
      // A = Q diag(d) Qᵀ with known det = Π d_i: sign and log|det| in closed form.
      const Matrix Q = randomOrthogonal(n, rng);
      Vector d = Vector::LinSpaced(n, 1.0, 3.0);
      d[0] = smallest;
      if (n > 2) d[1] = -0.5;
      const Matrix A = Q * d.asDiagonal() * Q.transpose();
      int expectedSign = 1;
      double expectedLog = 0.0;
      for (int i = 0; i < n; ++i) {
        if (d[i] < 0.0) expectedSign = -expectedSign;
        expectedLog += std::log(std::abs(d[i]));
      }
      for (auto rounding : {DenseLU::Rounding::Divide, DenseLU::Rounding::Reciprocal}) {
        DenseLU lu(n, rounding);
        lu.matrix() = A;
        REQUIRE(lu.factor());
        int sign = 0;
        double logAbs = 0.0;
        REQUIRE(signedLogDeterminant(lu.factors(), lu.permutationSign(), sign, logAbs));
        // The smallest eigenvalue is perturbed by ~ε‖A‖ in the factorization: exact sign and
        // log for a well-separated one, log within the relative perturbation otherwise.
        const double relative = 1e-13 / std::abs(d[0]) * 10.0;
        if (relative < 0.5) {
          CHECK(sign == expectedSign);
          CHECK(std::abs(logAbs - expectedLog) <= std::max(1e-12 * std::abs(expectedLog), relative) + 1e-12);
        }
        // Against Eigen's determinant, where it is representable.
        const double det = A.determinant();
        if (std::isnormal(det) && relative < 0.5) {
          CHECK(sign == (det > 0 ? 1 : -1));
          CHECK(std::abs(logAbs - std::log(std::abs(det))) <= 1e-10 + relative);
        }
      }
    }
  }
  // Scales whose determinant overflows (or underflows) a double: log|det| is still exact.
  for (double scale : {1e120, 1e-120}) {
    const int n = 6;
    Matrix A = randomMatrix(n, rng);
    const double base = std::log(std::abs(A.determinant()));
    const int baseSign = A.determinant() > 0 ? 1 : -1;
    A *= scale;
    DenseLU lu(n, DenseLU::Rounding::Divide);
    lu.matrix() = A;
    REQUIRE(lu.factor());
    int sign = 0;
    double logAbs = 0.0;
    REQUIRE(signedLogDeterminant(lu.factors(), lu.permutationSign(), sign, logAbs));
    CHECK(sign == baseSign);
    CHECK(std::abs(logAbs - (base + n * std::log(scale))) <= 1e-10 * std::abs(logAbs));
  }
}

TEST_CASE("DenseLU stops at an exactly zero pivot, the determinant refuses non-finite pivots", "[dense_lu]") {
  std::mt19937 rng(9);
  for (auto rounding : {DenseLU::Rounding::Divide, DenseLU::Rounding::Reciprocal}) {
    Matrix A = randomMatrix(5, rng);
    A.col(2).setZero();  // column 2 stays zero under elimination: exactly zero pivot at step 2
    DenseLU lu(5, rounding);
    lu.matrix() = A;
    CHECK_FALSE(lu.factor());
    // A non-finite entry survives factor() (as in both libraries) but not the determinant.
    A = randomMatrix(5, rng);
    A(4, 4) = std::numeric_limits<double>::infinity();
    lu.matrix() = A;
    lu.factor();
    int sign = 0;
    double logAbs = 0.0;
    CHECK_FALSE(signedLogDeterminant(lu.factors(), lu.permutationSign(), sign, logAbs));
  }
  CHECK_THROWS_AS(DenseLU(0, DenseLU::Rounding::Divide), std::invalid_argument);
}

TEST_CASE("signedLogDeterminant's one running product equals the per-pivot frexp loop bit for bit", "[dense_lu]") {
  // The running product is split into mantissa and exponent once; the reference splits after
  // every pivot (the textbook overflow-safe loop). Pivots over ±60 binary orders (the fast path)
  // and over ±700 (products leave the normal range: the per-pivot loop itself runs).
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> W(-3.0, 3.0);
  for (const int spread : {60, 700}) {
    std::uniform_int_distribution<int> E(-spread, spread);
    for (int trial = 0; trial < 2000; ++trial) {
      const int n = 1 + trial % 9;
      Matrix U = Matrix::Zero(n, n);
      for (int i = 0; i < n; ++i) U(i, i) = std::ldexp(W(rng), E(rng));
      if (U.diagonal().cwiseAbs().minCoeff() == 0.0) continue;
      double mantissa = 1.0;
      long exponent = 0;
      int expectedSign = trial % 2 ? -1 : 1;
      for (int i = 0; i < n; ++i) {
        int e = 0;
        mantissa = std::frexp(mantissa * std::abs(U(i, i)), &e);
        exponent += e;
        if (U(i, i) < 0.0) expectedSign = -expectedSign;
      }
      const double expected = std::log(mantissa) + static_cast<double>(exponent) * 0.6931471805599453;
      int sign = 0;
      double logAbs = 0.0;
      REQUIRE(signedLogDeterminant(U, trial % 2 ? -1 : 1, sign, logAbs));
      CHECK(sign == expectedSign);
      CHECK(std::memcmp(&logAbs, &expected, sizeof logAbs) == 0);
    }
  }
}
