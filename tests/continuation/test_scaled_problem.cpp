// ScaledProblem (scaled_problem.h): what the tracer's scaled variables hand to the user's problem.
#include "buckle/continuation/scaled_problem.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

namespace {

/// A problem that records the arguments of its rate bound and returns b = 2|du₀| + 3|du₁| + 5|dλ|
/// (user units), to check the change of variables of ScaledProblem::stabilityRateBound.
class RecordingBound : public Problem {
 public:
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double, VectorRef F) const override {
    F = u;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef, double, MatrixRef Fu, VectorRef Fl) const override {
    Fu.setIdentity();
    Fl.setZero();
    return true;
  }
  bool stabilityRateBound(ProblemWorkspace &, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda,
                          double &bound) const override {
    seenU = u;
    seenLambda = lambda;
    bound = 2.0 * std::abs(du[0]) + 3.0 * std::abs(du[1]) + 5.0 * std::abs(dlambda);
    return offer;
  }
  bool offer = true;
  mutable Vector seenU;  // probes of this single-threaded test
  mutable double seenLambda = 0.0;
};

}  // namespace

TEST_CASE("ScaledProblem's rate bound: the user's bound along the user direction, per stability unit") {
  RecordingBound problem;
  ProblemScales scales = ProblemScales::ones(2);
  scales.unknowns << 10.0, 0.1;
  scales.parameter = 4.0;
  scales.stability = 8.0;
  const UnitScaling units(scales);
  ScaledProblem scaled(problem, units);
  Vector u(2), du(2);
  u << 0.3, -2.0;
  du << 0.5, -1.5;
  double bound = 0.0;
  REQUIRE(BoundProblem(scaled).stabilityRateBound(u, 0.25, du, -0.75, bound));
  // user direction (10·0.5, 0.1·(−1.5), 4·(−0.75)) = (5, −0.15, −3): 10 + 0.45 + 15, / 8
  CHECK(bound == Approx((10.0 + 0.45 + 15.0) / 8.0).epsilon(1e-15));
  CHECK(problem.seenU[0] == Approx(3.0).epsilon(1e-15));
  CHECK(problem.seenU[1] == Approx(-0.2).epsilon(1e-15));
  CHECK(problem.seenLambda == Approx(1.0).epsilon(1e-15));
  problem.offer = false;
  CHECK_FALSE(BoundProblem(scaled).stabilityRateBound(u, 0.25, du, -0.75, bound));
  // the default Problem offers no bound
  class NoBound : public RecordingBound {
   public:
    bool stabilityRateBound(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du, double dlambda,
                            double &bound) const override {
      return Problem::stabilityRateBound(ws, u, lambda, du, dlambda, bound);
    }
  } none;
  CHECK_FALSE(BoundProblem(none).stabilityRateBound(u, 0.25, du, -0.75, bound));
}
