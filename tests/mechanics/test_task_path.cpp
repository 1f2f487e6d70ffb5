// Task-space paths (task_path.h, task_path_solver.h, task_path_trace.h; issue 29 item 2): the
// derivatives of both rules against finite differences, the O(n) solver against dense LU, the
// task constraint and the equilibrium along a traced path (checked with the plain load-path
// EquilibriumProblem of the chain built with the inputs), rule (b) against a brute-force
// minimisation on the constraint manifold, the special points against what defines them, scaled
// units and bad input.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/derivative_check.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/task_path.h"
#include "buckle/mechanics/task_path_kkt_solver.h"
#include "buckle/mechanics/task_path_solver.h"
#include "buckle/mechanics/task_path_trace.h"
#include "task_path_follow.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

Chain chainOf(int n, double L = 1.0, double k = 1.0) {
  return Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L));
}

// The chain under `load` reached from the straight unloaded shape by loading it, λ: 0 → 1.
Eigen::VectorXd loadedAngles(const Chain& chain, const Eigen::Vector3d& load) {
  EquilibriumProblem ramp(chain, EndCondition::freeEnd(), load);
  cont::TracerOptions o;
  o.lambdaMin = -1.0;
  o.lambdaMax = 1.0;
  o.maxPoints = 5000;
  o.corrector.tolerance = 1e-12;
  const cont::Branch b = cont::trace(ramp, Eigen::VectorXd::Zero(chain.size()), 0.0,
                                     cont::InitialDirection::increasingLambda(), o);
  REQUIRE(b.stopReason == cont::StopReason::LambdaRange);
  REQUIRE(b.points.back().lambda == Approx(1.0).margin(1e-14));
  return b.points.back().u;
}

TaskSetup chosenSetup(const Eigen::Vector3d& payload) {
  TaskSetup s;
  s.payload = payload;
  s.coordinates = {0, 1};
  s.inputs = {{ControlInput::dL0, 0}, {ControlInput::dL0, 1}};
  return s;
}

TaskSetup minChangeSetup(int n, const Eigen::Vector3d& payload) {
  TaskSetup s;
  s.payload = payload;
  s.coordinates = {0, 1};
  s.rule = TaskRule::MinimumChange;
  for (int i = 0; i < n; ++i) s.inputs.push_back({ControlInput::dL0, i, 1.0 + 0.5 * i});
  s.inputs.push_back({ControlInput::L0, -1, 2.0});
  return s;
}

// [H, B; J_c] blocks of the constraints g, τ from the dense Jacobian (rule (b) layout).
void constraintBlocks(TaskPathProblem& p, const Eigen::VectorXd& u, double s, Eigen::MatrixXd& H, Eigen::MatrixXd& B,
                      Eigen::MatrixXd& Jc) {
  const int n = p.segments(), mi = p.inputCount(), m = p.taskCount(), N = p.dimension();
  Eigen::MatrixXd Fu(N, N);
  Eigen::VectorXd Fs(N);
  REQUIRE(buckle::continuation::BoundProblem(p).jacobian(u, s, Fu, Fs));
  H = Fu.block(n + mi, 0, n, n);
  B = Fu.block(n + mi, n, n, mi);
  Jc = Fu.block(2 * n + mi, 0, m, n);
}

