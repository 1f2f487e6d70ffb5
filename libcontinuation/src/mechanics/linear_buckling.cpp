#include "buckle/mechanics/linear_buckling.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <limits>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/validation.h"
#include "linear_buckling_structured.h"

namespace buckle::mechanics {

namespace {

// The `wanted` eigenpairs of the symmetric C with the largest |μ| (λ = 1/μ smallest), by
// Householder tridiagonalisation (4/3 k³), eigenvalues of the tridiagonal (O(k²)) and inverse
// iteration on it (O(k) per vector). False if a pair is not resolved (clustered eigenvalues):
// the caller then uses the full eigen-decomposition.
bool fewLargestPairs(const Matrix& C, int wanted, double relTiny, std::vector<std::pair<double, Vector>>& out,
                     int& infinite) {
  const Eigen::Index k = C.rows();
  const Eigen::Tridiagonalization<Matrix> tri(C);
  const Vector d = tri.diagonal();
  const Vector e = tri.subDiagonal();
  Eigen::SelfAdjointEigenSolver<Matrix> es;
  es.computeFromTridiagonal(d, e, Eigen::EigenvaluesOnly);
  const Vector mu = es.eigenvalues();
  const double muMax = mu.cwiseAbs().maxCoeff();
  if (!(muMax > 0.0)) return false;
  std::vector<Eigen::Index> order(static_cast<size_t>(k));
  for (Eigen::Index i = 0; i < k; ++i) order[size_t(i)] = i;
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return std::abs(mu[a]) > std::abs(mu[b]); });
  int tiny = 0;
  for (Eigen::Index i = 0; i < k; ++i)
    if (std::abs(mu[i]) <= relTiny * muMax) ++tiny;
  const double tnorm = d.cwiseAbs().maxCoeff() + 2.0 * (e.size() ? e.cwiseAbs().maxCoeff() : 0.0);
  std::vector<std::pair<double, Vector>> found;
  for (size_t r = 0; r < order.size() && int(found.size()) < wanted; ++r) {
    const double m = mu[order[r]];
    if (std::abs(m) <= relTiny * muMax) break;
    // isolated enough for inverse iteration?
    double gap = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < k; ++j)
      if (j != order[r]) gap = std::min(gap, std::abs(mu[j] - m));
    if (gap <= 1e-8 * tnorm) return false;
    // unpivoted LDLᵀ of T − σI with safeguarded pivots; σ slightly off m keeps it regular
    const double sigma = m + 1e-14 * tnorm;
    Vector piv(k), l(std::max<Eigen::Index>(k - 1, 0));
    const double floorPivot = 1e-300 + std::numeric_limits<double>::epsilon() * tnorm;
    piv[0] = d[0] - sigma;
    for (Eigen::Index i = 1; i < k; ++i) {
      if (std::abs(piv[i - 1]) < floorPivot) piv[i - 1] = piv[i - 1] < 0 ? -floorPivot : floorPivot;
      l[i - 1] = e[i - 1] / piv[i - 1];
      piv[i] = d[i] - sigma - l[i - 1] * e[i - 1];
    }
    if (std::abs(piv[k - 1]) < floorPivot) piv[k - 1] = floorPivot;
    Vector y = Vector::Ones(k) / std::sqrt(double(k));
    for (Eigen::Index i = 0; i < k; ++i) y[i] += 1e-3 * std::sin(double(i + 1) * 1.2345);  // not orthogonal to any eigvec
    y.normalize();
    for (int it = 0; it < 4; ++it) {
      for (Eigen::Index i = 1; i < k; ++i) y[i] -= l[i - 1] * y[i - 1];
      y.array() /= piv.array();
      for (Eigen::Index i = k - 2; i >= 0; --i) y[i] -= l[i] * y[i + 1];
      const double nrm = y.norm();
      if (!(nrm > 0.0) || !std::isfinite(nrm)) return false;
      y /= nrm;
    }
    // residual of T y = m y
    Vector Ty = d.cwiseProduct(y);
    if (k > 1) {
      Ty.head(k - 1) += e.cwiseProduct(y.tail(k - 1));
      Ty.tail(k - 1) += e.cwiseProduct(y.head(k - 1));
    }
    if ((Ty - m * y).norm() > 1e-10 * tnorm) return false;
    Vector v = tri.matrixQ() * y;  // eigenvector of C
    found.emplace_back(m, std::move(v));
  }
  out = std::move(found);
  infinite = tiny;
  return true;
}

