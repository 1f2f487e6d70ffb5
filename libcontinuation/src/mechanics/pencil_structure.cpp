// The vibration pencil's quasiseparable LDLᵀ, solves, mass product, counts and eigenvalues
// (pencil_structure.h).
#include "buckle/mechanics/pencil_structure.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "eigenvalue_search.h"
#include "structure_kernels.h"

namespace buckle::mechanics {

using structure::kBunchAlpha;
using structure::largestBlockEigenvalue;
using structure::kTinyPivot;

MassGenerators massGenerators(const Chain& chain, const InertiaData& inertia) {
  const int n = chain.size();
  const Vector& l = chain.linkLengths();
  MassGenerators out;
  out.diagonal.resize(n);
  out.weight.resize(n);
  out.length = l.tail(n);
  out.com.resize(n);
  // μ_ij of the kinetic energy ½ Σ μ_ij cos(θ_i − θ_j) θ̇_i θ̇_j (see dynamics.h): link k's
  // centre of mass moves with ℓ_p θ̇_p for every link p before it and d_k θ̇_k for itself, so
  // μ_ii = I_i + m_i d_i² + ℓ_i² Σ_{k>i} m_k and μ_ij = ℓ_i w_j (i < j), w_j = m_j d_j + ℓ_j Σ_{k>j} m_k.
  double tail = 0.0;  // Σ_{k>i} m_k
  for (int i = n - 1; i >= 0; --i) {
    const LinkInertia& L = inertia.links[size_t(i)];
    const double li = l[i + 1];
    const double d = std::isnan(L.comOffset) ? 0.5 * li : L.comOffset;
    out.com[i] = d;
    out.diagonal[i] = L.inertia + L.mass * d * d + li * li * tail;
    out.weight[i] = L.mass * d + li * tail;
    tail += L.mass;
  }
  return out;
}

PencilStructure::PencilStructure(int cap)
    : capacity(cap),
      t(Vector::Zero(cap)),
      e(Vector::Zero(std::max(cap, 1))),
      a(Vector::Zero(cap)),
      p(Matrix::Zero(cap, 2)),
      r(Matrix::Zero(cap, 2)),
      block(size_t(std::max(cap, 1)), 1),
      d(Vector::Zero(cap)),
      dOff(Vector::Zero(cap)),
      tri(Vector::Zero(cap)),
      g(Matrix::Zero(cap, 2)),
      Q(Matrix::Zero(cap, 3)),
      B(Matrix::Zero(cap, kMaxBorder)),
      X(Matrix::Zero(cap, kMaxBorder)),
      work(Vector::Zero(cap)),
      guessChunk(Vector::Zero(0)) {
  if (cap < 1) throw std::invalid_argument("PencilStructure: capacity must be >= 1");
}

void factorizePencil(PencilStructure& ws, double sigma, bool determinant) {
  const int n = ws.n;
  ws.shift = sigma;
  ++ws.factorizations;
  ws.singular = false;
  ws.negative = 0;
  ws.twoByTwo = 0;
  double scale = 0.0;
  for (int j = 0; j < n; ++j)
    scale = std::max(scale, std::abs(ws.t[j]) + std::abs(sigma) * ws.a[j] + (j + 1 < n ? std::abs(ws.e[j]) : 0.0));
  if (scale == 0.0) scale = 1.0;
  const double pivmin = kTinyPivot * scale;
  double minRatio = std::numeric_limits<double>::infinity();
  structure::ScaledProduct det;
  double dLog = 0.0;
  int sign = 1;
  // State after the pivots before j: P_j; the last pivot block's generator column and (D⁻¹)_last,last
  // (gPrev, invPrev: the tridiagonal channel into row j through ePrev); their σ-derivatives while
  // every pivot is 1×1 (dLog is carried only then: NaN after a 2×2 block, the search's counts take over).
  double P00 = 0.0, P01 = 0.0, P11 = 0.0, D00 = 0.0, D01 = 0.0, D11 = 0.0;
  double g0Prev = 0.0, g1Prev = 0.0, invPrev = 0.0, ePrev = 0.0;
  double dg0Prev = 0.0, dg1Prev = 0.0, dInvPrev = 0.0;
  bool derivative = determinant;
  int j = 0;
  while (j < n) {
    const double p0 = ws.p(j, 0), p1 = ws.p(j, 1);
    const double Pp0 = P00 * p0 + P01 * p1, Pp1 = P01 * p0 + P11 * p1;
    // ρ = r_j − z_j, z_j = −σ P_j p_j + e_{j−1} gPrev; the pivot candidate S(j, j)
    const double z0 = -sigma * Pp0 + ePrev * g0Prev, z1 = -sigma * Pp1 + ePrev * g1Prev;
    const double rho0 = ws.r(j, 0) - z0, rho1 = ws.r(j, 1) - z1;
    double dj = ws.t[j] - sigma * ws.a[j] - sigma * sigma * (p0 * Pp0 + p1 * Pp1) +
                2.0 * sigma * ePrev * (p0 * g0Prev + p1 * g1Prev) - ePrev * ePrev * invPrev;
    // S(j + 1, j): the coupling to the next row (Bunch's test on the tridiagonal channel)
    double c = 0.0;
    if (j + 1 < n) c = -sigma * (ws.p(j + 1, 0) * rho0 + ws.p(j + 1, 1) * rho1) + ws.e[j];
    // S(j + 1, j + 1) (its Schur complement entry may exceed G_σ's scale)
    double b = 0.0, Pq0 = 0.0, Pq1 = 0.0;
    if (j + 1 < n) {
      const double q0 = ws.p(j + 1, 0), q1 = ws.p(j + 1, 1);
      Pq0 = P00 * q0 + P01 * q1;
      Pq1 = P01 * q0 + P11 * q1;
      b = ws.t[j + 1] - sigma * ws.a[j + 1] - sigma * sigma * (q0 * Pq0 + q1 * Pq1);
    }
    if (j + 1 == n || std::abs(dj) * std::max(scale, std::abs(b)) >= kBunchAlpha * c * c) {
      double ddj = 0.0, dz0 = 0.0, dz1 = 0.0;
      if (derivative) {
        const double DPp0 = D00 * p0 + D01 * p1, DPp1 = D01 * p0 + D11 * p1;
        dz0 = -Pp0 - sigma * DPp0 + ePrev * dg0Prev;
        dz1 = -Pp1 - sigma * DPp1 + ePrev * dg1Prev;
        // d/dσ of d_j = T_jj − σ a_j + σ p_jᵀ z_j − e_{j−1}(−σ p_jᵀ gPrev + e_{j−1} invPrev)
        ddj = -ws.a[j] + (p0 * z0 + p1 * z1) + sigma * (p0 * dz0 + p1 * dz1) + ePrev * (p0 * g0Prev + p1 * g1Prev) +
              sigma * ePrev * (p0 * dg0Prev + p1 * dg1Prev) - ePrev * ePrev * dInvPrev;
      }
      if (std::abs(dj) < pivmin) {
        dj = -pivmin;
        ws.singular = true;
      }
      ws.block[size_t(j)] = 1;
      ws.d[j] = dj;
      if (dj < 0.0) {
        ++ws.negative;
        sign = -sign;
      }
      minRatio = std::min(minRatio, std::abs(dj) / scale);
      const double g0 = rho0 / dj, g1 = rho1 / dj;
      ws.g(j, 0) = g0;
      ws.g(j, 1) = g1;
      ws.tri[j] = j + 1 < n ? ws.e[j] / dj : 0.0;
      P00 += rho0 * g0;
      P01 += rho0 * g1;
      P11 += rho1 * g1;
      if (determinant) det.multiply(dj);
      if (derivative) {
        dLog += ddj / dj;
        const double dg0 = (-dz0 - g0 * ddj) / dj, dg1 = (-dz1 - g1 * ddj) / dj;
        D00 += ddj * g0 * g0 + 2.0 * dj * dg0 * g0;
        D01 += ddj * g0 * g1 + dj * (dg0 * g1 + g0 * dg1);
        D11 += ddj * g1 * g1 + 2.0 * dj * dg1 * g1;
        dg0Prev = dg0;
        dg1Prev = dg1;
        dInvPrev = -ddj / (dj * dj);
      }
      g0Prev = g0;
      g1Prev = g1;
      invPrev = 1.0 / dj;
      ePrev = j + 1 < n ? ws.e[j] : 0.0;
      j += 1;
      continue;
    }
    // 2×2 pivot D = [[d_j, c], [c, b]] on rows j, j + 1 (Bunch: |d_j b| < α c², so det D < −(1 − α)c²
    // < 0, one eigenvalue of each sign). Row j + 1 has no tridiagonal channel from before j.
    derivative = false;
    ++ws.twoByTwo;
    const double sig0 = ws.r(j + 1, 0) + sigma * Pq0, sig1 = ws.r(j + 1, 1) + sigma * Pq1;  // ρ of row j + 1
    const double detD = dj * b - c * c;
    const double i00 = b / detD, i01 = -c / detD, i11 = dj / detD;  // D⁻¹
    ws.block[size_t(j)] = 2;
    ws.block[size_t(j) + 1] = 0;
    ws.d[j] = i00;  // a 2×2 block stores D⁻¹: (d[j], dOff[j]; dOff[j], d[j + 1])
    ws.d[j + 1] = i11;
    ws.dOff[j] = i01;
    ++ws.negative;
    sign = -sign;
    const double big = largestBlockEigenvalue(dj, b, c);
    minRatio = std::min(minRatio, std::abs(detD) / (big * scale));
    if (determinant) det.multiply(detD);
    // generators [g_j g_{j+1}] = [ρ_j ρ_{j+1}] D⁻¹; P += [ρ_j ρ_{j+1}] D⁻¹ [ρ_j ρ_{j+1}]ᵀ
    const double ga0 = rho0 * i00 + sig0 * i01, ga1 = rho1 * i00 + sig1 * i01;
    const double gb0 = rho0 * i01 + sig0 * i11, gb1 = rho1 * i01 + sig1 * i11;
    ws.g(j, 0) = ga0;
    ws.g(j, 1) = ga1;
    ws.g(j + 1, 0) = gb0;
    ws.g(j + 1, 1) = gb1;
    const double eNext = j + 2 < n ? ws.e[j + 1] : 0.0;
    ws.tri[j] = eNext * i01;  // row j + 2's tridiagonal channel: e_{j+1} (D⁻¹)_{1,:}
    ws.tri[j + 1] = eNext * i11;
    P00 += ga0 * rho0 + gb0 * sig0;
    P01 += ga0 * rho1 + gb0 * sig1;
    P11 += ga1 * rho1 + gb1 * sig1;
    g0Prev = gb0;
    g1Prev = gb1;
    invPrev = i11;
    ePrev = eNext;
    j += 2;
  }
  ws.minPivotRatio = minRatio;
  ws.detSign = sign;
  ws.logAbsDet = determinant ? det.logAbs() : std::numeric_limits<double>::quiet_NaN();
  ws.dLogAbsDet = derivative ? dLog : std::numeric_limits<double>::quiet_NaN();
}

void solvePencil(const PencilStructure& ws, VectorRef y) {
  const int n = ws.n;
  const double sigma = ws.shift;
  // L y = b: y_i = b_i + σ p_iᵀ Σ_{k<i} g_k y_k − (the last block's tri·y into the row after it);
  // rows inside a 2×2 block are not coupled by L (block LDLᵀ)
  double s0 = 0.0, s1 = 0.0, channel = 0.0;
  for (int i = 0; i < n;) {
    const int size = ws.block[size_t(i)] == 2 ? 2 : 1;
    double next = 0.0;
    for (int k = i; k < i + size; ++k) {
      double yk = y[k] + sigma * (ws.p(k, 0) * s0 + ws.p(k, 1) * s1);
      if (k == i) yk -= channel;
      y[k] = yk;
      next += ws.tri[k] * yk;
    }
    for (int k = i; k < i + size; ++k) {
      s0 += ws.g(k, 0) * y[k];
      s1 += ws.g(k, 1) * y[k];
    }
    // D⁻¹
    if (size == 1) {
      y[i] /= ws.d[i];
    } else {
      const double a0 = y[i], a1 = y[i + 1];
      y[i] = ws.d[i] * a0 + ws.dOff[i] * a1;
      y[i + 1] = ws.dOff[i] * a0 + ws.d[i + 1] * a1;
    }
    channel = next;
    i += size;
  }
  // Lᵀ x = y: x_k = y_k + σ g_kᵀ Σ_{i after k's block} p_i x_i − tri_k x_(first row after the block)
  double t0 = 0.0, t1 = 0.0, xNext = 0.0;
  for (int i = n - 1; i >= 0;) {
    const int first = ws.block[size_t(i)] == 0 ? i - 1 : i;
    for (int k = first; k <= i; ++k) y[k] += sigma * (ws.g(k, 0) * t0 + ws.g(k, 1) * t1) - ws.tri[k] * xNext;
    for (int k = first; k <= i; ++k) {
      t0 += ws.p(k, 0) * y[k];
      t1 += ws.p(k, 1) * y[k];
    }
    xNext = y[first];
    i = first - 1;
  }
}

void applyPencilMass(const PencilStructure& ws, ConstVectorRef x, VectorRef y) {
  const int n = ws.n;
  // y_i = a_i x_i + p_iᵀ Σ_{j<i} r_j x_j + r_iᵀ Σ_{j>i} p_j x_j
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < n; ++i) {
    y[i] = ws.a[i] * x[i] + ws.p(i, 0) * s0 + ws.p(i, 1) * s1;
    s0 += ws.r(i, 0) * x[i];
    s1 += ws.r(i, 1) * x[i];
  }
  double t0 = 0.0, t1 = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    y[i] += ws.r(i, 0) * t0 + ws.r(i, 1) * t1;
    t0 += ws.p(i, 0) * x[i];
    t1 += ws.p(i, 1) * x[i];
  }
}

