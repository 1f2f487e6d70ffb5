#include "buckle/continuation/branch_point_coefficients.h"

#include "buckle/continuation/bordered_solver.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/continuation/internal/structured_refinement.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace buckle::continuation {

namespace {
bool fail(std::string *why, const std::string &reason) {
  if (why) *why = reason;
  return false;
}

/// What the reduction needs from the problem at the branch point x0 = (u0, λc): the second
/// directional derivatives F_xx[x, z] as vectors (at x0 and at nearby points, for the third
/// derivatives), F_λ, the left null vector system [[F_uᵀ, c], [v̂ᵀ, 0]] and the bordered
/// [[F_u, ψ], [cᵀ, 0]] for every solve with F_u.
class Algebra {
 public:
  virtual ~Algebra() = default;
  /// F_x at x0 (what factor and the size check need); false when the problem refuses x0.
  virtual bool linearise(Vector &Fl) = 0;
  /// A size of F_u (the singularity check of the left null vector).
  virtual double jacobianSize() const = 0;
  /// [ψ; σ] = [[F_uᵀ, c], [v̂ᵀ, 0]]⁻¹ e_{N+1}.
  virtual bool leftNull(const Vector &c, const Vector &vHat, Vector &sol) = 0;
  /// Factors [[F_u, ψ], [cᵀ, 0]]; solve() then gives its inverse applied to r (size N+1).
  virtual bool factorBordered(const Vector &psi, const Vector &c) = 0;
  virtual bool solve(const Vector &r, Vector &x) = 0;
  /// y = F_xx[x, z] at (u, λ) (x, z size N+1).
  virtual bool second(const Vector &u, double lambda, const Vector &x, const Vector &z, Vector &y) = 0;
};

/// Dense: F_u as a matrix, partial-pivoting LU, F_xx[x, ·] the matrices of
/// jacobianDirectionalDerivative (kept for the last x and point: most products share them).
class DenseAlgebra final : public Algebra {
 public:
  DenseAlgebra(const BoundProblem &problem, ConstVectorRef u0, double lambda)
      : problem_(problem), n_(problem.dimension()), u0_(u0), lambda_(lambda), Fu_(n_, n_), D_(n_, n_), Dl_(n_) {}

  bool linearise(Vector &Fl) override {
    Fl.resize(n_);
    return problem_.jacobian(u0_, lambda_, Fu_, Fl);
  }
  double jacobianSize() const override { return Fu_.norm(); }
  bool leftNull(const Vector &c, const Vector &vHat, Vector &sol) override {
    Matrix A = Matrix::Zero(n_ + 1, n_ + 1);
    A.topLeftCorner(n_, n_) = Fu_.transpose();
    A.block(0, n_, n_, 1) = c;
    A.block(n_, 0, 1, n_) = vHat.transpose();
    Vector rhs = Vector::Zero(n_ + 1);
    rhs[n_] = 1.0;
    sol = Eigen::PartialPivLU<Matrix>(A).solve(rhs);
    return sol.allFinite();
  }
  bool factorBordered(const Vector &psi, const Vector &c) override {
    Matrix B = Matrix::Zero(n_ + 1, n_ + 1);
    B.topLeftCorner(n_, n_) = Fu_;
    B.block(0, n_, n_, 1) = psi;
    B.block(n_, 0, 1, n_) = c.transpose();
    lu_.compute(B);
    return true;
  }
  bool solve(const Vector &r, Vector &x) override {
    x = lu_.solve(r);
    return x.allFinite();
  }
  bool second(const Vector &u, double lambda, const Vector &x, const Vector &z, Vector &y) override {
    const bool same = cached_ && lambda == cachedLambda_ && x == cachedX_ && u == cachedU_;
    if (!same) {
      cached_ = false;
      if (!problem_.jacobianDirectionalDerivative(u, lambda, x.head(n_), x[n_], D_, Dl_)) return false;
      cachedU_ = u;
      cachedLambda_ = lambda;
      cachedX_ = x;
      cached_ = true;
    }
    y.noalias() = D_ * z.head(n_);
    if (z[n_] != 0.0) y += z[n_] * Dl_;
    return true;
  }

