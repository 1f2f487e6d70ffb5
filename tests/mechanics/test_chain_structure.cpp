#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/equilibrium_problem.h"

#include "random_segments.h"

using namespace buckle::mechanics;
using buckle::continuation::projectedInertia;
using buckle::continuation::StabilityInfo;

namespace {

// b in [0.8, 1.4]: away from degenerate geometry.
const testing::SegmentRanges kNarrowChain{0.1, 0.9, 0.8, 1.4, 0.5, 3.0, 1.0, 2.8};

struct Instance {
  Chain chain;
  Vector q;
  Wrench F;
  Matrix H, J;
};

Instance randomInstance(int n, std::mt19937& rng, double loadScale = 1.0) {
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < n; ++i) segs.push_back(testing::randomSegment(rng, kNarrowChain));
  Chain chain(segs);
  Vector q(n);
  for (int i = 0; i < n; ++i) {
    std::uniform_real_distribution<double> Q(0.6 * chain.lowerLimits()[i], 0.6 * chain.upperLimits()[i]);
    q[i] = Q(rng);
  }
  std::uniform_real_distribution<double> Fd(-loadScale, loadScale);
  Wrench F(Fd(rng), Fd(rng), Fd(rng));
  Matrix H(n, n);
  totalPotentialHessian(chain, q, F, H);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  return {chain, q, F, H, J};
}

void assembleInstance(const Instance& in, ChainStructure& ws) {
  ChainData data(in.chain);
  forwardKinematics(in.chain, in.q, data);
  assemble(in.chain, data, in.q, in.F, ws);
}

Matrix rows(const Matrix& J, const std::vector<int>& idx) {
  Matrix C(int(idx.size()), J.cols());
  for (size_t k = 0; k < idx.size(); ++k) C.row(int(k)) = J.row(idx[k]);
  return C;
}

const std::vector<std::vector<int>> kHeldSets = {{}, {1}, {0, 1}, {0, 1, 2}, {2}};

// Zᵀ H Z on ker C (Z an orthonormal basis from a QR of Cᵀ): the dense reference of the
// constrained spectrum; H itself without constraints.
Matrix reducedOnKernel(const Matrix& H, const Matrix& C) {
  if (C.rows() == 0) return H;
  const Eigen::Index n = H.rows();
  Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
  const Matrix Qf = qr.householderQ() * Matrix::Identity(n, n);
  const Matrix Z = Qf.rightCols(n - qr.rank());
  return Z.transpose() * H * Z;
}

/// The ascending eigenvalues of H on ker C (all of H's without constraints): the dense reference.
Vector reducedEigenvalues(const Matrix& H, const Matrix& C) {
  Eigen::SelfAdjointEigenSolver<Matrix> es(reducedOnKernel(H, C), Eigen::EigenvaluesOnly);
  return es.eigenvalues();
}

}  // namespace

TEST_CASE("T is congruent to H: H = U T Uᵀ, equal inertia", "[chain_structure]") {
  std::mt19937 rng(11);
  for (int n : {1, 2, 3, 17, 200}) {
    for (int trial = 0; trial < 4; ++trial) {
      Instance in = randomInstance(n, rng, trial == 0 ? 0.0 : 2.0);
      ChainStructure ws(n);
      assembleInstance(in, ws);
      Matrix U = Matrix::Zero(n, n);
      for (int i = 0; i < n; ++i)
        for (int k = i; k < n; ++k) U(i, k) = 1.0;
      const Matrix T = tridiagonalMatrix(ws);
      const Matrix rebuilt = U * T * U.transpose();
      CHECK((rebuilt - in.H).norm() <= 1e-11 * std::max(1.0, in.H.norm()));
      CHECK(ws.frobeniusH == Approx(in.H.norm()).epsilon(1e-10).margin(1e-12));
      Eigen::SelfAdjointEigenSolver<Matrix> eT(T), eH(in.H);
      int negT = 0, negH = 0;
      for (int i = 0; i < n; ++i) {
        negT += eT.eigenvalues()[i] < 0;
        negH += eH.eigenvalues()[i] < 0;
      }
      CHECK(negT == negH);
      CHECK(hessianInertia(ws).negative == negH);
      factorize(ws, 0.0);
      CHECK(ws.factorInertia.negative == negH);
      // O(n) product
      Vector x = Vector::Random(n), y(n);
      applyHessian(ws, x, y);
      CHECK((y - in.H * x).norm() <= 1e-11 * std::max(1.0, in.H.norm()) * x.norm());
    }
  }
}

