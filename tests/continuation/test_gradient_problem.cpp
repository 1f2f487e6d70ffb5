// GradientProblem: the stability operator of a gradient system is its Hessian, with nothing but
// the gradient and the Hessian written. Checked on Π(u, λ) = ¼(u₀⁴ + u₁⁴) + ½(1 − λ)u₀² +
// ½(2 − λ)u₁² + ε u₀u₁, whose trivial branch u = 0 has the Hessian [[1 − λ, ε], [ε, 2 − λ]]:
// eigenvalues 3/2 − λ ± √(1/4 + ε²), zero (branch points) at λ = 3/2 ∓ √(1/4 + ε²).
#include "buckle/continuation/gradient_problem.h"
#include "buckle/continuation/tracer.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace buckle::continuation;

namespace {

constexpr double kEps = 0.3;

class Potential : public GradientProblem {
 public:
  explicit Potential(Residual r) : GradientProblem(r), sign_(r == Residual::Gradient ? 1.0 : -1.0) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double l, VectorRef F) const override {
    F << u[0] * u[0] * u[0] + (1.0 - l) * u[0] + kEps * u[1], u[1] * u[1] * u[1] + (2.0 - l) * u[1] + kEps * u[0];
    F *= sign_;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double l, MatrixRef Fu, VectorRef Fl) const override {
    Fu << 3.0 * u[0] * u[0] + 1.0 - l, kEps, kEps, 3.0 * u[1] * u[1] + 2.0 - l;
    Fl << -u[0], -u[1];
    Fu *= sign_;
    Fl *= sign_;
    return true;
  }

 private:
  double sign_;
};

double root() { return std::sqrt(0.25 + kEps * kEps); }

}  // namespace

TEST_CASE("GradientProblem: H is the Hessian, whichever sign the residual has", "[gradient_problem]") {
  for (auto kind : {GradientProblem::Residual::Gradient, GradientProblem::Residual::RestoringForce}) {
    INFO("restoring force " << (kind == GradientProblem::Residual::RestoringForce));
    Potential p(kind);
    REQUIRE(p.hasStabilityOperator());
    Matrix H, C;
    const Vector u = (Vector(2) << 0.4, -0.7).finished();
    REQUIRE(BoundProblem(p).stabilityOperator(u, 0.6, H, C));
    CHECK(C.rows() == 0);
    CHECK(C.cols() == 2);
    const Matrix hessian = (Matrix(2, 2) << 3 * 0.16 + 1 - 0.6, kEps, kEps, 3 * 0.49 + 2 - 0.6).finished();
    CHECK((H - hessian).norm() <= 1e-15);
    // stability(): the inertia and the lowest eigenvalues of that Hessian
    StabilityInfo info;
    REQUIRE(BoundProblem(p).stability(Vector::Zero(2), 1.5, 2, info));
    CHECK(info.negative == 1);
    REQUIRE(info.lowest.size() == 2);
    CHECK(info.lowest[0] == Approx(-root()).margin(1e-14));
    CHECK(info.lowest[1] == Approx(root()).margin(1e-14));
  }
}

TEST_CASE("GradientProblem: the trivial branch's branch points and inertia from the Hessian alone", "[gradient_problem]") {
  for (auto kind : {GradientProblem::Residual::Gradient, GradientProblem::Residual::RestoringForce}) {
    INFO("restoring force " << (kind == GradientProblem::Residual::RestoringForce));
    Potential p(kind);
    TracerOptions o;
    o.lambdaMax = 3.0;
    o.step.maxStep = 0.05;
    o.detection.lowestEigenvalues = 2;
    const Branch b = trace(p, Vector::Zero(2), 0.0, InitialDirection::increasingLambda(), o);
    const auto bps = b.specialPointsOfType(SpecialPointType::BranchPoint);
    REQUIRE(bps.size() == 2);
    CHECK(bps[0]->lambda == Approx(1.5 - root()).margin(1e-11));
    CHECK(bps[1]->lambda == Approx(1.5 + root()).margin(1e-11));
    CHECK(bps[0]->inertiaBefore == 0);
    CHECK(bps[0]->inertiaAfter == 1);
    CHECK(bps[1]->inertiaBefore == 1);
    CHECK(bps[1]->inertiaAfter == 2);
    // every point's recorded eigenvalues are the closed form's
    for (const ContinuationPoint &pt : b.points) {
      REQUIRE(pt.stability.lowest.size() == 2);
      CHECK(pt.stability.lowest[0] == Approx(1.5 - pt.lambda - root()).margin(1e-12));
      CHECK(pt.stability.lowest[1] == Approx(1.5 - pt.lambda + root()).margin(1e-12));
    }
  }
}
