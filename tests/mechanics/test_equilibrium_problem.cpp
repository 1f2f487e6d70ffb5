#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <thread>

#include <Eigen/LU>
#include <limits>

#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/jump.h"

#include "random_segments.h"
#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::randomChain;

struct Setting {
  std::string name;
  EndCondition end;
};

std::vector<Setting> settings(std::mt19937& rng) {
  std::uniform_real_distribution<double> W(-1.5, 1.5);
  return {{"free", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng)))},
          {"clamped-pinned", EndCondition::clampedPinned(W(rng), W(rng))},
          {"held position", EndCondition::heldPosition(3.0 + W(rng), W(rng))}};
}

using testing::randomState;

}  // namespace

TEST_CASE("EquilibriumProblem Jacobian and its directional derivative match finite differences", "[equilibrium]") {
  std::mt19937 rng(101);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  for (int n : {1, 3, 8}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      INFO("n = " << n << ", end: " << s.name);
      const Eigen::Vector3d dir(W(rng), W(rng), W(rng));
      EquilibriumProblem problem(chain, s.end, dir);
      const int N = problem.dimension();
      REQUIRE(N == n + s.end.heldCount());
      for (int trial = 0; trial < 3; ++trial) {
        const Vector u = randomState(rng, chain, N);
        const double lambda = Lam(rng);
        Matrix Fu(N, N), dFu(N, N);
        Vector Fl(N), dFl(N), F(N), Fp(N), Fm(N);
        REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, Fu, Fl));
        const double h = 1e-6;
        double err = 0.0;
        for (int j = 0; j < N; ++j) {
          Vector up = u, um = u;
          up[j] += h;
          um[j] -= h;
          REQUIRE(buckle::continuation::BoundProblem(problem).residual(up, lambda, Fp));
          REQUIRE(buckle::continuation::BoundProblem(problem).residual(um, lambda, Fm));
          err = std::max(err, (Fu.col(j) - (Fp - Fm) / (2 * h)).lpNorm<Eigen::Infinity>());
        }
        REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda + h, Fp));
        REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda - h, Fm));
        const double errL = (Fl - (Fp - Fm) / (2 * h)).lpNorm<Eigen::Infinity>();
        CHECK(err < 1e-7 * std::max(1.0, Fu.lpNorm<Eigen::Infinity>()));
        CHECK(errL < 1e-7 * std::max(1.0, Fl.lpNorm<Eigen::Infinity>()));
        CHECK((Fu - Fu.transpose()).lpNorm<Eigen::Infinity>() < 1e-14 * std::max(1.0, Fu.lpNorm<Eigen::Infinity>()));
        // Into a block of a larger matrix (outer stride ≠ rows, as the bordered solvers pass it):
        // the same entries, nothing written outside the block.
        Matrix big = Matrix::Constant(N + 2, N + 3, 7.0);
        Vector bigL = Vector::Constant(N + 1, 7.0);
        REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, big.block(1, 2, N, N), bigL.head(N)));
        CHECK(big.block(1, 2, N, N) == Fu);
        CHECK(bigL.head(N) == Fl);
        CHECK(bigL[N] == 7.0);
        CHECK((big.row(0).array() == 7.0).all());
        CHECK((big.row(N + 1).array() == 7.0).all());
        CHECK((big.leftCols(2).array() == 7.0).all());
        CHECK((big.rightCols(1).array() == 7.0).all());
        // An independent assembly: the K_q − K_g block is stabilityOperator's H (totalPotentialHessian
        // from the cache), the borders are −Cᵀ and −C, the multipliers' block is zero.
        Matrix H, C;
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
        CHECK((Fu.topLeftCorner(n, n) - H).lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, H.lpNorm<Eigen::Infinity>()));
        if (N > n) {
          CHECK(Fu.topRightCorner(n, N - n) == -C.transpose());
          CHECK(Fu.bottomLeftCorner(N - n, n) == -C);
          CHECK((Fu.bottomRightCorner(N - n, N - n).array() == 0.0).all());
        }
        // directional second derivative
        Vector du(N);
        for (int i = 0; i < N; ++i) du[i] = W(rng);
        const double dl = W(rng);
        REQUIRE(buckle::continuation::BoundProblem(problem).jacobianDirectionalDerivative(u, lambda, du, dl, dFu, dFl));
        Matrix Jp(N, N), Jm(N, N);
        Vector Jlp(N), Jlm(N);
        REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u + h * du, lambda + h * dl, Jp, Jlp));
        REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u - h * du, lambda - h * dl, Jm, Jlm));
        CHECK((dFu - (Jp - Jm) / (2 * h)).lpNorm<Eigen::Infinity>() < 1e-6 * std::max(1.0, dFu.lpNorm<Eigen::Infinity>()));
        CHECK((dFl - (Jlp - Jlm) / (2 * h)).lpNorm<Eigen::Infinity>() < 1e-6 * std::max(1.0, dFl.lpNorm<Eigen::Infinity>()));
        // residual is ∂E/∂q − Jᵀ F(u, λ) in its first n rows
        REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
        Vector g(n);
        totalPotentialGradient(chain, u.head(n), problem.wrench(u, lambda), g);
        CHECK((F.head(n) - g).lpNorm<Eigen::Infinity>() < 1e-13 * std::max(1.0, g.lpNorm<Eigen::Infinity>()));
      }
    }
  }
}

