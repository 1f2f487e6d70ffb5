// EquilibriumProblem with body loads (equilibrium_problem_body.cpp, body_loads.h): the residual
// against differences of the total potential E − F·p + V, every derivative route against
// differences and the dense matrices, the O(n) stability against a dense eigen-solve; the sag of
// a heavy cantilever and continuation in the gravity magnitude against an independent Newton
// solve (GravityPotential, absolute positions); the critical payload and the critical gravity of a
// heavy column against the zero of the smallest eigenvalue of a dense Hessian assembled here, by
// bisection; scaled units (lengths ×1e-4, stiffness ×1e8, masses with the force unit).
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "buckle/continuation/branch.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/gravity.h"
#include "buckle/mechanics/jump.h"
#include "heavy_newton.h"
#include "random_segments.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

Chain scaledUniform(int n, double L, double k) {
  return Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L));
}

BodyLoads randomBodyLoads(std::mt19937& rng, const Chain& chain) {
  std::uniform_real_distribution<double> W(-1.0, 1.0), M(0.2, 1.0);
  const int n = chain.size();
  BodyLoads b;
  b.mass.resize(n);
  b.centre.resize(n);
  for (int i = 0; i < n; ++i) {
    b.mass[i] = M(rng);
    b.centre[i] = 0.5 * (1.0 + W(rng)) * chain.linkLengths()[i + 1];
  }
  b.gravity = {W(rng), W(rng)};
  b.gravityRate = {W(rng), W(rng)};
  for (int j = 1; j <= n + 1; j += 2) b.points.push_back({j, {W(rng), W(rng)}, {W(rng), W(rng)}});
  return b;
}

// The straight heavy column (gravity along −x, payload P at the end along −x): the dense Hessian
// κ_i δ_ij − P (x_end − x_max) − g Σ_{k≥max} m_k (c_k − x_max) of eq 27 and (G3), positions
// summed here along the straight line.
Matrix columnHessian(const Chain& chain, const Vector& mass, double g, double P) {
  const int n = chain.size();
  const Vector& l = chain.linkLengths();
  Vector x(n + 1), c(n);  // joints 1 … n and the end; centres mid-link
  double s = l[0];
  for (int i = 0; i < n; ++i) {
    x[i] = s;
    c[i] = s + 0.5 * l[i + 1];
    s += l[i + 1];
  }
  x[n] = s;
  Vector kappa(n);
  jointStiffness(chain, Vector::Zero(n), kappa);
  Matrix H(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int m = std::max(i, j);
      double weight = 0.0;
      for (int k = m; k < n; ++k) weight += mass[k] * (c[k] - x[m]);
      H(i, j) = -P * (x[n] - x[m]) - g * weight + (i == j ? kappa[i] : 0.0);
    }
  return H;
}

