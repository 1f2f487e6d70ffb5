// Rule (c) of a task path (task_path.h, task_path_most_stable.cpp; issue 29): along the path the
// inputs keep the equilibrium as stable as the task allows. Checked against a brute-force
// maximisation of the smallest eigenvalue of K_q − K_g over the task's constraint manifold at
// sample points (three inputs, two task coordinates: a one-parameter family solved point by point
// with the first input fixed), the tracked eigenpair against a dense eigen-solve, and the same
// path in scaled units.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>

#include "buckle/mechanics/task_path.h"
#include "buckle/mechanics/task_path_trace.h"
#include "task_path_follow.h"
#include "payload_start.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

struct Scaled {
  double L = 1.0, k = 1.0;
  Chain chain() const { return Chain::uniform(3, SegmentParameters::symmetric(0.5 * L, L, k, 2.25 * L)); }
  Eigen::Vector3d payload() const { return Eigen::Vector3d(-0.3 * k * L, -0.3 * k * L, 0.0); }
  TaskSetup setup() const {
    TaskSetup s;
    s.payload = payload();
    s.coordinates = {0, 1};
    s.rule = TaskRule::MostStable;
    s.inputs = {{ControlInput::dL0, 0}, {ControlInput::dL0, 1}, {ControlInput::dL0, 2}};
    return s;
  }
};

// The smallest eigenvalue of K_q − K_g on the task's manifold with the first input at `p1`: the
// other two inputs and q solved (rule (a) on the chain with the first input moved) by Newton from
// the point's own values. False when Newton does not converge.
bool manifoldEigenvalue(const Scaled& c, const TaskPathPoint& pt, double p1, double& mu) {
  const Chain moved = chainWithControls(c.chain(), ControlDirection::named(3, ControlInput::dL0, 0), p1);
  TaskSetup s = c.setup();
  s.rule = TaskRule::Chosen;
  s.inputs = {{ControlInput::dL0, 1}, {ControlInput::dL0, 2}};
  TaskPathProblem chosen(moved, s);
  chosen.setLeg({pt.target, Eigen::VectorXd::Zero(2), pt.s});
  const cont::BoundProblem bound(chosen);
  Eigen::VectorXd u(5), F(5), Fs(5);
  u << pt.q, pt.inputs[1], pt.inputs[2];
  Eigen::MatrixXd J(5, 5);
  bool converged = false;
  for (int it = 0; it < 40 && !converged; ++it) {
    if (!bound.residual(u, pt.s, F) || !bound.jacobian(u, pt.s, J, Fs)) return false;
    converged = F.norm() < 1e-13 * c.k * c.L * c.L;
    if (!converged) u -= J.lu().solve(F);
  }
  if (!converged) return false;
  mu = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(J.topLeftCorner(3, 3)).eigenvalues()[0];
  return true;
}

void checkOptimal(const Scaled& c, const TaskPathPoint& pt) {
  INFO("s = " << pt.s << ", inputs = " << pt.inputs.transpose());
  double mu0 = 0.0;
  REQUIRE(manifoldEigenvalue(c, pt, pt.inputs[0], mu0));
  const double torque = c.k * c.L * c.L;
  CHECK(pt.minEigenvalue == Approx(mu0).margin(1e-10 * torque));
  CHECK(mu0 > 0.0);
  // brute force over the one-parameter manifold: no sample does better, and the best sample is a
  // neighbour of the point (the optimum is interior and isolated)
  const double step = 0.02 * c.L;
  double best = -std::numeric_limits<double>::infinity(), bestAt = 0.0;
  for (int i = -15; i <= 15; ++i) {
    double mu = 0.0;
    if (!manifoldEigenvalue(c, pt, pt.inputs[0] + i * step, mu)) continue;
    CHECK(mu <= mu0 + 1e-10 * torque);
    if (mu > best) best = mu, bestAt = i * step;
  }
  CHECK(std::abs(bestAt) <= step * (1 + 1e-12));
  double left = 0.0, right = 0.0;
  REQUIRE(manifoldEigenvalue(c, pt, pt.inputs[0] - 1e-3 * c.L, left));
  REQUIRE(manifoldEigenvalue(c, pt, pt.inputs[0] + 1e-3 * c.L, right));
  CHECK(left < mu0);
  CHECK(right < mu0);
}

}  // namespace

TEST_CASE("task path rule (c): the most stable configuration against a brute-force search on the task manifold",
          "[task_path]") {
  const Scaled c;
  const Eigen::VectorXd q0 = buckle::test::underPayload(c.chain(), c.payload());
  TaskPathProblem p(c.chain(), c.setup());
  const TaskPathResult r = buckle::test::followTaskPath(p, q0, -0.1, 0.2, c.L);
  INFO(r.message);
  REQUIRE(r.points.size() > 4);
  // the start is the optimum at the start pose, not the chain's own inputs
  CHECK((r.points.front().inputs - p.startInputs()).norm() > 1e-3);
  for (size_t i : {size_t(0), r.points.size() / 2, r.points.size() - 1}) checkOptimal(c, r.points[i]);
}

TEST_CASE("task path rule (c): the same path in scaled units", "[task_path]") {
  const Scaled ref;
  TaskPathProblem p0(ref.chain(), ref.setup());
  const TaskPathResult r0 = buckle::test::followTaskPath(p0, buckle::test::underPayload(ref.chain(), ref.payload()), -0.1, 0.2, 1.0);
  REQUIRE(r0.points.size() > 4);
  const double L = GENERATE(1e-4, 1e4);
  const double k = GENERATE(1e-8, 1e8);
  const Scaled c{L, k};
  TaskPathProblem p(c.chain(), c.setup());
  const TaskPathResult r = buckle::test::followTaskPath(p, buckle::test::underPayload(c.chain(), c.payload()), -0.1, 0.2, L);
  INFO("L = " << L << ", k = " << k << ": " << r.message);
  REQUIRE(r.end == r0.end);
  // the first and the last point: the same optimum in the scaled units
  for (const auto& [a, b] : {std::pair{r0.points.front(), r.points.front()}, std::pair{r0.points.back(), r.points.back()}}) {
    CHECK((b.inputs / L - a.inputs).norm() < 1e-8);
    CHECK((b.q - a.q).norm() < 1e-8);
    CHECK(b.minEigenvalue / (k * L * L) == Approx(a.minEigenvalue).epsilon(1e-8));
  }
}
