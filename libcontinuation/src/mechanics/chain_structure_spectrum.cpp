// Inertia and lowest eigenvalues of H and of H on the null space of held rows, by O(n) counts
// on the chain structure (chain_structure.h, "factorization and counts"); the small dense route.
#include "buckle/continuation/root_finding.h"
#include "buckle/mechanics/chain_structure.h"

#include <array>
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

int constrainedCountBelow(ChainStructure& ws, double sigma, bool determinant) {
  const int r = ws.rank;
  factorize(ws, sigma, determinant);
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

/// Count below σ and log|det|, sign of det K_σ (or of det(T − σM) without constraints), and the
/// logarithmic derivative d log|det|/dσ: det K_σ = c·Π(ν_j − σ) over the eigenvalues ν_j wanted
/// (chain_structure.h), so σ − 1/dLog is Newton's step towards the nearest of them.
struct ShiftEvaluation {
  int below = 0;
  double logAbsDet = 0.0;
  int sign = 1;
  double dLog = 0.0;
};

ShiftEvaluation evaluateShift(ChainStructure& ws, bool useConstraints, double sigma) {
  ShiftEvaluation ev;
  const int r = useConstraints ? ws.rank : 0;
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
  // det K_σ = det(T − σM)·det S, S = −BᵀX with X = (T − σM)⁻¹B: S' = −XᵀMX (M tridiagonal:
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

/// Newton on det K_σ from σ0 towards eigenvalue `index` (ascending, counted by the evaluations),
/// every evaluation narrowing (lo, hi) by its count. True when a step fell below tol/4 and counts
/// isolate the eigenvalue in a bracket of width < tol around the limit: `record` has then seen
/// shifts a, b with count(a) = index, count(b) = index + 1, b − a < tol. False (the caller's
/// isolation and Illinois polish take over from what was recorded) when an iterate leaves the
/// bracket, a step fails to halve the one before (Newton far from the root, on the flat part
/// of a polynomial with many roots), or after `maxSteps` evaluations.
template <class Record>
bool newtonFrom(ChainStructure& ws, bool useConstraints, int index, double sigma0, double tol, int maxSteps,
                double lo, double hi, Record&& record) {
  int countLo = -1, countHi = -1;  // counts at lo and hi once evaluated
  auto evaluate = [&](double s) {
    const ShiftEvaluation ev = evaluateShift(ws, useConstraints, s);
    record(s, ev);
    if (ev.below > index) {
      if (s < hi) hi = s, countHi = ev.below;
    } else if (s > lo) {
      lo = s, countLo = ev.below;
    }
    return ev;
  };
  double c = sigma0, lastStep = std::numeric_limits<double>::infinity();
  for (int step = 0; step < maxSteps; ++step) {
    if (!(c > lo && c < hi)) return false;
    const ShiftEvaluation ev = evaluate(c);
    if (!std::isfinite(ev.dLog) || ev.dLog == 0.0) return false;
    const double next = c - 1.0 / ev.dLog;
    const double size = std::abs(next - c);
    if (!std::isfinite(next) || size > 0.5 * lastStep) return false;
    // Quadratic convergence: the error left after this step is about (size/lastStep)²·size.
    const double predicted = std::isfinite(lastStep) ? size * (size / lastStep) * (size / lastStep) : size;
    lastStep = size;
    if (size <= 0.25 * tol || predicted <= 0.01 * tol) {
      // Converged, quadratically: the root is far closer to `next` than the step. Certify by the
      // counts at next ∓ 0.45 tol (the bracket then narrower than tol after rounding), or at
      // lo / hi where they already lie that close.
      const double a = next - 0.45 * tol, b = next + 0.45 * tol;
      if (!(lo >= a && countLo == index) && !(a > lo && evaluate(a).below == index)) return false;
      return (hi <= b && countHi == index + 1) || (b < hi && evaluate(b).below == index + 1);
    }
    c = next;
  }
  return false;
}

}  // namespace

int eigenvaluesFrom(ChainStructure& ws, bool useConstraints, int first, int count, VectorRef out, double tolerance,
                    const Vector* guess) {
  const int dim = ws.n - (useConstraints ? ws.rank : 0);
  if (first < 0) return 0;
  const int k = std::max(0, std::min(count, dim - first));
  if (k == 0) return 0;
  const double scale = std::max(ws.typicalScale, ws.frobeniusH);  // as zeroThreshold: any units
  const double tol = tolerance * scale;
  // All eigenvalues lie in [−‖H‖_F, ‖H‖_F]; widen against rounding until the counts confirm it.
  // Confirmed only when a bracket is not isolated from the warm start alone (`outer`): an
  // isolation by the counts at both ends of a bracket needs no outer bound.
  double lo0 = -ws.frobeniusH * (1.0 + 1e-10) - tol, hi0 = ws.frobeniusH * (1.0 + 1e-10) + tol;
  // Brackets: eigenvalue first + j lies in [lo[j], hi[j]) with count(lo[j]) ≤ first + j < count(hi[j]),
  // with the evaluations at their ends (the Illinois iteration starts from them).
  ChainStructure::SmallVector lo = ChainStructure::SmallVector::Constant(k, lo0);
  ChainStructure::SmallVector hi = ChainStructure::SmallVector::Constant(k, hi0);
  ChainStructure::SmallVector cntLo = ChainStructure::SmallVector::Zero(k);
  ChainStructure::SmallVector cntHi = ChainStructure::SmallVector::Constant(k, double(dim));
  std::array<ShiftEvaluation, ChainStructure::kMaxBorder> evLo, evHi;
  std::array<bool, ChainStructure::kMaxBorder> haveLo{}, haveHi{};
  auto record = [&](double s, const ShiftEvaluation& e) {
    for (int j = 0; j < k; ++j) {
      if (e.below > first + j) {
        if (s < hi[j]) { hi[j] = s; cntHi[j] = e.below; evHi[size_t(j)] = e; haveHi[size_t(j)] = true; }
      } else if (s > lo[j]) {
        lo[j] = s;
        cntLo[j] = e.below;
        evLo[size_t(j)] = e;
        haveLo[size_t(j)] = true;
      }
    }
  };
  bool outerConfirmed = false;
  auto outer = [&]() {
    if (outerConfirmed) return;
    outerConfirmed = true;
    const double lo1 = lo0, hi1 = hi0;
    ShiftEvaluation e;
    while ((e = evaluateShift(ws, useConstraints, lo0)).below > 0) lo0 = 2.0 * lo0 - scale;
    const ShiftEvaluation eLo = e;
    while ((e = evaluateShift(ws, useConstraints, hi0)).below < first + k) hi0 = 2.0 * hi0 + scale;
    for (int j = 0; j < k; ++j) {  // ends still at the unconfirmed bounds take the confirmed ones
      if (lo[j] == lo1) { lo[j] = lo0; evLo[size_t(j)] = eLo; haveLo[size_t(j)] = true; }
      if (hi[j] == hi1) { hi[j] = hi0; evHi[size_t(j)] = e; haveHi[size_t(j)] = true; }
    }
  };
  auto isolated = [&](int j) { return int(cntLo[j]) == first + j && int(cntHi[j]) == first + j + 1; };
  for (int j = 0; j < k; ++j) {
    if (j > 0 && out[j - 1] - tol > lo[j]) {
      lo[j] = out[j - 1] - tol;
      haveLo[size_t(j)] = false;
    }
    // Warm start: Newton on det K_σ from the guess, certified by the counts either side of its
    // limit. A guess a step δ along the branch away (the spectral monitor's second evaluation) or
    // one continuation step away is within Newton's quadratic range, so this costs three to five
    // factorizations where isolation and Illinois took ten or more.
    if (guess && j < guess->size() && std::isfinite((*guess)[j]) && (*guess)[j] > lo[j] && (*guess)[j] < hi[j]) {
      if (newtonFrom(ws, useConstraints, first + j, (*guess)[j], tol, 8, lo[j], hi[j], record) && isolated(j) &&
          hi[j] - lo[j] <= tol) {
        out[j] = 0.5 * (lo[j] + hi[j]);
        continue;
      }
    }
    // Otherwise counts around the guess, widening by 8 from 2 % of it. (A width tied to ‖H‖
    // instead isolates nothing on a long or strongly loaded chain, whose lowest eigenvalues are
    // spaced ~κ/n² ≪ 1e−3‖H‖_F, and bisection then pays ~log2(‖H‖ n²/κ) counts per eigenvalue.)
    if (guess && j < guess->size() && std::isfinite((*guess)[j]) && (*guess)[j] > lo[j] && (*guess)[j] < hi[j]) {
      double delta = std::max(1e-9 * scale, 0.02 * std::abs((*guess)[j]));
      for (int attempt = 0; attempt < 10 && !isolated(j); ++attempt, delta *= 8.0) {
        const double a = (*guess)[j] - delta, b = (*guess)[j] + delta;
        if (a > lo[j]) record(a, evaluateShift(ws, useConstraints, a));
        if (b < hi[j]) record(b, evaluateShift(ws, useConstraints, b));
      }
    }
    if (!isolated(j)) outer();
    // isolate: exactly one eigenvalue (j) in [lo, hi)
    while (!isolated(j) && hi[j] - lo[j] > tol) {
      const double mid = 0.5 * (lo[j] + hi[j]);
      if (mid <= lo[j] || mid >= hi[j]) break;
      record(mid, evaluateShift(ws, useConstraints, mid));
    }
    if (isolated(j) && hi[j] - lo[j] > tol) {
      // Illinois on det, one simple root in the bracket; the counts keep the bracket honest.
      // (Newton from here, far from the root, fails its halving test almost always: 10 of 345
      // brackets in the n = 300 race.)
      const ShiftEvaluation ea = haveLo[size_t(j)] ? evLo[size_t(j)] : evaluateShift(ws, useConstraints, lo[j]);
      const ShiftEvaluation eb = haveHi[size_t(j)] ? evHi[size_t(j)] : evaluateShift(ws, useConstraints, hi[j]);
      const double ref = 0.5 * (ea.logAbsDet + eb.logAbsDet);
      auto value = [&](const ShiftEvaluation& e) {
        return e.sign * std::exp(std::max(-700.0, std::min(700.0, e.logAbsDet - ref)));
      };
      // Illinois on the determinant, the side of the root decided by the count (exact)
      continuation::IllinoisBracket br{lo[j], hi[j], value(ea), value(eb), 0};
      for (int it = 0; it < 200 && br.width() > tol; ++it) {
        // keep progress: never closer than tol/4 to an end
        const double c = std::min(std::max(br.next(), br.left + 0.25 * tol), br.right - 0.25 * tol);
        const ShiftEvaluation ec = evaluateShift(ws, useConstraints, c);
        const double fc = value(ec);
        br.replace(ec.below > first + j ? 1 : -1, c, fc);  // the root is below c: c is the new right end
        if (fc == 0.0) {
          br.left = br.right = c;
          break;
        }
      }
      lo[j] = br.left;
      hi[j] = br.right;
    }
    out[j] = 0.5 * (lo[j] + hi[j]);
  }
  return k;
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