double smallestEigenvalue(const Matrix& H) {
  return Eigen::SelfAdjointEigenSolver<Matrix>(H, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

// The zero of f (f(lo) > 0 > f(hi)) by bisection to rounding.
template <class F>
double bisect(F f, double lo, double hi) {
  for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double firstCriticalLoad(EquilibriumProblem& problem, int n, double lambdaMax) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = lambdaMax;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  o.contact = false;
  const EquilibriumBranches r =
      traceEquilibria(problem, Vector::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
  const auto bps = r.tree.branches.at(0).specialPointsOfType(cont::SpecialPointType::BranchPoint);
  REQUIRE(!bps.empty());
  return bps.front()->lambda;
}

}  // namespace

TEST_CASE("body loads in EquilibriumProblem: residual, Jacobian, F_lambda, second derivatives, products by differences",
          "[equilibrium][body_loads]") {
  std::mt19937 rng(131);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  for (int n : {1, 3, 8, 40}) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < n; ++i) segs.push_back(testing::randomSegment(rng));
    const Chain chain(segs);
    const std::vector<std::pair<std::string, EndCondition>> ends = {
        {"free", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng)))},
        {"clamped-pinned", EndCondition::clampedPinned(W(rng), W(rng))},
        {"held position", EndCondition::heldPosition(0.6 * chain.length(), W(rng))}};
    for (const auto& [name, end] : ends) {
      INFO("n = " << n << ", end: " << name);
      EquilibriumProblem problem(chain, end, Eigen::Vector3d(W(rng), W(rng), W(rng)), {}, {},
                                 randomBodyLoads(rng, chain));
      REQUIRE(problem.hasBodyLoads());
      const int N = problem.dimension();
      const Vector u = testing::randomState(rng, chain, N);
      const double lambda = Lam(rng), h = 1e-6;
      Matrix Fu(N, N), dFu(N, N), Jp(N, N), Jm(N, N);
      Vector Fl(N), dFl(N), F(N), Fp(N), Fm(N), Jlp(N), Jlm(N);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, Fu, Fl));
      const double scale = std::max(1.0, Fu.lpNorm<Eigen::Infinity>());
      // the q rows are ∂Π/∂q of Π = E − F·p + V (F the wrench at (u, λ), held fixed)
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
      const Wrench Wr = problem.wrench(u, lambda);
      for (int j = 0; j < n; ++j) {
        Vector qp = u.head(n), qm = u.head(n);
        qp[j] += h;
        qm[j] -= h;
        const double Pp = totalPotential(chain, qp, Wr) + problem.bodyLoadPotential(qp, lambda);
        const double Pm = totalPotential(chain, qm, Wr) + problem.bodyLoadPotential(qm, lambda);
        CHECK(std::abs((Pp - Pm) / (2 * h) - F[j]) <= 1e-7 * scale);
      }
      double err = 0.0;
      for (int j = 0; j < N; ++j) {
        Vector up = u, um = u;
        up[j] += h;
        um[j] -= h;
        REQUIRE(buckle::continuation::BoundProblem(problem).residual(up, lambda, Fp));
        REQUIRE(buckle::continuation::BoundProblem(problem).residual(um, lambda, Fm));
        err = std::max(err, (Fu.col(j) - (Fp - Fm) / (2 * h)).lpNorm<Eigen::Infinity>());
      }
      CHECK(err <= 1e-7 * scale);
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda + h, Fp));
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda - h, Fm));
      CHECK((Fl - (Fp - Fm) / (2 * h)).lpNorm<Eigen::Infinity>() <= 1e-7 * scale);
      Matrix H, C;
      REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
      CHECK((Fu.topLeftCorner(n, n) - H).lpNorm<Eigen::Infinity>() <= 1e-14 * scale);
      // F_u's directional derivative and the O(n) second derivative along (du, dλ)
      Vector x(N + 1), z(N + 1);
      for (int i = 0; i <= N; ++i) x[i] = W(rng), z[i] = W(rng);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianDirectionalDerivative(u, lambda, x.head(N), x[N], dFu,
                                                                                        dFl));
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u + h * x.head(N), lambda + h * x[N], Jp, Jlp));
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u - h * x.head(N), lambda - h * x[N], Jm, Jlm));
      CHECK((dFu - (Jp - Jm) / (2 * h)).lpNorm<Eigen::Infinity>() <= 1e-6 * scale);
      CHECK((dFl - (Jlp - Jlm) / (2 * h)).lpNorm<Eigen::Infinity>() <= 1e-6 * scale);
      Vector s2(N), s2t(N), y(N), yt(N + 1);
      REQUIRE(buckle::continuation::BoundProblem(problem).secondDerivativeApply(u, lambda, x, z, s2));
      REQUIRE(buckle::continuation::BoundProblem(problem).secondDerivativeApply(u, lambda, z, x, s2t));
      const Vector dense = dFu * z.head(N) + dFl * z[N];
      CHECK((s2 - dense).lpNorm<Eigen::Infinity>() <= 1e-12 * scale * N);
      CHECK((s2 - s2t).lpNorm<Eigen::Infinity>() <= 1e-12 * scale * N);
      // O(n) products with F_x and F_xᵀ
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianApply(u, lambda, x, y));
      CHECK((y - Fu * x.head(N) - Fl * x[N]).lpNorm<Eigen::Infinity>() <= 1e-13 * scale * N);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianTransposeApply(u, lambda, z.head(N), yt));
      CHECK((yt.head(N) - Fu.transpose() * z.head(N)).lpNorm<Eigen::Infinity>() <= 1e-13 * scale * N);
      CHECK(std::abs(yt[N] - Fl.dot(z.head(N))) <= 1e-13 * scale * N);
      // the O(n) stability: inertia and lowest eigenvalues of H on ker C, against a dense solve
      Matrix Z = Matrix::Identity(n, n);
      if (C.rows() > 0) {
        const Eigen::FullPivLU<Matrix> lu(C);
        Z = lu.rank() == n ? Matrix(n, 0) : Matrix(lu.kernel());  // kernel() of a full-rank C is one zero column
      }
      Vector mu(0);
      if (Z.cols() > 0) {
        Eigen::HouseholderQR<Matrix> qr(Z);
        const Matrix Q = qr.householderQ() * Matrix::Identity(n, Z.cols());
        mu = Eigen::SelfAdjointEigenSolver<Matrix>(Q.transpose() * H * Q).eigenvalues();
      }
      cont::StabilityInfo info;
      REQUIRE(buckle::continuation::BoundProblem(problem).stability(u, lambda, 2, info));
      int negative = 0;
      for (int i = 0; i < mu.size(); ++i) negative += mu[i] < 0.0;
      CHECK(info.negative == negative);
      REQUIRE(info.lowest.size() == std::min<Eigen::Index>(2, mu.size()));
      for (int i = 0; i < info.lowest.size(); ++i) CHECK(std::abs(info.lowest[i] - mu[i]) <= 1e-9 * scale * n);
      // the eigenvalue rate bound holds along (du, dλ)
      double bound = 0.0;
      if (buckle::continuation::BoundProblem(problem).stabilityRateBound(u, lambda, x.head(N), x[N], bound)) {
        Matrix Hp, Cp, Hm, Cm;
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u + h * x.head(N), lambda + h * x[N], Hp,
                                                                              Cp));
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u - h * x.head(N), lambda - h * x[N], Hm,
                                                                              Cm));
        if (C.rows() == 0) CHECK(((Hp - Hm) / (2 * h)).norm() <= bound * (1 + 1e-6) + 1e-6 * scale);
      }
    }
  }
}

