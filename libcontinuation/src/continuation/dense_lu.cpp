#include "buckle/continuation/internal/dense_lu.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace buckle::continuation {

DenseLU::DenseLU(int size, Rounding rounding)
    : n_(size), rounding_(rounding), lu_(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), 0.0),
      pivots_(static_cast<std::size_t>(size), 0) {
  if (size < 1) throw std::invalid_argument("DenseLU: size must be positive");
}

bool DenseLU::factor() { return rounding_ == Rounding::Divide ? factorDispatch<false>() : factorDispatch<true>(); }

void DenseLU::solveInPlace(double *b) const {
  if (rounding_ == Rounding::Divide)
    solveDispatch<false>(b);
  else
    solveDispatch<true>(b);
}

template <bool reciprocal>
bool DenseLU::factorDispatch() {
  switch (n_) {
    case 2: return factorImpl<2, reciprocal>();
    case 3: return factorImpl<3, reciprocal>();
    case 4: return factorImpl<4, reciprocal>();
    case 5: return factorImpl<5, reciprocal>();
    case 6: return factorImpl<6, reciprocal>();
    case 7: return factorImpl<7, reciprocal>();
    case 8: return factorImpl<8, reciprocal>();
    default: return factorImpl<0, reciprocal>();
  }
}

template <bool reciprocal>
void DenseLU::solveDispatch(double *b) const {
  switch (n_) {
    case 2: return solveImpl<2, reciprocal>(b);
    case 3: return solveImpl<3, reciprocal>(b);
    case 4: return solveImpl<4, reciprocal>(b);
    case 5: return solveImpl<5, reciprocal>(b);
    case 6: return solveImpl<6, reciprocal>(b);
    case 7: return solveImpl<7, reciprocal>(b);
    case 8: return solveImpl<8, reciprocal>(b);
    default: return solveImpl<0, reciprocal>(b);
  }
}

namespace {

// P A = L U of the n×n column-major `a` in place (see the header for the two roundings).
template <int Fixed, bool reciprocal>
bool factorKernel(double *a, int runtimeSize, int *pivots, int &swaps) {
  const int n = Fixed > 0 ? Fixed : runtimeSize;
  swaps = 0;
  for (int k = 0; k < n; ++k) {
    double *colK = a + static_cast<std::ptrdiff_t>(k) * n;
    // The first entry of largest magnitude (a NaN never wins a comparison, as in both libraries).
    int p = k;
    double largest = std::abs(colK[k]);
    for (int i = k + 1; i < n; ++i) {
      const double magnitude = std::abs(colK[i]);
      if (magnitude > largest) {
        largest = magnitude;
        p = i;
      }
    }
    pivots[k] = p;
    if (largest == 0.0) return false;
    if (p != k) {
      for (int j = 0; j < n; ++j) std::swap(a[j * n + k], a[j * n + p]);
      ++swaps;
    }
    const double pivot = colK[k];
    if (reciprocal) {
      const double inverse = 1.0 / pivot;
      for (int i = k + 1; i < n; ++i) colK[i] *= inverse;
    } else {
      for (int i = k + 1; i < n; ++i) colK[i] /= pivot;
    }
    // Rank-one update of the trailing block, column by column.
    for (int j = k + 1; j < n; ++j) {
      double *colJ = a + static_cast<std::ptrdiff_t>(j) * n;
      const double ukj = colJ[k];
      if (reciprocal && ukj == 0.0) continue;
      for (int i = k + 1; i < n; ++i) colJ[i] -= ukj * colK[i];
    }
  }
  return true;
}

// b ← U⁻¹ L⁻¹ P b.
template <int Fixed, bool reciprocal>
void solveKernel(const double *a, int runtimeSize, const int *pivots, double *b) {
  const int n = Fixed > 0 ? Fixed : runtimeSize;
  for (int k = 0; k < n; ++k) {
    const int p = pivots[k];
    if (p != k) std::swap(b[k], b[p]);
  }
  // L y = P b (unit diagonal), column by column.
  for (int k = 0; k + 1 < n; ++k) {
    const double bk = b[k];
    if (!reciprocal && bk == 0.0) continue;
    const double *colK = a + static_cast<std::ptrdiff_t>(k) * n;
    for (int i = k + 1; i < n; ++i) b[i] -= bk * colK[i];
  }
  // U x = y, column by column from the last.
  for (int k = n - 1; k >= 0; --k) {
    if (!reciprocal && b[k] == 0.0) continue;
    const double *colK = a + static_cast<std::ptrdiff_t>(k) * n;
    b[k] /= colK[k];
    const double bk = b[k];
    for (int i = 0; i < k; ++i) b[i] -= bk * colK[i];
  }
}

}  // namespace

template <int Fixed, bool reciprocal>
bool DenseLU::factorImpl() {
  return factorKernel<Fixed, reciprocal>(lu_.data(), n_, pivots_.data(), swaps_);
}

// At a compile-time size the solve runs on a local copy of b: the compiler then sees that b does
// not overlap the factors and keeps it in registers.
template <int Fixed, bool reciprocal>
void DenseLU::solveImpl(double *b) const {
  if constexpr (Fixed == 0) {
    solveKernel<0, reciprocal>(lu_.data(), n_, pivots_.data(), b);
  } else {
    double x[Fixed];
    std::copy(b, b + Fixed, x);
    solveKernel<Fixed, reciprocal>(lu_.data(), n_, pivots_.data(), x);
    std::copy(x, x + Fixed, b);
  }
}

bool signedLogDeterminant(const Eigen::Ref<const Matrix> &factors, int permutationSign, int &sign, double &logAbs) {
  sign = permutationSign;
  // |det| = Π|u_ii| as one running product, split into mantissa and exponent once at the end
  // (one frexp instead of one per pivot). While every pivot and every partial product stay well
  // inside the normal range, scaling by a power of two is exact, so the product is the per-pivot
  // loop's mantissa times its power of two, and the final split gives that loop's (mantissa,
  // exponent) bit for bit; outside that range the per-pivot loop below runs instead.
  constexpr double kLow = 0x1p-500, kHigh = 0x1p500;
  const Eigen::Index n = factors.rows();
  double product = 1.0;
  bool inRange = true;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double pivot = factors(i, i);
    if (pivot == 0.0 || !std::isfinite(pivot)) return false;
    if (pivot < 0.0) sign = -sign;
    const double magnitude = std::abs(pivot);
    product *= magnitude;
    inRange = inRange && magnitude >= kLow && magnitude <= kHigh && product >= kLow && product <= kHigh;
  }
  double mantissa = 1.0;
  long exponent = 0;
  if (n > 0 && inRange) {
    int e = 0;
    mantissa = std::frexp(product, &e);
    exponent = e;
  } else {
    for (Eigen::Index i = 0; i < n; ++i) {
      int e = 0;
      mantissa = std::frexp(mantissa * std::abs(factors(i, i)), &e);
      exponent += e;
    }
  }
  logAbs = std::log(mantissa) + static_cast<double>(exponent) * 0.6931471805599453;
  return true;
}

}  // namespace buckle::continuation