 private:
  BoundProblem problem_;
  int n_;
  ConstVectorRef u0_;
  double lambda_;
  Matrix Fu_, D_;
  Vector Dl_;
  Eigen::PartialPivLU<Matrix> lu_;
  bool cached_ = false;
  Vector cachedU_, cachedX_;
  double cachedLambda_ = 0.0;
};

/// Structured: the problem's O(N) products (jacobianApply, secondDerivativeApply) and its
/// bordered solver's general borders (k = 1), iteratively refined on the exact residual
/// (RefinedBorderedSystem): O(N) per solve and product for a chain.
class StructuredAlgebra final : public Algebra {
 public:
  StructuredAlgebra(const BoundProblem &problem, std::unique_ptr<BorderedSolver> solver, ConstVectorRef u0,
                    double lambda)
      : problem_(problem),
        n_(problem.dimension()),
        solver_(std::move(solver)),
        system_(problem, *solver_),
        u0_(u0),
        lambda_(lambda),
        zero_(Matrix::Zero(1, 1)) {}

  bool linearise(Vector &Fl) override {
    Vector x = Vector::Zero(n_ + 1);
    x[n_] = 1.0;
    Fl.resize(n_);
    if (!problem_.jacobianApply(u0_, lambda_, x, Fl)) return false;
    // ‖F_u z‖/‖z‖ for a fixed z spread over all unknowns (in their scales): a lower bound of ‖F_u‖
    const ProblemScales s = problem_.scales();
    for (int i = 0; i < n_; ++i) x[i] = (std::sin(0.7 * double(i) + 0.3) + 0.5) * s.unknowns[i];
    x[n_] = 0.0;
    Vector y(n_);
    if (!problem_.jacobianApply(u0_, lambda_, x, y)) return false;
    size_ = y.norm() / x.norm();
    return Fl.allFinite() && std::isfinite(size_);
  }
  double jacobianSize() const override { return size_; }
  bool leftNull(const Vector &c, const Vector &vHat, Vector &sol) override {
    if (!system_.factor(u0_, lambda_, c, vHat, zero_, true)) return false;
    Vector rhs = Vector::Zero(n_ + 1);
    rhs[n_] = 1.0;
    return system_.solve(rhs, sol);
  }
  bool factorBordered(const Vector &psi, const Vector &c) override {
    return system_.factor(u0_, lambda_, psi, c, zero_, false);
  }
  bool solve(const Vector &r, Vector &x) override { return system_.solve(r, x); }
  bool second(const Vector &u, double lambda, const Vector &x, const Vector &z, Vector &y) override {
    y.resize(n_);
    return problem_.secondDerivativeApply(u, lambda, x, z, y);
  }

 private:
  BoundProblem problem_;
  int n_;
  std::unique_ptr<BorderedSolver> solver_;
  RefinedBorderedSystem system_;
  ConstVectorRef u0_;
  double lambda_;
  Matrix zero_;
  double size_ = 0.0;
};

/// The second derivatives F_xx[e, e], F_xx[e, d], F_xx[d, d] (e = (v, 0), d = (p1, 1)) at
/// x0 + ε·w, and their derivatives along w by central differences (the third derivatives).
class SecondDerivatives {
 public:
  SecondDerivatives(Algebra &algebra, ConstVectorRef u0, double lambda, const Vector &e, const Vector &d)
      : algebra_(algebra), u0_(u0), lambda_(lambda), e_(e), d_(d) {}

  /// At x0 + ε w (w size N+1): ee = F_xx[e, e], ed = F_xx[e, d], dd = F_xx[d, d] (dd only when asked).
  bool at(double eps, const Vector &w, Vector &ee, Vector &ed, Vector *dd) {
    const Eigen::Index n = u0_.size();
    u_ = u0_ + eps * w.head(n);
    const double l = lambda_ + eps * w[n];
    if (!algebra_.second(u_, l, e_, e_, ee) || !algebra_.second(u_, l, e_, d_, ed)) return false;
    return !dd || algebra_.second(u_, l, d_, d_, *dd);
  }