// A structured solver against dense LU at u: the tracer's border (factor, determinant, solve) and
// the locator's general borders, plain and transposed.
void compareWithDense(TaskPathProblem& p, cont::BorderedSolver& fast, const Eigen::VectorXd& u) {
  const int N = p.dimension();
  cont::DenseBorderedSolver dense(p);
  const Eigen::VectorXd c = Eigen::VectorXd::LinSpaced(N + 1, 0.3, -0.7);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(N + 1, 1.0, 2.0);
  Eigen::VectorXd x1(N + 1), x2(N + 1);
  REQUIRE(fast.factor(u, 0.2, c) == cont::Factorization::Regular);
  REQUIRE(dense.factor(u, 0.2, c) == cont::Factorization::Regular);
  CHECK(fast.determinantSign() == dense.determinantSign());
  CHECK(fast.logAbsDeterminant() == Approx(dense.logAbsDeterminant()).epsilon(1e-10));
  REQUIRE(fast.solve(b, x1));
  REQUIRE(dense.solve(b, x2));
  CHECK((x1 - x2).norm() <= 1e-10 * x2.norm());
  for (bool transposed : {false, true}) {
    Eigen::MatrixXd Bg = Eigen::MatrixXd::Random(N, 2), Cg = Eigen::MatrixXd::Random(N, 2),
                    Dg = Eigen::MatrixXd::Random(2, 2);
    Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(N + 2, -1.0, 1.0), y1(N + 2), y2(N + 2);
    REQUIRE(fast.factorGeneral(u, 0.2, Bg, Cg, Dg, transposed) == cont::Factorization::Regular);
    REQUIRE(dense.factorGeneral(u, 0.2, Bg, Cg, Dg, transposed) == cont::Factorization::Regular);
    REQUIRE(fast.solve(r, y1));
    REQUIRE(dense.solve(r, y2));
    CHECK((y1 - y2).norm() <= 1e-10 * y2.norm());
  }
}

}  // namespace

namespace {
// Rule (b) on 4 segments with x, y and φ on a leg (minChangeSetup's five inputs): a generic point,
// the inputs moved and every multiplier nonzero, so that no term of the Jacobian is multiplied away.
Eigen::VectorXd genericOptimalityPoint(TaskPathProblem& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd a(3), d(3);
  a << 3.0, 0.2, 0.1;
  d << 0.6, -0.8, 0.0;
  p.setLeg({a, d, 0.0});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(p.dimension());
  u.head(4) = q;
  u.segment(4, 5) << 0.3, -0.2, 0.1, 0.4, 2.3;
  u.segment(9, 4) << 0.7, -0.3, 0.2, 0.5;  // μ
  u.tail(3) << 0.4, -0.6, 0.3;              // ν
  return u;
}
}  // namespace

TEST_CASE("task path: derivatives of both rules against finite differences", "[task_path]") {
  const Chain chain = chainOf(4);
  const Eigen::Vector3d payload(-0.3, -0.2, 0.05);
  Eigen::VectorXd q(4);
  q << -0.4, 0.3, -0.2, 0.5;
  SECTION("rule (a), x and phi") {
    TaskSetup s = chosenSetup(payload);
    s.coordinates = {0, 2};
    s.inputs = {{ControlInput::L1_0, 1}, {ControlInput::L0, -1}};
    TaskPathProblem p(chain, s);
    Eigen::VectorXd a(2), d(2);
    a << 3.0, 0.2;
    d << 0.6, -0.8;
    p.setLeg({a, d, 0.1});
    Eigen::VectorXd pin(2);
    pin << 2.4, 2.1;
    const cont::DerivativeCheck c = cont::checkDerivatives(p, p.pack(q, pin), 0.3);
    INFO(c.message);
    CHECK(c.success);
  }
  SECTION("rule (b) with multipliers, x, y and phi") {
    TaskSetup s = minChangeSetup(4, payload);
    s.coordinates = {0, 1, 2};
    TaskPathProblem p(chain, s);
    const Eigen::VectorXd u = genericOptimalityPoint(p, q);
    const cont::DerivativeCheck c = cont::checkDerivatives(p, u, 0.2);
    INFO(c.message);
    CHECK(c.success);
  }
}

// The links' weight (rods of 0.3 mass per length under g = 0.5 along −y) and a point load at
// joint 2, at their values (rates zero) or growing with λ (forces zero at λ = 0, `ramp`).
namespace {
BodyLoads heavyBody(const Chain& chain, bool ramp) {
  const Eigen::Vector2d g(0.0, -0.5), f(0.05, -0.1);
  BodyLoads body = BodyLoads::weight(chain, InertiaData::uniformRods(chain, 0.3), ramp ? Eigen::Vector2d::Zero() : g,
                                     ramp ? g : Eigen::Vector2d::Zero());
  body.points.push_back({2, ramp ? Eigen::Vector2d::Zero() : f, ramp ? f : Eigen::Vector2d::Zero()});
  return body;
}
}  // namespace