TEST_CASE("counts below a shift match the dense spectrum", "[chain_structure]") {
  std::mt19937 rng(5);
  for (int n : {1, 3, 17, 200}) {
    Instance in = randomInstance(n, rng, 3.0);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    Eigen::SelfAdjointEigenSolver<Matrix> es(in.H, Eigen::EigenvaluesOnly);
    const Vector& mu = es.eigenvalues();
    for (int i = 0; i + 1 < n; ++i) {
      const double s = 0.5 * (mu[i] + mu[i + 1]);
      if (mu[i + 1] - mu[i] < 1e-8 * std::max(1.0, in.H.norm())) continue;
      CHECK(countBelow(ws, s) == i + 1);
      factorize(ws, s);
      CHECK(ws.factorInertia.negative == i + 1);
      // the smallest pivot relative to max |T − σM| (M: 2, …, 2, 1 on the diagonal, −1 beside it),
      // from the pivots themselves; a count without the determinant is the same count
      Matrix shifted = tridiagonalMatrix(ws);
      for (int k = 0; k < n; ++k) {
        shifted(k, k) -= s * (k + 1 < n ? 2.0 : 1.0);
        if (k + 1 < n) shifted(k, k + 1) += s, shifted(k + 1, k) += s;
      }
      const double scale = shifted.cwiseAbs().maxCoeff();
      double ratio = std::numeric_limits<double>::infinity();
      for (int k = 0; k < n; k += ws.blockStart[size_t(k)]) {
        if (ws.blockStart[size_t(k)] == 1) {
          ratio = std::min(ratio, std::abs(ws.pivA[k]) / scale);
        } else {
          const double a = ws.pivA[k], b = ws.pivA[k + 1], e = ws.pivE[k];
          const double big = 0.5 * std::abs(a + b) + std::hypot(0.5 * (a - b), e);
          ratio = std::min(ratio, std::abs(a * b - e * e) / (big * scale));
        }
      }
      CHECK(ws.minPivotRatio == Approx(ratio).epsilon(1e-15));
      factorize(ws, s, false);
      CHECK(ws.factorInertia.negative == i + 1);
      CHECK(ws.minPivotRatio == Approx(ratio).epsilon(1e-15));
    }
  }
}

TEST_CASE("inertia of H and of H on ker C agree with the dense projection", "[chain_structure]") {
  std::mt19937 rng(2024);
  for (int n : {1, 2, 3, 17, 200}) {
    for (int trial = 0; trial < 6; ++trial) {
      Instance in = randomInstance(n, rng, 0.5 + trial);
      ChainStructure ws(n);
      assembleInstance(in, ws);
      for (const auto& held : kHeldSets) {
        if (int(held.size()) > n) continue;
        const Matrix C = rows(in.J, held);
        const StabilityInfo dense = projectedInertia(in.H, C);
        const Inertia fast = constrainedInertia(ws, C);
        INFO("n = " << n << ", held rows " << held.size() << ", trial " << trial);
        CHECK(fast.negative == dense.negative);
        CHECK(fast.zero == dense.zero);
        CHECK(fast.size() == n - ws.rank);
      }
    }
  }
}

TEST_CASE("a count's Schur complement from the factor's forward sweep equals Bᵀ(T − σM)⁻¹B by the full solve",
          "[chain_structure]") {
  // constrainedCountBelow without the determinant forms S = −Bᵀ(T − σM)⁻¹B by L⁻¹B and the pivot
  // blocks alone; with it, by solving for X = (T − σM)⁻¹B (forward and backward). Both at shifts
  // between the eigenvalues, where the Bunch factorization takes 1×1 and 2×2 pivots alike.
  std::mt19937 rng(77);
  int twoByTwo = 0;
  for (int n : {2, 3, 17, 200}) {
    Instance in = randomInstance(n, rng, 3.0);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    Eigen::SelfAdjointEigenSolver<Matrix> es(in.H, Eigen::EigenvaluesOnly);
    const Vector& mu = es.eigenvalues();
    for (const auto& held : kHeldSets) {
      if (held.empty() || int(held.size()) > n) continue;
      const int r = setConstraints(ws, rows(in.J, held));
      if (r == 0) continue;
      for (int i = 0; i + 1 < n; i += std::max(1, n / 20)) {
        const double s = 0.5 * (mu[i] + mu[i + 1]);
        const int withDet = constrainedCountBelow(ws, s, true);
        const ChainStructure::SmallMatrix full = ws.S;
        const int countOnly = constrainedCountBelow(ws, s, false);
        for (int k = 0; k < n; ++k) twoByTwo += ws.blockStart[size_t(k)] == 2;
        INFO("n = " << n << ", held rows " << held.size() << ", shift " << s);
        CHECK(countOnly == withDet);
        CHECK((ws.S - full).cwiseAbs().maxCoeff() <= 1e-10 * std::max(1.0, full.cwiseAbs().maxCoeff()));
      }
    }
  }
  CHECK(twoByTwo > 0);  // the 2×2 pivots' terms were exercised
}

