#include "buckle/mechanics/chain_structure.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace buckle::mechanics {

namespace {

constexpr double kBunchAlpha = 0.6180339887498949;  // (√5 − 1)/2
constexpr double kTinyPivot = 1e-290;

/// Diagonal of the q-space identity in θ-coordinates, M = U⁻¹U⁻ᵀ (off-diagonal −1).
inline double metricDiagonal(int k, int n) { return k + 1 < n ? 2.0 : 1.0; }

/// Number of negative eigenvalues of a small symmetric matrix (r ≤ kMaxBorder).
int smallNegativeCount(const ChainStructure::SmallMatrix& S) {
  const Eigen::Index r = S.rows();
  if (r == 0) return 0;
  if (r == 1) return S(0, 0) < 0.0 ? 1 : 0;
  if (r == 2) {
    const double mean = 0.5 * (S(0, 0) + S(1, 1));
    const double rad = std::hypot(0.5 * (S(0, 0) - S(1, 1)), 0.5 * (S(0, 1) + S(1, 0)));
    return (mean - rad < 0.0 ? 1 : 0) + (mean + rad < 0.0 ? 1 : 0);
  }
  Eigen::SelfAdjointEigenSolver<ChainStructure::SmallMatrix> es(0.5 * (S + S.transpose()), Eigen::EigenvaluesOnly);
  int neg = 0;
  for (Eigen::Index i = 0; i < r; ++i)
    if (es.eigenvalues()[i] < 0.0) ++neg;
  return neg;
}

/// Solve (T − σM)ξ and the bordered elimination for one right-hand side, with the Schur LU.
template <class LU>
void borderedElimination(ChainStructure& ws, int p, const LU& lu, ConstVectorRef f, ConstVectorRef g, VectorRef x,
                         VectorRef y) {
  const int n = ws.n;
  Vector& t = ws.t1;
  applyUInverse(f, t);
  solveFactored(ws, t);
  ChainStructure::SmallVector rhs(p);
  for (int j = 0; j < p; ++j) rhs[j] = g[j] - ws.W2.col(j).dot(t);
  const ChainStructure::SmallVector yy = lu.solve(rhs);
  for (int j = 0; j < p; ++j) {
    y[j] = yy[j];
    t.noalias() -= yy[j] * ws.V2.col(j);
  }
  applyUInverseTranspose(t, x.head(n));
}

}  // namespace

ChainStructure::ChainStructure(int size)
    : n(size),
      kappa(Vector::Zero(size)),
      h(Vector::Zero(size)),
      diag(Vector::Zero(size)),
      off(Vector::Zero(std::max(size, 1))),
      blockStart(size_t(std::max(size, 1)), 1),
      pivA(Vector::Zero(size)),
      pivE(Vector::Zero(size)),
      l1(Vector::Zero(size)),
      l2(Vector::Zero(size)),
      Q(Matrix::Zero(size, kMaxBorder)),
      B(Matrix::Zero(size, kMaxBorder)),
      X(Matrix::Zero(size, kMaxBorder)),
      V2(Matrix::Zero(size, kMaxBorder)),
      W2(Matrix::Zero(size, kMaxBorder)),
      t1(Vector::Zero(size)),
      t2(Vector::Zero(size)),
      t3(Vector::Zero(size)),
      zeroBorder(Matrix::Zero(kMaxBorder, kMaxBorder)) {
  if (size < 1) throw std::invalid_argument("ChainStructure: n must be >= 1");
}

void assemble(ConstVectorRef kappa, ConstVectorRef h, ChainStructure& ws) {
  const int n = ws.n;
  assert(kappa.size() == n && h.size() == n);
  double fro2 = 0.0;
  for (int m = 0; m < n; ++m) {
    const double km = kappa[m], hm = h[m];
    const double kn = m + 1 < n ? kappa[m + 1] : 0.0;
    const double hn = m + 1 < n ? h[m + 1] : 0.0;
    ws.diag[m] = km + kn - (hm - hn);
    if (m + 1 < n) ws.off[m] = -kn;
    fro2 += (km - hm) * (km - hm) + 2.0 * m * hm * hm;
  }
  if (ws.kappa.data() != kappa.data()) ws.kappa = kappa;
  if (ws.h.data() != h.data()) ws.h = h;
  ws.frobeniusH = std::sqrt(fro2);
}