TEST_CASE("task path with weight and point loads: derivatives, solvers and equilibria of the heavy chain",
          "[task_path]") {
  const Eigen::Vector3d payload(-0.3, -0.2, 0.05);
  SECTION("both rules' derivatives against finite differences, the O(n) solvers against dense LU") {
    const Chain chain = chainOf(4);
    Eigen::VectorXd q(4);
    q << -0.4, 0.3, -0.2, 0.5;
    TaskSetup a = chosenSetup(payload);
    a.body = heavyBody(chain, false);
    TaskPathProblem pa(chain, a);
    Eigen::VectorXd t0(2), d2(2);
    t0 << 3.0, 0.2;
    d2 << 0.6, -0.8;
    pa.setLeg({t0, d2, 0.1});
    const Eigen::VectorXd ua = pa.pack(q, pa.startInputs() + Eigen::Vector2d(0.2, -0.1));
    const cont::DerivativeCheck ca = cont::checkDerivatives(pa, ua, 0.3);
    INFO(ca.message);
    CHECK(ca.success);
    const auto fastWorkspace = pa.createWorkspace();
    TaskPathBorderedSolver fast(pa, *fastWorkspace);
    compareWithDense(pa, fast, ua);

    TaskSetup b = minChangeSetup(4, payload);
    b.coordinates = {0, 1, 2};
    b.body = heavyBody(chain, false);
    TaskPathProblem pb(chain, b);
    const Eigen::VectorXd u = genericOptimalityPoint(pb, q);
    const cont::DerivativeCheck cb = cont::checkDerivatives(pb, u, 0.2);
    INFO(cb.message);
    CHECK(cb.success);
    const auto kktWorkspace = pb.createWorkspace();
    TaskPathKktSolver kkt(pb, *kktWorkspace);
    compareWithDense(pb, kkt, u);
  }
  SECTION("every traced point an equilibrium of the heavy chain at its inputs, and the weight matters") {
    const Chain chain = chainOf(3);
    // the start: payload, weight and point load applied together from the straight shape, λ: 0 → 1
    EquilibriumProblem ramp(chain, EndCondition::freeEnd(), payload, {}, {}, heavyBody(chain, true));
    cont::TracerOptions o;
    o.lambdaMin = -1.0;
    o.lambdaMax = 1.0;
    o.corrector.tolerance = 1e-12;
    const cont::Branch start = cont::trace(ramp, Eigen::VectorXd::Zero(3), 0.0,
                                           cont::InitialDirection::increasingLambda(), o);
    REQUIRE(start.points.back().lambda == Approx(1.0).margin(1e-14));
    const Eigen::VectorXd q0 = start.points.back().u;
    TaskSetup s = chosenSetup(payload);
    s.body = heavyBody(chain, false);
    TaskPathProblem p(chain, s);
    const Pose pose = endPose(chain, q0);
    Eigen::VectorXd to(2);
    to << pose[0] - 0.1, pose[1] + 0.2;
    TaskPathOptions opt;
    opt.tracer.corrector.tolerance = 1e-12;
    const TaskPathResult r = traceTaskPath(p, q0, {to}, chain.length(), opt);
    REQUIRE(r.end == TaskPathEvent::Completed);
    REQUIRE(r.points.size() > 5);
    // the start needed no change of the inputs: it is the heavy chain's equilibrium already
    CHECK((r.points.front().inputs - p.startInputs()).cwiseAbs().maxCoeff() <= 1e-12);
    double weightShare = 0.0;
    for (const TaskPathPoint& pt : r.points) {
      const Chain at = p.chainAt(pt.inputs);
      EquilibriumProblem heavy(at, EndCondition::freeEnd(payload), Eigen::Vector3d::Zero(), {}, {}, s.body);
      Eigen::VectorXd F(3);
      REQUIRE(buckle::continuation::BoundProblem(heavy).residual(pt.q, 0.0, F));
      CHECK(F.cwiseAbs().maxCoeff() <= 1e-12);  // torques in k b² = 1
      cont::StabilityInfo info;
      REQUIRE(buckle::continuation::BoundProblem(heavy).stability(pt.q, 0.0, 1, info));
      CHECK(info.negative == pt.inertia.negative);
      CHECK(info.smallest == Approx(pt.minEigenvalue).epsilon(1e-9));
      EquilibriumProblem weightless(at, EndCondition::freeEnd(payload), Eigen::Vector3d::Zero());
      REQUIRE(buckle::continuation::BoundProblem(weightless).residual(pt.q, 0.0, F));
      weightShare = std::max(weightShare, F.cwiseAbs().maxCoeff());
    }
    CHECK(weightShare > 0.05);  // the weight's torques are far above the tolerance: ignoring it fails
  }
}