TEST_CASE("degenerate straight chain: κ = 0 at F = 0 gives n (n − 1 on ker C) zero eigenvalues",
          "[chain_structure]") {
  // κ = k (b L0 − 2(b² − a²)) = 0 for a = 0.5, b = 1, k = 1, L0 = 1.5 (the L_triv case).
  for (int n : {1, 2, 3, 17, 200}) {
    Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.5));
    Vector q = Vector::Zero(n);
    ChainData data(chain);
    forwardKinematics(chain, q, data);
    Matrix J(3, n);
    endJacobian(data, J);
    ChainStructure ws(n);
    assemble(chain, data, q, Wrench::Zero(), ws);
    const Inertia free = hessianInertia(ws);
    CHECK(free.zero == n);
    CHECK(free.negative == 0);
    const Inertia pinned = constrainedInertia(ws, rows(J, {1}));
    CHECK(pinned.zero == n - 1);
    CHECK(pinned.negative == 0);
    // straight chain, x and y held: the x row (−S) vanishes, so rank(C) = 1
    const Inertia held = constrainedInertia(ws, rows(J, {0, 1}));
    CHECK(ws.rank == 1);
    CHECK(held.zero == n - 1);
    // just past F = 0 in compression the index jumps to n − 1 at once (on ker y: L_triv's 0 → 2)
    for (double Fx : {-1e-3, 1e-3}) {
      Matrix H(n, n);
      totalPotentialHessian(chain, q, Wrench(Fx, 0, 0), H);
      assemble(chain, data, q, Wrench(Fx, 0, 0), ws);
      const StabilityInfo dense = projectedInertia(H, rows(J, {1}));
      const Inertia fast = constrainedInertia(ws, rows(J, {1}));
      CHECK(fast.negative == dense.negative);
      CHECK(fast.zero == dense.zero);
      if (Fx < 0) CHECK(fast.negative == n - 1);
      else CHECK(fast.negative == 0);
    }
  }
}

TEST_CASE("clamped–pinned 3-chain: the eq 17 branch points are zeros of the reduced Hessian",
          "[chain_structure]") {
  const double kappa = 0.75;  // a = 0.5, b = 1, k = 1, L0 = 2.25
  Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  Vector q = Vector::Zero(3);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, 3);
  endJacobian(data, J);
  const Matrix C = rows(J, {1});
  ChainStructure ws(3);
  const double lamU = (std::sqrt(21.0) - 14.0) / 10.0, lamZ = -(std::sqrt(21.0) + 14.0) / 10.0;
  int index = 0;
  for (double lam : {lamU, lamZ}) {
    const double Fx = lam * kappa;
    assemble(chain, data, q, Wrench(Fx, 0, 0), ws);
    const Inertia at = constrainedInertia(ws, C);
    CHECK(at.zero == 1);
    CHECK(at.negative == index);
    // at U the zero is the lowest eigenvalue; at Z one eigenvalue is already negative
    if (index == 0) CHECK(std::abs(smallestEigenvalue(ws, true, 1e-14)) < 1e-12);
    else CHECK(smallestEigenvalue(ws, true, 1e-14) < -0.1);
    for (double d : {-1e-9, 1e-9}) {
      assemble(chain, data, q, Wrench(Fx + d, 0, 0), ws);
      const Inertia near = constrainedInertia(ws, C);
      CHECK(near.zero == 0);
      CHECK(near.negative == (d < 0 ? index + 1 : index));
    }
    ++index;
  }
}

TEST_CASE("near-singular H (an eigenvalue shifted to zero) on and off ker C", "[chain_structure]") {
  std::mt19937 rng(99);
  for (int n : {2, 3, 17, 200}) {
    Instance in = randomInstance(n, rng, 1.5);
    Eigen::SelfAdjointEigenSolver<Matrix> es(in.H, Eigen::EigenvaluesOnly);
    ChainStructure ws(n);
    ChainData data(in.chain);
    forwardKinematics(in.chain, in.q, data);
    Vector kappa(n), h(n);
    jointStiffness(in.chain, in.q, kappa);
    loadHessianGenerator(data, in.F, h);
    for (int k : {0, n / 2}) {
      const double mu = es.eigenvalues()[k];
      // H − μI is again of chain form: K_q − μI is diagonal
      Vector kap = kappa.array() - mu;
      assemble(kap, h, ws);
      Matrix Hs = in.H - mu * Matrix::Identity(n, n);
      for (const auto& held : kHeldSets) {
        if (int(held.size()) > n) continue;
        const Matrix C = rows(in.J, held);
        const StabilityInfo dense = projectedInertia(Hs, C);
        const Inertia fast = constrainedInertia(ws, C);
        INFO("n = " << n << ", k = " << k << ", held rows " << held.size());
        CHECK(fast.negative == dense.negative);
        CHECK(fast.zero == dense.zero);
        if (held.empty()) CHECK(fast.zero == 1);
      }
    }
  }
}