bool pencilMassPositive(const PencilStructure& ws) {
  // the recursion at T = 0, σ = −1 (G = M_θ): z_j = P_j p_j, d_j = a_j − p_jᵀP_jp_j
  double P00 = 0.0, P01 = 0.0, P11 = 0.0;
  for (int j = 0; j < ws.n; ++j) {
    const double p0 = ws.p(j, 0), p1 = ws.p(j, 1);
    const double Pp0 = P00 * p0 + P01 * p1, Pp1 = P01 * p0 + P11 * p1;
    const double dj = ws.a[j] - (p0 * Pp0 + p1 * Pp1);
    if (!(dj > 1e-14 * ws.a[j])) return false;
    const double g0 = (ws.r(j, 0) - Pp0) / dj, g1 = (ws.r(j, 1) - Pp1) / dj;
    P00 += dj * g0 * g0;
    P01 += dj * g0 * g1;
    P11 += dj * g1 * g1;
  }
  return true;
}

int setPencilConstraints(PencilStructure& ws, const Eigen::Ref<const Matrix>& C, double rankTolerance) {
  const int n = ws.n;
  if (C.rows() > 3 || (C.rows() > 0 && C.cols() != n))
    throw std::invalid_argument("setPencilConstraints: C must be m×n with m <= 3");
  const int rank = structure::orthonormaliseRows(C, ws.Q.topRows(n), ws.B.topRows(n).leftCols(3), rankTolerance);
  ws.rank = rank;
  ws.couplingCount = 0;
  return rank;
}