TEST_CASE("the straight chain is an equilibrium under any axial load", "[equilibrium]") {
  const Chain chain = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  for (double Fx : {-3.0, -0.1, 0.0, 0.7}) {
    EquilibriumProblem freeEnd(chain, EndCondition::freeEnd(Eigen::Vector3d(Fx, 0, 0)), Eigen::Vector3d(1, 0, 0));
    Vector F(5);
    REQUIRE(buckle::continuation::BoundProblem(freeEnd).residual(Vector::Zero(5), 0.0, F));
    CHECK(F.lpNorm<Eigen::Infinity>() < 1e-15);
    EquilibriumProblem pinned(chain, EndCondition::clampedPinned(Fx), Eigen::Vector3d(1, 0, 0));
    Vector Fp(6);
    REQUIRE(buckle::continuation::BoundProblem(pinned).residual(Vector::Zero(6), 0.3, Fp));
    CHECK(Fp.lpNorm<Eigen::Infinity>() < 1e-15);
    // a lateral load is not balanced by the straight chain
    EquilibriumProblem lateral(chain, EndCondition::freeEnd(Eigen::Vector3d(Fx, 0.2, 0)), Eigen::Vector3d(1, 0, 0));
    REQUIRE(buckle::continuation::BoundProblem(lateral).residual(Vector::Zero(5), 0.0, F));
    CHECK(F.lpNorm<Eigen::Infinity>() > 0.1);
  }
}

TEST_CASE("the corrector's fixed-parameter solve converges quadratically to an equilibrium of the loaded chain",
          "[equilibrium]") {
  const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(-0.05, 0.08, 0.0)), Eigen::Vector3d(0, 1, 0));
  const PolishResult r = polishEquilibrium(problem, Vector::Zero(4), 0.0);
  REQUIRE(r.converged);
  CHECK(r.iterations <= 8);
  Vector F(4);
  REQUIRE(buckle::continuation::BoundProblem(problem).residual(r.u, 0.0, F));
  CHECK(F.lpNorm<Eigen::Infinity>() < 1e-12);
  CHECK(endPose(chain, r.u)[1] > 0.0);  // bends towards the lateral load
  // held position with a reaction
  EquilibriumProblem held(chain, EndCondition::heldPosition(7.5, 0.6), Eigen::Vector3d::Zero());
  const PolishResult rh = polishEquilibrium(held, Vector::Constant(4, 0.05), 0.0);
  REQUIRE(rh.converged);
  const Pose p = endPose(chain, rh.u.head(4));
  CHECK(p[0] == Approx(7.5).margin(1e-12));
  CHECK(p[1] == Approx(0.6).margin(1e-12));
}

TEST_CASE("EquilibriumProblem: cached evaluations equal a fresh problem's in any call order", "[equilibrium]") {
  // residual / jacobian / stability share the kinematics and spring jets of the last q. Calls in
  // random order at a few states (repeated q with other λ or multipliers, a q changed in place in
  // the same buffer, points outside the domain in between) must give bitwise the
  // results of a problem that has never seen another point.
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  std::uniform_int_distribution<int> Op(0, 6), Pick(0, 3);
  for (int n : {1, 3, 8}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      INFO("n = " << n << ", end: " << s.name);
      const Eigen::Vector3d dir(W(rng), W(rng), W(rng));
      EquilibriumProblem cached(chain, s.end, dir);
      const int N = cached.dimension();
      std::vector<Vector> states;
      for (int k = 0; k < 3; ++k) states.push_back(randomState(rng, chain, N));
      states.push_back(states[0]);
      states[3].tail(N - n).setConstant(0.25);  // same q, other multipliers
      Vector buffer(N);
      for (int call = 0; call < 60; ++call) {
        const int which = Pick(rng);
        buffer = states[size_t(which)];
        const bool outside = call % 17 == 5;
        if (outside) buffer[0] = chain.segment(0).geometricUpperLimit() + 0.1;
        const double lambda = call % 3 == 0 ? 0.1 * which : Lam(rng);
        EquilibriumProblem fresh(chain, s.end, dir);
        const int op = Op(rng);
        if (op <= 1) {
          Vector F1(N), F2(N);
          const bool ok1 = buckle::continuation::BoundProblem(cached).residual(buffer, lambda, F1),
                     ok2 = buckle::continuation::BoundProblem(fresh).residual(buffer, lambda, F2);
          REQUIRE(ok1 == ok2);
          CHECK(ok1 != outside);
          if (ok1) CHECK((F1.array() == F2.array()).all());
        } else if (op <= 3) {
          Matrix J1(N, N), J2(N, N);
          Vector L1(N), L2(N);
          const bool ok1 = buckle::continuation::BoundProblem(cached).jacobian(buffer, lambda, J1, L1),
                     ok2 = buckle::continuation::BoundProblem(fresh).jacobian(buffer, lambda, J2, L2);
          REQUIRE(ok1 == ok2);
          if (ok1) CHECK(((J1.array() == J2.array()).all() && (L1.array() == L2.array()).all()));
        } else if (op == 4) {
          buckle::continuation::StabilityInfo i1, i2;
          const int count = call % 2 ? 3 : 0;
          const bool ok1 = buckle::continuation::BoundProblem(cached).stability(buffer, lambda, count, i1),
                     ok2 = buckle::continuation::BoundProblem(fresh).stability(buffer, lambda, count, i2);
          REQUIRE(ok1 == ok2);
          if (ok1) {
            CHECK(i1.negative == i2.negative);
            CHECK(i1.zero == i2.zero);
            REQUIRE(i1.lowest.size() == i2.lowest.size());
            CHECK((i1.lowest.array() == i2.lowest.array()).all());
          }
        } else if (op == 6) {  // the small dense spectrum, shared with stability() at its point
          Vector v1(1), v2(1);
          const bool ok1 = buckle::continuation::BoundProblem(cached).stabilityEigenvalues(buffer, lambda, 0, v1);
          const bool ok2 = buckle::continuation::BoundProblem(fresh).stabilityEigenvalues(buffer, lambda, 0, v2);
          REQUIRE(ok1 == ok2);
          if (ok1) CHECK(v1[0] == v2[0]);
        } else {
          Matrix H1, C1, H2, C2;
          const bool ok1 = buckle::continuation::BoundProblem(cached).stabilityOperator(buffer, lambda, H1, C1);
          const bool ok2 = buckle::continuation::BoundProblem(fresh).stabilityOperator(buffer, lambda, H2, C2);
          REQUIRE(ok1 == ok2);
          if (ok1) CHECK(((H1.array() == H2.array()).all() && (C1.array() == C2.array()).all()));
          Matrix H3(n, n);
          if (ok1) {
            // the chain functions take one sincos per link, the problem's kinematics rotate the
            // links by the springs' half angles (chain.h): equal to a few ulp of the load terms
            const Wrench Wt = cached.wrench(buffer, lambda);
            totalPotentialHessian(chain, buffer.head(n), Wt, H3);
            const double scale = H3.cwiseAbs().maxCoeff() + Wt.head<2>().norm() * chain.length();
            CHECK((H1 - H3).cwiseAbs().maxCoeff() <= 64.0 * std::numeric_limits<double>::epsilon() * scale);
          }
        }
        // the finite-difference check of the Jacobian still holds right after a cached call
        if (call % 20 == 7 && !outside) {
          Matrix Fu(N, N);
          Vector Fl(N), Fp(N), Fm(N);
          REQUIRE(buckle::continuation::BoundProblem(cached).jacobian(buffer, lambda, Fu, Fl));
          const double h = 1e-6;
          for (int j = 0; j < N; ++j) {
            Vector up = buffer, um = buffer;
            up[j] += h;
            um[j] -= h;
            REQUIRE(buckle::continuation::BoundProblem(cached).residual(up, lambda, Fp));
            REQUIRE(buckle::continuation::BoundProblem(cached).residual(um, lambda, Fm));
            CHECK((Fu.col(j) - (Fp - Fm) / (2 * h)).lpNorm<Eigen::Infinity>() < 1e-7 * std::max(1.0, Fu.lpNorm<Eigen::Infinity>()));
          }
        }
      }
    }
  }
}

