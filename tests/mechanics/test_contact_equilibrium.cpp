// Vertices held on the base wall (contact.h, wall_contact.h): the constrained equilibria, their
// forces, stability and units, against computations of the test's own.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/unloaded_shape.h"

#include "curled_chain.h"
#include "test_geometry.h"
#include "wall_statics.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using buckle::test::geometry;
using buckle::test::Geometry;
using buckle::test::Statics;
using buckle::test::vertexAt;
using buckle::test::wallStatics;

// The contact_release chain without its joint stop, lengths scaled by sL, stiffnesses by sK.
Chain curledChain(double sL = 1.0, double sK = 1.0) { return testing::curledChain(false, sL, sK); }

// Fy from 0 to `to` (in force units k b of the scaled chain) with the wall as a constraint.
EquilibriumBranches traceCurled(EquilibriumProblem& problem, double to) {
  return traceEquilibria(problem, testing::curledShape(), 0.0, cont::InitialDirection::increasingLambda(),
                         testing::curledTrace(to));
}

const SpecialPointReport* firstOf(const BranchReport& r, EventType t) {
  for (const SpecialPointReport& s : r.specialPoints)
    if (s.type == t) return &s;
  return nullptr;
}

}  // namespace

namespace {

/// n equal segments (a = 0.5, b = 1, k = 1, L0 = 2.25), clamped with y held at −0.3, loaded along x.
struct PinnedChain {
  explicit PinnedChain(int n)
      : chain(std::vector<SegmentParameters>(size_t(n), SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25))),
        problem(chain, EndCondition::clampedPinned(-0.3), Eigen::Vector3d(1, 0, 0)) {}
  const Chain chain;
  EquilibriumProblem problem;
};

// The three-segment chain's tree (the default scene's, contact off) to Fx = −2.5, past its folds,
// and its first fold (null if none). Built in place: the problem refers to the chain.
struct ThreeSegmentFold {
  Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  mutable EquilibriumProblem problem{chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0)};
  EquilibriumBranchOptions options = toFold();
  EquilibriumBranches tree =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::decreasingLambda(), options);
  const cont::SpecialPoint* fold = firstFold(tree);

  static EquilibriumBranchOptions toFold() {
    EquilibriumBranchOptions o;
    o.tracer.lambdaMin = -2.5;
    o.tracer.lambdaMax = 0.0;
    o.tree.branchSwitching = 1;
    o.contact = false;
    return o;
  }
  static const cont::SpecialPoint* firstFold(const EquilibriumBranches& r) {
    for (const cont::Branch& b : r.tree.branches)
      for (const cont::SpecialPoint& sp : b.specialPoints)
        if (sp.type == cont::SpecialPointType::Fold) return &sp;
    return nullptr;
  }
};

}  // namespace

TEST_CASE("wall: a segment pressed against the wall holds its vertex there with the force of a moment balance",
          "[contact][wall]") {
  const Chain chain = curledChain();
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  const EquilibriumBranches r = traceCurled(problem, 0.14);
  const BranchReport& rep = r.reports[0];
  const SpecialPointReport* wc = firstOf(rep, EventType::WallContact);
  for (const SpecialPointReport& sp : rep.specialPoints) INFO(label(sp.type) << " " << sp.parameter << " " << sp.note);
  INFO(rep.stopReason << ": " << rep.stopMessage);
  REQUIRE(wc != nullptr);
  CHECK(wc->vertex == WallVertex{4, 4});  // segment 5's distal corner −a
  CHECK(std::abs(wc->contactPoint.x()) <= 1e-12);
  CHECK(std::abs(wc->contactForce) <= 1e-12);
  int pressed = 0;
  for (const PointReport& pt : rep.points) {
    if (pt.locked.wallCount() == 0) continue;
    REQUIRE(pt.locked.wall() == std::vector<WallVertex>{WallVertex{4, 4}});
    ++pressed;
    CHECK(std::abs(vertexAt(chain, pt.q, WallVertex{4, 4}).x()) <= 1e-12);  // on the wall
    // Moment balance of the part beyond each joint j (wall_statics.h): the springs' ∂E/∂q_j
    // carries the moments of the end force and of the wall's push μ (along +x, at the vertex)
    // about P_j. Joint 5's row gives μ; the four others must then balance with it.
    const Statics st = wallStatics(chain, pt.q, Eigen::Vector2d(pt.F[0], pt.F[1]), WallVertex{4, 4});
    CHECK(st.imbalance <= 1e-12);
    REQUIRE(pt.wallForces.size() == 1);
    CHECK(pt.wallForces[0] == Approx(st.mu).epsilon(1e-10).margin(1e-13));
    CHECK(st.mu >= -1e-13);  // the wall pushes
  }
  CHECK(pressed >= 5);
  // the force grows from zero at the contact
  CHECK(rep.points.back().wallForces.size() == 1);
  CHECK(rep.points.back().wallForces[0] > 1e-3);
}