void setPencilCoupling(PencilStructure& ws, const Eigen::Ref<const Matrix>& R, const Eigen::Ref<const Vector>& signs) {
  ws.couplingCount =
      structure::setCouplingColumns("setPencilCoupling", R, signs, ws.rank, ws.B.topRows(ws.n), ws.couplingSign);
}

int pencilCountBelow(PencilStructure& ws, double sigma, bool determinant) {
  factorizePencil(ws, sigma, determinant);
  const int r = ws.rank + ws.couplingCount;  // the constraints' and the coupling's columns
  if (r == 0) return ws.negative;
  for (int c = 0; c < r; ++c) {
    ws.X.col(c).head(ws.n) = ws.B.col(c).head(ws.n);
    solvePencil(ws, ws.X.col(c).head(ws.n));
  }
  ws.S.resize(r, r);
  ws.S.noalias() = ws.B.topLeftCorner(ws.n, r).transpose() * ws.X.topLeftCorner(ws.n, r);
  ws.S = -0.5 * (ws.S + ws.S.transpose()).eval();
  int positiveSigns = 0;  // the negative eigenvalues of the coupling's block −E
  for (int j = 0; j < ws.couplingCount; ++j) {
    ws.S(ws.rank + j, ws.rank + j) -= ws.couplingSign[j];
    positiveSigns += ws.couplingSign[j] > 0.0 ? 1 : 0;
  }
  const Eigen::SelfAdjointEigenSolver<PencilStructure::SmallMatrix> es(ws.S, Eigen::EigenvaluesOnly);
  int negS = 0;
  for (int i = 0; i < r; ++i) negS += es.eigenvalues()[i] < 0.0 ? 1 : 0;
  return ws.negative + negS - ws.rank - positiveSigns;
}

