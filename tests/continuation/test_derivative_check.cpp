// checkDerivatives: passes problems whose derivatives are right, in any units, and names the
// entry of one that is wrong, for each derivative the core uses.
#include "buckle/continuation/derivative_check.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace buckle::continuation;

namespace {

/// Bratu with one wrong entry of F_u (row, column), or a wrong sign of F_λ in one row.
class WrongBratu : public toys::Bratu {
 public:
  WrongBratu(int n, int row, int column, bool lambdaColumn) : Bratu(n), row_(row), column_(column), lambda_(lambdaColumn) {}
  bool jacobian(ProblemWorkspace &ws, ConstVectorRef u, double lambda, MatrixRef Fu, VectorRef Fl) const override {
    if (!Bratu::jacobian(ws, u, lambda, Fu, Fl)) return false;
    if (lambda_) Fl[row_] = -Fl[row_];
    else Fu(row_, column_) *= 1.001;  // a 0.1 % slip
    return true;
  }

 private:
  int row_, column_;
  bool lambda_;
};

/// ScaledExponentials whose exact second derivative misses one term in entry (1, 0).
class WrongSecondDerivative : public toys::ScaledExponentials {
 public:
  using ScaledExponentials::ScaledExponentials;
  bool jacobianDirectionalDerivative(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef du,
                                     double dlambda, MatrixRef dFu, VectorRef dFl) const override {
    if (!ScaledExponentials::jacobianDirectionalDerivative(ws, u, lambda, du, dlambda, dFu, dFl)) return false;
    const Vector s = scales().unknowns;
    dFu(1, 0) += scales().residuals[1] / s[0] * 6.0 * (u[0] / s[0]) * (du[0] / s[0]);  // the −6a·da term dropped
    return true;
  }
};

/// ScaledExponentials whose O(N) product forgets the F_λ column.
class WrongProduct : public toys::ScaledExponentials {
 public:
  using ScaledExponentials::ScaledExponentials;
  bool jacobianApply(ProblemWorkspace &ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                     VectorRef y) const override {
    Matrix J(2, 3);
    if (!jacobian(ws, u, lambda, J.leftCols(2), J.col(2))) return false;
    y = J.leftCols(2) * x.head(2);
    return true;
  }
};

const Vector kPoint = (Vector(2) << 0.3, -0.7).finished();

}  // namespace

TEST_CASE("checkDerivatives passes right derivatives in any units", "[derivative_check]") {
  for (toys::ScaledExponentials problem :
       {toys::ScaledExponentials(), toys::ScaledExponentials(1e-3, 1e4, 1e6, 1e-5)}) {
    const ProblemScales s = problem.scales();
    const DerivativeCheck check =
        checkDerivatives(problem, kPoint.cwiseProduct(s.unknowns), 1.2 * s.parameter);
    INFO(check.message);
    CHECK(check.success);
    CHECK(check.maxRelativeError < 1e-7);
    // Every derivative the core uses was compared.
    for (const char *name : {"F_u", "F_lambda", "jacobianApply", "jacobianTransposeApply",
                             "jacobianDirectionalDerivative", "secondDerivativeApply",
                             "secondDerivativeTransposeApply"}) {
      const DerivativeComparison *c = check.find(name);
      REQUIRE(c != nullptr);
      CHECK(c->evaluated);
    }
  }
  toys::Bratu bratu(20);
  const DerivativeCheck check = checkDerivatives(bratu, Vector::Constant(20, 0.4), 2.0);
  INFO(check.message);
  CHECK(check.success);
  CHECK(check.maxRelativeError < 1e-7);
}

