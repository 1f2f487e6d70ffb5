// Inertia and lowest eigenvalues of H and of H on the null space of held rows, by O(n) counts
// on the chain structure (chain_structure.h, "factorization and counts"); the small dense route.
#include "buckle/mechanics/chain_structure.h"
#include "eigenvalue_search.h"
#include "structure_kernels.h"

#include <array>
#include <cstdint>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace buckle::mechanics {

namespace {

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

/// The border columns the constrained counts take: the rank of C and the coupling's.
int borderCount(const ChainStructure& ws, bool useConstraints) {
  return useConstraints ? ws.rank + ws.couplingCount : 0;
}

/// #{E_jj > 0}: the negative eigenvalues of the coupling's block −E (setCoupling).
int couplingNegative(const ChainStructure& ws) {
  int count = 0;
  for (int j = 0; j < ws.couplingCount; ++j) count += ws.couplingSign[j] > 0.0 ? 1 : 0;
  return count;
}

/// S += sign · diag(0_r, E) on the coupling's rows.
void addCouplingBlock(const ChainStructure& ws, double sign, ChainStructure::SmallMatrix& S) {
  for (int j = 0; j < ws.couplingCount; ++j) S(ws.rank + j, ws.rank + j) += sign * ws.couplingSign[j];
}

}  // namespace

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
  if (C.rows() > 3 || (C.rows() > 0 && C.cols() != n))
    throw std::invalid_argument("setConstraints: C must be m×n with m <= 3");
  const int r = structure::orthonormaliseRows(C, ws.Q, ws.B, rankTolerance);
  ws.rank = r;
  ws.couplingCount = 0;
  return r;
}

void setCoupling(ChainStructure& ws, const Eigen::Ref<const Matrix>& R, const Eigen::Ref<const Vector>& signs) {
  ws.couplingCount = structure::setCouplingColumns("setCoupling", R, signs, ws.rank, ws.B, ws.couplingSign);
}

int constrainedCountBelow(ChainStructure& ws, double sigma, bool determinant) {
  const int r = ws.rank, b = borderCount(ws, true);
  factorize(ws, sigma, determinant);
  if (b == 0) return ws.factorInertia.negative;
  if (!determinant) {
    // a count reads S alone: the factor's forward sweep gives it without the solve for X
    structure::factoredSchur(ws, b);
    ws.S = -ws.S;
  } else {
    ws.X.leftCols(b) = ws.B.leftCols(b);
    solveFactored(ws, ws.X, b);
    ws.S.resize(b, b);
    // b ≤ kMaxBorder dot products of length n: coefficient-wise (a general matrix product would
    // pack both n×b operands for a few entries, and −(BᵀX) as one expression allocated a temporary)
    ws.S.noalias() = -ws.B.leftCols(b).transpose().lazyProduct(ws.X.leftCols(b));
  }
  addCouplingBlock(ws, -1.0, ws.S);  // S = diag(0, −E) − BᵀX (setCoupling)
  return ws.factorInertia.negative + smallNegativeCount(ws.S) - r - couplingNegative(ws);
}