TEST_CASE("wall: scaled units give the same angles and the force scaled by the force unit k b", "[contact][wall]") {
  const Chain chain1 = curledChain();
  EquilibriumProblem p1(chain1, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
  const EquilibriumBranches ref = traceCurled(p1, 0.14);
  REQUIRE(firstOf(ref.reports[0], EventType::WallContact) != nullptr);
  const SpecialPointReport& wc0 = *firstOf(ref.reports[0], EventType::WallContact);
  for (const auto& [sL, sK] : {std::pair{1e4, 1e8}, std::pair{1e-4, 1e-8}, std::pair{1e4, 1e-8}}) {
    INFO("lengths x" << sL << ", stiffness x" << sK);
    const double force = sL * sK;  // k b
    const Chain chain = curledChain(sL, sK);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0), testing::withWall());
    const EquilibriumBranches r = traceCurled(problem, 0.14 * force);
    const SpecialPointReport* wc = firstOf(r.reports[0], EventType::WallContact);
    REQUIRE(wc != nullptr);
    CHECK(wc->vertex == wc0.vertex);
    CHECK(wc->parameter / force == Approx(wc0.parameter).epsilon(1e-9));
    CHECK((wc->q - wc0.q).cwiseAbs().maxCoeff() <= 1e-9);
    // the pressed state at the same scaled load: same angles, force scaled by k b
    ContactSet set;
    set.touch(wc0.vertex);
    const double f = 0.13;
    const Eigen::VectorXd u0 = wc0.q;
    const ConstrainedEquilibrium e1 = solveConstrainedEquilibrium(p1, set, u0, f);
    const ConstrainedEquilibrium es = solveConstrainedEquilibrium(problem, set, u0, f * force);
    REQUIRE(e1.converged);
    REQUIRE(es.converged);
    CHECK((es.u - e1.u).cwiseAbs().maxCoeff() <= 1e-9);
    CHECK(es.wallForces[0] / force == Approx(e1.wallForces[0]).epsilon(1e-9));
    CHECK(e1.wallForces[0] > 0.0);
  }
}