TEST_CASE("task path: the O(n) bordered solver agrees with dense LU", "[task_path]") {
  const Chain chain = chainOf(12);
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(12, -0.3, 0.4);
  TaskSetup s = chosenSetup(Eigen::Vector3d(-0.2, 0.1, 0.02));
  s.coordinates = {0, 1, 2};
  s.inputs.push_back({ControlInput::L2_0, 5});
  TaskPathProblem p(chain, s);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(3), d(3);
  d << 0.48, 0.6, 0.64;
  p.setLeg({a, d, 0.0});
  const Eigen::VectorXd u = p.pack(q, p.startInputs() + Eigen::Vector3d(0.1, -0.2, 0.05));
  const auto fastWorkspace = p.createWorkspace();
  TaskPathBorderedSolver fast(p, *fastWorkspace);
  compareWithDense(p, fast, u);
}

TEST_CASE("task path: the O(n) elimination of rule (b)'s optimality system agrees with dense LU", "[task_path]") {
  const int n = 15;
  const Chain chain = chainOf(n);
  TaskSetup s = minChangeSetup(2, Eigen::Vector3d(-0.2, 0.1, 0.02));
  s.coordinates = {0, 1, 2};
  TaskPathProblem p(chain, s);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(3), d(3);
  d << 0.48, 0.6, 0.64;
  p.setLeg({a, d, 0.0});
  const int N = p.dimension(), mi = p.inputCount();
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(N, -0.3, 0.4);
  u.segment(n, mi) = p.startInputs() + Eigen::VectorXd::LinSpaced(mi, 0.1, -0.1);
  const auto fastWorkspace = p.createWorkspace();
  TaskPathKktSolver fast(p, *fastWorkspace);
  compareWithDense(p, fast, u);
}

TEST_CASE("task path rule (a): the task held and every point an equilibrium of the chain at its inputs", "[task_path]") {
  const Chain chain = chainOf(3);
  const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
  const Eigen::VectorXd q0 = loadedAngles(chain, payload);
  TaskPathProblem p(chain, chosenSetup(payload));
  // two legs: a corner at the first waypoint
  const Pose pose = endPose(chain, q0);
  Eigen::VectorXd w1(2), w2(2);
  w1 << pose[0] - 0.1, pose[1] + 0.3;
  w2 << pose[0] - 0.2, pose[1] + 0.2;
  TaskPathOptions opt;
  opt.tracer.corrector.tolerance = 1e-12;
  const TaskPathResult r = traceTaskPath(p, q0, {w1, w2}, chain.length(), opt);
  REQUIRE(r.end == TaskPathEvent::Completed);
  REQUIRE(r.legEnds.size() == 3);
  CHECK(r.legEnds[1] == Approx(std::hypot(0.1, 0.3)).epsilon(1e-14));
  REQUIRE(r.points.size() > 10);
  const double length = chain.length(), torque = 1.0;  // k b² = 1
  for (const TaskPathPoint& pt : r.points) {
    for (int k = 0; k < 2; ++k) CHECK(std::abs(pt.pose[k] - pt.target[k]) <= 1e-12 * length);
    // the plain load-path problem of the chain built with these inputs, at the payload
    const Chain at = p.chainAt(pt.inputs);
    EquilibriumProblem plain(at, EndCondition::freeEnd(payload), Eigen::Vector3d::Zero());
    Eigen::VectorXd F(3);
    REQUIRE(buckle::continuation::BoundProblem(plain).residual(pt.q, 0.0, F));
    CHECK(F.cwiseAbs().maxCoeff() <= 1e-12 * torque);
    cont::StabilityInfo info;
    REQUIRE(buckle::continuation::BoundProblem(plain).stability(pt.q, 0.0, 1, info));
    CHECK(info.negative == pt.inertia.negative);
    CHECK(info.smallest == Approx(pt.minEigenvalue).epsilon(1e-9));
    // only the chosen inputs move: segment 3's free lengths are the chain's
    CHECK(at.segment(2).parameters().L1_0 == chain.segment(2).parameters().L1_0);
  }
  // the corner is reached exactly
  const auto corner = std::find_if(r.points.begin(), r.points.end(), [&](const TaskPathPoint& pt) { return pt.leg == 1; });
  REQUIRE(corner != r.points.begin());
  REQUIRE(corner != r.points.end());
  CHECK(std::prev(corner)->s == Approx(r.legEnds[1]).epsilon(1e-14));
  CHECK(std::abs(std::prev(corner)->pose[0] - w1[0]) <= 1e-12 * length);
  CHECK(std::abs(std::prev(corner)->pose[1] - w1[1]) <= 1e-12 * length);
  CHECK(std::abs(r.points.back().pose[1] - w2[1]) <= 1e-12 * length);
}