void assemble(const Chain& chain, const ChainData& data, ConstVectorRef q, const Wrench& F, ChainStructure& ws) {
  jointStiffness(chain, q, ws.kappa);
  loadHessianGenerator(data, F, ws.h);
  assemble(ws.kappa, ws.h, ws);
}

void applyU(ConstVectorRef x, VectorRef y) {
  double s = 0.0;
  for (Eigen::Index i = x.size() - 1; i >= 0; --i) {
    s += x[i];
    y[i] = s;
  }
}

void applyUInverse(ConstVectorRef x, VectorRef y) {
  const Eigen::Index n = x.size();
  for (Eigen::Index i = 0; i + 1 < n; ++i) y[i] = x[i] - x[i + 1];
  y[n - 1] = x[n - 1];
}

void applyUTranspose(ConstVectorRef x, VectorRef y) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    s += x[i];
    y[i] = s;
  }
}

void applyUInverseTranspose(ConstVectorRef x, VectorRef y) {
  for (Eigen::Index i = x.size() - 1; i > 0; --i) y[i] = x[i] - x[i - 1];
  y[0] = x[0];
}

void applyHessian(const ChainStructure& ws, ConstVectorRef x, VectorRef y) {
  const int n = ws.n;
  applyUTranspose(x, y);
  // y ← T y in place, keeping the previous original entry
  double prev = 0.0;
  for (int i = 0; i < n; ++i) {
    const double cur = y[i];
    double v = ws.diag[i] * cur;
    if (i > 0) v += ws.off[i - 1] * prev;
    if (i + 1 < n) v += ws.off[i] * y[i + 1];
    prev = cur;
    y[i] = v;
  }
  applyU(y, y);
}

Matrix tridiagonalMatrix(const ChainStructure& ws) {
  const int n = ws.n;
  Matrix T = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    T(i, i) = ws.diag[i];
    if (i + 1 < n) T(i, i + 1) = T(i + 1, i) = ws.off[i];
  }
  return T;
}