// Eigenpairs (λ, w) of A w = λ B w with A, B symmetric; infinite λ (B w = 0) are counted, not returned.
void generalisedEigen(const Matrix& A, const Matrix& B, int wanted, std::vector<std::pair<double, Vector>>& pairs,
                      int& infinite) {
  const Eigen::Index k = A.rows();
  infinite = 0;
  if (k == 0) return;
  const double scaleA = A.cwiseAbs().maxCoeff(), scaleB = B.cwiseAbs().maxCoeff();
  if (!(scaleB > 0.0)) {
    infinite = int(k);
    return;
  }
  // A definite (the stable or uniformly unstable chain): B w = μ A w, λ = 1/μ, symmetric and robust.
  // With sign·A = L Lᵀ: C = L⁻¹ (sign·B) L⁻ᵀ, C y = μ y, w = L⁻ᵀ y. A diagonal A (the free end)
  // skips the Cholesky factorisation.
  const bool diagonal = (Matrix(A.diagonal().asDiagonal()) - A).cwiseAbs().maxCoeff() == 0.0;
  for (double sign : {1.0, -1.0}) {
    if (!(scaleA > 0.0)) break;
    const Matrix As = sign * A;
    Eigen::LLT<Matrix> llt;
    Vector sqrtDiag;
    Matrix C;
    if (diagonal) {
      if (As.diagonal().minCoeff() <= 1e-20 * scaleA) continue;
      sqrtDiag = As.diagonal().cwiseSqrt();
      const Vector s = sqrtDiag.cwiseInverse();
      C = s.asDiagonal() * (sign * B) * s.asDiagonal();
    } else {
      llt.compute(As);
      if (llt.info() != Eigen::Success) continue;
      if (Vector(llt.matrixLLT().diagonal()).minCoeff() <= 1e-10 * std::sqrt(scaleA)) continue;  // semidefinite
      C = llt.matrixL().solve(sign * B);
      C = llt.matrixL().solve(C.transpose()).transpose();
    }
    C = 0.5 * (C + C.transpose());
    auto back = [&](const Vector& y) -> Vector {
      if (diagonal) return y.cwiseQuotient(sqrtDiag);
      return llt.matrixU().solve(y);
    };
    if (wanted > 0 && 8 * Eigen::Index(wanted) <= k) {
      std::vector<std::pair<double, Vector>> few;
      int tiny = 0;
      if (fewLargestPairs(C, wanted, 1e-12, few, tiny)) {
        infinite = tiny;
        for (auto& [mu, y] : few) pairs.emplace_back(1.0 / mu, back(y));
        return;
      }
    }
    const Eigen::SelfAdjointEigenSolver<Matrix> es(C);
    const Vector& mu = es.eigenvalues();
    const double muMax = mu.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < k; ++i) {
      if (std::abs(mu[i]) <= 1e-12 * muMax || !(muMax > 0.0)) {
        ++infinite;
        continue;
      }
      pairs.emplace_back(1.0 / mu[i], back(es.eigenvectors().col(i)));
    }
    return;
  }
  // A indefinite or singular: B may be definite (then A w = λ B w is symmetric in B's metric).
  for (double sign : {1.0, -1.0}) {
    const Matrix Bs = sign * B;
    const Eigen::LLT<Matrix> llt(Bs);
    if (llt.info() != Eigen::Success) continue;
    const Vector diag = llt.matrixL().toDenseMatrix().diagonal();
    if (diag.minCoeff() <= 1e-10 * std::sqrt(scaleB)) continue;
    Matrix C = llt.matrixL().solve(sign * A);
    C = llt.matrixL().solve(C.transpose()).transpose();
    C = 0.5 * (C + C.transpose());
    const Eigen::SelfAdjointEigenSolver<Matrix> es(C);
    for (Eigen::Index i = 0; i < k; ++i)
      pairs.emplace_back(es.eigenvalues()[i], Vector(llt.matrixU().solve(es.eigenvectors().col(i))));
    return;
  }
  // Neither definite: general real QZ, keeping real finite eigenvalues.
  Eigen::GeneralizedEigenSolver<Matrix> ges(A, B, true);
  const auto alphas = ges.alphas();
  const Vector betas = ges.betas();
  const auto vecs = ges.eigenvectors();
  const double bscale = betas.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < k; ++i) {
    if (std::abs(betas[i]) <= 1e-12 * std::max(bscale, 1e-300)) {
      ++infinite;
      continue;
    }
    const std::complex<double> lam = alphas[i] / betas[i];
    if (std::abs(lam.imag()) > 1e-9 * std::max(1.0, std::abs(lam.real()))) continue;
    pairs.emplace_back(lam.real(), Vector(vecs.col(i).real()));
  }
}