namespace {

search::ShiftEvaluation evaluatePencil(PencilStructure& ws, double sigma, bool countOnly) {
  search::ShiftEvaluation ev;
  ev.below = pencilCountBelow(ws, sigma, !countOnly);
  if (countOnly) {
    ev.determinant = false;
    return ev;
  }
  ev.logAbsDet = ws.logAbsDet;
  ev.sign = ws.detSign;
  ev.dLog = ws.dLogAbsDet;
  const int r = ws.rank + ws.couplingCount;
  if (r == 0) return ev;
  const Eigen::PartialPivLU<PencilStructure::SmallMatrix> lu(ws.S);
  const double detS = lu.determinant();
  ev.logAbsDet += std::log(std::abs(detS));
  ev.sign *= detS < 0.0 ? -1 : 1;
  // (log|det S|)' = tr(S⁻¹S'), S' = −XᵀM_θX
  PencilStructure::SmallMatrix dS(r, r);
  for (int b = 0; b < r; ++b) {
    applyPencilMass(ws, ws.X.col(b).head(ws.n), ws.work.head(ws.n));
    for (int c = 0; c < r; ++c) dS(c, b) = -ws.X.col(c).head(ws.n).dot(ws.work.head(ws.n));
  }
  ev.dLog += lu.solve(dS).trace();
  return ev;
}

}  // namespace

