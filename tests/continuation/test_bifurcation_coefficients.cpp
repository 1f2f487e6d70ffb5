#include "buckle/continuation/bifurcation_coefficients.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace buckle::continuation;

namespace {
/// F = ((1 − λ)x + αx² + xy + βx³, 2y − x²): trivial branch u = 0, a simple branch point at
/// λ = 1 with v = (1, 0); the bifurcated branch is y = x²/2, λ = 1 + αx + (½ + β)x² exactly.
class Reduced : public Problem {
 public:
  double alpha = 0.0, beta = 0.0;
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double l, VectorRef F) const override {
    const double x = u[0], y = u[1];
    F << (1.0 - l) * x + alpha * x * x + x * y + beta * x * x * x, 2.0 * y - x * x;
    return true;
  }
  bool jacobian(ProblemWorkspace &, ConstVectorRef u, double l, MatrixRef Fu, VectorRef Fl) const override {
    const double x = u[0], y = u[1];
    Fu << 1.0 - l + 2.0 * alpha * x + y + 3.0 * beta * x * x, x, -2.0 * x, 2.0;
    Fl << -x, 0.0;
    return true;
  }
  bool jacobianDirectionalDerivative(ProblemWorkspace &, ConstVectorRef u, double, ConstVectorRef du, double dl,
                                     MatrixRef dFu, VectorRef dFl) const override {
    dFu << -dl + 2.0 * alpha * du[0] + du[1] + 6.0 * beta * u[0] * du[0], du[0], -2.0 * du[0], 0.0;
    dFl << -du[0], 0.0;
    return true;
  }
};
}  // namespace

TEST_CASE("Bifurcation coefficients: a and b of the exact bifurcated branch", "[bifurcation_coefficients]") {
  Reduced p;
  const Vector u0 = Vector::Zero(2), c = (Vector(2) << 1.0, 0.0).finished();
  for (double alpha : {0.0, 0.7}) {
    for (double beta : {0.0, -1.3}) {
      p.alpha = alpha;
      p.beta = beta;
      BifurcationCoefficients bc;
      std::string why;
      // a null vector of any length and sign: v is rescaled to cᵀv = 1
      REQUIRE(bifurcationCoefficients(p, u0, 1.0, (Vector(2) << -2.0, 0.0).finished(), c, bc, &why));
      CHECK(std::abs(bc.a - alpha) <= 1e-14);
      CHECK(std::abs(bc.b - (0.5 + beta)) <= 1e-9);
      CHECK(std::abs(bc.v[0] - 1.0) <= 1e-15);
      CHECK(std::abs(bc.u2[1] - 0.5) <= 1e-14);  // y = x²/2
      CHECK(std::abs(bc.transversality + 1.0) <= 1e-14);
    }
  }
}

TEST_CASE("Bifurcation coefficients: refused input", "[bifurcation_coefficients]") {
  Reduced p;
  BifurcationCoefficients bc;
  std::string why;
  CHECK_FALSE(bifurcationCoefficients(p, Vector::Zero(3), 1.0, Vector::Ones(2), Vector::Ones(2), bc, &why));
  CHECK(why.find("dimension") != std::string::npos);
  CHECK_FALSE(bifurcationCoefficients(p, Vector::Zero(2), 1.0, (Vector(2) << 1.0, 0.0).finished(),
                                      (Vector(2) << 0.0, 1.0).finished(), bc, &why));
  CHECK(why.find("orthogonal") != std::string::npos);
  // not a branch point: F_u regular at λ = 3
  CHECK_FALSE(bifurcationCoefficients(p, Vector::Zero(2), 3.0, (Vector(2) << 1.0, 0.0).finished(),
                                      (Vector(2) << 1.0, 0.0).finished(), bc, &why));
  CHECK(why.find("not singular") != std::string::npos);
}
