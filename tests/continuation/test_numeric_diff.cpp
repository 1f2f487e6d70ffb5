// NumericDiffProblem: a Problem from its residual alone. Its derivatives against the closed forms
// in two unit systems, and traces of residual-only problems against closed-form special points.
#include "buckle/continuation/numeric_diff.h"

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"

#include "toy_problems.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace buckle::continuation;

namespace {

/// ScaledExponentials through its residual only.
class NumericExponentials : public NumericDiffProblem {
 public:
  explicit NumericExponentials(const toys::ScaledExponentials &exact) : exact_(exact) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
    return exact_.residual(ws, u, lambda, F);
  }
  ProblemScales scales() const override { return exact_.scales(); }

 private:
  toys::ScaledExponentials exact_;
};

/// The von Mises truss of examples/von_mises_truss.cpp through its residual only:
/// F(w, P) = 2k w (1 − L0/L) + P, L = √(a² + w²); folds at L³ = L0 a².
class NumericTruss : public NumericDiffProblem {
 public:
  NumericTruss(double a, double h, double k) : a_(a), h_(h), k_(k), L0_(std::hypot(a, h)) {}
  int dimension() const override { return 1; }
  bool residual(ProblemWorkspace &, ConstVectorRef u, double P, VectorRef F) const override {
    F[0] = 2.0 * k_ * u[0] * (1.0 - L0_ / std::hypot(a_, u[0])) + P;
    return std::isfinite(F[0]);
  }
  ProblemScales scales() const override {
    ProblemScales s = ProblemScales::ones(1);
    s.unknowns[0] = h_;
    s.parameter = s.residuals[0] = k_ * h_ * h_ * h_ / (a_ * a_);
    s.stability = k_;
    return s;
  }
  double foldDeflection() const { return std::sqrt(std::pow(L0_ * a_ * a_, 2.0 / 3.0) - a_ * a_); }
  double foldLoad() const {
    const double L = std::cbrt(L0_ * a_ * a_);
    return 2.0 * k_ * foldDeflection() * (L0_ / L - 1.0);
  }

 private:
  double a_, h_, k_, L0_;
};

/// TwoPitchforks through its residual only, stability H = −F_u (its differenced F_u).
class NumericPitchforks : public NumericDiffProblem {
 public:
  explicit NumericPitchforks(double c) : exact_(c) {}
  int dimension() const override { return 2; }
  bool residual(ProblemWorkspace &ws, ConstVectorRef u, double lambda, VectorRef F) const override {
    return exact_.residual(ws, u, lambda, F);
  }
  bool hasStabilityOperator() const override { return true; }
  bool stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H, Matrix &C) const override {
    return toys::negatedJacobian(*this, ws, u, lambda, H, C);
  }

 private:
  toys::TwoPitchforks exact_;
};