TEST_CASE("wall: the constrained stability equals a dense eigen-solve on the kernel of the constraint gradients",
          "[contact][wall]") {
  // Any (q, r, μ) will do (the operator is defined off equilibrium too): a 40-segment chain
  // (the O(n) Sturm route) and a 6-segment one (the small dense route), y held, one or two
  // vertices on the wall, one joint locked.
  for (const int n : {6, 40}) {
    INFO("n = " << n);
    std::vector<SegmentParameters> segs(size_t(n), SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    for (int i = 0; i < n; ++i) segs[size_t(i)].L1_0 = 2.25 + 0.02 * std::sin(1.0 + i), segs[size_t(i)].L2_0 = 2.25;
    const Chain chain(segs);
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(-0.3), Eigen::Vector3d(1, 0, 0));
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = 0.4 * std::sin(0.7 * i + 0.3);
    ContactSet set;
    set.touch(WallVertex{n / 2, 3});
    set.touch(WallVertex{n - 1, 0});
    set.lock(1, LimitSide::Upper);
    ContactProblem cp(problem, set);
    const int N = problem.dimension();
    Eigen::VectorXd u(cp.dimension());
    u.head(n) = q;
    u[n] = 0.2;                // the held y's reaction Fy
    u[N] = 0.7;                // μ of vertex (n/2 + 1)d+
    u[N + 1] = 0.35;           // μ of joint n's vertex
    const double lambda = -0.4;
    cont::StabilityInfo info;
    REQUIRE(buckle::continuation::BoundProblem(cp).stability(u, lambda, 3, info));
    // Dense: Π's Hessian from the library's total potential (end wrench) plus the wall forces'
    // −Σ μ ∂²x_v, on ker [J_y; e_2; ∇x_v]. ∂x_v by central differences of the test's own vertex
    // x; ∂²x_v = −(x_v − x_P,max(j,l)) (a rotation about joint max(j, l) moves v by R90 (v − P)),
    // checked against central differences.
    Eigen::MatrixXd H(n, n);
    totalPotentialHessian(chain, q, Wrench(-0.3 + lambda, 0.2, 0.0), H);
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(4, n);
    const Geometry g = geometry(chain, q);
    for (int j = 0; j < n; ++j) C(0, j) = g.end.x() - g.P(0, j);  // ∂y/∂q_j
    C(1, 1) = 1.0;
    for (int k = 0; k < 2; ++k) {
      const WallVertex& v = set.wall()[size_t(k)];
      const Eigen::Vector2d x = vertexAt(chain, q, v);
      const int last = v.corner == 0 ? v.segment - 1 : v.segment;
      for (int j = 0; j < n; ++j) {
        Eigen::VectorXd a = q, b = q;
        a[j] += 1e-6;
        b[j] -= 1e-6;
        C(2 + k, j) = (vertexAt(chain, a, v).x() - vertexAt(chain, b, v).x()) / 2e-6;
        for (int l = 0; l < n; ++l) {
          const double d2 = j <= last && l <= last ? -(x.x() - g.P(0, std::max(j, l))) : 0.0;
          if (j % 7 == 0 && l % 5 == 0) {  // spot checks of the closed form
            Eigen::VectorXd pp = q, pm = q, mp = q, mm = q;
            const double h = 1e-4;
            pp[j] += h, pp[l] += h, pm[j] += h, pm[l] -= h, mp[j] -= h, mp[l] += h, mm[j] -= h, mm[l] -= h;
            const double fd = (vertexAt(chain, pp, v).x() - vertexAt(chain, pm, v).x() - vertexAt(chain, mp, v).x() + vertexAt(chain, mm, v).x()) /
                              (4 * h * h);
            CHECK(std::abs(fd - d2) <= 1e-5 * std::max(1.0, std::abs(d2)));
          }
          H(j, l) -= u[N + k] * d2;
        }
      }
    }
    H = 0.5 * (H + H.transpose()).eval();
    const Eigen::MatrixXd Z = C.transpose().fullPivHouseholderQr().matrixQ().rightCols(n - 4);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Z.transpose() * H * Z);
    const Eigen::VectorXd ev = es.eigenvalues();
    int negative = 0;
    for (int i = 0; i < ev.size(); ++i) negative += ev[i] < 0.0;
    CHECK(info.negative == negative);
    const int wanted = std::min(3, int(ev.size()));  // n = 6: a kernel of 2 (5 free joints, 3 rows)
    REQUIRE(info.lowest.size() == wanted);
    for (int i = 0; i < wanted; ++i) CHECK(info.lowest[i] == Approx(ev[i]).margin(1e-8));
    // the same operator from stabilityOperator() (the dense route of the core)
    Eigen::MatrixXd Hs, Cs;
    REQUIRE(buckle::continuation::BoundProblem(cp).stabilityOperator(u, lambda, Hs, Cs));
    CHECK((Hs - H).cwiseAbs().maxCoeff() <= 1e-11 * std::max(1.0, H.cwiseAbs().maxCoeff()));
    CHECK((Cs - C).cwiseAbs().maxCoeff() <= 1e-8);
  }
}