TEST_CASE("a heavy cantilever sags as an independent Newton solve, in the paper's and in scaled units",
          "[equilibrium][body_loads]") {
  const int n = 12;
  for (double L : {1.0, 1e-4}) {
    const double k = L == 1.0 ? 1.0 : 1e8, force = k * L;
    const Chain chain = scaledUniform(n, L, k);
    // ρ so that each link weighs 0.05 force units at g = 9.81 (the same g in both unit systems)
    const double g = 9.81, rho = 0.05 * force / (g * chain.linkLengths()[1]);
    const InertiaData inertia = InertiaData::uniformRods(chain, rho);
    const Eigen::Vector2d down(0.0, -1.0);
    // the library: continuation in λ = g from the weightless chain
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {}, {},
                               BodyLoads::weight(chain, inertia, Eigen::Vector2d::Zero(), down));
    EquilibriumBranchOptions o;
    o.tracer.lambdaMax = g;
    o.tree.branchSwitching = 0;
    o.contact = false;
    const EquilibriumBranches r =
        traceEquilibria(problem, Vector::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
    const cont::ContinuationPoint& last = r.tree.branches.at(0).points.back();
    REQUIRE(last.lambda == Approx(g).epsilon(1e-12));
    // independent: Newton on E + V (GravityPotential) with g raised in 40 equal steps
    Vector q = Vector::Zero(n);
    for (int step = 1; step <= 40; ++step) q = testing::heavyNewton(chain, inertia, (last.lambda * step / 40.0) * down, q);
    INFO("L = " << L);
    CHECK((last.u.head(n) - q).lpNorm<Eigen::Infinity>() <= 1e-10 * q.lpNorm<Eigen::Infinity>());
    CHECK(endPose(chain, q)[1] < -0.05 * chain.length());  // a real sag, not a small one
    // the same angles in both unit systems (lengths, stiffness and masses scaled together)
    static Vector reference;
    if (L == 1.0) reference = q;
    CHECK((q - reference).lpNorm<Eigen::Infinity>() <= 1e-10 * reference.lpNorm<Eigen::Infinity>());
  }
}