TEST_CASE("smallest eigenvalue by bisection", "[chain_structure]") {
  std::mt19937 rng(3);
  for (int n : {1, 3, 17, 200}) {
    Instance in = randomInstance(n, rng, 1.0);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const double scale = std::max(1.0, in.H.norm());
    for (const auto& held : kHeldSets) {
      if (int(held.size()) >= n) continue;
      const Matrix C = rows(in.J, held);
      const StabilityInfo dense = projectedInertia(in.H, C);
      setConstraints(ws, C);
      const double s = smallestEigenvalue(ws, !held.empty(), 1e-13);
      CHECK(std::abs(s - dense.smallest) <= 1e-10 * scale);
    }
  }
}

TEST_CASE("O(n) solves of H, the KKT system and a Keller-type bordered system", "[chain_structure]") {
  std::mt19937 rng(17);
  for (int n : {1, 2, 3, 17, 200}) {
    for (int trial = 0; trial < 3; ++trial) {
      Instance in = randomInstance(n, rng, 1.0);
      ChainStructure ws(n);
      assembleInstance(in, ws);
      const double cond = [&] {
        Eigen::SelfAdjointEigenSolver<Matrix> es(in.H, Eigen::EigenvaluesOnly);
        return es.eigenvalues().cwiseAbs().maxCoeff() / es.eigenvalues().cwiseAbs().minCoeff();
      }();
      const double tol = 1e-13 * n * n * std::max(1.0, cond);
      Vector r = Vector::Random(n), x(n);
      REQUIRE(solve(ws, r, x));
      const Vector xd = in.H.partialPivLu().solve(r);
      CHECK((x - xd).norm() <= tol * xd.norm());

      for (const auto& held : kHeldSets) {
        const int m = int(held.size());
        if (m == 0 || m > n) continue;
        const Matrix C = rows(in.J, held);
        Matrix K = Matrix::Zero(n + m, n + m);
        K.topLeftCorner(n, n) = in.H;
        K.topRightCorner(n, m) = C.transpose();
        K.bottomLeftCorner(m, n) = C;
        Vector f = Vector::Random(n), g = Vector::Random(m), xs(n), ys(m);
        Eigen::FullPivLU<Matrix> lu(K);
        if (!lu.isInvertible()) continue;
        REQUIRE(solveKKT(ws, C, f, g, xs, ys));
        Vector rhs(n + m);
        rhs << f, g;
        const Vector sol = lu.solve(rhs);
        const Vector mine = (Vector(n + m) << xs, ys).finished();
        Eigen::JacobiSVD<Matrix> svd(K);
        const double condK = svd.singularValues()[0] / svd.singularValues()[n + m - 1];
        INFO("n = " << n << " m = " << m << " cond(K) = " << condK);
        CHECK((mine - sol).norm() <= 1e-13 * n * n * std::max(1.0, condK) * sol.norm());
      }

      // Keller system [[H, V], [Wᵀ, D]] with p = 2 (a multiplier column and the F_λ / tangent column)
      const int p = std::min(2, n);
      Matrix V = Matrix::Random(n, p), W = Matrix::Random(n, p), D = Matrix::Random(p, p);
      Matrix K(n + p, n + p);
      K << in.H, V, W.transpose(), D;
      Vector f = Vector::Random(n), g = Vector::Random(p), xs(n), ys(p);
      REQUIRE(solveBordered(ws, V, W, D, f, g, xs, ys));
      Vector rhs(n + p);
      rhs << f, g;
      const Vector sol = K.fullPivLu().solve(rhs);
      Eigen::JacobiSVD<Matrix> svd(K);
      const double condK = svd.singularValues()[0] / svd.singularValues()[n + p - 1];
      const Vector mine = (Vector(n + p) << xs, ys).finished();
      CHECK((mine - sol).norm() <= 1e-13 * n * n * std::max(1.0, condK) * sol.norm());
    }
  }
}