TEST_CASE("wall: the O(n) bordered solver of the wall-constrained chain equals a dense solve", "[contact][wall]") {
  const int n = 30;
  PinnedChain pinned(n);
  EquilibriumProblem& problem = pinned.problem;
  ContactSet set;
  set.touch(WallVertex{7, 1});
  set.touch(WallVertex{20, 4});
  set.lock(3, LimitSide::Lower);
  ContactProblem cp(problem, set);
  const int D = cp.dimension();
  Eigen::VectorXd u(D);
  for (int i = 0; i < n; ++i) u[i] = 0.3 * std::cos(0.9 * i);
  u.tail(D - n) << 0.1, 0.5, 0.25;
  const double lambda = -0.2;
  Eigen::VectorXd c = Eigen::VectorXd::LinSpaced(D + 1, 0.3, -0.5), b = Eigen::VectorXd::LinSpaced(D + 1, 1.0, 2.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(D + 1, D + 1);
  Eigen::VectorXd Fl(D);
  REQUIRE(buckle::continuation::BoundProblem(cp).jacobian(u, lambda, A.topLeftCorner(D, D), Fl));
  A.topRightCorner(D, 1) = Fl;
  A.row(D) = c.transpose();
  const Eigen::VectorXd dense = A.fullPivLu().solve(b);
  const buckle::continuation::BoundProblem solverBound(cp);  // outlives the solver
  auto solver = solverBound.makeStructuredSolver();
  REQUIRE(solver->factor(u, lambda, c) == cont::Factorization::Regular);
  Eigen::VectorXd x(D + 1);
  REQUIRE(solver->solve(b, x));
  CHECK((x - dense).cwiseAbs().maxCoeff() <= 1e-10 * dense.cwiseAbs().maxCoeff());
  CHECK(solver->determinantSign() == (A.determinant() > 0 ? 1 : -1));
  // the Jacobian itself against central differences of the residual
  Eigen::VectorXd Fp(D), Fm(D);
  for (int j = 0; j < D; ++j) {
    Eigen::VectorXd up = u, um = u;
    up[j] += 1e-6;
    um[j] -= 1e-6;
    REQUIRE(buckle::continuation::BoundProblem(cp).residual(up, lambda, Fp));
    REQUIRE(buckle::continuation::BoundProblem(cp).residual(um, lambda, Fm));
    CHECK(((Fp - Fm) / 2e-6 - A.col(j).head(D)).cwiseAbs().maxCoeff() <= 1e-7);
  }
}

TEST_CASE("wall: the O(n) solver takes the locator's general borders, F_u and its transpose, as a dense solve",
          "[contact][wall]") {
  // G = [[F_u, B], [Cᵀ, D]] and [[F_uᵀ, B], [Cᵀ, D]] with k = 1, 2 dense random border columns
  // (nonzero on the locked rows too): locked joints, wall vertices and a held coordinate together,
  // and locked joints alone; the solution and the sign of det G against a dense LU of G.
  const int n = 30;
  PinnedChain pinned(n);
  EquilibriumProblem& problem = pinned.problem;
  for (int variant = 0; variant < 2; ++variant) {
    ContactSet set;
    if (variant == 0) {
      set.touch(WallVertex{7, 1});
      set.touch(WallVertex{20, 4});
      set.lock(3, LimitSide::Lower);
    } else {
      set.lock(0, LimitSide::Upper);
      set.lock(11, LimitSide::Lower);
      set.lock(12, LimitSide::Lower);
      set.lock(29, LimitSide::Upper);
    }
    ContactProblem cp(problem, set);
    const int N = cp.dimension();
    Eigen::VectorXd u(N);
    for (int i = 0; i < n; ++i) u[i] = 0.3 * std::cos(0.9 * i);
    for (int j = n; j < N; ++j) u[j] = 0.1 + 0.2 * (j - n);
    const double lambda = -0.2;
    Eigen::MatrixXd Fu(N, N);
    Eigen::VectorXd Fl(N);
    REQUIRE(cont::BoundProblem(cp).jacobian(u, lambda, Fu, Fl));
    const cont::BoundProblem bound(cp);  // outlives the solver
    auto solver = bound.makeStructuredSolver();
    REQUIRE(solver->maxGeneralBorder() >= 2);
    for (int k = 1; k <= 2; ++k)
      for (bool transposed : {false, true}) {
        INFO("variant " << variant << ", k = " << k << (transposed ? ", transposed" : ""));
        const Eigen::MatrixXd B = Eigen::MatrixXd::Random(N, k), C = Eigen::MatrixXd::Random(N, k);
        const Eigen::MatrixXd D = Eigen::MatrixXd::Random(k, k);
        Eigen::MatrixXd G(N + k, N + k);
        G << (transposed ? Eigen::MatrixXd(Fu.transpose()) : Fu), B, C.transpose(), D;
        const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(N + k, 1.0, -2.0);
        const Eigen::VectorXd dense = G.partialPivLu().solve(b);
        REQUIRE(solver->factorGeneral(u, lambda, B, C, D, transposed) == cont::Factorization::Regular);
        Eigen::VectorXd x(N + k);
        REQUIRE(solver->solve(b, x));
        CHECK((x - dense).cwiseAbs().maxCoeff() <= 1e-10 * dense.cwiseAbs().maxCoeff());
        CHECK(solver->determinantSign() == (G.determinant() > 0 ? 1 : -1));
      }
  }
}

TEST_CASE("contact: every boundary at once equals each boundary alone, a compression the free row's torque",
          "[contact]") {
  // locked joints on both sides with a torque bound, with and without vertices on the wall, u with
  // and without the wall forces among its entries (they then come from least squares)
  const int n = 12;
  PinnedChain pinned(n);
  EquilibriumProblem& problem = pinned.problem;
  for (int variant = 0; variant < 2; ++variant) {
    ContactSet set;
    set.lock(2, LimitSide::Lower);
    set.lock(7, LimitSide::Upper);
    if (variant == 1) {
      set.touch(WallVertex{5, 1});
      set.touch(WallVertex{9, 4});
    }
    ContactProblem cp(problem, set, 40.0);
    const cont::BoundProblem bound(cp);
    Eigen::VectorXd u(cp.dimension());
    for (int i = 0; i < n; ++i) u[i] = 0.3 * std::cos(0.9 * i);
    for (int j = n; j < cp.dimension(); ++j) u[j] = 0.1 + 0.2 * (j - n);
    const double lambda = -0.2;
    for (const Eigen::VectorXd& at : {u, Eigen::VectorXd(u.head(problem.dimension()))}) {
      INFO("variant " << variant << ", " << at.size() << " unknowns");
      Eigen::VectorXd all(cp.boundaryCount());
      bound.boundaries(at, lambda, all);
      for (int k = 0; k < cp.boundaryCount(); ++k) {
        INFO("boundary " << k << ": " << cp.boundaryName(k));
        const double one = bound.boundary(k, at, lambda);
        CHECK(((all[k] == one) || (std::isnan(all[k]) && std::isnan(one))));
      }
      if (variant == 0) {
        // without the wall: the contact torque is the free equilibrium's row, ∂E/∂q_i − (JᵀF)_i
        Eigen::VectorXd rows(problem.dimension());
        REQUIRE(cont::BoundProblem(problem).residual(at, lambda, rows));
        CHECK(all[2 + n] == Approx(rows[2]).margin(1e-14));  // lower side of joint 3: c = +τ
        CHECK(all[7] == Approx(-rows[7]).margin(1e-14));     // upper side of joint 8: c = −τ
        CHECK(all[cp.torqueBoundBegin()] == Approx(40.0 - rows[2]).margin(1e-13));
      }
    }
  }
}

TEST_CASE("constrained equilibrium: a polish that cannot reach its tolerance returns its best iterate and says "
          "what it reached",
          "[contact]") {
  // A fold of the three-segment chain's tree (the default scene): at fixed λ the Jacobian is
  // singular there. With a tolerance no iterate can meet, every polish runs all its iterations.
  const ThreeSegmentFold tree;
  const cont::SpecialPoint* fold = tree.fold;
  REQUIRE(fold != nullptr);
  // A tenth past the fold, where the branch has no equilibrium: Newton from the fold's state
  // wanders (its residual goes down and up again); the answer after more iterations is never worse.
  const double lambda = fold->lambda * 1.1;
  double previous = solveConstrainedEquilibrium(tree.problem, ContactSet(), fold->u, lambda, 0.0, 0).residual;
  REQUIRE(previous > 0.0);
  for (int iterations = 1; iterations <= 30; ++iterations) {
    const ConstrainedEquilibrium polished = solveConstrainedEquilibrium(tree.problem, ContactSet(), fold->u, lambda, 0.0, iterations);
    INFO(iterations << ": " << polished.message);
    CHECK_FALSE(polished.converged);
    CHECK(polished.residual <= previous);
    previous = polished.residual;
    if (polished.message.rfind("no convergence", 0) == 0) CHECK_THAT(polished.message, Catch::Contains("scaled residual"));
  }
}

TEST_CASE("the start after a contact event: where the polish at fixed λ cannot converge, across the branch",
          "[contact]") {
  // polishEventStart (contact.h) at a fold of the three-segment tree, moved a millionth past it in
  // λ: at that λ there is no equilibrium near the point (what a release right after its contact
  // meets where the free motion turns back), so the polish at fixed λ fails, while the Keller
  // system through the point normal to the branch (the fold's tangent) is regular and lands on
  // the branch.
  const ThreeSegmentFold f;
  REQUIRE(f.fold != nullptr);
  EquilibriumProblem& problem = f.problem;
  const EquilibriumBranchOptions& o = f.options;
  const cont::SpecialPoint* fold = f.fold;
  const int N = problem.dimension();  // the joint angles and the held coordinate's reaction
  REQUIRE(fold->tangent.size() == N + 1);
  cont::SpecialPoint at = *fold;
  at.lambda = fold->lambda * (1.0 + 1e-6);  // |Fx| past its largest on the branch
  cont::Tracer tracer(problem, o.tracer);
  const ConstrainedEquilibrium fixed =
      solveConstrainedEquilibrium(problem, ContactSet(), at.u, at.lambda, std::max(o.tracer.location.newtonTolerance, 1e-12));
  REQUIRE_FALSE(fixed.converged);
  REQUIRE(fixed.residual > o.tracer.corrector.tolerance);  // the fallback is what is tested

  // without a direction: the fixed-λ polish alone, unpolished and saying why
  const EventStart alone = polishEventStart(problem, ContactSet(), at, tracer, Eigen::VectorXd());
  CHECK_FALSE(alone.polished);
  CHECK_THAT(alone.message, Catch::Contains("could not be polished"));

  const EventStart start = polishEventStart(problem, ContactSet(), at, tracer, fold->tangent);
  INFO(start.message);
  REQUIRE(start.polished);
  CHECK(start.acrossBranch);
  REQUIRE(start.u.size() == N);
  // an equilibrium (the residual of the test's own evaluation) at the fold's load: within the
  // millionth moved (the branch turns back there, λ − λ_fold quadratic in the distance along it)
  Eigen::VectorXd F(N);
  cont::BoundProblem bound(problem);
  REQUIRE(bound.residual(start.u, start.lambda, F));
  CHECK(F.cwiseAbs().maxCoeff() <= 1e-9);
  CHECK(std::abs(start.lambda - fold->lambda) <= 2e-6 * std::abs(fold->lambda));
  CHECK((start.u - fold->u).norm() <= 1e-2);
}