TEST_CASE("continuation in the gravity magnitude passes through the fixed-gravity equilibria", "[equilibrium][body_loads]") {
  const int n = 10;
  for (double L : {1.0, 1e-4}) {
    const double k = L == 1.0 ? 1.0 : 1e8, force = k * L;
    const Chain chain = scaledUniform(n, L, k);
    const double rho = 0.05 * force / chain.linkLengths()[1];  // weight 0.05 force units per link per unit g
    const InertiaData inertia = InertiaData::uniformRods(chain, rho);
    const Eigen::Vector2d down(0.0, -1.0);
    // λ = g: g(λ) = λ·(0, −1)
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {}, {},
                               BodyLoads::weight(chain, inertia, Eigen::Vector2d::Zero(), down));
    EquilibriumBranchOptions o;
    o.tracer.lambdaMax = 8.0;
    o.tree.branchSwitching = 0;
    o.contact = false;
    const EquilibriumBranches r =
        traceEquilibria(problem, Vector::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
    const cont::Branch& b = r.tree.branches.at(0);
    INFO("L = " << L);
    REQUIRE(b.points.size() > 5);
    CHECK(b.points.back().lambda == Approx(8.0).epsilon(1e-12));
    // a λ unit that moves the weight's moment by the torque unit: steps the same in any units
    static size_t pointsAtUnitScale = 0;
    if (L == 1.0) pointsAtUnitScale = b.points.size();
    CHECK(b.points.size() == pointsAtUnitScale);
    for (size_t p = 0; p < b.points.size(); p += 3) {
      const double lambda = b.points[p].lambda;
      const Vector q = testing::heavyNewton(chain, inertia, lambda * down, b.points[p].u.head(n));
      CHECK((b.points[p].u.head(n) - q).lpNorm<Eigen::Infinity>() <= 1e-9 * std::max(1e-3, q.lpNorm<Eigen::Infinity>()));
    }
  }
}

TEST_CASE("the critical payload and the critical gravity of a heavy column equal a dense eigen-solve's by bisection",
          "[equilibrium][body_loads]") {
  for (int n : {3, 12}) {
    for (double L : {1.0, 1e-4}) {
      const double k = L == 1.0 ? 1.0 : 1e8, force = k * L;
      const Chain chain = scaledUniform(n, L, k);
      const double rho = 0.5 * force / (n * n * n * chain.linkLengths()[1]);  // sub-critical at g = 1
      const InertiaData inertia = InertiaData::uniformRods(chain, rho);
      Vector mass(n);
      for (int i = 0; i < n; ++i) mass[i] = inertia.links[size_t(i)].mass;
      INFO("n = " << n << ", L = " << L);
      // payload P = λ along −x at the end, the column's own weight at g = 1 along −x
      const double g = 1.0;
      EquilibriumProblem payload(chain, EndCondition::freeEnd(), Eigen::Vector3d(-1, 0, 0), {}, {},
                                 BodyLoads::weight(chain, inertia, Eigen::Vector2d(-g, 0.0), Eigen::Vector2d::Zero()));
      const double located = firstCriticalLoad(payload, n, 5.0 * force);
      const double direct =
          bisect([&](double P) { return smallestEigenvalue(columnHessian(chain, mass, g, P)); }, 0.0, 5.0 * force);
      CHECK(located == Approx(direct).epsilon(1e-9));
      CHECK(smallestEigenvalue(columnHessian(chain, mass, g, 0.0)) > 0.0);  // its weight alone does not buckle it
      // gravity g = λ along −x with half that critical payload: its critical g is above 1
      const double P = 0.5 * located;
      EquilibriumProblem heavy(chain, EndCondition::freeEnd(Eigen::Vector3d(-P, 0, 0)), Eigen::Vector3d::Zero(), {}, {},
                               BodyLoads::weight(chain, inertia, Eigen::Vector2d::Zero(), Eigen::Vector2d(-1.0, 0.0)));
      const double gLocated = firstCriticalLoad(heavy, n, 1e4);
      const double gDirect =
          bisect([&](double gg) { return smallestEigenvalue(columnHessian(chain, mass, gg, P)); }, 0.0, 1e4);
      CHECK(gLocated == Approx(gDirect).epsilon(1e-9));
    }
  }
}