TEST_CASE("task path rule (b): least weighted change against a brute-force search on the constraint manifold",
          "[task_path]") {
  const Chain chain = chainOf(3);
  const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
  const Eigen::VectorXd q0 = loadedAngles(chain, payload);
  TaskPathProblem p(chain, minChangeSetup(3, payload));
  const TaskPathResult r = buckle::test::followTaskPath(p, q0, -0.2, 0.5);
  REQUIRE(r.end == TaskPathEvent::Completed);
  const int n = 3, mi = 4;
  Eigen::VectorXd w(mi);
  for (int j = 0; j < mi; ++j) w[j] = p.setup().inputs[size_t(j)].weight;
  const auto objective = [&](const Eigen::VectorXd& pin) {
    return 0.5 * (pin - p.startInputs()).cwiseProduct(pin - p.startInputs()).dot(w);
  };
  for (size_t i : {r.points.size() / 3, r.points.size() - 1}) {
    const TaskPathPoint& pt = r.points[i];
    // the optimum: (q, p) of the point, multipliers from the point's own unknowns are not used
    Eigen::VectorXd u = Eigen::VectorXd::Zero(p.dimension());
    u.head(n) = pt.q;
    u.segment(n, mi) = pt.inputs;
    Eigen::MatrixXd H, B, Jc;
    constraintBlocks(p, u, pt.s, H, B, Jc);
    // tangent directions of the constraint manifold in input space: null(G), G = −J_c H⁻¹ B
    const Eigen::MatrixXd G = -Jc * H.lu().solve(B);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(G);
    const Eigen::MatrixXd Z = lu.kernel();
    REQUIRE(Z.cols() == mi - 2);
    const double f0 = objective(pt.inputs);
    for (int col = 0; col < Z.cols(); ++col)
      for (double eps : {-1e-2, -1e-3, 1e-3, 1e-2}) {
        // back onto the manifold: p = p* + εz + Gᵀy, (q, y) by Newton on g = 0, τ = 0
        Eigen::VectorXd qq = pt.q, y = Eigen::VectorXd::Zero(2);
        for (int it = 0; it < 30; ++it) {
          Eigen::VectorXd uu = u;
          uu.head(n) = qq;
          uu.segment(n, mi) = pt.inputs + eps * Z.col(col) + G.transpose() * y;
          Eigen::VectorXd F(p.dimension());
          REQUIRE(buckle::continuation::BoundProblem(p).residual(uu, pt.s, F));
          Eigen::VectorXd rr(n + 2);
          rr << F.segment(n + mi, n), F.tail(2);
          if (rr.norm() < 1e-15) break;
          constraintBlocks(p, uu, pt.s, H, B, Jc);
          Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + 2, n + 2);
          K.topLeftCorner(n, n) = H;
          K.topRightCorner(n, 2) = B * G.transpose();
          K.bottomLeftCorner(2, n) = Jc;
          const Eigen::VectorXd step = K.lu().solve(rr);
          qq -= step.head(n);
          y -= step.tail(2);
        }
        const Eigen::VectorXd moved = pt.inputs + eps * Z.col(col) + G.transpose() * y;
        CHECK(objective(moved) >= f0 - 1e-13 * std::max(1.0, f0));
        CHECK(objective(moved) > f0);  // strictly: the optimum is isolated
      }
  }
}