int pencilEigenvalues(PencilStructure& ws, int first, int count, VectorRef out, double tolerance,
                      const Vector* guess) {
  const int dim = ws.n - ws.rank;
  const int k = std::max(0, std::min(count, dim - first));
  if (k <= 0) return 0;
  // The spectrum's size for the tolerance's unit and the search's outer bound: no cheap norm bound
  // of the pencil (‖T‖/λ_min(M_θ)) is at hand, and the diagonal scale can be 1e5 below max |ω²|
  // (a heavy tip), so grow it until the counts confirm it.
  double bound = 4.0 * ws.scale;
  while (pencilCountBelow(ws, -bound, false) > 0) bound *= 4.0;
  while (pencilCountBelow(ws, bound, false) < dim) bound *= 4.0;
  // the tolerance's unit: the spectrum's size (bound/4 < max |ω²| when the bound had to grow)
  const double unit = std::max(ws.scale, 0.25 * bound);
  int done = 0;
  while (done < k) {
    const int m = std::min(search::kMaxSearch, k - done);
    const Vector* chunkGuess = nullptr;
    if (guess && guess->size() > done) {
      // the guesses of one chunk (a chunk's search is at most kMaxSearch wide)
      ws.guessChunk.resize(std::min<Eigen::Index>(m, guess->size() - done));
      ws.guessChunk = guess->segment(done, ws.guessChunk.size());
      chunkGuess = &ws.guessChunk;
    }
    done += search::searchEigenvalues([&](double s, bool countOnly) { return evaluatePencil(ws, s, countOnly); }, dim, unit, bound,
                                      first + done, m, out.segment(done, m), tolerance, chunkGuess);
  }
  return k;
}

}  // namespace buckle::mechanics
