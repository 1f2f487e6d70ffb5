// LDLᵀ of T − σM with Bunch pivoting, the plain Sturm count and the factored solves
// (chain_structure.h, "factorization and counts").
#include "buckle/mechanics/chain_structure.h"
#include "structure_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace buckle::mechanics {

using structure::kBunchAlpha;
using structure::largestBlockEigenvalue;
using structure::kTinyPivot;

namespace {

/// Diagonal of the q-space identity in θ-coordinates, M = U⁻¹U⁻ᵀ (off-diagonal −1).
inline double metricDiagonal(int k, int n) { return k + 1 < n ? 2.0 : 1.0; }

}  // namespace

void factorize(ChainStructure& ws, double sigma, bool determinant) {
  const int n = ws.n;
  ws.shift = sigma;
  ++ws.factorizations;
  ws.singular = false;
  ws.factorInertia = Inertia{};
  // det as mantissa · 2^exponent, rescaled occasionally (a log per pivot would dominate the cost)
  structure::ScaledProduct det;
  auto accumulate = [&](double v) {
    if (determinant) det.multiply(v);
  };
  int sign = 1;
  // max |entry| of T − σM (M: diagonal 2, …, 2, 1; off-diagonal −1) as whole-array reductions,
  // which vectorise (a max is exact: the same value as entry by entry)
  double scale = std::abs(ws.diag[n - 1] - sigma);
  if (n > 1) {
    scale = std::max(scale, (ws.diag.head(n - 1).array() - 2.0 * sigma).abs().maxCoeff());
    scale = std::max(scale, (ws.off.head(n - 1).array() + sigma).abs().maxCoeff());
  }
  if (scale == 0.0) scale = 1.0;
  const double pivmin = kTinyPivot * scale;
  // The 1×1 pivots' smallest |d| divided by the scale once at the end (x ↦ x/scale is monotonic
  // in rounding too: the same ratio as dividing each), the 2×2 blocks' ratios as they come.
  double minRatio = std::numeric_limits<double>::infinity();
  double minPivot = std::numeric_limits<double>::infinity();
  // The factor's arrays through local pointers and the counts in locals: the block markers are
  // bytes, and a byte store may alias anything, so through `ws` every marker written would make
  // the compiler reload each array's address and the counts from memory.
  const double* diag = ws.diag.data();
  const double* off = ws.off.data();
  double* pivA = ws.pivA.data();
  double* pivE = ws.pivE.data();
  double* l1 = ws.l1.data();
  double* l2 = ws.l2.data();
  unsigned char* blockStart = ws.blockStart.data();
  int negative = 0, positive = 0;
  bool singular = false;
  auto a = [&](int k) { return diag[k] - sigma * metricDiagonal(k, n); };
  auto e = [&](int k) { return off[k] + sigma; };  // M off-diagonal is −1

  // With the determinant: its logarithmic derivative d log|det(T − σM)|/dσ = Σ p'/p over the
  // pivots p (the 2×2 blocks' determinants), carried through the recurrence (dk' is the σ-derivative
  // of the pivot candidate dk; a' = −M_kk, e' = 1): Newton on det in eigenvaluesFrom().
  double ddk = -metricDiagonal(0, n), dLog = 0.0;
  int k = 0;
  double dk = a(0);
  while (k < n) {
    const double ek = k + 1 < n ? e(k) : 0.0;
    if (k + 1 == n || std::abs(dk) * scale >= kBunchAlpha * ek * ek) {
      if (dk == 0.0) {
        dk = -pivmin;
        singular = true;
      }
      blockStart[k] = 1;
      pivA[k] = dk;
      // without a branch: the pivots' signs follow the spectrum about σ, no pattern to predict
      const bool below = dk < 0.0;
      negative += below;
      positive += !below;
      sign = below ? -sign : sign;
      accumulate(dk);
      minPivot = std::min(minPivot, std::abs(dk));
      if (determinant) dLog += ddk / dk;
      if (k + 1 < n) {
        const double l = ek / dk;
        l1[k] = l;
        dk = a(k + 1) - ek * l;
        if (determinant) ddk = -metricDiagonal(k + 1, n) - 2.0 * l + l * l * ddk;  // (a − e²/d)'
      }
      k += 1;
    } else {
      // 2×2 pivot [[dk, ek], [ek, a_{k+1}]]: det < −(1 − α) ek² < 0, one eigenvalue of each sign.
      const double b = a(k + 1);
      const double det = dk * b - ek * ek;
      blockStart[k] = 2;
      blockStart[k + 1] = 0;
      pivA[k] = dk;
      pivA[k + 1] = b;
      pivE[k] = ek;
      ++negative;
      ++positive;
      sign = -sign;
      accumulate(det);
      // smallest |eigenvalue| of the block ≥ |det| / (largest |eigenvalue|)
      const double big = largestBlockEigenvalue(dk, b, ek);
      minRatio = std::min(minRatio, std::abs(det) / (big * scale));
      const double ddet = ddk * b - dk * metricDiagonal(k + 1, n) - 2.0 * ek;
      if (determinant) dLog += ddet / det;
      if (k + 2 < n) {
        const double ek1 = e(k + 1);
        l1[k] = -ek1 * ek / det;
        l2[k] = ek1 * dk / det;
        if (determinant) {
          const double r = dk / det, dr = (ddk - r * ddet) / det;  // dk/det and its derivative
          ddk = -metricDiagonal(k + 2, n) - 2.0 * ek1 * r - ek1 * ek1 * dr;
        }
        dk = a(k + 2) - ek1 * ek1 * dk / det;
      }
      k += 2;
    }
  }
  ws.factorInertia.negative = negative;
  ws.factorInertia.positive = positive;
  ws.singular = singular;
  ws.minPivotRatio = std::min(minRatio, minPivot / scale);
  ws.logAbsDet = determinant ? det.logAbs() : std::numeric_limits<double>::quiet_NaN();
  ws.detSign = sign;
  ws.dLogAbsDet = determinant ? dLog : std::numeric_limits<double>::quiet_NaN();
}