TEST_CASE("EquilibriumProblem's domain: the geometric limits, the traced overshoot, non-finite values", "[equilibrium]") {
  // Every joint within its geometric limits is evaluated; with the limits traced as boundaries
  // also up to 0.05 rad beyond them (the tracer brackets a limit from its far side), otherwise
  // nothing beyond them. NaN and ±∞ are refused in any coordinate (joint or multiplier).
  std::mt19937 rng(77);
  const Chain chain = randomChain(rng, 3);
  const EndCondition end = EndCondition::clampedPinned(0.2, 0.1);
  for (bool traced : {true, false}) {
    EquilibriumOptions options;
    options.jointLimitsAsBoundaries = traced;
    EquilibriumProblem problem(chain, end, Eigen::Vector3d(1, 0, 0), options);
    const int N = problem.dimension();
    const Vector u0 = randomState(rng, chain, N);
    Vector F(N);
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(u0, 0.3, F));
    const double overshoot = traced ? 0.05 : 0.0;
    for (int i = 0; i < chain.size(); ++i) {
      INFO("traced = " << traced << ", joint " << i);
      const double upper = chain.segment(i).geometricUpperLimit(), lower = chain.segment(i).geometricLowerLimit();
      Vector u = u0;
      u[i] = upper + overshoot - 1e-9;
      CHECK(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
      u[i] = upper + overshoot + 1e-9;
      CHECK_FALSE(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
      u[i] = lower - overshoot + 1e-9;
      CHECK(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
      u[i] = lower - overshoot - 1e-9;
      CHECK_FALSE(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
      for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity()}) {
        u[i] = bad;
        CHECK_FALSE(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
      }
      // back inside after a refusal: the same values as before it
      Vector G(N);
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(u0, 0.3, G));
      Vector F0(N);
      EquilibriumProblem fresh(chain, end, Eigen::Vector3d(1, 0, 0), options);
      REQUIRE(buckle::continuation::BoundProblem(fresh).residual(u0, 0.3, F0));
      CHECK((G.array() == F0.array()).all());
    }
    Vector u = u0;
    u[N - 1] = std::numeric_limits<double>::quiet_NaN();  // a multiplier
    CHECK_FALSE(buckle::continuation::BoundProblem(problem).residual(u, 0.3, F));
  }
}

namespace {

// The BD special point of the first branch traced from the straight chain along `direction`.
const buckle::continuation::SpecialPoint* tracedLimit(EquilibriumProblem& problem, EquilibriumBranches& r,
                                                       double lambdaMax) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = lambdaMax;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  o.contact = false;  // the limit itself (contact past it: test_contact.cpp)
  r = traceEquilibria(problem, Eigen::VectorXd::Zero(problem.segments()), 0.0,
                      buckle::continuation::InitialDirection::increasingLambda(), o);
  const auto bds = r.tree.branches.at(0).specialPointsOfType(buckle::continuation::SpecialPointType::Boundary);
  return bds.size() == 1 ? bds[0] : nullptr;
}

// Independent: Newton on the equilibrium with joint k fixed at `limit` and λ free (the unknowns
// are the other joint angles and λ; free end, so no multipliers), to the rounding floor.
Vector solveWithJointAt(EquilibriumProblem& problem, Vector u, double& lambda, int k, double limit) {
  const int n = problem.segments();
  u[k] = limit;
  Vector F(n), Fl(n), z(n);
  Matrix Fu(n, n), A(n, n);
  int small = 0;
  for (int it = 0; it < 60 && small < 3; ++it) {
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, lambda, F));
    REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, Fu, Fl));
    A = Fu;
    A.col(k) = Fl;  // column k now moves λ
    z = A.partialPivLu().solve(F);
    for (int i = 0; i < n; ++i)
      if (i != k) u[i] -= z[i];
    lambda -= z[k];
    if (z.lpNorm<Eigen::Infinity>() < 1e-15 * std::max(1.0, std::abs(lambda))) ++small;
  }
  REQUIRE(small >= 3);
  return u;
}

}  // namespace