// max |D_F⁻¹ (A − B) D_x| over the entries: the difference in the scaled variables, where the
// entries of the problem are O(1).
double scaledDifference(const Matrix &A, const Matrix &B, const ProblemScales &s) {
  Vector column(s.unknowns.size() + 1);
  column << s.unknowns, s.parameter;
  return (s.residuals.cwiseInverse().asDiagonal() * (A - B) * column.asDiagonal()).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("NumericDiffProblem: derivatives agree with the closed form in any units", "[numeric_diff]") {
  // The same problem in O(1) units and in units 1e-3 … 1e6 apart: the steps are relative to each
  // variable's scale, so the accuracy in the scaled variables is the same.
  for (const toys::ScaledExponentials &exact :
       {toys::ScaledExponentials(), toys::ScaledExponentials(1e-3, 1e4, 1e6, 1e-5)}) {
    toys::ScaledExponentials reference = exact;
    NumericExponentials numeric(exact);
    const ProblemScales s = exact.scales();
    const Vector u = (Vector(2) << 0.3 * s.unknowns[0], -0.7 * s.unknowns[1]).finished();
    const double lambda = 1.2 * s.parameter;
    INFO("unknown scales " << s.unknowns.transpose() << ", parameter scale " << s.parameter);

    Matrix exactJ(2, 3), numericJ(2, 3);
    REQUIRE(BoundProblem(reference).jacobian(u, lambda, exactJ.leftCols(2), exactJ.col(2)));
    REQUIRE(BoundProblem(numeric).jacobian(u, lambda, numericJ.leftCols(2), numericJ.col(2)));
    // Central differences: O(h²) + O(ε/h) with h ≈ ε^{1/3} relative, ~1e-10 of the O(1) entries.
    CHECK(scaledDifference(numericJ, exactJ, s) < 1e-9);

    const Vector x = (Vector(3) << 0.8 * s.unknowns[0], -0.6 * s.unknowns[1], 0.5 * s.parameter).finished();
    const Vector z = (Vector(3) << -0.4 * s.unknowns[0], 0.9 * s.unknowns[1], 0.7 * s.parameter).finished();
    Matrix exactD(2, 3), numericD(2, 3);
    REQUIRE(BoundProblem(reference).jacobianDirectionalDerivative(u, lambda, x.head(2), x[2], exactD.leftCols(2),
                                                                  exactD.col(2)));
    REQUIRE(BoundProblem(numeric).jacobianDirectionalDerivative(u, lambda, x.head(2), x[2], numericD.leftCols(2),
                                                                numericD.col(2)));
    // Second differences with steps ε^{1/4}: O(h²) + O(ε/h²), ~1e-8.
    CHECK(scaledDifference(numericD, exactD, s) < 1e-6);

    // F_xx[x, z] (four residuals) and (F_xx[x, ·])ᵀw against the exact directional derivative.
    Vector y(2), yt(3);
    REQUIRE(BoundProblem(numeric).secondDerivativeApply(u, lambda, x, z, y));
    CHECK((s.residuals.cwiseInverse().asDiagonal() * (y - exactD * z)).cwiseAbs().maxCoeff() < 1e-6);
    const Vector w = (Vector(2) << 0.3, -1.1).finished().cwiseQuotient(s.residuals);
    REQUIRE(BoundProblem(numeric).secondDerivativeTransposeApply(u, lambda, x, w, yt));
    Vector column(3);
    column << s.unknowns, s.parameter;
    CHECK((yt - exactD.transpose() * w).cwiseProduct(column).cwiseAbs().maxCoeff() < 1e-6);
  }
}

TEST_CASE("NumericDiffProblem: a refused perturbed point refuses the derivative", "[numeric_diff]") {
  class HalfLine : public NumericDiffProblem {
   public:
    int dimension() const override { return 1; }
    bool residual(ProblemWorkspace &, ConstVectorRef u, double lambda, VectorRef F) const override {
      if (u[0] < 0.0) return false;
      F[0] = std::sqrt(u[0]) - lambda;
      return true;
    }
  } problem;
  Matrix Fu(1, 1);
  Vector Fl(1);
  REQUIRE(BoundProblem(problem).jacobian(Vector::Constant(1, 4.0), 1.0, Fu, Fl));
  CHECK(Fu(0, 0) == Approx(0.25).epsilon(1e-9));
  CHECK(Fl[0] == Approx(-1.0).epsilon(1e-9));
  // At u = 0 the step reaches u < 0, outside the domain.
  CHECK_FALSE(BoundProblem(problem).jacobian(Vector::Zero(1), 0.0, Fu, Fl));
}

TEST_CASE("NumericDiffProblem: the truss's limit points from its residual alone", "[numeric_diff][tracer]") {
  NumericTruss truss(2.0, 0.3, 5.0e6);
  TracerOptions options;
  options.lambdaMax = 2.0 * truss.foldLoad();
  const Branch branch =
      trace(truss, Vector::Constant(1, 0.3), 0.0, InitialDirection::increasingLambda(), options);
  const auto folds = branch.specialPointsOfType(SpecialPointType::Fold);
  REQUIRE(folds.size() == 2);
  const double scaleP = truss.scales().parameter, scaleW = truss.scales().unknowns[0];
  for (const SpecialPoint *fold : folds) {
    const double sign = fold->u[0] > 0.0 ? 1.0 : -1.0;
    INFO("fold at w = " << fold->u[0] << ", P = " << fold->lambda);
    CHECK(fold->refined);
    // The fold is where the differenced F_u vanishes: w off by F_u's error over F_uu, ~ε^{2/3}
    // relative; P is stationary there, so it is off by the square of that plus the location
    // tolerance.
    CHECK(std::abs(fold->u[0] - sign * truss.foldDeflection()) < 1e-8 * scaleW);
    CHECK(std::abs(fold->lambda - sign * truss.foldLoad()) < 1e-11 * std::max(scaleP, std::abs(truss.foldLoad())));
  }
}

TEST_CASE("NumericDiffProblem: pitchforks located and switched from the residual alone", "[numeric_diff][switching]") {
  const double c = 0.5;
  NumericPitchforks problem(c);
  TracerOptions options;
  options.lambdaMax = 1.0;
  const BranchTree tree =
      traceTree(problem, Vector::Zero(2), -0.3, InitialDirection::increasingLambda(), options, 1);
  REQUIRE(!tree.branches.empty());
  const auto bps = tree.branches[0].specialPointsOfType(SpecialPointType::BranchPoint);
  REQUIRE(bps.size() == 2);
  // The differenced F_u = diag(λ − 3u₁² − h₁², …) vanishes at λ = h² ≈ ε^{2/3} on u = 0.
  CHECK(std::abs(bps[0]->lambda - 0.0) < 1e-9);
  CHECK(std::abs(bps[1]->lambda - c) < 1e-9);
  // Both sides of both pitchforks, switched with the differenced second derivatives: the
  // children lie on u₁² = λ (u₂ = 0) and u₂² = λ − c (u₁ = 0), off the trivial branch.
  int children = 0;
  for (const Branch &child : tree.branches) {
    if (child.parentId != 0) continue;
    ++children;
    REQUIRE(child.points.size() > 3);
    const ContinuationPoint &p = child.points.back();
    const bool first = std::abs(tree.branches[0].specialPoints[size_t(child.parentSpecialPoint)].lambda) < 0.5 * c;
    const double off = first ? p.u[0] : p.u[1], along = first ? p.u[1] : p.u[0];
    INFO("child of BP " << child.parentSpecialPoint << " ends at u = " << p.u.transpose() << ", λ = " << p.lambda);
    CHECK(std::abs(off) > 0.1);
    CHECK(std::abs(along) < 1e-8);
    CHECK(off * off == Approx(first ? p.lambda : p.lambda - c).epsilon(1e-8));
  }
  CHECK(children == 4);
}
