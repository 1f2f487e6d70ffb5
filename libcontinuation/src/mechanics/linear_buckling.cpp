#include "buckle/mechanics/linear_buckling.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/validation.h"

namespace buckle::mechanics {

namespace {

// Eigenpairs (λ, w) of A w = λ B w with A, B symmetric; infinite λ (B w = 0) are counted, not returned.
void generalisedEigen(const Matrix& A, const Matrix& B, std::vector<std::pair<double, Vector>>& pairs, int& infinite) {
  const Eigen::Index k = A.rows();
  infinite = 0;
  if (k == 0) return;
  const double scaleA = A.cwiseAbs().maxCoeff(), scaleB = B.cwiseAbs().maxCoeff();
  if (!(scaleB > 0.0)) {
    infinite = int(k);
    return;
  }
  // A definite (the stable or uniformly unstable chain): B w = μ A w, λ = 1/μ, symmetric and robust.
  for (double sign : {1.0, -1.0}) {
    if (!(scaleA > 0.0)) break;
    const Matrix As = sign * A;
    const Eigen::LLT<Matrix> llt(As);
    if (llt.info() != Eigen::Success) continue;
    const Vector diag = llt.matrixL().toDenseMatrix().diagonal();
    if (diag.minCoeff() <= 1e-10 * std::sqrt(scaleA)) continue;  // numerically semidefinite
    // C = L⁻¹ (sign B) L⁻ᵀ
    Matrix C = llt.matrixL().solve(sign * B);
    C = llt.matrixL().solve(C.transpose()).transpose();
    C = 0.5 * (C + C.transpose());
    const Eigen::SelfAdjointEigenSolver<Matrix> es(C);
    const Vector& mu = es.eigenvalues();
    const double muMax = mu.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < k; ++i) {
      if (std::abs(mu[i]) <= 1e-12 * muMax || !(muMax > 0.0)) {
        ++infinite;
        continue;
      }
      const Vector w = llt.matrixU().solve(es.eigenvectors().col(i));  // L⁻ᵀ y
      pairs.emplace_back(1.0 / mu[i], w);
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

}  // namespace

LinearBucklingResult linearBuckling(const Chain& chain, ConstVectorRef q0, const EndCondition& end,
                                    const LinearBucklingOptions& options) {
  const int n = chain.size();
  if (q0.size() != n) {
    std::ostringstream os;
    os << "q0 must have one angle per segment (got " << q0.size() << " for n = " << n << ")";
    throw std::invalid_argument(os.str());
  }
  for (int i = 0; i < n; ++i) requireFinite("q0[" + std::to_string(i + 1) + "]", q0[i]);
  for (int c = 0; c < 3; ++c) requireFinite("load direction component " + std::to_string(c), options.direction[c]);

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
  Matrix G(n, n);
  loadMatrix(data, Wrench(options.direction[0], options.direction[1], 0.0), G);

  // Orthonormal basis of ker J_h.
  const std::vector<int> held = end.heldIndices();
  const int m = int(held.size());
  Matrix Z;
  if (m == 0) {
    Z = Matrix::Identity(n, n);
  } else {
    Matrix Ch(n, m);
    for (int k = 0; k < m; ++k) Ch.col(k) = J.row(held[size_t(k)]).transpose();
    const Eigen::ColPivHouseholderQR<Matrix> qr(Ch);
    const int rank = int(qr.rank());
    const Matrix Q = qr.householderQ() * Matrix::Identity(n, n);
    Z = Q.rightCols(n - rank);
  }
  LinearBucklingResult out;
  out.constrainedDimension = int(Z.cols());
  if (Z.cols() == 0) {
    out.unloadedStable = true;
    return out;
  }
  const Matrix A = Z.transpose() * kq.asDiagonal() * Z;
  Matrix B = Z.transpose() * G * Z;
  B = 0.5 * (B + B.transpose());

  const Eigen::SelfAdjointEigenSolver<Matrix> esA(A, Eigen::EigenvaluesOnly);
  out.unloadedStable = esA.eigenvalues()[0] > 0.0;
  const double Ascale = esA.eigenvalues().cwiseAbs().maxCoeff();
  const double Gscale = std::max(1e-300, G.cwiseAbs().maxCoeff());
  // K_q ≈ 0 relative to the load matrix (per unit load and length): κ = 0.
  out.degenerate = Ascale <= 1e-13 * Gscale;

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
    generalisedEigen(A, B, pairs, out.droppedInfinite);
  }

  for (auto& [lambda, w] : pairs) {
    BucklingMode mode;
    mode.lambda = lambda;
    Vector z = Z * w;
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