TEST_CASE("a geometric joint limit is located at the limit itself, with the exact limit load", "[equilibrium]") {
  // One segment under an end torque Me = λ: the torque balance dE/dq = Me (J_φ = 1) at
  // q = q_max = π − β12 in closed form from eq 1. Spring 1 has zero length there (identical
  // triangles): L1 = 0, dL1/dq = −√P; spring 2: θ2 = β12 − q_max = 2β12 − π, L2 = 2√P sin β12,
  // dL2/dq = −√P cos β12 (P = a² + b², β12 = 2 atan(a/b)).
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  for (double qMaxUser : {std::numeric_limits<double>::infinity(), 1.0}) {
    SegmentParameters p = SegmentParameters::symmetric(a, b, k, L0);
    p.qMaxUser = qMaxUser;
    const Chain chain = Chain::uniform(1, p);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1));
    EquilibriumBranches r;
    const buckle::continuation::SpecialPoint* bd = tracedLimit(problem, r, 50.0);
    REQUIRE(bd);
    const double P = a * a + b * b, beta = 2.0 * std::atan(a / b);
    double limit, exact;
    if (std::isinf(qMaxUser)) {
      limit = M_PI - beta;
      exact = k * L0 * std::sqrt(P) - k * (2.0 * std::sqrt(P) * std::sin(beta) - L0) * std::sqrt(P) * std::cos(beta);
      CHECK_THAT(bd->boundaryName, Catch::Contains("geometric"));
    } else {  // a user limit: eq 1 at θ = β12 ± q directly
      limit = qMaxUser;
      exact = 0.0;
      for (double sgn : {1.0, -1.0}) {
        const double th = beta + sgn * limit, L = std::sqrt(2.0 * P * (1.0 + std::cos(th)));
        exact += k * (L - L0) * (-sgn * P * std::sin(th) / L);
      }
    }
    INFO("limit " << limit << ", exact limit torque " << exact << ", located " << bd->lambda << " at q = " << bd->u[0]);
    CHECK(std::abs(bd->u[0] - limit) <= 1e-12);
    CHECK(std::abs(bd->lambda - exact) <= 1e-12 * std::abs(exact));
  }
}

TEST_CASE("a chain's geometric joint limit: the load equals Newton's with the joint fixed there", "[equilibrium]") {
  // Three segments of different heights under an end torque and a small lateral force: the
  // joints are coupled through the force, and one of them reaches its geometric limit first.
  std::vector<SegmentParameters> segs = {SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25),
                                         SegmentParameters::symmetric(0.45, 1.0, 1.0, 2.25),
                                         SegmentParameters::symmetric(0.4, 1.0, 1.0, 2.25)};
  const Chain chain(segs);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0.2, 1));
  EquilibriumBranches r;
  const buckle::continuation::SpecialPoint* bd = tracedLimit(problem, r, 50.0);
  const buckle::continuation::Branch& br = r.tree.branches.at(0);
  INFO(br.stopMessage << " after " << br.points.size() << " points, last q " << br.points.back().u.transpose()
                      << " at " << br.points.back().lambda);
  REQUIRE(bd);
  int joint = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(bd->u[i]) / chain.upperLimits()[i] > std::abs(bd->u[joint]) / chain.upperLimits()[joint]) joint = i;
  const double limit = bd->u[joint] > 0 ? chain.upperLimits()[joint] : chain.lowerLimits()[joint];
  CHECK(limit == (bd->u[joint] > 0 ? chain.segment(joint).geometricUpperLimit() : chain.segment(joint).geometricLowerLimit()));
  double lambda = bd->lambda;
  const Vector u = solveWithJointAt(problem, bd->u, lambda, joint, limit);
  INFO("joint " << joint + 1 << ": located " << bd->lambda << ", Newton with the joint fixed " << lambda);
  CHECK(std::abs(bd->u[joint] - limit) <= 1e-12);
  CHECK(std::abs(bd->lambda - lambda) <= 1e-12 * std::abs(lambda));
  CHECK((bd->u - u).norm() <= 1e-11);
}