void factorize(ChainStructure& ws, double sigma) {
  const int n = ws.n;
  ws.shift = sigma;
  ws.singular = false;
  ws.factorInertia = Inertia{};
  // det as mantissa · 2^exponent, rescaled occasionally (a log per pivot would dominate the cost)
  double mant = 1.0;
  long expo = 0;
  auto accumulate = [&](double v) {
    mant *= v;
    const double am = std::abs(mant);
    if (am > 1e150 || am < 1e-150) {
      int e2 = 0;
      mant = std::frexp(mant, &e2);
      expo += e2;
    }
  };
  int sign = 1;
  double scale = 0.0;
  for (int k = 0; k < n; ++k) {
    scale = std::max(scale, std::abs(ws.diag[k] - sigma * metricDiagonal(k, n)));
    if (k + 1 < n) scale = std::max(scale, std::abs(ws.off[k] + sigma));
  }
  if (scale == 0.0) scale = 1.0;
  const double pivmin = kTinyPivot * scale;
  double minRatio = std::numeric_limits<double>::infinity();
  auto a = [&](int k) { return ws.diag[k] - sigma * metricDiagonal(k, n); };
  auto e = [&](int k) { return ws.off[k] + sigma; };  // M off-diagonal is −1

  int k = 0;
  double dk = a(0);
  while (k < n) {
    const double ek = k + 1 < n ? e(k) : 0.0;
    if (k + 1 == n || std::abs(dk) * scale >= kBunchAlpha * ek * ek) {
      if (dk == 0.0) {
        dk = -pivmin;
        ws.singular = true;
      }
      ws.blockStart[size_t(k)] = 1;
      ws.pivA[k] = dk;
      if (dk < 0.0) {
        ++ws.factorInertia.negative;
        sign = -sign;
      } else {
        ++ws.factorInertia.positive;
      }
      accumulate(dk);
      minRatio = std::min(minRatio, std::abs(dk) / scale);
      if (k + 1 < n) {
        ws.l1[k] = ek / dk;
        dk = a(k + 1) - ek * ws.l1[k];
      }
      k += 1;
    } else {
      // 2×2 pivot [[dk, ek], [ek, a_{k+1}]]: det < −(1 − α) ek² < 0, one eigenvalue of each sign.
      const double b = a(k + 1);
      const double det = dk * b - ek * ek;
      ws.blockStart[size_t(k)] = 2;
      ws.blockStart[size_t(k) + 1] = 0;
      ws.pivA[k] = dk;
      ws.pivA[k + 1] = b;
      ws.pivE[k] = ek;
      ++ws.factorInertia.negative;
      ++ws.factorInertia.positive;
      sign = -sign;
      accumulate(det);
      // smallest |eigenvalue| of the block ≥ |det| / (largest |eigenvalue|)
      const double big = 0.5 * std::abs(dk + b) + std::hypot(0.5 * (dk - b), ek);
      minRatio = std::min(minRatio, std::abs(det) / (big * scale));
      if (k + 2 < n) {
        const double ek1 = e(k + 1);
        ws.l1[k] = -ek1 * ek / det;
        ws.l2[k] = ek1 * dk / det;
        dk = a(k + 2) - ek1 * ek1 * dk / det;
      }
      k += 2;
    }
  }
  ws.minPivotRatio = minRatio;
  ws.logAbsDet = std::log(std::abs(mant)) + double(expo) * 0.6931471805599453;
  ws.detSign = sign;
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
  // forward: L
  for (int k = 0; k < n;) {
    if (ws.blockStart[size_t(k)] == 1) {
      if (k + 1 < n) y[k + 1] -= ws.l1[k] * y[k];
      k += 1;
    } else {
      if (k + 2 < n) y[k + 2] -= ws.l1[k] * y[k] + ws.l2[k] * y[k + 1];
      k += 2;
    }
  }
  // block diagonal
  for (int k = 0; k < n;) {
    if (ws.blockStart[size_t(k)] == 1) {
      y[k] /= ws.pivA[k];
      k += 1;
    } else {
      const double a = ws.pivA[k], b = ws.pivA[k + 1], e = ws.pivE[k];
      const double det = a * b - e * e;
      const double y0 = y[k], y1 = y[k + 1];
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

void solveFactored(const ChainStructure& ws, MatrixRef Y, int cols) {
  for (int j = 0; j < cols; ++j) solveFactored(ws, Y.col(j));
}

double zeroThreshold(const ChainStructure& ws, double zeroTolerance) {
  return zeroTolerance * std::max(ws.typicalScale, ws.frobeniusH);  // the same count in any units
}

Inertia hessianInertia(const ChainStructure& ws, double zeroTolerance) {
  const double tau = zeroThreshold(ws, zeroTolerance);
  Inertia in;
  const int below = countBelow(ws, -tau);
  const int belowPlus = countBelow(ws, tau);
  in.negative = below;
  in.zero = belowPlus - below;
  in.positive = ws.n - belowPlus;
  return in;
}

int setConstraints(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, double rankTolerance) {
  const int n = ws.n;
  if (C.rows() > ChainStructure::kMaxBorder - 1 || (C.rows() > 0 && C.cols() != n))
    throw std::invalid_argument("setConstraints: C must be m×n with m <= 3");
  double maxNorm = 0.0;
  for (Eigen::Index i = 0; i < C.rows(); ++i) maxNorm = std::max(maxNorm, C.row(i).norm());
  int r = 0;
  if (maxNorm > 0.0) {
    for (Eigen::Index i = 0; i < C.rows(); ++i) {
      auto qr = ws.Q.col(r);
      qr = C.row(i).transpose();
      for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j < r; ++j) qr -= ws.Q.col(j).dot(qr) * ws.Q.col(j);
      const double nrm = qr.norm();
      if (nrm <= rankTolerance * maxNorm) continue;
      qr /= nrm;
      applyUInverse(qr, ws.B.col(r));
      ++r;
    }
  }
  ws.rank = r;
  return r;
}

int constrainedCountBelow(ChainStructure& ws, double sigma) {
  const int r = ws.rank;
  factorize(ws, sigma);
  if (r == 0) return ws.factorInertia.negative;
  ws.X.leftCols(r) = ws.B.leftCols(r);
  solveFactored(ws, ws.X, r);
  ws.S.resize(r, r);
  // (product, then negate in place: −(BᵀX) as one expression evaluated the product into a heap
  // temporary on every call)
  ws.S.noalias() = ws.B.leftCols(r).transpose() * ws.X.leftCols(r);
  ws.S = -ws.S;
  return ws.factorInertia.negative + smallNegativeCount(ws.S) - r;
}

namespace {

/// Constrained count at σ0, moving σ within [σ0/2, 2σ0] when T − σM is nearly singular.
int robustConstrainedCount(ChainStructure& ws, double sigma0) {
  static constexpr double factors[] = {1.0, 1.5, 0.7, 2.0, 0.5, 1.25, 0.85};
  double bestRatio = -1.0, bestFactor = 1.0;
  int bestCount = 0;
  for (double f : factors) {
    const int c = constrainedCountBelow(ws, sigma0 * f);
    if (ws.minPivotRatio >= 1e-10 && !ws.singular) return c;
    if (ws.minPivotRatio > bestRatio) {
      bestRatio = ws.minPivotRatio;
      bestFactor = f;
      bestCount = c;
    }
  }
  (void)bestFactor;
  return bestCount;
}

}  // namespace

Inertia constrainedInertia(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, double zeroTolerance,
                           double rankTolerance) {
  const int r = C.rows() > 0 ? setConstraints(ws, C, rankTolerance) : (ws.rank = 0);
  if (r == 0) return hessianInertia(ws, zeroTolerance);
  const double tau = zeroThreshold(ws, zeroTolerance);
  const int below = robustConstrainedCount(ws, -tau);
  const int belowPlus = robustConstrainedCount(ws, tau);
  Inertia in;
  in.negative = below;
  in.zero = belowPlus - below;
  in.positive = (ws.n - r) - belowPlus;
  return in;
}

namespace {

/// Count below σ and log|det|, sign of det K_σ (or of det(T − σM) without constraints).
struct ShiftEvaluation {
  int below = 0;
  double logAbsDet = 0.0;
  int sign = 1;
};

ShiftEvaluation evaluateShift(ChainStructure& ws, bool useConstraints, double sigma) {
  ShiftEvaluation ev;
  const int r = useConstraints ? ws.rank : 0;
  if (r == 0) {
    factorize(ws, sigma);
    ev.below = ws.factorInertia.negative;
    ev.logAbsDet = ws.logAbsDet;
    ev.sign = ws.detSign;
    return ev;
  }
  ev.below = constrainedCountBelow(ws, sigma);
  const double detS = ws.S.determinant();
  ev.logAbsDet = ws.logAbsDet + std::log(std::abs(detS));
  ev.sign = ws.detSign * (detS < 0.0 ? -1 : 1);
  return ev;
}

}  // namespace

int lowestEigenvalues(ChainStructure& ws, bool useConstraints, int count, VectorRef out, double tolerance,
                      const Vector* guess) {
  const int dim = ws.n - (useConstraints ? ws.rank : 0);
  const int k = std::max(0, std::min(count, dim));
  if (k == 0) return 0;
  const double scale = std::max(ws.typicalScale, ws.frobeniusH);  // as zeroThreshold: any units
  const double tol = tolerance * scale;
  // All eigenvalues lie in [−‖H‖_F, ‖H‖_F]; widen against rounding until the counts confirm it.
  double lo0 = -ws.frobeniusH * (1.0 + 1e-10) - tol, hi0 = ws.frobeniusH * (1.0 + 1e-10) + tol;
  while (evaluateShift(ws, useConstraints, lo0).below > 0) lo0 = 2.0 * lo0 - scale;
  while (evaluateShift(ws, useConstraints, hi0).below < k) hi0 = 2.0 * hi0 + scale;
  // Brackets: eigenvalue j lies in [lo[j], hi[j]) with count(lo[j]) ≤ j < count(hi[j]).
  ChainStructure::SmallVector lo = ChainStructure::SmallVector::Constant(k, lo0);
  ChainStructure::SmallVector hi = ChainStructure::SmallVector::Constant(k, hi0);
  ChainStructure::SmallVector cntLo = ChainStructure::SmallVector::Zero(k);
  ChainStructure::SmallVector cntHi = ChainStructure::SmallVector::Constant(k, double(dim));
  auto record = [&](double s, int c) {
    for (int j = 0; j < k; ++j) {
      if (c > j) {
        if (s < hi[j]) { hi[j] = s; cntHi[j] = c; }
      } else if (s > lo[j]) {
        lo[j] = s;
        cntLo[j] = c;
      }
    }
  };
  for (int j = 0; j < k; ++j) {
    lo[j] = std::max(lo[j], j > 0 ? out[j - 1] - tol : lo[j]);
    // Warm start (e.g. the previous continuation point): a few counts around the guess.
    if (guess && j < guess->size() && std::isfinite((*guess)[j]) && (*guess)[j] > lo[j] && (*guess)[j] < hi[j]) {
      double delta = std::max(1e-3 * scale, 0.02 * std::abs((*guess)[j]));
      for (int attempt = 0; attempt < 3 && !(int(cntLo[j]) == j && int(cntHi[j]) == j + 1); ++attempt, delta *= 8.0) {
        const double a = (*guess)[j] - delta, b = (*guess)[j] + delta;
        if (a > lo[j]) record(a, evaluateShift(ws, useConstraints, a).below);
        if (b < hi[j]) record(b, evaluateShift(ws, useConstraints, b).below);
      }
    }
    // isolate: exactly one eigenvalue (j) in [lo, hi)
    while (!(int(cntLo[j]) == j && int(cntHi[j]) == j + 1) && hi[j] - lo[j] > tol) {
      const double mid = 0.5 * (lo[j] + hi[j]);
      if (mid <= lo[j] || mid >= hi[j]) break;
      record(mid, evaluateShift(ws, useConstraints, mid).below);
    }
    if (int(cntLo[j]) == j && int(cntHi[j]) == j + 1 && hi[j] - lo[j] > tol) {
      // Illinois on det, one simple root in the bracket; the counts keep the bracket honest.
      ShiftEvaluation ea = evaluateShift(ws, useConstraints, lo[j]);
      ShiftEvaluation eb = evaluateShift(ws, useConstraints, hi[j]);
      const double ref = 0.5 * (ea.logAbsDet + eb.logAbsDet);
      auto value = [&](const ShiftEvaluation& e) {
        return e.sign * std::exp(std::max(-700.0, std::min(700.0, e.logAbsDet - ref)));
      };
      double a = lo[j], b = hi[j], fa = value(ea), fb = value(eb);
      int side = 0;
      for (int it = 0; it < 200 && b - a > tol; ++it) {
        double c = (fa * b - fb * a) / (fa - fb);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        // keep progress: never closer than tol/2 to an end
        c = std::min(std::max(c, a + 0.25 * tol), b - 0.25 * tol);
        const ShiftEvaluation ec = evaluateShift(ws, useConstraints, c);
        const double fc = value(ec);
        if (ec.below > j) {  // the root is below c
          b = c;
          fb = fc;
          if (side == -1) fa *= 0.5;
          side = -1;
        } else {
          a = c;
          fa = fc;
          if (side == 1) fb *= 0.5;
          side = 1;
        }
        if (fc == 0.0) {
          a = b = c;
          break;
        }
      }
      lo[j] = a;
      hi[j] = b;
    }
    out[j] = 0.5 * (lo[j] + hi[j]);
  }
  return k;
}

double smallestEigenvalue(ChainStructure& ws, bool useConstraints, double tolerance) {
  Eigen::Matrix<double, 1, 1> out;
  return lowestEigenvalues(ws, useConstraints, 1, out, tolerance, nullptr) == 1 ? out[0] : 0.0;
}

Inertia smallDenseInertia(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, int count, VectorRef lowest,
                          int& found, double zeroTolerance, double rankTolerance) {
  using SM = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmallDense, kSmallDense>;
  const int n = ws.n;
  if (n > kSmallDense) throw std::invalid_argument("smallDenseInertia: n > kSmallDense");
  const int r = C.rows() > 0 ? setConstraints(ws, C, rankTolerance) : (ws.rank = 0);
  SM A(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) A(i, j) = -ws.h[std::max(i, j)];
  for (int i = 0; i < n; ++i) A(i, i) += ws.kappa[i];
  // Householder reflectors P_j map the orthonormal Q onto the first r coordinates; then
  // ker C ↔ the last d coordinates and Zᵀ H Z is the trailing d×d block of P H P.
  SM Qw = ws.Q.topLeftCorner(n, r);
  double v[kSmallDense];
  for (int j = 0; j < r; ++j) {
    const int len = n - j;
    double norm2 = 0.0;
    for (int i = 0; i < len; ++i) {
      v[i] = Qw(j + i, j);
      norm2 += v[i] * v[i];
    }
    const double alpha = v[0] >= 0.0 ? -std::sqrt(norm2) : std::sqrt(norm2);
    v[0] -= alpha;
    double beta = 0.0;
    for (int i = 0; i < len; ++i) beta += v[i] * v[i];
    if (beta == 0.0) continue;
    const double f = 2.0 / beta;
    for (int c = 0; c < r; ++c) {  // Qw ← P Qw
      double dot = 0.0;
      for (int i = 0; i < len; ++i) dot += v[i] * Qw(j + i, c);
      for (int i = 0; i < len; ++i) Qw(j + i, c) -= f * dot * v[i];
    }
    for (int c = 0; c < n; ++c) {  // A ← P A
      double dot = 0.0;
      for (int i = 0; i < len; ++i) dot += v[i] * A(j + i, c);
      for (int i = 0; i < len; ++i) A(j + i, c) -= f * dot * v[i];
    }
    for (int c = 0; c < n; ++c) {  // A ← A P
      double dot = 0.0;
      for (int i = 0; i < len; ++i) dot += A(c, j + i) * v[i];
      for (int i = 0; i < len; ++i) A(c, j + i) -= f * dot * v[i];
    }
  }
  const int d = n - r;
  Inertia in;
  found = std::min(count, d);
  if (d == 0) return in;
  SM S = A.bottomRightCorner(d, d);
  double mu[kSmallDense];
  if (d > 4) {
    // Larger blocks: Eigen's tridiagonal QR (Jacobi's O(d³) sweeps lose from d ≈ 5 on).
    Eigen::SelfAdjointEigenSolver<SM> es(S, Eigen::EigenvaluesOnly);
    for (int i = 0; i < d; ++i) mu[i] = es.eigenvalues()[i];
  } else {
    // Cyclic Jacobi: accurate and, for blocks up to 4×4, cheaper than a QR solver.
    double total = 0.0;
    for (int j = 0; j < d; ++j)
      for (int i = 0; i < d; ++i) total += S(i, j) * S(i, j);
    for (int sweep = 0; sweep < 60; ++sweep) {
      double off = 0.0;
      for (int q = 1; q < d; ++q)
        for (int p = 0; p < q; ++p) off += S(p, q) * S(p, q);
      if (off <= 1e-34 * total || off == 0.0) break;
      for (int q = 1; q < d; ++q)
        for (int p = 0; p < q; ++p) {
          const double apq = S(p, q);
          if (apq == 0.0) continue;
          const double theta = (S(q, q) - S(p, p)) / (2.0 * apq);
          const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
          const double c = 1.0 / std::sqrt(t * t + 1.0), sn = t * c;
          S(p, p) -= t * apq;
          S(q, q) += t * apq;
          S(p, q) = S(q, p) = 0.0;
          for (int k = 0; k < d; ++k) {
            if (k == p || k == q) continue;
            const double skp = S(k, p), skq = S(k, q);
            S(k, p) = S(p, k) = c * skp - sn * skq;
            S(k, q) = S(q, k) = sn * skp + c * skq;
          }
        }
    }
    for (int i = 0; i < d; ++i) mu[i] = S(i, i);
    std::sort(mu, mu + d);
  }
  double maxAbs = 0.0;
  for (int i = 0; i < d; ++i) maxAbs = std::max(maxAbs, std::abs(mu[i]));
  const double tol = zeroTolerance * std::max(ws.typicalScale, maxAbs);  // the same count in any units
  for (int i = 0; i < d; ++i) {
    if (std::abs(mu[i]) <= tol) ++in.zero;
    else if (mu[i] < 0.0) ++in.negative;
    else ++in.positive;
  }
  for (int i = 0; i < found; ++i) lowest[i] = mu[i];
  return in;
}

bool solve(ChainStructure& ws, ConstVectorRef r, VectorRef x) {
  factorize(ws, 0.0);
  if (ws.singular) return false;
  applyUInverse(r, x);
  solveFactored(ws, x);
  applyUInverseTranspose(x, x);
  return x.allFinite();
}

bool factorBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                    const Eigen::Ref<const Matrix>& D) {
  const int n = ws.n;
  const int p = int(V.cols());
  if (p > ChainStructure::kMaxBorder || W.cols() != p || D.rows() != p || D.cols() != p || V.rows() != n ||
      W.rows() != n)
    throw std::invalid_argument("factorBordered: V, W must be n×p and D p×p with p <= 4");
  ws.borderSize = -1;
  factorize(ws, 0.0);
  if (ws.singular) return false;
  for (int j = 0; j < p; ++j) {
    applyUInverse(V.col(j), ws.V2.col(j));
    applyUInverse(W.col(j), ws.W2.col(j));
  }
  solveFactored(ws, ws.V2, p);
  // det [[H, V], [Wᵀ, D]] = det H · det S with det H = det T (det U = 1).
  ws.schur.resize(p, p);
  if (p > 0) {  // (an empty matrix is not valid LU input)
    ws.schur.noalias() = D - ws.W2.leftCols(p).transpose() * ws.V2.leftCols(p);
    ws.schurLU.compute(ws.schur);
    if (!ws.schurLU.isInvertible()) return false;
  }
  ws.borderSize = p;
  ws.borderedLogAbsDet = ws.logAbsDet;
  ws.borderedDetSign = ws.detSign;
  if (p > 0) {
    const double detS = ws.schurLU.determinant();
    ws.borderedLogAbsDet += std::log(std::abs(detS));
    if (detS < 0.0) ws.borderedDetSign = -ws.borderedDetSign;
  }
  return true;
}

bool solveFactoredBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                           const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x,
                           VectorRef y) {
  const int n = ws.n;
  const int p = int(V.cols());
  if (ws.borderSize != p) throw std::logic_error("solveFactoredBordered: factorBordered was not called for this border");
  if (p == 0) {
    applyUInverse(f, x);
    solveFactored(ws, x);
    applyUInverseTranspose(x, x);
    return x.allFinite();
  }
  borderedElimination(ws, p, ws.schurLU, f, g, x, y);
  // One step of iterative refinement with the exact O(n) residual.
  Vector& r1 = ws.t2;
  applyHessian(ws, x.head(n), r1);
  r1 = f - r1;
  r1.noalias() -= V * y.head(p);
  ChainStructure::SmallVector r2 = g.head(p);
  r2.noalias() -= W.transpose() * x.head(n);
  r2.noalias() -= D * y.head(p);
  Vector& dx = ws.t3;
  ChainStructure::SmallVector dy(p);
  borderedElimination(ws, p, ws.schurLU, r1, r2, dx, dy);
  x.head(n) += dx;
  y.head(p) += dy;
  return x.allFinite() && y.allFinite();
}

bool solveBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                   const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x, VectorRef y) {
  return factorBordered(ws, V, W, D) && solveFactoredBordered(ws, V, W, D, f, g, x, y);
}

bool solveKKT(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, ConstVectorRef f, ConstVectorRef g, VectorRef x,
              VectorRef y) {
  const int m = int(C.rows());
  if (m > ChainStructure::kMaxBorder) throw std::invalid_argument("solveKKT: at most 4 constraint rows");
  ws.X.leftCols(m) = C.transpose();
  ws.zeroBorder.setZero();
  return solveBordered(ws, ws.X.leftCols(m), ws.X.leftCols(m), ws.zeroBorder.topLeftCorner(m, m), f, g, x, y);
}

}  // namespace buckle::mechanics