TEST_CASE("task path: the special points are what they say", "[task_path]") {
  const Chain chain = chainOf(3);
  SECTION("fold of the task map: F_u singular, s largest there") {
    const Eigen::Vector3d payload(-0.3, -0.1, 0.0);
    TaskPathProblem p(chain, chosenSetup(payload));
    const TaskPathResult r = buckle::test::followTaskPath(p, loadedAngles(chain, payload), -0.2, -1.0);
    REQUIRE(r.end == TaskPathEvent::Fold);
    REQUIRE(r.specials.size() == 1);
    const TaskPathPoint& f = r.specials[0].point;
    for (const TaskPathPoint& pt : r.points) CHECK(pt.s <= f.s + 1e-12);
    Eigen::MatrixXd Fu(5, 5);
    Eigen::VectorXd Fs(5);
    REQUIRE(buckle::continuation::BoundProblem(p).jacobian(p.pack(f.q, f.inputs), f.s, Fu, Fs));
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Fu);  // rows and unknowns O(1) here (k = b = 1)
    CHECK(svd.singularValues()[4] <= 1e-8 * svd.singularValues()[0]);
  }
  SECTION("loss of stability at fixed inputs: an eigenvalue of the dense Hessian reaches zero") {
    const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
    TaskPathProblem p(chain, minChangeSetup(3, payload));
    const TaskPathResult r = buckle::test::followTaskPath(p, loadedAngles(chain, payload), -0.2, 6.0);
    REQUIRE(r.end == TaskPathEvent::StabilityLoss);
    // every point before the special one (the last point) is stable
    for (size_t i = 0; i + 1 < r.points.size(); ++i) CHECK(r.points[i].stable);
    const TaskPathPoint& sp = r.specials[0].point;
    CHECK(sp.s == Approx(r.points.back().s).epsilon(1e-14));
    Eigen::MatrixXd H(3, 3);
    totalPotentialHessian(p.chainAt(sp.inputs), sp.q, payload, H);
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues();
    CHECK(std::abs(ev[0]) <= 1e-9 * ev.cwiseAbs().maxCoeff());
  }
  SECTION("input bound and a free length reaching zero") {
    const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
    TaskSetup s = chosenSetup(payload);
    TaskPathProblem free(chain, s);
    const Eigen::VectorXd q0 = loadedAngles(chain, payload);
    const TaskPathResult r = buckle::test::followTaskPath(free, q0, -0.2, 3.0);
    REQUIRE(r.end == TaskPathEvent::InputBound);
    const Chain at = free.chainAt(r.specials[0].point.inputs + Eigen::Vector2d(0.0, -1e-9));  // just inside
    CHECK(std::abs(at.segment(1).parameters().L2_0) <= 1e-9);
    s.inputs[1].upper = 1.0;
    TaskPathProblem bounded(chain, s);
    const TaskPathResult rb = buckle::test::followTaskPath(bounded, q0, -0.2, 3.0);
    REQUIRE(rb.end == TaskPathEvent::InputBound);
    CHECK(std::abs(rb.specials[0].point.inputs[1] - 1.0) <= 1e-12);
    CHECK(rb.specials[0].note == "input dL0[2] upper bound");
  }
  SECTION("joint limit") {
    const Eigen::Vector3d payload(-0.3, -0.3, 0.0);
    const Eigen::VectorXd q0 = loadedAngles(chain, payload);
    TaskPathProblem p(chain, chosenSetup(payload));
    const TaskPathResult r = buckle::test::followTaskPath(p, q0, -0.2, 0.5);
    REQUIRE(r.end == TaskPathEvent::Completed);
    const Eigen::VectorXd dq = r.points.back().q - q0;
    int j = 0;
    dq.cwiseAbs().maxCoeff(&j);
    std::vector<SegmentParameters> segs(3, chain.segment(0).parameters());
    const double limit = q0[j] + 0.5 * dq[j];
    (dq[j] > 0 ? segs[size_t(j)].qMaxUser : segs[size_t(j)].qMinUser) = limit;
    const Chain limited(segs);
    TaskPathProblem pl(limited, chosenSetup(payload));
    const TaskPathResult rl = buckle::test::followTaskPath(pl, q0, -0.2, 0.5);
    REQUIRE(rl.end == TaskPathEvent::JointLimit);
    CHECK(std::abs(rl.specials[0].point.q[j] - limit) <= 1e-12);
  }
}