  /// d/dε of (F_xx[e, e], F_xx[e, d], F_xx[d, d]) at ε = 0 along h·w: central differences
  /// at ±h and ±h/2, one Richardson step (error O(h⁴)), divided by h.
  bool along(double h, const Vector &w, Vector &dee, Vector &ded, Vector *ddd) {
    const double t[4] = {h, -h, 0.5 * h, -0.5 * h};
    Vector ee[4], ed[4], dd[4];
    for (int k = 0; k < 4; ++k)
      if (!at(t[k], w, ee[k], ed[k], ddd ? &dd[k] : nullptr)) return false;
    auto richardson = [h](const Vector *f) -> Vector {
      return (4.0 * (f[2] - f[3]) - 0.5 * (f[0] - f[1])) / (3.0 * h);
    };
    dee = richardson(ee);
    ded = richardson(ed);
    if (ddd) *ddd = richardson(dd);
    return true;
  }

 private:
  Algebra &algebra_;
  ConstVectorRef u0_;
  double lambda_;
  const Vector &e_, &d_;
  Vector u_;
};

/// (x, 0) and (x, 1) as (N+1)-vectors.
Vector extended(const Vector &x, double last) {
  Vector y(x.size() + 1);
  y << x, last;
  return y;
}

/// What the third-order solvability condition needs (reduce()'s quantities at the point).
struct ThirdOrderInput {
  Algebra &algebra;
  ConstVectorRef u0;
  double lambdaC;
  const ProblemScales &s;
  const Vector &e, &dv, &v, &psi, &p1, &p2Perp, &u2;
  double a, tau;
};

struct ThirdOrder {
  double b = 0.0;
  double scale = 0.0;  ///< Σ|ψ_i|·|terms_i| / |τ|
  Vector p2;           ///< the parent's curvature d²u_p/dλ²
};

/// b from the third-order condition, the third derivatives by differences at `factor` times the
/// standard step (1e-3 in the scaled variables).
bool thirdOrder(const ThirdOrderInput &in, double factor, ThirdOrder &out) {
  const Vector uc = in.u0;
  // third derivatives D³F[e,e,e] along e; D³F[e,e,d], D³F[e,d,d], D³F[d,d,d] along d
  SecondDerivatives second(in.algebra, in.u0, in.lambdaC, in.e, in.dv);
  const double pScaled = in.s.parameter * in.p1.cwiseQuotient(in.s.unknowns).norm();
  const double hu = factor * 1e-3 / in.v.cwiseQuotient(in.s.unknowns).norm();
  const double hd =
      factor * 1e-3 * std::max(in.s.parameter, std::abs(in.lambdaC)) / std::sqrt(1.0 + pScaled * pScaled);
  Vector Teee, unused, Teed, Tedd, Tddd;
  if (!second.along(hu, in.e, Teee, unused, nullptr) || !second.along(hd, in.dv, Teed, Tedd, &Tddd)) return false;
  // p2's component along v from ψᵀ(D³F[d,d,d] + 3F_xx[d, (p2, 0)]) = 0
  Vector Fdp2Perp, Fdu2, Feu2, Fep2;
  if (!in.algebra.second(uc, in.lambdaC, in.dv, extended(in.p2Perp, 0.0), Fdp2Perp)) return false;
  const double sigma = -(in.psi.dot(Tddd) + 3.0 * in.psi.dot(Fdp2Perp)) / (3.0 * in.tau);
  out.p2 = in.p2Perp + sigma * in.v;
  const Vector u2e = extended(in.u2, 0.0);
  if (!in.algebra.second(uc, in.lambdaC, in.dv, u2e, Fdu2) || !in.algebra.second(uc, in.lambdaC, in.e, u2e, Feu2) ||
      !in.algebra.second(uc, in.lambdaC, in.e, extended(out.p2, 0.0), Fep2))
    return false;
  const double a = in.a;
  const Vector third = a * Fdu2 + Feu2 + Teee / 6.0 + 0.5 * a * Teed + 0.5 * a * a * (Tedd + Fep2);
  out.b = -in.psi.dot(third) / in.tau;
  const Vector absPsi = in.psi.cwiseAbs();
  auto size = [&](const Vector &y) { return absPsi.dot(y.cwiseAbs()); };
  out.scale = (std::abs(a) * size(Fdu2) + size(Feu2) + size(Teee) / 6.0 + 0.5 * std::abs(a) * size(Teed) +
               0.5 * a * a * (size(Tedd) + size(Fep2))) / std::abs(in.tau);
  return std::isfinite(out.b);
}

bool reduce(const BoundProblem &problem, Algebra &algebra, ConstVectorRef u0, double lambdaC,
            ConstVectorRef parentTangent, ConstVectorRef v0, ConstVectorRef c, BranchPointCoefficients &out,
            std::string *why) {
  const int n = problem.dimension();
  const double cv = c.dot(v0);
  if (!(std::abs(cv) > 0.0) || !std::isfinite(cv))
    return fail(why, "branch-point coefficients: the normalisation c is orthogonal to v");
  const ProblemScales s = problem.scales();
  const double tl = parentTangent[n];
  // the parent's slope in the scaled variables: a vertical parent (a fold) has no u_p(λ)
  if (!(std::abs(tl) / s.parameter > 1e-8 * parentTangent.head(n).cwiseQuotient(s.unknowns).norm()))
    return fail(why, "branch-point coefficients: the parent branch is vertical at the point (also a fold)");
  Vector Fl;
  if (!algebra.linearise(Fl)) return fail(why, "branch-point coefficients: the problem refused (u0, λc)");

  // ψ from [[F_uᵀ, c], [v̂ᵀ, 0]] [ψ; σ] = [0; 1]: ψᵀF_u = 0 at the branch point
  const Vector cc = c;
  const Vector vHat = v0 / cv;
  Vector sol;
  if (!algebra.leftNull(cc, vHat, sol) || !sol.head(n).allFinite())
    return fail(why, "branch-point coefficients: the null space of F_u is not one-dimensional");
  Vector psi = sol.head(n);
  // F_uᵀψ = −c·σ: σ is the distance from singularity (0 at the branch point)
  if (std::abs(sol[n]) * c.norm() > 1e-6 * algebra.jacobianSize() * psi.norm())
    return fail(why, "branch-point coefficients: F_u is not singular at λc (not a branch point)");

  // one bordered matrix [[F_u, ψ], [cᵀ, 0]] for every solve with F_u (cᵀx = 0 fixes the null part)
  if (!algebra.factorBordered(psi, cc)) return fail(why, "branch-point coefficients: singular bordered system");
  Vector r = Vector::Zero(n + 1), x(n + 1);
  auto solve = [&](const Vector &right, Vector &result) {
    r.head(n) = right;
    r[n] = 0.0;
    if (!algebra.solve(r, x)) return false;
    result = x.head(n);
    return true;
  };
  // the null vector itself, refined: F_u v ∝ ψ-residual only, cᵀv = 1
  r.setZero();
  r[n] = 1.0;
  if (!algebra.solve(r, x)) return fail(why, "branch-point coefficients: singular bordered system");
  const Vector v = x.head(n);
  psi /= psi.dot(v);
  if (!v.allFinite() || !psi.allFinite()) return fail(why, "branch-point coefficients: singular bordered system");

  // p1 = p1⊥ + κv: F_u p1⊥ = −F_λ (in range: ψᵀF_λ = 0 at a branch point), κ a root of the ABE
  // ψᵀF_xx[d, d] = P⊥⊥ + 2κP⊥e + κ²Pee = 0 (its two roots are the two branches' slopes)
  const std::string noSecond = "branch-point coefficients: no second derivatives at (u0, λc)";
  const Vector uc = u0;
  Vector p1Perp;
  if (!solve(-Fl, p1Perp)) return fail(why, "branch-point coefficients: singular bordered system");
  const Vector e = extended(v, 0.0), dPerp = extended(p1Perp, 1.0);
  Vector Fee, FePerp, FperpPerp;
  if (!algebra.second(uc, lambdaC, e, e, Fee) || !algebra.second(uc, lambdaC, e, dPerp, FePerp) ||
      !algebra.second(uc, lambdaC, dPerp, dPerp, FperpPerp))
    return fail(why, noSecond);
  const double Pee = psi.dot(Fee);
  const double PperpE = psi.dot(FePerp);
  const double PperpPerp = psi.dot(FperpPerp);
  const double kappaGiven = c.dot(parentTangent.head(n)) / tl;
  const double disc = PperpE * PperpE - Pee * PperpPerp;
  const double q = -(PperpE + std::copysign(std::sqrt(std::max(disc, 0.0)), PperpE));
  double kappa = kappaGiven, best = std::numeric_limits<double>::infinity();
  for (double root : {q / Pee, PperpPerp / q})
    if (std::isfinite(root) && std::abs(root - kappaGiven) < best) {
      best = std::abs(root - kappaGiven);
      kappa = root;
    }
  const Vector p1 = p1Perp + kappa * v;
  const Vector dv = extended(p1, 1.0);

  // transversality τ = ψᵀF_xx[e, d] against its own size in the scaled variables
  const double tau = PperpE + kappa * Pee;
  const double tScale = psi.cwiseProduct(s.residuals).norm() * v.cwiseQuotient(s.unknowns).norm() / s.parameter;
  if (!(std::abs(tau) > 1e-10 * tScale))
    return fail(why, "branch-point coefficients: the zero eigenvalue does not cross transversally (ψᵀF_xx[e, d] = 0)");
  const double a = -0.5 * Pee / tau;

  // second derivatives at the point along e and d
  Vector Fed, Fdd;
  if (!algebra.second(uc, lambdaC, e, dv, Fed) || !algebra.second(uc, lambdaC, dv, dv, Fdd))
    return fail(why, noSecond);
  Vector u2, p2Perp;
  if (!solve(-(a * Fed + 0.5 * Fee), u2) || !solve(-Fdd, p2Perp) || !u2.allFinite() || !p2Perp.allFinite())
    return fail(why, "branch-point coefficients: singular bordered system for u2");

  // third order: b at the difference step h, and at 2h and h/2: the spread of the three bounds
  // the differences' error (truncation, which grows with the step, and rounding, which falls
  // with it; one pair alone can agree by chance), in any units
  ThirdOrder third, coarse, fine;
  const ThirdOrderInput in{algebra, u0, lambdaC, s, e, dv, v, psi, p1, p2Perp, u2, a, tau};
  if (!thirdOrder(in, 1.0, third) || !thirdOrder(in, 2.0, coarse) || !thirdOrder(in, 0.5, fine))
    return fail(why, "branch-point coefficients: the problem refused a point near (u0, λc)");
  const double b = third.b;
  if (!std::isfinite(a) || !std::isfinite(b)) return fail(why, "branch-point coefficients: not finite");
  // b's accuracy: a b that cancels to zero keeps the rounding of its terms (64ε for the sums and
  // the bordered solves) and the third derivatives' error, bounded by the two steps' difference
  out.bScale = third.scale;
  out.bAccuracy = out.bScale * 64.0 * std::numeric_limits<double>::epsilon() +
                  2.0 * std::max(std::abs(coarse.b - b), std::abs(fine.b - b));
  const Vector &p2 = third.p2;

  // the ABE in the orthonormal basis t = d/|d|, φ ⊥ t of ker F_x (Euclidean in (u, λ))
  Vector d = dv;
  if (d.dot(parentTangent) < 0.0) d = -d;  // t along the parent's orientation
  const double nd = d.norm(), gamma = e.dot(d) / nd;
  const double nphi = (e - gamma * d / nd).norm();
  const double sd = d[n];  // ±1: the sign d was given
  const double Pdd = psi.dot(Fdd), Pde = sd * tau;
  out.a11 = Pdd / (nd * nd);
  out.a12 = (Pde / nd - gamma * Pdd / (nd * nd)) / nphi;
  out.a22 = (Pee - 2.0 * gamma * Pde / nd + gamma * gamma * Pdd / (nd * nd)) / (nphi * nphi);
  Vector child = Vector::Zero(n + 1);
  child.head(n) = v + a * p1;
  child[n] = a;
  out.childTangent = child / child.norm();
  out.a = a;
  out.b = b;
  out.transversality = tau;
  out.v = v;
  out.psi = psi;
  out.parentSlope = p1;
  out.parentCurvature = p2;
  out.u2 = u2;
  return true;
}

/// The reduction in the problem's scaled variables (scaled_problem.h), its results in the user's:
/// with u = D_u ũ, λ = λ₀λ̃, F = D_F F̃ and ξ = cᵀ(u − u_p) = (D_u c)ᵀ(ũ − ũ_p) the same amplitude,
///   a = λ₀ã, b = λ₀b̃, v = D_u ṽ, p1 = D_u p̃1/λ₀, p2 = D_u p̃2/λ₀², u2 = D_u ũ2,
///   ψ = D_F⁻¹ψ̃/ν and τ = τ̃/(νλ₀) with ν = (D_F⁻¹ψ̃)ᵀv (so that ψᵀv = 1).
/// Differences, solves and thresholds then act on O(1) quantities in every unit system: in the
/// user's variables a chain in lengths of 1e−4 mixes rows and unknowns 1e4 apart, and the third
/// derivatives lose four digits more than their estimate.
bool scaledReduction(const BoundProblem &problem, const ProblemScales &s, ConstVectorRef u0, double lambdaC,
                     ConstVectorRef parentTangent, ConstVectorRef v0, ConstVectorRef c, BranchPointCoefficients &out,
                     std::string *why, CoefficientAlgebra algebra) {
  const UnitScaling units(s);
  const BoundScaledProblem scaledProblem(problem, units);
  const BoundProblem &scaled = scaledProblem.bound();
  const Vector &Du = s.unknowns;
  const double l0 = s.parameter;
  BranchPointCoefficients g;
  if (!branchPointCoefficients(scaled, u0.cwiseQuotient(Du), lambdaC / l0, units.directionToScaled(parentTangent),
                               v0.cwiseQuotient(Du), c.cwiseProduct(Du), g, why, algebra))
    return false;
  out = g;
  out.a = l0 * g.a;
  out.b = l0 * g.b;
  out.bScale = l0 * g.bScale;
  out.bAccuracy = l0 * g.bAccuracy;
  out.v = g.v.cwiseProduct(Du);
  const Vector psi = g.psi.cwiseQuotient(s.residuals);
  const double nu = psi.dot(out.v);
  if (!(std::abs(nu) > 0.0) || !std::isfinite(nu))
    return fail(why, "branch-point coefficients: the left null vector is orthogonal to v in the user's units");
  out.psi = psi / nu;
  out.transversality = g.transversality / (nu * l0);
  out.parentSlope = g.parentSlope.cwiseProduct(Du) / l0;
  out.parentCurvature = g.parentCurvature.cwiseProduct(Du) / (l0 * l0);
  out.u2 = g.u2.cwiseProduct(Du);
  out.childTangent = units.directionToUser(g.childTangent);
  return true;
}

}  // namespace