TEST_CASE("bordered solve stays accurate where H is singular but the bordered matrix is not (a fold)",
          "[chain_structure]") {
  std::mt19937 rng(41);
  for (int n : {3, 17, 200}) {
    Instance in = randomInstance(n, rng, 1.0);
    Eigen::SelfAdjointEigenSolver<Matrix> es(in.H);
    const double mu = es.eigenvalues()[0];
    ChainData data(in.chain);
    forwardKinematics(in.chain, in.q, data);
    Vector kappa(n), h(n);
    jointStiffness(in.chain, in.q, kappa);
    loadHessianGenerator(data, in.F, h);
    // shift so that H is singular up to ~1e-10 relative
    const double shift = mu - 1e-10 * std::max(1.0, in.H.norm());
    Vector kap = kappa.array() - shift;
    ChainStructure ws(n);
    assemble(kap, h, ws);
    const Matrix Hs = in.H - shift * Matrix::Identity(n, n);
    Matrix V = Matrix::Random(n, 1), W = Matrix::Random(n, 1), D = Matrix::Random(1, 1);
    Matrix K(n + 1, n + 1);
    K << Hs, V, W.transpose(), D;
    Vector f = Vector::Random(n), g = Vector::Random(1), xs(n), ys(1);
    REQUIRE(solveBordered(ws, V, W, D, f, g, xs, ys));
    Vector rhs(n + 1);
    rhs << f, g;
    const Vector mine = (Vector(n + 1) << xs, ys).finished();
    // backward error of the O(n) solve
    const double backward = (K * mine - rhs).norm() / (K.norm() * mine.norm() + rhs.norm());
    INFO("n = " << n << " backward error " << backward);
    CHECK(backward < 1e-12);
  }
}

TEST_CASE("lowest eigenvalues (isolation + Illinois on det K_σ) match the dense ones", "[chain_structure]") {
  std::mt19937 rng(8);
  for (int n : {1, 2, 3, 17, 200}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const double scale = std::max(1.0, in.H.norm());
    for (const auto& held : kHeldSets) {
      if (int(held.size()) >= n) continue;
      const Matrix C = rows(in.J, held);
      const Matrix reduced = reducedOnKernel(in.H, C);
      Eigen::SelfAdjointEigenSolver<Matrix> es(reduced, Eigen::EigenvaluesOnly);
      setConstraints(ws, C);
      Vector out(3);
      const int k = lowestEigenvalues(ws, !held.empty(), 3, out);
      REQUIRE(k == std::min<int>(3, int(reduced.rows())));
      for (int j = 0; j < k; ++j) CHECK(std::abs(out[j] - es.eigenvalues()[j]) <= 1e-11 * scale);
    }
  }
}

TEST_CASE("lowest eigenvalues from a warm start: near, far and wrong guesses give the dense ones",
          "[chain_structure]") {
  // The warm start widens a bracket around each guessed eigenvalue from 2 % of it; guesses close
  // to the answer, off by many eigenvalue gaps, of the wrong sign or zero must all end on the
  // dense spectrum (the counts keep every bracket honest).
  std::mt19937 rng(21);
  for (int n : {40, 300}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const double scale = std::max(1.0, in.H.norm());
    Eigen::SelfAdjointEigenSolver<Matrix> es(in.H, Eigen::EigenvaluesOnly);
    const Vector exact = es.eigenvalues().head(3);
    const double gap = exact[2] - exact[0];
    for (const Vector& guess : {Vector(exact * (1.0 + 1e-6)), Vector(exact.array() + 7.0 * gap),
                                Vector(-exact), Vector(Vector::Zero(3)), Vector(exact.array() - 0.5 * scale)}) {
      setConstraints(ws, Matrix(0, n));
      Vector out(3);
      REQUIRE(lowestEigenvalues(ws, false, 3, out, 1e-13, &guess) == 3);
      for (int j = 0; j < 3; ++j) CHECK(std::abs(out[j] - exact[j]) <= 1e-11 * scale);
    }
  }
}