TEST_CASE("task path: the same path in scaled units (lengths x1e-4, stiffness x1e8)", "[task_path]") {
  const double L = 1e-4, k = 1e8;
  for (TaskRule rule : {TaskRule::Chosen, TaskRule::MinimumChange}) {
    const Eigen::Vector3d payload(-0.3, -0.1, 0.0);
    TaskSetup s = rule == TaskRule::Chosen ? chosenSetup(payload) : minChangeSetup(3, payload);
    TaskPathProblem unit(chainOf(3), s);
    const TaskPathResult r1 = buckle::test::followTaskPath(unit, loadedAngles(chainOf(3), payload), -0.2, -1.0);
    s.payload *= k * L;
    for (TaskInput& in : s.inputs) in.upper *= L, in.lower *= L;
    TaskPathProblem scaled(chainOf(3, L, k), s);
    const TaskPathResult r2 = buckle::test::followTaskPath(scaled, loadedAngles(chainOf(3, L, k), s.payload), -0.2, -1.0, L);
    REQUIRE(r1.end == r2.end);
    REQUIRE(r1.points.size() == r2.points.size());
    for (size_t i = 0; i < r1.points.size(); ++i) {
      CHECK(r2.points[i].s / L == Approx(r1.points[i].s).epsilon(1e-9).margin(1e-12));
      CHECK((r2.points[i].q - r1.points[i].q).cwiseAbs().maxCoeff() <= 1e-9);
      CHECK((r2.points[i].inputs / L - r1.points[i].inputs).cwiseAbs().maxCoeff() <= 1e-9);
      CHECK(r2.points[i].minEigenvalue / (k * L * L) == Approx(r1.points[i].minEigenvalue).epsilon(1e-8));
    }
    if (!r1.specials.empty()) CHECK(r2.specials[0].point.s / L == Approx(r1.specials[0].point.s).epsilon(1e-10));
  }
}

TEST_CASE("task path: bad input is refused with the reason", "[task_path]") {
  const Chain chain = chainOf(3);
  TaskSetup s = chosenSetup(Eigen::Vector3d::Zero());
  s.inputs.pop_back();
  CHECK_THROWS_WITH(TaskPathProblem(chain, s), Catch::Contains("as many inputs as task coordinates"));
  s = minChangeSetup(3, Eigen::Vector3d::Zero());
  s.coordinates = {0, 1, 2};
  s.inputs.resize(2);
  CHECK_THROWS_WITH(TaskPathProblem(chain, s), Catch::Contains("at least as many inputs"));
  s = chosenSetup(Eigen::Vector3d::Zero());
  s.inputs[0].segment = 3;
  CHECK_THROWS_WITH(TaskPathProblem(chain, s), Catch::Contains("segment out of range 1..3"));
  s = chosenSetup(Eigen::Vector3d::Zero());
  s.inputs[1].weight = 0.0;
  CHECK_THROWS_WITH(TaskPathProblem(chain, s), Catch::Contains("weight must be > 0"));
  s = chosenSetup(Eigen::Vector3d::Zero());
  s.coordinates = {1, 0};
  CHECK_THROWS_WITH(TaskPathProblem(chain, s), Catch::Contains("in the order x, y, phi"));
}