TEST_CASE("checkDerivatives names the wrong entry of F_u and F_lambda", "[derivative_check]") {
  WrongBratu wrongFu(20, 7, 7, false);
  const DerivativeCheck fu = checkDerivatives(wrongFu, Vector::Constant(20, 0.4), 2.0);
  CHECK_FALSE(fu.success);
  const DerivativeComparison *c = fu.find("F_u");
  REQUIRE(c != nullptr);
  CHECK(c->row == 7);
  CHECK(c->column == 7);
  // A 0.1 % slip of the diagonal, the row's largest entry: the error is 1e-3 of the row.
  CHECK(c->maxRelativeError == Approx(1e-3).epsilon(1e-3));
  CHECK(c->exact == Approx(1.001 * c->numeric).epsilon(1e-9));
  CHECK(fu.message.find("F_u: entry (7, 7)") != std::string::npos);
  // The right F_λ passes.
  CHECK(fu.find("F_lambda")->maxRelativeError < 1e-7);

  WrongBratu wrongFl(20, 3, 0, true);
  const DerivativeCheck fl = checkDerivatives(wrongFl, Vector::Constant(20, 0.4), 2.0);
  CHECK_FALSE(fl.success);
  CHECK(fl.find("F_lambda")->row == 3);
  CHECK(fl.find("F_lambda")->column == 20);
  CHECK(fl.find("F_u")->maxRelativeError < 1e-7);
}

TEST_CASE("checkDerivatives catches a wrong second derivative and a wrong product", "[derivative_check]") {
  for (const double unit : {1.0, 1e5}) {
    WrongSecondDerivative second(unit, 1.0 / unit, unit, unit * unit);
    const ProblemScales s = second.scales();
    const DerivativeCheck check = checkDerivatives(second, kPoint.cwiseProduct(s.unknowns), 1.2 * s.parameter);
    INFO(check.message);
    CHECK_FALSE(check.success);
    CHECK(check.find("F_u")->maxRelativeError < 1e-7);
    const DerivativeComparison *c = check.find("jacobianDirectionalDerivative");
    CHECK(c->row == 1);
    CHECK(c->column == 0);
    CHECK(c->maxRelativeError > 1e-2);

    WrongProduct product(unit, 1.0 / unit, unit, unit * unit);
    const DerivativeCheck p = checkDerivatives(product, kPoint.cwiseProduct(s.unknowns), 1.2 * s.parameter);
    CHECK_FALSE(p.success);
    CHECK(p.find("jacobianApply")->maxRelativeError > 1e-2);
    CHECK(p.find("jacobianTransposeApply")->maxRelativeError < 1e-7);
    CHECK(p.message.rfind("jacobianApply", 0) == 0);
  }
}

TEST_CASE("checkDerivatives: a residual-only problem's derivatives are consistent", "[derivative_check]") {
  class Numeric : public NumericDiffProblem {
   public:
    int dimension() const override { return 2; }
    bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
      return exact.residual(ws, u, lambda, F);
    }
    ProblemScales scales() const override { return exact.scales(); }
    toys::ScaledExponentials exact{1e-3, 1e4, 1e6, 1e-5};
  } numeric;
  const ProblemScales s = numeric.scales();
  const DerivativeCheck check = checkDerivatives(numeric, kPoint.cwiseProduct(s.unknowns), 1.2 * s.parameter);
  INFO(check.message);
  CHECK(check.success);
}

TEST_CASE("checkDerivatives refuses invalid input with a reason", "[derivative_check]") {
  toys::Bratu bratu(4);
  const DerivativeCheck size = checkDerivatives(bratu, Vector::Zero(3), 1.0);
  CHECK_FALSE(size.success);
  CHECK(size.message.find("size N = 4") != std::string::npos);
  DerivativeCheckOptions options;
  options.direction = Vector::Ones(2);
  const DerivativeCheck direction = checkDerivatives(bratu, Vector::Zero(4), 1.0, options);
  CHECK_FALSE(direction.success);
  CHECK(direction.message.find("direction must be empty or have size N + 1 = 5") != std::string::npos);
  // A point the problem refuses: reported, not thrown.
  toys::LineWithDomain domain(0.5);
  const DerivativeCheck refused = checkDerivatives(domain, Vector::Constant(1, 0.5), 0.0);
  CHECK_FALSE(refused.success);
  CHECK(std::isinf(refused.maxRelativeError));
  CHECK(refused.message.find("refused") != std::string::npos);
}