// The chain's force unit k̄ b̄ (largest spring stiffness × largest half-length). K_q is a torque
// per rad (k b²), the load matrix per unit load a length (b): "K_q ≈ 0 against the loads" compares
// K_q with the load matrix times this unit, the same in every system of units.
double forceUnit(const Chain& chain) {
  double k = 0.0, b = 0.0;
  for (int i = 0; i < chain.size(); ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    k = std::max({k, p.k1, p.k2});
    b = std::max({b, p.b1, p.b2});
  }
  return k * b;
}

}  // namespace

std::string LinearBucklingOptions::validate(const std::string& prefix) const {
  namespace cont = continuation;
  return cont::firstProblem(
      {cont::require(direction.allFinite(), prefix, "direction", "must be finite"),
       cont::require(count >= -1, prefix, "count", "must be >= -1 (-1: every mode)"),
       cont::requirePositive(prefix, "gradientTolerance", gradientTolerance)});
}

LinearBucklingResult linearBuckling(const Chain& chain, ConstVectorRef q0, const EndCondition& end,
                                    const LinearBucklingOptions& options) {
  const int n = chain.size();
  if (q0.size() != n) {
    std::ostringstream os;
    os << "q0 must have one angle per segment (got " << q0.size() << " for n = " << n << ")";
    throw std::invalid_argument(os.str());
  }
  for (int i = 0; i < n; ++i) requireFinite("q0[" + std::to_string(i + 1) + "]", q0[i]);
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("LinearBucklingOptions: " + why);

  Vector g(n), kq(n);
  energyGradient(chain, q0, g);
  jointStiffness(chain, q0, kq);
  const double kscale = std::max(1e-300, kq.cwiseAbs().maxCoeff());
  if (g.lpNorm<Eigen::Infinity>() > options.gradientTolerance * std::max(1.0, kscale)) {
    std::ostringstream os;
    os << "q0 is not an unloaded equilibrium: max |dE/dq| = " << g.lpNorm<Eigen::Infinity>();
    throw std::invalid_argument(os.str());
  }

  ChainData data(chain);
  forwardKinematics(chain, q0, data);
  Matrix J(3, n);
  endJacobian(data, J);

  // ker J_h: the last n − rank columns of Q in J_hᵀ P = Q R. The reflectors are applied to K_q
  // and G directly (O(m n²)) rather than forming Q.
  const std::vector<int> held = end.heldIndices();
  const int m = int(held.size());
  Matrix Ch(n, m);
  for (int k = 0; k < m; ++k) Ch.col(k) = J.row(held[size_t(k)]).transpose();
  // Long chains and a few modes: O(n) per mode through the chain structure.
  if (n > kStructuredBucklingFrom && options.count > 0 && m <= 3) {
    LinearBucklingResult fast;
    if (structuredBuckling(data, kq, Ch, options, forceUnit(chain), fast)) return fast;
  }
  if (n > kMaxDensePencil) {
    std::ostringstream os;
    os << "linear buckling of " << n << " segments needs the dense pencil (O(n^3), above n = " << kMaxDensePencil
       << "): the O(n) route takes a positive count of modes and a stiffness K_q that is definite (not zero or "
          "indefinite) on the null space of the held end coordinates";
    throw std::invalid_argument(os.str());
  }
  Matrix G(n, n);
  loadMatrix(data, Wrench(options.direction[0], options.direction[1], 0.0), G);
  // (an n×0 factorisation is not valid Eigen input: factor a zero column instead, unused)
  const Eigen::ColPivHouseholderQR<Matrix> qr(m > 0 ? Ch : Matrix(Matrix::Zero(n, 1)));
  const int rank = m == 0 ? 0 : int(qr.rank());
  const int nr = n - rank;
  LinearBucklingResult out;
  out.constrainedDimension = nr;
  if (nr == 0) {
    out.unloadedStable = true;
    return out;
  }
  Matrix A, B;
  if (rank == 0) {
    A = kq.asDiagonal();
    B = G;
  } else {
    const auto Q = qr.householderQ().setLength(rank);
    Matrix Kf = kq.asDiagonal();
    Kf.applyOnTheLeft(Q.transpose());
    Kf.applyOnTheRight(Q);
    Matrix Gf = G;
    Gf.applyOnTheLeft(Q.transpose());
    Gf.applyOnTheRight(Q);
    A = Kf.bottomRightCorner(nr, nr);
    B = Gf.bottomRightCorner(nr, nr);
  }
  A = 0.5 * (A + A.transpose());
  B = 0.5 * (B + B.transpose());
  auto expand = [&](const Vector& w) {
    Vector z = Vector::Zero(n);
    z.tail(nr) = w;
    if (rank > 0) z.applyOnTheLeft(qr.householderQ().setLength(rank));
    return z;
  };

  const Eigen::SelfAdjointEigenSolver<Matrix> esA(A, Eigen::EigenvaluesOnly);
  const double Ascale = esA.eigenvalues().cwiseAbs().maxCoeff();
  const double Gscale = std::max(1e-300, G.cwiseAbs().maxCoeff());
  // K_q ≈ 0 relative to the load matrix (per unit load and length) in the chain's force unit: κ = 0.
  out.degenerate = Ascale <= 1e-13 * Gscale * forceUnit(chain);
  // κ = 0 is marginal, not stable: the sign of a rounding-level K_q must not decide it.
  out.unloadedStable = !out.degenerate && esA.eigenvalues()[0] > 0.0;

  std::vector<std::pair<double, Vector>> pairs;
  if (out.degenerate) {
    // Every direction with G z ≠ 0 buckles at λ = 0; the modes are G's eigenvectors.
    const Eigen::SelfAdjointEigenSolver<Matrix> esB(B);
    const double bmax = esB.eigenvalues().cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < B.rows(); ++i) {
      if (std::abs(esB.eigenvalues()[i]) <= 1e-12 * bmax) {
        ++out.droppedInfinite;
        continue;
      }
      pairs.emplace_back(0.0, esB.eigenvectors().col(i));
    }
  } else {
    generalisedEigen(A, B, options.count, pairs, out.droppedInfinite);
  }

  for (auto& [lambda, w] : pairs) {
    BucklingMode mode;
    mode.lambda = lambda;
    Vector z = expand(w);
    const double norm = z.norm();
    if (!(norm > 0.0) || !std::isfinite(lambda)) continue;
    z /= norm;
    Eigen::Index imax = 0;
    z.cwiseAbs().maxCoeff(&imax);
    if (z[imax] < 0) z = -z;
    mode.mode = z;
    mode.shape = modeShapeName(z);
    mode.shortening = -0.5 * z.dot(G * z);
    if (n == 3 && std::abs(z[1]) > 1e-12) {
      mode.mu = mode.shortening / (chain.linkLengths()[0] * z[1] * z[1]);
      mode.alpha1 = z[0] / z[1];
      mode.alpha3 = z[2] / z[1];
    }
    out.modes.push_back(std::move(mode));
  }
  std::stable_sort(out.modes.begin(), out.modes.end(),
                   [](const BucklingMode& a, const BucklingMode& b) { return std::abs(a.lambda) < std::abs(b.lambda); });
  if (options.count >= 0 && int(out.modes.size()) > options.count) out.modes.resize(size_t(options.count));
  return out;
}

AnalyticBuckling3 analyticClampedPinned3(double a, double b, double k, double L0) {
  requireNonNegative("a", a);
  requirePositive("b", b);
  requirePositive("k", k);
  requirePositive("L0", L0);
  const double r21 = std::sqrt(21.0);
  AnalyticBuckling3 r;
  r.kappa = k * (b * L0 - 2.0 * (b * b - a * a));
  r.lambdaU = (r21 - 14.0) / 10.0;
  r.lambdaZ = -(r21 + 14.0) / 10.0;
  // eq 17: Fx = −λ (k/b)(2(b² − a²) − b L0) = λ κ / b
  r.FxU = r.lambdaU * r.kappa / b;
  r.FxZ = r.lambdaZ * r.kappa / b;
  r.alpha1U = -(r21 + 11.0) / 20.0;
  r.alpha3U = (r21 - 1.0) / 4.0;
  r.alpha1Z = -(-r21 + 11.0) / 20.0;
  r.alpha3Z = (-r21 - 1.0) / 4.0;
  r.muU = (21.0 + r21) / 20.0;
  r.muZ = (21.0 - r21) / 20.0;
  return r;
}

}  // namespace buckle::mechanics