namespace {

/// Constrained count at σ0, moving σ within [σ0/2, 2σ0] when T − σM is nearly singular.
int robustConstrainedCount(ChainStructure& ws, double sigma0) {
  static constexpr double factors[] = {1.0, 1.5, 0.7, 2.0, 0.5, 1.25, 0.85};
  double bestRatio = -1.0, bestFactor = 1.0;
  int bestCount = 0;
  for (double f : factors) {
    const int c = constrainedCountBelow(ws, sigma0 * f, false);  // a count: no determinant
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
  if (C.rows() > 0)
    setConstraints(ws, C, rankTolerance);
  else
    ws.rank = ws.couplingCount = 0;
  return borderedInertia(ws, zeroTolerance);
}

Inertia borderedInertia(ChainStructure& ws, double zeroTolerance) {
  const int r = ws.rank;
  if (borderCount(ws, true) == 0) return hessianInertia(ws, zeroTolerance);
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

using search::ShiftEvaluation;

ShiftEvaluation evaluateShift(ChainStructure& ws, bool useConstraints, double sigma, bool countOnly) {
  ShiftEvaluation ev;
  const int r = borderCount(ws, useConstraints);  // S's size: the constraints' and the coupling's columns
  if (countOnly) {
    // the same factorization's inertia without the determinant's products and derivative
    ev.below = r == 0 ? (factorize(ws, sigma, false), ws.factorInertia.negative) : constrainedCountBelow(ws, sigma, false);
    ev.determinant = false;
    return ev;
  }
  if (r == 0) {
    factorize(ws, sigma);
    ev.below = ws.factorInertia.negative;
    ev.logAbsDet = ws.logAbsDet;
    ev.sign = ws.detSign;
    ev.dLog = ws.dLogAbsDet;
    return ev;
  }
  ev.below = constrainedCountBelow(ws, sigma);
  const double detS = ws.S.determinant();
  ev.logAbsDet = ws.logAbsDet + std::log(std::abs(detS));
  ev.sign = ws.detSign * (detS < 0.0 ? -1 : 1);
  // det K_σ = det(T − σM)·det S, S = diag(0, −E) − BᵀX with X = (T − σM)⁻¹B: S' = −XᵀMX (M tridiagonal:
  // diagonal 2, …, 2, 1, off-diagonal −1), and (log|det S|)' = tr(S⁻¹S').
  const int n = ws.n;
  ChainStructure::SmallMatrix dS(r, r);
  for (int b = 0; b < r; ++b) {
    const auto xb = ws.X.col(b);
    for (int a = 0; a <= b; ++a) {
      const auto xa = ws.X.col(a);
      double sum = 0.0;
      for (int i = 0; i < n; ++i) {
        double mx = (i + 1 < n ? 2.0 : 1.0) * xb[i];
        if (i > 0) mx -= xb[i - 1];
        if (i + 1 < n) mx -= xb[i + 1];
        sum += xa[i] * mx;
      }
      dS(a, b) = dS(b, a) = -sum;
    }
  }
  ev.dLog = ws.dLogAbsDet + Eigen::PartialPivLU<ChainStructure::SmallMatrix>(ws.S).solve(dS).trace();
  return ev;
}

}  // namespace

int eigenvaluesFrom(ChainStructure& ws, bool useConstraints, int first, int count, VectorRef out, double tolerance,
                    const Vector* guess) {
  const int dim = ws.n - (useConstraints ? ws.rank : 0);
  const double scale = std::max(ws.typicalScale, ws.frobeniusH);  // as zeroThreshold: any units
  return search::searchEigenvalues([&](double s, bool countOnly) { return evaluateShift(ws, useConstraints, s, countOnly); },
                                   dim, scale,
                                   ws.frobeniusH, first, count, out, tolerance, guess);
}

int lowestEigenvalues(ChainStructure& ws, bool useConstraints, int count, VectorRef out, double tolerance,
                      const Vector* guess) {
  return eigenvaluesFrom(ws, useConstraints, 0, count, out, tolerance, guess);
}

double smallestEigenvalue(ChainStructure& ws, bool useConstraints, double tolerance) {
  Eigen::Matrix<double, 1, 1> out;
  return lowestEigenvalues(ws, useConstraints, 1, out, tolerance, nullptr) == 1 ? out[0] : 0.0;
}

namespace {

bool inverseIteration(ChainStructure& ws, bool useConstraints, double sigma, VectorRef v, int iterations) {
  const int n = ws.n, r = borderCount(ws, useConstraints);
  if (v.size() != n || !std::isfinite(sigma)) return false;
  factorize(ws, sigma, false);
  if (ws.singular) {
    // An exactly zero pivot stands in the factor as the counts' floor (kTinyPivot of the scale),
    // whose inverse would overflow the solves; for inverse iteration it is the direction wanted,
    // amplified by 1/ε as by a pivot of rounding size.
    const double floor = 1e-200 * std::max(ws.typicalScale, ws.frobeniusH);
    const double rounding = std::numeric_limits<double>::epsilon() * std::max(ws.typicalScale, ws.frobeniusH);
    for (int k = 0; k < n; ++k)
      if (ws.blockStart[size_t(k)] == 1 && std::abs(ws.pivA[k]) < floor) ws.pivA[k] = -rounding;
  }
  // (H − σI) x + Q y = v, Qᵀx = 0 with H − σI = U (T − σM) Uᵀ and z = Uᵀx, B = U⁻¹Q:
  //   (T − σM) z + B y = U⁻¹ v,  Bᵀz = 0,  x = U⁻ᵀ z,
  // by the Schur complement S = Bᵀ(T − σM)⁻¹B of the r ≤ 3 border columns; with a coupling
  // (setCoupling) its rows read Bᵀz − E y = 0 and S gains diag(0, E).
  if (r > 0) {
    ws.X.leftCols(r) = ws.B.leftCols(r);
    solveFactored(ws, ws.X, r);
    ws.S.resize(r, r);
    ws.S.noalias() = ws.B.leftCols(r).transpose().lazyProduct(ws.X.leftCols(r));
    if (useConstraints) addCouplingBlock(ws, 1.0, ws.S);
  }
  // S is nearly singular at σ (that is what an eigenvalue on ker C means): partial pivoting
  // divides by its small pivot, which is the amplification wanted; a rank-revealing LU would zero
  // the very component that carries the eigenvector.
  const Eigen::PartialPivLU<ChainStructure::SmallMatrix> schur =
      r > 0 ? Eigen::PartialPivLU<ChainStructure::SmallMatrix>(ws.S) : Eigen::PartialPivLU<ChainStructure::SmallMatrix>();
  // A fixed start with no structure of its own (no eigenvector of a chain is orthogonal to it
  // but by accident), the same every call: the same vector for the same point.
  std::uint32_t state = 2463534242u;
  for (int i = 0; i < n; ++i) {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    v[i] = double(state) / 4294967296.0 - 0.5;
  }
  auto g = ws.t1.head(n);
  for (int it = 0; it < iterations; ++it) {
    applyUInverse(v, g);
    solveFactored(ws, g);
    if (r > 0) {
      ChainStructure::SmallVector rhs(r);
      rhs.noalias() = ws.B.leftCols(r).transpose() * g;
      const ChainStructure::SmallVector y = schur.solve(rhs);
      g.noalias() -= ws.X.leftCols(r) * y;
    }
    applyUInverseTranspose(g, v);
    const double norm = v.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return false;
    v /= norm;
  }
  return true;
}

}  // namespace

bool eigenvectorAt(ChainStructure& ws, bool useConstraints, double sigma, VectorRef v, int iterations) {
  // σ on the eigenvalue to the last bit can make a pivot of T − σM exactly zero (replaced by the
  // floor, whose inverse overflows): a shift by a few units of rounding leaves the vector as it is.
  const double nudge = 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(sigma), ws.frobeniusH);
  for (int attempt = 0; attempt < 3; ++attempt)
    if (inverseIteration(ws, useConstraints, sigma + attempt * nudge, v, iterations)) return true;
  return false;
}

namespace {

// smallDenseInertia after setConstraints (rank r, orthonormal rows in ws.Q). N > 0 is the chain
// length at compile time: the same arithmetic in the same order (bitwise the same eigenvalues),
// but with fixed trip counts the loops unroll. For n = 3 the generic loops' set-up and
// vectorisation prologues cost ~1.2 k instructions per call against ~0.3 k unrolled
// (benchmarks/RESULTS.md, "Cheaper points, round 5"); N = 0 takes n = ws.n at run time.
template <int N>
Inertia denseConstrainedSpectrum(ChainStructure& ws, int r, int count, VectorRef lowest, int& found,
                                 double zeroTolerance) {
  constexpr int kMax = N > 0 ? N : kSmallDense;
  using SM = std::conditional_t<(N > 0), Eigen::Matrix<double, kMax, kMax>,
                                Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMax, kMax>>;
  using Block = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMax, kMax>;
  const int n = N > 0 ? N : ws.n;
  SM A(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) A(i, j) = -ws.h[std::max(i, j)];
  for (int i = 0; i < n; ++i) A(i, i) += ws.kappa[i];
  // Householder reflectors P_j map the orthonormal Q onto the first r coordinates; then
  // ker C ↔ the last d coordinates and Zᵀ H Z is the trailing d×d block of P H P.
  Block Qw = ws.Q.topLeftCorner(n, r);
  double v[kMax];
  // v is indexed by row. At a compile-time size the reflector's products run over all n rows, v
  // zero above row j: adding or subtracting those exact zeros changes no value (at most the sign
  // of a zero entry), and the fixed trip counts unroll (≈ 300 fewer instructions per call at
  // n = 3). At a run-time size they run over rows j … n − 1 only.
  for (int j = 0; j < r; ++j) {
    const int lo = N > 0 ? 0 : j;
    for (int i = lo; i < j; ++i) v[i] = 0.0;
    double norm2 = 0.0;
    for (int i = j; i < n; ++i) {
      v[i] = Qw(i, j);
      norm2 += v[i] * v[i];
    }
    const double alpha = v[j] >= 0.0 ? -std::sqrt(norm2) : std::sqrt(norm2);
    v[j] -= alpha;
    double beta = 0.0;
    for (int i = j; i < n; ++i) beta += v[i] * v[i];
    if (beta == 0.0) continue;
    const double f = 2.0 / beta;
    for (int c = 0; c < r; ++c) {  // Qw ← P Qw
      double dot = 0.0;
      for (int i = lo; i < n; ++i) dot += v[i] * Qw(i, c);
      for (int i = lo; i < n; ++i) Qw(i, c) -= f * dot * v[i];
    }
    for (int c = 0; c < n; ++c) {  // A ← P A
      double dot = 0.0;
      for (int i = lo; i < n; ++i) dot += v[i] * A(i, c);
      for (int i = lo; i < n; ++i) A(i, c) -= f * dot * v[i];
    }
    for (int c = 0; c < n; ++c) {  // A ← A P
      double dot = 0.0;
      for (int i = lo; i < n; ++i) dot += A(c, i) * v[i];
      for (int i = lo; i < n; ++i) A(c, i) -= f * dot * v[i];
    }
  }
  const int d = n - r;
  Inertia in;
  found = std::min(count, d);
  if (d == 0) return in;
  Block S = A.bottomRightCorner(d, d);
  double mu[kMax];
  if (d > 4) {
    // Larger blocks: Eigen's tridiagonal QR (Jacobi's O(d³) sweeps lose from d ≈ 5 on).
    Eigen::SelfAdjointEigenSolver<Block> es(S, Eigen::EigenvaluesOnly);
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
    for (int i = 1; i < d; ++i)  // insertion sort of d ≤ 4 values (std::sort's 16-wide pass
      for (int j = i; j > 0 && mu[j - 1] > mu[j]; --j) std::swap(mu[j - 1], mu[j]);  // overruns mu[N])
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

}  // namespace

Inertia smallDenseInertia(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, int count, VectorRef lowest,
                          int& found, double zeroTolerance, double rankTolerance) {
  const int n = ws.n;
  if (n > kSmallDense) throw std::invalid_argument("smallDenseInertia: n > kSmallDense");
  const int r = C.rows() > 0 ? setConstraints(ws, C, rankTolerance) : (ws.rank = 0);
  switch (n) {  // the short chains of the continuation hot path: unrolled
    case 2: return denseConstrainedSpectrum<2>(ws, r, count, lowest, found, zeroTolerance);
    case 3: return denseConstrainedSpectrum<3>(ws, r, count, lowest, found, zeroTolerance);
    case 4: return denseConstrainedSpectrum<4>(ws, r, count, lowest, found, zeroTolerance);
    default: return denseConstrainedSpectrum<0>(ws, r, count, lowest, found, zeroTolerance);
  }
}

}  // namespace buckle::mechanics
