// Small pieces shared by the chain structure's and the vibration pencil's O(n) factorizations
// (chain_structure_*.cpp, pencil_structure.cpp). Private to libcontinuation/src/mechanics.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics::structure {

/// Bunch's pivoting threshold for the symmetric tridiagonal factorizations: (√5 − 1)/2.
constexpr double kBunchAlpha = 0.6180339887498949;
/// A pivot this small relative to the matrix's scale is an exact zero to the recursion
/// (LAPACK dstebz's pivmin).
constexpr double kTinyPivot = 1e-290;

/// The largest |eigenvalue| of the symmetric 2×2 pivot block [[d, c], [c, b]]:
/// |d + b|/2 + √(((d − b)/2)² + c²). The plain square root of the sum where that neither over-
/// nor underflows: std::hypot's scaling costs more than the rest of a 2×2 step, and indefinite
/// chains take many.
inline double largestBlockEigenvalue(double d, double b, double c) {
  const double h = 0.5 * (d - b);
  const double s = h * h + c * c;
  const double radius = s > 1e-290 && s < 1e290 ? std::sqrt(s) : std::hypot(h, c);
  return 0.5 * std::abs(d + b) + radius;
}

/// A product of many pivots kept as mantissa · 2^exponent (a log per pivot would dominate the
/// factorization's cost; the plain product over- or underflows for long chains).
struct ScaledProduct {
  double mantissa = 1.0;
  long exponent = 0;
  void multiply(double v) {
    mantissa *= v;
    const double am = std::abs(mantissa);
    if (am > 1e150 || am < 1e-150) {
      int e2 = 0;
      mantissa = std::frexp(mantissa, &e2);
      exponent += e2;
    }
  }
  double logAbs() const { return std::log(std::abs(mantissa)) + double(exponent) * 0.6931471805599453; }
};

/// ws.S = Bᵀ(T − σM)⁻¹B for the first r columns of ws.B, after factorize(ws, σ): WᵀD⁻¹W with
/// W = L⁻¹B by the factor's forward sweep alone, without the solve for (T − σM)⁻¹B.
void factoredSchur(ChainStructure& ws, int r);

/// A coupling R E Rᵀ's columns U⁻¹R into B's columns rank … rank + c − 1 and E's diagonal into
/// `sign` (chain_structure.h setCoupling, pencil_structure.h setPencilCoupling; R n×c, n = B's
/// active rows). Returns c; throws std::invalid_argument, naming `caller`, for a wrong size or sign.
template <class Signs>
int setCouplingColumns(const char* caller, const Eigen::Ref<const Matrix>& R, const Eigen::Ref<const Vector>& signs,
                       int rank, Eigen::Ref<Matrix> B, Signs& sign) {
  const int c = int(R.cols());
  if (R.rows() != B.rows() || signs.size() != c || rank + c > B.cols())
    throw std::invalid_argument(std::string(caller) + ": R must be n×c with rank(C) + c <= kMaxBorder and c signs");
  for (int j = 0; j < c; ++j) {
    if (signs[j] != 1.0 && signs[j] != -1.0) throw std::invalid_argument(std::string(caller) + ": each sign must be +1 or -1");
    applyUInverse(R.col(j), B.col(rank + j));
    sign[j] = signs[j];
  }
  return c;
}

/// Orthonormalise the rows of C (m×n) by modified Gram–Schmidt, twice, into the first columns of Q
/// (n rows), with B = U⁻¹Q alongside; rows whose remainder is below rankTolerance of the largest
/// row norm are dropped. Returns the rank.
inline int orthonormaliseRows(const Eigen::Ref<const Matrix>& C, Eigen::Ref<Matrix> Q, Eigen::Ref<Matrix> B,
                              double rankTolerance) {
  double maxNorm = 0.0;
  for (Eigen::Index i = 0; i < C.rows(); ++i) maxNorm = std::max(maxNorm, C.row(i).norm());
  int r = 0;
  if (maxNorm > 0.0) {
    for (Eigen::Index i = 0; i < C.rows(); ++i) {
      auto qr = Q.col(r);
      qr = C.row(i).transpose();
      for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j < r; ++j) qr -= Q.col(j).dot(qr) * Q.col(j);
      const double nrm = qr.norm();
      if (nrm <= rankTolerance * maxNorm) continue;
      qr /= nrm;
      applyUInverse(qr, B.col(r));
      ++r;
    }
  }
  return r;
}

}  // namespace buckle::mechanics::structure