int countBelow(const ChainStructure& ws, double sigma) {
  const int n = ws.n;
  double scale = 0.0;
  for (int k = 0; k < n; ++k) scale = std::max(scale, std::abs(ws.diag[k]) + std::abs(sigma) * 2.0);
  if (scale == 0.0) scale = 1.0;
  const double pivmin = kTinyPivot * scale;
  int count = 0;
  double d = ws.diag[0] - sigma * metricDiagonal(0, n);
  for (int k = 0;; ++k) {
    if (std::abs(d) < pivmin) d = -pivmin;
    if (d < 0.0) ++count;
    if (k + 1 == n) break;
    const double e = ws.off[k] + sigma;
    d = ws.diag[k + 1] - sigma * metricDiagonal(k + 1, n) - e * e / d;
  }
  return count;
}

void solveFactored(const ChainStructure& ws, VectorRef y) {
  const int n = ws.n;
  // forward with L, and the block diagonal in the same pass: a block's entries are final once
  // the rows above are eliminated
  for (int k = 0; k < n;) {
    if (ws.blockStart[size_t(k)] == 1) {
      const double y0 = y[k];
      if (k + 1 < n) y[k + 1] -= ws.l1[k] * y0;
      y[k] = y0 / ws.pivA[k];
      k += 1;
    } else {
      const double y0 = y[k], y1 = y[k + 1];
      if (k + 2 < n) y[k + 2] -= ws.l1[k] * y0 + ws.l2[k] * y1;
      const double a = ws.pivA[k], b = ws.pivA[k + 1], e = ws.pivE[k];
      const double det = a * b - e * e;
      y[k] = (b * y0 - e * y1) / det;
      y[k + 1] = (a * y1 - e * y0) / det;
      k += 2;
    }
  }
  // backward: Lᵀ
  for (int k = n - 1; k >= 0;) {
    if (ws.blockStart[size_t(k)] == 0) {  // second row of a 2×2 starting at k − 1
      if (k + 1 < n) {
        y[k - 1] -= ws.l1[k - 1] * y[k + 1];
        y[k] -= ws.l2[k - 1] * y[k + 1];
      }
      k -= 2;
    } else {
      if (k + 1 < n) y[k] -= ws.l1[k] * y[k + 1];
      k -= 1;
    }
  }
}