TEST_CASE("EquilibriumProblem O(n) products equal the dense F_x, F_x^T and second derivatives", "[equilibrium]") {
  std::mt19937 rng(303);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  for (int n : {1, 4, 30}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      INFO("n = " << n << ", end: " << s.name);
      EquilibriumProblem problem(chain, s.end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      const int N = problem.dimension();
      const Vector u = randomState(rng, chain, N);
      const double lambda = Lam(rng);
      Vector x(N + 1), w(N), dx(N + 1);
      for (int i = 0; i <= N; ++i) x[i] = W(rng), dx[i] = W(rng);
      for (int i = 0; i < N; ++i) w[i] = W(rng);
      Matrix Fx(N, N + 1), dFx(N, N + 1);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, lambda, Fx.leftCols(N), Fx.col(N)));
      // Rounding bound of the dense product: eps·|F_x|·|x| row by row.
      const double eps = std::numeric_limits<double>::epsilon();
      Vector y(N), yt(N + 1), y2(N + 1);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianApply(u, lambda, x, y));
      const Vector bound = Fx.cwiseAbs() * x.cwiseAbs();
      for (int i = 0; i < N; ++i) CHECK(std::abs(y[i] - Fx.row(i).dot(x)) <= 8.0 * (n + 3) * eps * bound[i]);
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianTransposeApply(u, lambda, w, yt));
      const Vector boundT = Fx.transpose().cwiseAbs() * w.cwiseAbs();
      for (int i = 0; i <= N; ++i) CHECK(std::abs(yt[i] - Fx.col(i).dot(w)) <= 8.0 * (n + 3) * eps * boundT[i]);
      // (F_xx[dx, ·])ᵀw (central differences of jacobianTransposeApply) against the exact
      // directional derivative of F_x.
      REQUIRE(buckle::continuation::BoundProblem(problem).secondDerivativeTransposeApply(u, lambda, dx, w, y2));
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianDirectionalDerivative(u, lambda, dx.head(N), dx[N],
                                                                                        dFx.leftCols(N), dFx.col(N)));
      const Vector exact = dFx.transpose() * w;
      CHECK((y2 - exact).norm() <= 1e-7 * std::max(1.0, exact.norm()));
      // F_xx[dx, x] in O(n) (secondDerivativeApply): the exact matrix derivative applied to x, to
      // rounding; symmetric in its two directions; central differences of F_x x along dx
      Vector s2(N), s2t(N), yp(N), ym(N);
      REQUIRE(buckle::continuation::BoundProblem(problem).secondDerivativeApply(u, lambda, dx, x, s2));
      const Vector dense = dFx * x;
      const double size = std::max((dFx.cwiseAbs() * x.cwiseAbs()).maxCoeff(), 1e-300);
      CHECK((s2 - dense).lpNorm<Eigen::Infinity>() <= 1e-13 * size);
      REQUIRE(buckle::continuation::BoundProblem(problem).secondDerivativeApply(u, lambda, x, dx, s2t));
      CHECK((s2 - s2t).lpNorm<Eigen::Infinity>() <= 1e-13 * size);
      const double h = 1e-5;
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianApply(u + h * dx.head(N), lambda + h * dx[N], x, yp));
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobianApply(u - h * dx.head(N), lambda - h * dx[N], x, ym));
      CHECK((s2 - (yp - ym) / (2.0 * h)).lpNorm<Eigen::Infinity>() <= 1e-7 * std::max(size, 1.0));
    }
  }
}

TEST_CASE("stabilityEigenvalues by index: the O(n) counts and the small dense route equal a dense eigen-solve",
          "[equilibrium]") {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  for (int n : {5, 40}) {  // below and above kSmallDense
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      INFO("n = " << n << ", end: " << s.name);
      EquilibriumProblem problem(chain, s.end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      EquilibriumProblem dense(chain, s.end, problem.direction(), EquilibriumOptions{true, false});
      const Vector u = randomState(rng, chain, problem.dimension());
      const double lambda = Lam(rng);
      Matrix H, C;
      REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
      const int dim = n - int(C.rows());
      const double scale = std::max(1.0, H.norm());
      for (int first : {0, dim / 2, dim - 2}) {
        Vector mine(2), reference(2);
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityEigenvalues(u, lambda, first, mine));
        REQUIRE(buckle::continuation::BoundProblem(dense).stabilityEigenvalues(u, lambda, first,
                                                                               reference));  // Problem's dense default
        CHECK((mine - reference).cwiseAbs().maxCoeff() <= 1e-11 * scale);
      }
      Vector beyond(2);
      CHECK_FALSE(buckle::continuation::BoundProblem(problem).stabilityEigenvalues(u, lambda, dim - 1, beyond));
    }
  }
}

