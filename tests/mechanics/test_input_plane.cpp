// The plane of two control inputs (input_plane.h; issue 29): the bounding-curve system's exact rows
// against finite differences, its singular condition against the determinant of the
// input-to-position map differenced over equilibria solved apart, and the inputs refused when
// dependent or with a held end.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/input_plane.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "fixed_lambda_newton.h"
#include "payload_start.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

const Eigen::Vector3d kPlanePayload(-0.3, -0.3, 0.0);

// A three-segment chain, not uniform (so no symmetry makes a determinant vanish by accident).
Chain planeChain(double L = 1.0, double k = 1.0) {
  std::vector<SegmentParameters> s;
  for (int i = 0; i < 3; ++i) {
    SegmentParameters p = SegmentParameters::symmetric((0.5 + 0.05 * i) * L, L, (1.0 + 0.2 * i) * k, 2.25 * L);
    p.L1_0 += 0.1 * (i - 1) * L;
    s.push_back(p);
  }
  return Chain(s);
}

// The end position at inputs (u1, u2), Newton from q.
Eigen::Vector2d positionAt(const InputPlane& plane, const Eigen::VectorXd& q, double u1, double u2) {
  auto p = plane.along(0, u2);
  const Eigen::VectorXd qs = buckle::test::polishAtFixedLambda(*p, q, u1, 12);
  Eigen::VectorXd F(qs.size());
  REQUIRE(cont::BoundProblem(*p).residual(qs, u1, F));
  REQUIRE(F.norm() < 1e-12);
  return endPose(p->chain(), qs).head<2>();
}

}  // namespace

TEST_CASE("input plane: the curve system's rows against finite differences", "[input_plane]") {
  const double L = GENERATE(1.0, 1e-4, 1e4);
  const double k = GENERATE(1.0, 1e8);
  const Chain chain = planeChain(L, k);
  const Eigen::Vector3d payload(kPlanePayload[0] * k * L, kPlanePayload[1] * k * L, 0.0);
  const Eigen::VectorXd q = buckle::test::underPayload(chain, payload);
  const InputPlane plane(chain, EndCondition::freeEnd(payload), {}, {ControlInput::L0, -1}, {ControlInput::dL0, 1});
  for (auto condition : {InputPlaneCurveProblem::Condition::Fold, InputPlaneCurveProblem::Condition::Singular}) {
    INFO(conditionName(condition) << ", L = " << L << ", k = " << k);
    const InputPlaneCurveProblem problem(plane, condition);
    const cont::BoundProblem bound(problem);
    const int N = problem.dimension();
    Eigen::VectorXd U(N);
    U << q, plane.origin(1);
    const double u1 = plane.origin(0);
    Eigen::MatrixXd GU(N, N);
    Eigen::VectorXd Gl(N);
    REQUIRE(bound.jacobian(U, u1, GU, Gl));
    Eigen::MatrixXd J(N, N + 1);
    J << GU, Gl;
    // central differences of the residual in each of (q, u2, u1), in their own scales
    const cont::ProblemScales s = problem.scales();
    Eigen::MatrixXd D(N, N + 1);
    for (int j = 0; j <= N; ++j) {
      const double h = 1e-4 * (j < N ? s.unknowns[j] : s.parameter);
      Eigen::VectorXd Up = U, Um = U, Fp(N), Fm(N);
      double lp = u1, lm = u1;
      (j < N ? Up[j] : lp) += h;
      (j < N ? Um[j] : lm) -= h;
      REQUIRE(bound.residual(Up, lp, Fp));
      REQUIRE(bound.residual(Um, lm, Fm));
      D.col(j) = (Fp - Fm) / (2.0 * h);
    }
    // the equilibrium rows are exact: they agree with the differences to the differences' error
    const double rowsScale = J.topRows(N - 1).cwiseAbs().maxCoeff();
    CHECK((J.topRows(N - 1) - D.topRows(N - 1)).cwiseAbs().maxCoeff() < 1e-6 * rowsScale);
    // the condition row is itself differenced (step 1e-6): it agrees with a step 100 times larger
    const double lastScale = D.row(N - 1).cwiseAbs().maxCoeff();
    REQUIRE(lastScale > 0.0);
    CHECK((J.row(N - 1) - D.row(N - 1)).cwiseAbs().maxCoeff() < 1e-5 * lastScale);
  }
}

TEST_CASE("input plane: the singular condition is the determinant of the differenced input-to-position map",
          "[input_plane]") {
  const Chain chain = planeChain();
  const Eigen::VectorXd q0 = buckle::test::underPayload(chain, kPlanePayload);
  const InputPlane plane(chain, EndCondition::freeEnd(kPlanePayload), {}, {ControlInput::L1_0, -1},
                         {ControlInput::L2_0, 2});
  const InputPlaneCurveProblem problem(plane, InputPlaneCurveProblem::Condition::Singular);
  auto ws = problem.createWorkspace();
  // two points of the plane: the start, and one off it (the equilibrium moved there by Newton)
  for (const auto& [d1, d2] : {std::pair{0.0, 0.0}, std::pair{0.15, -0.2}}) {
    const double u1 = plane.origin(0) + d1, u2 = plane.origin(1) + d2;
    auto p = plane.along(0, u2);
    // reach it in small steps of u1 (Newton from the previous one)
    Eigen::VectorXd q = q0;
    for (int s = 1; s <= 10; ++s) q = buckle::test::polishAtFixedLambda(*p, q, plane.origin(0) + d1 * s / 10.0, 10);
    const double h = 1e-5;
    Eigen::Matrix2d J;
    J.col(0) = (positionAt(plane, q, u1 + h, u2) - positionAt(plane, q, u1 - h, u2)) / (2 * h);
    J.col(1) = (positionAt(plane, q, u1, u2 + h) - positionAt(plane, q, u1, u2 - h)) / (2 * h);
    const double expected = J.determinant() / (0.5 * J.squaredNorm());
    double c = 0.0;
    REQUIRE(problem.condition(*ws, q, u1, u2, c));
    INFO("u = (" << u1 << ", " << u2 << ")");
    CHECK(std::abs(expected) > 1e-3);  // a regular point: the comparison means something
    CHECK(c == Approx(expected).epsilon(1e-7));
  }
}