TEST_CASE("d log|det(T − σM)|/dσ of the factorization against central differences, 1×1 and 2×2 pivots",
          "[chain_structure]") {
  // Shifts between eigenvalues make Bunch's pivoting take 2×2 blocks (an indefinite T − σM
  // with small diagonal entries); the derivative carried through both kinds of pivot must match
  // the difference quotient of log|det| itself.
  std::mt19937 rng(55);
  for (int n : {1, 2, 5, 40}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const Vector mu = reducedEigenvalues(in.H, Matrix(0, n));
    const double scale = std::max(1.0, in.H.norm());
    bool twoByTwo = false;
    for (int i = 0; i + 1 < n; ++i) {
      const double sigma = 0.5 * (mu[i] + mu[i + 1]);
      factorize(ws, sigma);
      const double d = ws.dLogAbsDet;
      for (int k = 0; k < n; ++k) twoByTwo = twoByTwo || ws.blockStart[size_t(k)] == 2;
      const double h = 1e-6 * std::min(mu[i + 1] - mu[i], scale);
      factorize(ws, sigma + h);
      const double up = ws.logAbsDet;
      factorize(ws, sigma - h);
      const double down = ws.logAbsDet;
      // Σ 1/(σ − μ_j) exactly (det(T − σM) = det(U)⁻²·Π(μ_j − σ))
      const double exact = (1.0 / (sigma - mu.array())).sum();
      CHECK(std::abs(d - exact) <= 1e-7 * (std::abs(exact) + 1.0 / (mu[i + 1] - mu[i])));
      CHECK(std::abs(d - (up - down) / (2.0 * h)) <= 1e-5 * (std::abs(d) + 1.0 / (mu[i + 1] - mu[i])));
    }
    if (n >= 40) CHECK(twoByTwo);
  }
}

TEST_CASE("eigenvalues from a warm start a step away cost a few factorizations each (Newton on det)",
          "[chain_structure]") {
  // The spectral monitor asks for the same eigenvalues at a point and a step δ along the branch
  // away, and the next point is one step away: each a guess within Newton's quadratic range.
  // Newton on det K_σ, certified by two counts, must give the dense values to the tolerance with
  // at most 8 factorizations for any eigenvalue and 5 on average (isolation and Illinois took
  // 10–25), on and off ker C.
  std::mt19937 rng(89);
  long total = 0, eigenvalues = 0;
  for (int n : {12, 60, 400}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const double scale = std::max(1.0, in.H.norm());
    for (const auto& held : kHeldSets) {
      const Matrix C = rows(in.J, held);
      const Vector mu = reducedEigenvalues(in.H, C);
      for (int first : {0, 3}) {
        const Vector exact = mu.segment(first, 2);
        // off by a fraction of the smallest spacing around them (the continuation's steps are
        // far below the spacing: an eigenvalue does not pass its neighbour between two points)
        const Vector around = mu.segment(std::max(0, first - 1), first > 0 ? 4 : 3);
        const double spacing = (around.tail(around.size() - 1) - around.head(around.size() - 1)).minCoeff();
        for (double rel : {1e-9, 1e-3}) {
          const Vector guess = exact.array() + rel * spacing;
          setConstraints(ws, C);
          const long before = ws.factorizations;
          Vector out(2);
          REQUIRE(eigenvaluesFrom(ws, !held.empty(), first, 2, out, 1e-13, &guess) == 2);
          for (int j = 0; j < 2; ++j) CHECK(std::abs(out[j] - exact[j]) <= 1e-11 * scale);
          const long used = ws.factorizations - before;
          CHECK(used <= 2 * 8);
          total += used;
          eigenvalues += 2;
        }
      }
    }
  }
  CHECK(double(total) / double(eigenvalues) <= 5.0);
}

TEST_CASE("eigenvalues in a cluster: a warm start is certified within the tolerance, not bisected from the outer bounds",
          "[chain_structure]") {
  // An unloaded uniform chain (a stretch whose load the base wall takes) has H = K_q: every
  // eigenvalue at κ within rounding, or, under a load of 1e-14 k, hundreds within 1e-10 of it
  // (wider than the tolerance). From the previous point's value (here the exact one or 1e-12 of
  // it away) Newton on det stops at the cluster; the counts either side then put eigenvalue j
  // in a bracket narrower than the tolerance. Both against the dense reduced spectrum, on and off
  // ker C; the tight cluster in at most 10 factorizations an eigenvalue (a demand for isolation
  // bisected from ±‖H‖: about 25), the wider one from below in at most 10 too (the bracket's
  // end widening towards it).
  const int n = 300;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const Vector q = Vector::Constant(n, 0.01);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  for (double load : {0.0, 1e-14}) {
    const Wrench F(-load, 0.5 * load, 0.0);
    Matrix H(n, n);
    totalPotentialHessian(chain, q, F, H);
    ChainStructure ws(n);
    assemble(chain, data, q, F, ws);
    const double scale = std::max(1.0, H.norm());
    for (const auto& held : kHeldSets) {
      INFO("load " << load << ", " << held.size() << " held rows");
      const Matrix C = rows(J, held);
      const Vector all = reducedEigenvalues(H, C);
      const Vector exact = all.head(2);
      const double spread = all.maxCoeff() - all.minCoeff();
      CHECK(spread <= (load == 0.0 ? 1e-13 : 1e-9) * scale);  // a cluster, within the tolerance or not
      for (double rel : {0.0, -1e-12, 1e-12}) {
        const Vector guess = exact.array() * (1.0 + rel);
        setConstraints(ws, C);
        const long before = ws.factorizations;
        Vector out(2);
        REQUIRE(lowestEigenvalues(ws, !held.empty(), 2, out, 1e-13, &guess) == 2);
        for (int j = 0; j < 2; ++j) CHECK(std::abs(out[j] - exact[j]) <= 1e-11 * scale);
        if (load == 0.0 || rel <= 0.0) CHECK(ws.factorizations - before <= 2 * 10);
      }
    }
  }
}