TEST_CASE("along a load path past many critical loads: the inertia and the values next to zero equal a dense eigen-solve, "
          "in a few factorizations each where nu changes from point to point",
          "[equilibrium]") {
  // The monitor's calls (spectral_monitor.h) at points of a compressed chain, ν rising by
  // several per step: the indices asked for change at every point, so only the eigenvalues found
  // lately by index (eigenvalue_memory.h) can warm-start the searches. Held ends, body loads and
  // lengths ×1e±4, stiffnesses ×1e±8: every value against the dense route.
  struct Case {
    int n;
    double L, K;
  };
  std::mt19937 rng(2718);
  std::uniform_real_distribution<double> W(-1.0, 1.0);
  for (const Case& c : {Case{10, 1.0, 1.0}, Case{60, 1e-4, 1e8}, Case{60, 1e4, 1e-8}, Case{300, 1.0, 1.0},
                        Case{300, 1e4, 1e8}, Case{300, 1e-4, 1e-8}}) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < c.n; ++i) {
      SegmentParameters p = testing::randomSegment(rng);
      p.a1 *= c.L, p.a2 *= c.L, p.b1 *= c.L, p.b2 *= c.L, p.L1_0 *= c.L, p.L2_0 *= c.L;
      p.k1 *= c.K, p.k2 *= c.K;
      segs.push_back(p);
    }
    const Chain chain(segs);
    const double force = c.K * c.L;  // the force unit k b
    BodyLoads body;
    body.mass = Vector::Constant(c.n, 1e-3 * force);  // a light weight across the path
    body.centre = 0.5 * chain.linkLengths().tail(c.n);
    body.gravityRate = Eigen::Vector2d(0.0, -1.0);
    struct End {
      std::string name;
      EndCondition end;
      BodyLoads body;
    };
    for (const End& e : {End{"clamped-pinned", EndCondition::clampedPinned(0.0, 0.0), BodyLoads()},
                         End{"held position", EndCondition::heldPosition(0.0, 0.0), BodyLoads()},
                         End{"free end, weight", EndCondition::freeEnd(Eigen::Vector3d::Zero()), body}}) {
      INFO("n = " << c.n << ", lengths x" << c.L << ", stiffness x" << c.K << ", " << e.name);
      const bool held = e.name == "held position";
      // λ compresses the chain along x: the load Fx (free x) or, with x held, the reaction in u
      EquilibriumProblem problem(chain, e.end, Eigen::Vector3d(held ? 0.0 : -force, 0.0, 0.0), {}, {}, e.body);
      EquilibriumProblem dense(chain, e.end, problem.direction(), EquilibriumOptions{true, false}, {}, e.body);
      const buckle::continuation::BoundProblem bound(problem);  // one workspace: the searches warm-start
      const int N = problem.dimension();
      Vector u0 = Vector::Zero(N), du(N);
      for (int i = 0; i < c.n; ++i) u0[i] = 1e-3 * W(rng);  // near the straight chain, not on it
      for (int i = 0; i < N; ++i) du[i] = W(rng) * (i < c.n ? 1.0 : force);
      auto at = [&](double t) {
        Vector u = u0;
        if (held) u[c.n] = -t * force;  // the x reaction: the compressive force
        return u;
      };
      // the load at which a third of the spectrum (at most 40 values) is negative
      const int target = std::min(c.n / 3, 40);
      double tMax = 1e-3;
      buckle::continuation::StabilityInfo ref;
      for (;; tMax *= 2.0) {
        REQUIRE(tMax < 1e12);
        REQUIRE(buckle::continuation::BoundProblem(dense).stability(at(tMax), held ? 0.0 : tMax, 0, ref));
        if (ref.negative >= target) break;
      }
      const int points = 30;
      int changes = 0, lastNu = 0, values = 0;
      const long before = EquilibriumProblem::structuredFactorizations(bound.workspace());
      for (int j = 1; j <= points; ++j) {
        const double t = tMax * double(j * j) / double(points * points);
        const Vector u = at(t);
        const double lambda = held ? 0.0 : t;
        Matrix H, C;
        REQUIRE(bound.stabilityOperator(u, lambda, H, C));
        const double scale = std::max(c.K * c.L * c.L, H.norm());
        buckle::continuation::StabilityInfo mine, theirs;
        REQUIRE(bound.stability(u, lambda, 1, mine));
        REQUIRE(buckle::continuation::BoundProblem(dense).stability(u, lambda, 1, theirs));
        CHECK(mine.negative == theirs.negative);
        CHECK(mine.zero == theirs.zero);
        REQUIRE(mine.lowest.size() == 1);
        CHECK(std::abs(mine.lowest[0] - theirs.lowest[0]) <= 1e-11 * scale);
        const int nu = mine.negative;
        changes += nu != lastNu ? 1 : 0;
        lastNu = nu;
        // as the monitor: ν − 1 and ν at the point, then a step δ along a direction
        const int first = std::max(0, nu - 1);
        Vector here(2), reference(2);
        REQUIRE(bound.stabilityEigenvalues(u, lambda, first, here));
        REQUIRE(buckle::continuation::BoundProblem(dense).stabilityEigenvalues(u, lambda, first, reference));
        CHECK((here - reference).cwiseAbs().maxCoeff() <= 1e-11 * scale);
        const Vector shifted = u + 1e-6 * du;
        REQUIRE(bound.stabilityEigenvalues(shifted, lambda, first, here));
        REQUIRE(buckle::continuation::BoundProblem(dense).stabilityEigenvalues(shifted, lambda, first, reference));
        CHECK((here - reference).cwiseAbs().maxCoeff() <= 1e-11 * scale);
        values += 5;
      }
      if (c.n > 16) {  // the structured route (n ≤ 16: one small dense solve per point)
        CHECK(changes >= 4);  // the indices asked for moved along the path
        const double perValue =
            double(EquilibriumProblem::structuredFactorizations(bound.workspace()) - before) / double(values);
        INFO("factorizations per value " << perValue);
        CHECK(perValue <= 13.0);  // a bisection from ±‖H‖_F takes about 50, Newton from the last index's value 15 to 22
      }
    }
  }
}

TEST_CASE("the small dense spectrum is shared by stability and stabilityEigenvalues at one point and recomputed on a one-ulp change",
          "[equilibrium]") {
  // stability() keeps the whole small dense spectrum of its point (equilibrium_problem.h), and
  // stabilityEigenvalues() at the same (u, λ) serves it from there. Shared values must be bit for
  // bit those of a problem that never saw the point; a change of any one component of (u, λ) by
  // one ulp, in the same buffer, must recompute (the fresh values there differ from the cached
  // ones in many cases, so a stale cache fails the comparison).
  std::mt19937 rng(5151);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  int perturbed = 0, changed = 0;
  for (int n : {2, 3, 5}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      const Eigen::Vector3d dir(W(rng), W(rng), W(rng));
      EquilibriumProblem shared(chain, s.end, dir);
      const int N = shared.dimension();
      const int dim = n - (N - n);  // the held rows are independent at a random state
      // inertia only up to n = 3 (the dense route there), two values above (the route then)
      const int asked = n <= 3 ? 0 : 2;
      Vector x(N + 1);  // (u, λ) in one buffer, changed in place
      x.head(N) = randomState(rng, chain, N);
      x[N] = Lam(rng);
      auto valuesOf = [&](EquilibriumProblem& p, Vector& out) {
        out.resize(dim);
        return buckle::continuation::BoundProblem(p).stabilityEigenvalues(x.head(N), x[N], 0, out);
      };
      for (int component = -1; component <= N; ++component) {
        INFO("n = " << n << ", end: " << s.name << ", component " << component);
        Vector before(dim);
        REQUIRE(valuesOf(shared, before));  // the cache now holds the unperturbed point
        if (component >= 0) {
          x[component] = std::nextafter(x[component], std::numeric_limits<double>::infinity());
          if (dim > 0) ++perturbed;
        }
        buckle::continuation::StabilityInfo mine, theirs;
        EquilibriumProblem fresh(chain, s.end, dir), fresh2(chain, s.end, dir);
        REQUIRE(buckle::continuation::BoundProblem(shared).stability(x.head(N), x[N], asked, mine));
        REQUIRE(buckle::continuation::BoundProblem(fresh).stability(x.head(N), x[N], asked, theirs));
        CHECK(mine.negative == theirs.negative);
        CHECK(mine.zero == theirs.zero);
        REQUIRE(mine.lowest.size() == theirs.lowest.size());
        CHECK((mine.lowest.array() == theirs.lowest.array()).all());
        Vector sharedValues, freshValues;
        REQUIRE(valuesOf(shared, sharedValues));  // from stability()'s solve
        REQUIRE(valuesOf(fresh2, freshValues));   // a solve of its own
        CHECK((sharedValues.array() == freshValues.array()).all());
        if (component >= 0 && (freshValues.array() != before.array()).any()) ++changed;
        // Indices beyond the spectrum are refused from the cache as from a solve.
        Vector beyond(2);
        CHECK_FALSE(buckle::continuation::BoundProblem(shared).stabilityEigenvalues(x.head(N), x[N], dim - 1, beyond));
        // Another point in between (the slopes' point off the branch), then back: the same values.
        Vector off = x.head(N), elsewhere(dim), again(dim);
        off[0] += 1e-6;
        REQUIRE(buckle::continuation::BoundProblem(shared).stabilityEigenvalues(off, x[N], 0, elsewhere));
        if (dim > 0) CHECK((elsewhere.array() != freshValues.array()).any());
        REQUIRE(valuesOf(shared, again));
        CHECK((again.array() == freshValues.array()).all());
      }
    }
  }
  // The test can fail: many one-ulp changes move some eigenvalue's last bits (19 of 42 here), and
  // a stale cache would return the unperturbed values there.
  CHECK(4 * changed > perturbed);
}