namespace {

/// factoredSchur for R border columns. Row k of W = L⁻¹B is b_k less one term from the pivot
/// block just above it (a 1×1 at k − 1 or a 2×2 at k − 2; the second row of a 2×2 gets none):
/// that term is carried, nothing is stored.
template <int R>
void forwardSchur(const ChainStructure& ws, ChainStructure::SmallMatrix& S) {
  const int n = ws.n;
  const unsigned char* block = ws.blockStart.data();
  const double *pivA = ws.pivA.data(), *pivE = ws.pivE.data(), *l1 = ws.l1.data(), *l2 = ws.l2.data();
  const double* b[R];
  for (int c = 0; c < R; ++c) b[c] = ws.B.col(c).data();
  double carry[R] = {}, z0[R], z1[R], acc[R][R] = {};
  for (int k = 0; k < n;) {
    if (block[k] == 1) {
      const double inv = 1.0 / pivA[k], l = k + 1 < n ? l1[k] : 0.0;
      for (int c = 0; c < R; ++c) {
        z0[c] = b[c][k] - carry[c];
        carry[c] = l * z0[c];
      }
      for (int c = 0; c < R; ++c)
        for (int d = 0; d <= c; ++d) acc[c][d] += z0[c] * z0[d] * inv;
      k += 1;
    } else {
      // [z0 z1] D_b⁻¹ [z0; z1]ᵀ with D_b⁻¹ = [[b, −e], [−e, a]]/det
      const double a = pivA[k], bb = pivA[k + 1], e = pivE[k];
      const double inv = 1.0 / (a * bb - e * e);
      const double m0 = k + 2 < n ? l1[k] : 0.0, m1 = k + 2 < n ? l2[k] : 0.0;
      for (int c = 0; c < R; ++c) {
        z0[c] = b[c][k] - carry[c];
        z1[c] = b[c][k + 1];
        carry[c] = m0 * z0[c] + m1 * z1[c];
      }
      for (int c = 0; c < R; ++c)
        for (int d = 0; d <= c; ++d)
          acc[c][d] += (bb * z0[c] * z0[d] - e * (z0[c] * z1[d] + z1[c] * z0[d]) + a * z1[c] * z1[d]) * inv;
      k += 2;
    }
  }
  S.resize(R, R);
  for (int c = 0; c < R; ++c)
    for (int d = 0; d <= c; ++d) S(c, d) = S(d, c) = acc[c][d];
}

}  // namespace

void structure::factoredSchur(ChainStructure& ws, int r) {
  switch (r) {
    case 1: return forwardSchur<1>(ws, ws.S);
    case 2: return forwardSchur<2>(ws, ws.S);
    case 3: return forwardSchur<3>(ws, ws.S);
    case 4: return forwardSchur<4>(ws, ws.S);
    case 5: return forwardSchur<5>(ws, ws.S);
    case 6: return forwardSchur<6>(ws, ws.S);
    case 7: return forwardSchur<7>(ws, ws.S);
    case 8: return forwardSchur<8>(ws, ws.S);
    default:
      throw std::invalid_argument("factoredSchur: 1 to kMaxBorder border columns (setConstraints, setCoupling), got " +
                                  std::to_string(r));
  }
}

void solveFactored(const ChainStructure& ws, MatrixRef Y, int cols) {
  for (int j = 0; j < cols; ++j) solveFactored(ws, Y.col(j));
}

}  // namespace buckle::mechanics