bool branchPointCoefficients(const BoundProblem &problem, ConstVectorRef u0, double lambdaC,
                             ConstVectorRef parentTangent, ConstVectorRef v0, ConstVectorRef c,
                             BranchPointCoefficients &out, std::string *why, CoefficientAlgebra algebra) {
  const int n = problem.dimension();
  if (u0.size() != n || v0.size() != n || c.size() != n || parentTangent.size() != n + 1)
    return fail(why, "branch-point coefficients: u0, v and c must have the problem's dimension " + std::to_string(n) +
                         ", the parent tangent " + std::to_string(n + 1));
  const ProblemScales s = problem.scales();
  if (!s.identity()) return scaledReduction(problem, s, u0, lambdaC, parentTangent, v0, c, out, why, algebra);
  std::unique_ptr<BorderedSolver> solver;
  if (algebra == CoefficientAlgebra::Structured ||
      (algebra == CoefficientAlgebra::Automatic && n > kDenseCoefficientDimension)) {
    solver = problem.makeStructuredSolver();
    if (solver && solver->maxGeneralBorder() < 1) solver.reset();
    if (!solver && algebra == CoefficientAlgebra::Structured)
      return fail(why, "branch-point coefficients: the problem has no structured solver with general borders");
  }
  if (!solver) {
    DenseAlgebra dense(problem, u0, lambdaC);
    return reduce(problem, dense, u0, lambdaC, parentTangent, v0, c, out, why);
  }
  StructuredAlgebra structured(problem, std::move(solver), u0, lambdaC);
  if (reduce(problem, structured, u0, lambdaC, parentTangent, v0, c, out, why)) return true;
  if (why) *why += " (structured algebra)";
  return false;
}