TEST_CASE("stabilityRateBound bounds the rate of every eigenvalue of H on ker C (central differences)",
          "[equilibrium]") {
  std::mt19937 rng(1717);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  for (int n : {3, 5, 40}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      EquilibriumProblem problem(chain, s.end, Eigen::Vector3d(W(rng), W(rng), W(rng)));
      // every eigenvalue: Problem's dense default (the structured route isolates a few at a time)
      EquilibriumProblem dense(chain, s.end, problem.direction(), EquilibriumOptions{true, false});
      const int N = problem.dimension();
      for (int trial = 0; trial < 5; ++trial) {
        INFO("n = " << n << ", end: " << s.name << ", trial " << trial);
        const Vector u = randomState(rng, chain, N);
        const double lambda = Lam(rng);
        Vector du(N);
        for (int i = 0; i < N; ++i) du[i] = W(rng);
        const double dlambda = W(rng);
        double bound = -1.0;
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityRateBound(u, lambda, du, dlambda, bound));
        Matrix H, C;
        REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
        const int dim = n - int(C.rows());
        Vector plus(dim), minus(dim);
        const double h = 1e-6;
        REQUIRE(
            buckle::continuation::BoundProblem(dense).stabilityEigenvalues(u + h * du, lambda + h * dlambda, 0, plus));
        REQUIRE(
            buckle::continuation::BoundProblem(dense).stabilityEigenvalues(u - h * du, lambda - h * dlambda, 0, minus));
        const double rate = ((plus - minus) / (2.0 * h)).cwiseAbs().maxCoeff();
        // the difference quotient: O(h²) truncation, rounding ≈ ε‖H‖/h
        CHECK(rate <= bound + 1e-7 * std::max(1.0, H.norm()));
      }
    }
  }
}

TEST_CASE("stabilityRateBound of the unconstrained chain is ‖dH‖_F, by differences of the dense H", "[equilibrium]") {
  std::mt19937 rng(2718);
  std::uniform_real_distribution<double> W(-1.5, 1.5), Lam(-0.7, 0.7);
  const Chain chain = randomChain(rng, 7);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))),
                             Eigen::Vector3d(W(rng), W(rng), W(rng)));
  const Vector u = randomState(rng, chain, problem.dimension());
  Vector du(problem.dimension());
  for (int i = 0; i < du.size(); ++i) du[i] = W(rng);
  const double lambda = Lam(rng), dlambda = W(rng), h = 1e-6;
  double bound = 0.0;
  REQUIRE(buckle::continuation::BoundProblem(problem).stabilityRateBound(u, lambda, du, dlambda, bound));
  Matrix Hp, Hm, C;
  REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u + h * du, lambda + h * dlambda, Hp, C));
  REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u - h * du, lambda - h * dlambda, Hm, C));
  CHECK(bound == Approx(((Hp - Hm) / (2.0 * h)).norm()).epsilon(1e-7));
  // the straight chain with x held: C = J_h is rank-deficient there, no finite bound
  EquilibriumProblem held(chain, EndCondition::heldPosition(chain.linkLengths().sum(), 0.0), Eigen::Vector3d(1, 0, 0));
  double none = 0.0;
  CHECK_FALSE(buckle::continuation::BoundProblem(held).stabilityRateBound(Vector::Zero(held.dimension()), 0.0,
                                                                          Vector::Ones(held.dimension()), 1.0, none));
}