TEST_CASE("lowest eigenvalues from a warm start that isolates some brackets and not others, with held joints",
          "[chain_structure]") {
  // A guess that isolates eigenvalue j needs no outer bound ±‖H‖_F; one that does not falls back
  // to it (confirmed by counts) for that bracket only. Mixed guesses (exact, far, missing entries)
  // and the constrained count (held joints) must all end on the dense reduced spectrum.
  std::mt19937 rng(34);
  for (int n : {40, 120}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    const double scale = std::max(1.0, in.H.norm());
    for (const auto& held : kHeldSets) {
      const Matrix C = rows(in.J, held);
      const Vector exact = reducedEigenvalues(in.H, C).head(3);
      const double gap = exact[2] - exact[0];
      const double nan = std::numeric_limits<double>::quiet_NaN();
      for (const Vector& guess :
           {Vector(exact), Vector((Vector(3) << exact[0], exact[1] + 5.0 * gap, 2.0 * scale).finished()),
            Vector((Vector(3) << 3.0 * scale, exact[1], exact[2]).finished()),
            Vector((Vector(3) << nan, exact[1], nan).finished()), Vector(exact.head(1))}) {
        setConstraints(ws, C);
        Vector out(3);
        REQUIRE(lowestEigenvalues(ws, !held.empty(), 3, out, 1e-13, &guess) == 3);
        for (int j = 0; j < 3; ++j) CHECK(std::abs(out[j] - exact[j]) <= 1e-11 * scale);
      }
    }
  }
}

TEST_CASE("EquilibriumProblem: structured stability() agrees with the dense default", "[chain_structure]") {
  std::mt19937 rng(123);
  const std::vector<EndCondition> ends = {EndCondition::freeEnd(Eigen::Vector3d(0.3, -0.2, 0.1)),
                                          EndCondition::clampedPinned(-0.5), EndCondition::heldPosition(3.0, 0.5)};
  for (int n : {1, 2, 3, 4, 17, 40, 100}) {  // inertia alone: dense up to n = 3, counts from 4; n >= 32 O(n)
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < n; ++i) segs.push_back(testing::randomSegment(rng, kNarrowChain));
    Chain chain(segs);
    for (const EndCondition& end : ends) {
      if (end.heldCount() >= n) continue;
      EquilibriumOptions fastOpt, denseOpt;
      fastOpt.structuredStability = true;
      denseOpt.structuredStability = false;
      EquilibriumProblem fast(chain, end, Eigen::Vector3d(-1.0, 0.2, 0.0), fastOpt);
      EquilibriumProblem dense(chain, end, Eigen::Vector3d(-1.0, 0.2, 0.0), denseOpt);
      for (int trial = 0; trial < 10; ++trial) {
        Vector u(fast.dimension());
        for (int i = 0; i < n; ++i) {
          std::uniform_real_distribution<double> Q(0.5 * chain.lowerLimits()[i], 0.5 * chain.upperLimits()[i]);
          u[i] = trial == 0 ? 0.0 : Q(rng);
        }
        std::uniform_real_distribution<double> R(-2.0, 2.0);
        for (int k = n; k < u.size(); ++k) u[k] = R(rng);
        const double lambda = trial == 0 ? 0.0 : R(rng);
        StabilityInfo a, b;
        REQUIRE(buckle::continuation::BoundProblem(fast).stability(u, lambda, 3, a));
        REQUIRE(buckle::continuation::BoundProblem(dense).stability(u, lambda, 3, b));
        INFO("n = " << n << " held " << end.heldCount() << " trial " << trial);
        CHECK(a.negative == b.negative);
        CHECK(a.zero == b.zero);
        StabilityInfo c;  // inertia only (bench_cases' setting per point)
        REQUIRE(buckle::continuation::BoundProblem(fast).stability(u, lambda, 0, c));
        CHECK(c.negative == b.negative);
        CHECK(c.zero == b.zero);
        CHECK(c.lowest.size() == 0);
        REQUIRE(a.lowest.size() == b.lowest.size());
        const double scale = std::max(1.0, b.lowest.cwiseAbs().maxCoeff()) * n;
        for (Eigen::Index j = 0; j < a.lowest.size(); ++j) CHECK(a.lowest[j] == Approx(b.lowest[j]).margin(1e-10 * scale));
        CHECK(a.smallest == Approx(b.smallest).margin(1e-10 * scale));
      }
    }
  }
}