TEST_CASE("input plane: dependent inputs and a held end are refused", "[input_plane]") {
  const Chain chain = planeChain();
  const EndCondition payload = EndCondition::freeEnd(kPlanePayload);
  CHECK_THROWS_WITH(InputPlane(chain, payload, {}, {ControlInput::L0, -1}, {ControlInput::L0, 1}),
                    Catch::Contains("not independent"));
  CHECK_THROWS_WITH(InputPlane(chain, payload, {}, {ControlInput::L1_0, 0}, {ControlInput::L0, 0}),
                    Catch::Contains("not independent"));
  CHECK_NOTHROW(InputPlane(chain, payload, {}, {ControlInput::L0, -1}, {ControlInput::dL0, -1}));
  CHECK_NOTHROW(InputPlane(chain, payload, {}, {ControlInput::L1_0, 0}, {ControlInput::L1_0, 2}));
  CHECK_THROWS_WITH(InputPlane(chain, EndCondition::clampedPinned(-0.1), {}, {ControlInput::L0, -1},
                               {ControlInput::dL0, -1}),
                    Catch::Contains("hold no coordinate"));
}

namespace {

Eigen::MatrixX2d freeLengths(const Chain& chain) {
  Eigen::MatrixX2d L(chain.size(), 2);
  for (int i = 0; i < chain.size(); ++i)
    L.row(i) << chain.segment(i).parameters().L1_0, chain.segment(i).parameters().L2_0;
  return L;
}

}  // namespace

TEST_CASE("input plane: an input along a direction moves its complement by the given rates, its reading kept",
          "[input_plane]") {
  const Chain chain = planeChain();
  const EndCondition payload = EndCondition::freeEnd(kPlanePayload);
  const Eigen::MatrixX2d L = freeLengths(chain);
  // dL0 of segment 1 with L0 of segment 1 moving 0.3 per unit, against dL0 of segment 3
  PlaneInput first{ControlInput::dL0, 0, Eigen::Vector3d(0.3, 0.0, 0.0)};
  const PlaneInput second{ControlInput::dL0, 2, {}};
  const InputPlane plane(chain, payload, {}, first, second);
  CHECK(first.name() == "dL0[1] + (0.3 0 0) L0");
  CHECK(plane.origin(0) == L(0, 0) - L(0, 1));
  for (const auto& [d1, d2] : {std::pair{0.4, -0.25}, std::pair{-0.7, 0.6}}) {
    const Chain moved = plane.chainAt(plane.origin(0) + d1, plane.origin(1) + d2);
    Eigen::MatrixX2d expected = L;
    expected.row(0) += d1 * Eigen::RowVector2d(0.5 + 0.3, -0.5 + 0.3);  // d(L1, L2) = du (½, −½) + 0.3 du (1, 1)
    expected.row(2) += d2 * Eigen::RowVector2d(0.5, -0.5);
    CHECK((freeLengths(moved) - expected).cwiseAbs().maxCoeff() < 1e-14);
    // the readings stay absolute: dL0 of segment 1 is u₁, dL0 of segment 3 is u₂
    CHECK(controlInputValue(moved, ControlInput::dL0, 0) == Approx(plane.origin(0) + d1).margin(1e-14));
    CHECK(controlInputValue(moved, ControlInput::dL0, 2) == Approx(plane.origin(1) + d2).margin(1e-14));
  }
  // L1_0 of segment 1 moving L2_0 of segment 1 one for one is L0 of segment 1 (rates (1, 1))
  const InputPlane named(chain, payload, {}, {ControlInput::L0, 0, {}}, second);
  const InputPlane along(chain, payload, {}, {ControlInput::L1_0, 0, Eigen::Vector3d(1.0, 0.0, 0.0)}, second);
  for (double d1 : {-0.3, 0.25}) {
    const Eigen::MatrixX2d a = freeLengths(named.chainAt(named.origin(0) + d1, named.origin(1)));
    const Eigen::MatrixX2d b = freeLengths(along.chainAt(along.origin(0) + d1, along.origin(1)));
    CHECK((a - b).cwiseAbs().maxCoeff() < 1e-14);
  }
  // one rate for every segment: L0 every segment moves with dL0 of segment 1, so L0 of segment 3 would not be absolute
  first.along = Eigen::VectorXd::Constant(1, 0.3);
  CHECK_THROWS_WITH(InputPlane(chain, payload, {}, first, {ControlInput::L0, 2, {}}), Catch::Contains("not independent"));
  CHECK_NOTHROW(InputPlane(chain, payload, {}, first, {ControlInput::dL0, 2, {}}));
  first.along = Eigen::Vector2d(0.3, 0.1);
  CHECK_THROWS_WITH(InputPlane(chain, payload, {}, first, second), Catch::Contains("one per segment (3), got 2"));
}