TEST_CASE("EquilibriumProblem's boundaries in one call equal boundary(k) one by one, also scaled", "[equilibrium]") {
  // The tracer asks for every joint-limit boundary at every point with one boundaries() call
  // (problem.h); the override must give boundary(k)'s values bit for bit, and so must the
  // tracer's scaled wrapper, which scales u once for all of them.
  std::mt19937 rng(31);
  for (const int n : {1, 3, 50}) {
    const Chain chain = randomChain(rng, n);
    EquilibriumOptions options;
    options.jointLimitsAsBoundaries = true;
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.2, 0.1), Eigen::Vector3d(1, 0, 0), options);
    const int N = problem.dimension(), K = problem.boundaryCount();
    REQUIRE(K == 2 * n);
    const Vector u = randomState(rng, chain, N);
    Vector g(K);
    buckle::continuation::BoundProblem(problem).boundaries(u, 0.3, g);
    for (int k = 0; k < K; ++k) CHECK(g[k] == buckle::continuation::BoundProblem(problem).boundary(k, u, 0.3));
    // a shorter g takes the first ones
    Vector head(n);
    buckle::continuation::BoundProblem(problem).boundaries(u, 0.3, head);
    CHECK(head == g.head(n));

    buckle::continuation::ProblemScales scales = buckle::continuation::ProblemScales::ones(N);
    for (int i = 0; i < N; ++i) scales.unknowns[i] = std::pow(10.0, double(i % 5) - 2.0);
    scales.parameter = 1e3;
    const buckle::continuation::UnitScaling units(scales);
    buckle::continuation::ScaledProblem scaled(problem, units);
    const Vector v = u.cwiseQuotient(scales.unknowns);
    Vector gs(K);
    buckle::continuation::BoundProblem(scaled).boundaries(v, 0.3e-3, gs);
    for (int k = 0; k < K; ++k) CHECK(gs[k] == buckle::continuation::BoundProblem(scaled).boundary(k, v, 0.3e-3));
  }
}

TEST_CASE("EquilibriumProblem's Jacobian writes every entry of F_u and F_lambda, as it declares", "[equilibrium]") {
  // jacobianWritesAllEntries() lets the corrector and the bordered solver skip zeroing the Keller
  // matrix: on a matrix filled with NaN the Jacobian must be the one written over zeros.
  std::mt19937 rng(41);
  for (const int n : {1, 3, 12}) {
    const Chain chain = randomChain(rng, n);
    for (const Setting& s : settings(rng)) {
      INFO("n = " << n << ", end: " << s.name);
      EquilibriumProblem problem(chain, s.end, Eigen::Vector3d(0.3, -1.0, 0.2));
      REQUIRE(problem.jacobianWritesAllEntries());
      const int N = problem.dimension();
      const Vector u = randomState(rng, chain, N);
      Matrix zeroFilled = Matrix::Zero(N + 2, N + 2), nanFilled(N + 2, N + 2);
      nanFilled.setConstant(std::numeric_limits<double>::quiet_NaN());
      Vector lz = Vector::Zero(N), ln = Vector::Constant(N, std::numeric_limits<double>::quiet_NaN());
      // a block of a larger matrix, as the Keller matrix hands it over
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, 0.4, zeroFilled.block(1, 1, N, N), lz));
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(u, 0.4, nanFilled.block(1, 1, N, N), ln));
      CHECK(nanFilled.block(1, 1, N, N).allFinite());
      CHECK((nanFilled.block(1, 1, N, N).array() == zeroFilled.block(1, 1, N, N).array()).all());
      CHECK((ln.array() == lz.array()).all());
      // and nothing outside the block
      CHECK(std::isnan(nanFilled(0, 0)));
      CHECK(std::isnan(nanFilled(N + 1, N + 1)));
    }
  }
}

TEST_CASE("One const EquilibriumProblem traced from two threads at once: each trace as when run alone",
          "[equilibrium_problem][threads]") {
  // 30 segments: the structured stability isolates the lowest eigenvalues with warm starts
  // (the workspace's EigenvalueMemory) and every evaluation goes through the q-cache.
  const int n = 30;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  buckle::continuation::TracerOptions options;
  options.step.maxStep = 0.05;
  options.lambdaMin = -0.6;
  options.lambdaMax = 0.3;
  options.maxPoints = 150;
  options.detection.lowestEigenvalues = 3;
  const Vector u0 = Vector::Zero(problem.dimension());
  using buckle::continuation::Branch;
  using buckle::continuation::InitialDirection;
  auto compress = [&] {
    return buckle::continuation::trace(problem, u0, 0.0, InitialDirection::decreasingLambda(), options);
  };
  auto stretch = [&] {
    return buckle::continuation::trace(problem, u0, 0.0, InitialDirection::increasingLambda(), options);
  };
  const Branch compressedAlone = compress(), stretchedAlone = stretch();
  int branchPoints = 0;
  for (const auto& sp : compressedAlone.specialPoints)
    branchPoints += sp.type == buckle::continuation::SpecialPointType::BranchPoint ? 1 : 0;
  REQUIRE(branchPoints >= 1);  // the compressed chain buckles within the range
  REQUIRE(stretchedAlone.points.size() > 2);

  auto identical = [](const Branch& a, const Branch& b) {
    CHECK(a.stopReason == b.stopReason);
    REQUIRE(a.points.size() == b.points.size());
    for (size_t k = 0; k < a.points.size(); ++k) {
      CHECK(a.points[k].u == b.points[k].u);
      CHECK(a.points[k].lambda == b.points[k].lambda);
      CHECK(a.points[k].stability.negative == b.points[k].stability.negative);
      CHECK(a.points[k].stability.lowest == b.points[k].stability.lowest);
    }
    REQUIRE(a.specialPoints.size() == b.specialPoints.size());
    for (size_t k = 0; k < a.specialPoints.size(); ++k) {
      CHECK(a.specialPoints[k].type == b.specialPoints[k].type);
      CHECK(a.specialPoints[k].lambda == b.specialPoints[k].lambda);
    }
  };
  for (const bool sameStart : {false, true}) {
    INFO((sameStart ? "the same start" : "different starts"));
    Branch a, b;
    std::thread first([&] { a = compress(); });
    std::thread second([&] { b = sameStart ? compress() : stretch(); });
    first.join();
    second.join();
    identical(a, compressedAlone);
    identical(b, sameStart ? compressedAlone : stretchedAlone);
  }
}