TEST_CASE("small-chain dense path: inertia and lowest eigenvalues match the dense projection", "[chain_structure]") {
  std::mt19937 rng(77);
  for (int n : {1, 2, 3, 4, 5, 17, 32}) {  // 2, 3, 4: the unrolled sizes
    for (int trial = 0; trial < 8; ++trial) {
      Instance in = randomInstance(n, rng, 0.3 + trial);
      ChainStructure ws(n);
      assembleInstance(in, ws);
      for (const auto& held : kHeldSets) {
        if (int(held.size()) > n) continue;
        const Matrix C = rows(in.J, held);
        const StabilityInfo dense = projectedInertia(in.H, C);
        Eigen::Vector3d low;
        int found = 0;
        const Inertia fast = smallDenseInertia(ws, C, 3, low, found);
        INFO("n = " << n << " held " << held.size() << " trial " << trial);
        CHECK(fast.negative == dense.negative);
        CHECK(fast.zero == dense.zero);
        REQUIRE(found == int(dense.lowest.size()));
        const double scale = std::max(1.0, in.H.norm());
        for (int j = 0; j < found; ++j) CHECK(std::abs(low[j] - dense.lowest[j]) <= 1e-12 * scale);
      }
    }
  }
}

TEST_CASE("a coupling R E Rᵀ bordered on the counts: inertia, eigenvalues and eigenvectors of H + R E Rᵀ on ker C "
          "equal the dense ones",
          "[chain_structure]") {
  std::mt19937 rng(31);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int n : {40, 200}) {
    Instance in = randomInstance(n, rng, 1.5);
    ChainStructure ws(n);
    assembleInstance(in, ws);
    for (const auto& held : kHeldSets) {
      for (int c : {1, 2, 4}) {
        if (int(held.size()) + c > ChainStructure::kMaxBorder) continue;
        Matrix R(n, c);
        Vector E(c);
        for (int j = 0; j < c; ++j) {
          // a term of H's size, each sign, and one column zero (a self contact at μ = 0)
          for (int i = 0; i < n; ++i) R(i, j) = j == 3 ? 0.0 : 0.3 * N(rng) * std::sqrt(in.H.norm() / n);
          E[j] = j % 2 == 0 ? -1.0 : 1.0;
        }
        const Matrix C = rows(in.J, held);
        const Matrix Hc = in.H + R * E.asDiagonal() * R.transpose();
        const Vector dense = reducedEigenvalues(Hc, C);
        const double scale = std::max(1.0, Hc.norm()), tau = 1e-13 * std::max(ws.typicalScale, ws.frobeniusH);
        INFO("n = " << n << ", held " << held.size() << ", coupling columns " << c);
        if (held.empty())
          ws.rank = ws.couplingCount = 0;
        else
          setConstraints(ws, C);
        setCoupling(ws, R, E);
        const Inertia inertia = borderedInertia(ws);
        CHECK(inertia.negative == int((dense.array() < -tau).count()));
        CHECK(inertia.size() == int(dense.size()));
        Vector out(3);
        REQUIRE(lowestEigenvalues(ws, true, 3, out) == 3);
        for (int j = 0; j < 3; ++j) CHECK(std::abs(out[j] - dense[j]) <= 1e-10 * scale);
        // the eigenvector of the lowest: in ker C and solving (H + R E Rᵀ) v = λ v there
        Vector v(n);
        REQUIRE(eigenvectorAt(ws, true, out[0], v, 2));
        if (!held.empty()) CHECK((C * v).norm() <= 1e-10 * C.norm());
        Vector r = Hc * v - out[0] * v;
        if (!held.empty()) {  // the residual's part in ker C
          Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
          const Matrix Qf = qr.householderQ() * Matrix::Identity(n, n);
          const Matrix Z = Qf.rightCols(n - qr.rank());
          r = Z * (Z.transpose() * r);
        }
        CHECK(r.norm() <= 1e-8 * scale);
        // the constraints alone again: setConstraints drops the coupling
        if (!held.empty()) {
          setConstraints(ws, C);
          CHECK(ws.couplingCount == 0);
          Vector plain(1);
          lowestEigenvalues(ws, true, 1, plain);
          CHECK(std::abs(plain[0] - reducedEigenvalues(in.H, C)[0]) <= 1e-10 * scale);
        }
      }
    }
  }
}