bool foldCoefficient(const BoundProblem &problem, const SpecialPoint &fold, FoldCoefficient &out, std::string *why) {
  const int n = problem.dimension();
  if (fold.type != SpecialPointType::Fold || fold.u.size() != n || fold.nullVectors.rows() != n ||
      fold.nullVectors.cols() != 1)
    return fail(why, "fold coefficient: not a located fold of this problem");
  const Vector v = fold.nullVectors.col(0).normalized();
  std::unique_ptr<BorderedSolver> solver;
  if (n > kDenseCoefficientDimension) {
    solver = problem.makeStructuredSolver();
    if (solver && solver->maxGeneralBorder() < 1) solver.reset();
  }
  std::unique_ptr<Algebra> algebra;
  if (solver) algebra = std::make_unique<StructuredAlgebra>(problem, std::move(solver), fold.u, fold.lambda);
  else algebra = std::make_unique<DenseAlgebra>(problem, fold.u, fold.lambda);
  Vector Fl, sol, Fvv;
  if (!algebra->linearise(Fl)) return fail(why, "fold coefficient: the problem refused the point");
  if (!algebra->leftNull(v, v, sol) || !sol.head(n).allFinite())
    return fail(why, "fold coefficient: the null space of F_u is not one-dimensional");
  const Vector psi = sol.head(n);
  const Vector e = extended(v, 0.0);
  if (!algebra->second(fold.u, fold.lambda, e, e, Fvv)) return fail(why, "fold coefficient: no second derivatives");
  // λ(s) = λ0 + ½λ''s² + … with u = u0 + s v: ψᵀ(F_uu[v, v] + λ''F_λ) = 0
  const double psiFl = psi.dot(Fl);
  if (!(std::abs(psiFl) > 0.0)) return fail(why, "fold coefficient: ψᵀF_λ = 0 (a branch point, not a fold)");
  out.curvature = -psi.dot(Fvv) / psiFl;
  // the terms' rounding, and their move with the point's location error (relative to λ's scale)
  const double eps = std::numeric_limits<double>::epsilon();
  const double lambdaScale = std::max(problem.scales().parameter, std::abs(fold.lambda));
  const double located = std::isfinite(fold.lambdaAccuracy) ? fold.lambdaAccuracy / lambdaScale : 0.0;
  out.scale = psi.cwiseAbs().dot(Fvv.cwiseAbs()) / std::abs(psiFl);
  out.accuracy = out.scale * (64.0 * eps + located);
  out.cusp = std::abs(out.curvature) <= out.accuracy;
  return std::isfinite(out.curvature);
}

bool branchPointCoefficients(const BoundProblem &problem, const SpecialPoint &bp, ConstVectorRef c,
                             BranchPointCoefficients &out, std::string *why, CoefficientAlgebra algebra) {
  const int n = problem.dimension();
  if (bp.type != SpecialPointType::BranchPoint || bp.u.size() != n || bp.tangent.size() != n + 1 ||
      bp.nullVectors.rows() != n + 1 || bp.nullVectors.cols() != 2)
    return fail(why, "branch-point coefficients: not a located simple branch point of this problem");
  // the combination of ker F_x = span{t, φ} with no λ-component is the null vector of F_u
  const Vector t = bp.nullVectors.col(0), phi = bp.nullVectors.col(1);
  const Vector v = t[n] * phi.head(n) - phi[n] * t.head(n);
  if (!branchPointCoefficients(problem, bp.u, bp.lambda, bp.tangent, v, c, out, why, algebra)) return false;
  // the point's location error moves every term of b by its relative size (λ's own scale)
  const double lambdaScale = std::max(problem.scales().parameter, std::abs(bp.lambda));
  if (std::isfinite(bp.lambdaAccuracy)) out.bAccuracy += out.bScale * bp.lambdaAccuracy / lambdaScale;
  return true;
}

}  // namespace buckle::continuation
