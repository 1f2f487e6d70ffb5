#include "buckle/continuation/bifurcation_coefficients.h"

#include <Eigen/LU>
#include <cmath>
#include <limits>

namespace buckle::continuation {

namespace {
bool fail(std::string *why, const std::string &reason) {
  if (why) *why = reason;
  return false;
}

// The exact second derivatives along v at (u0 + εv, λ + δ): F_uu[v, v] and F_uλ v.
struct SecondDerivatives {
  Problem &problem;
  ConstVectorRef u0;
  double lambda;
  const Vector &v;
  Matrix D;
  Vector Dl, u;

  bool at(double eps, double delta, Vector &Fvv, Vector &Flv) {
    u = u0 + eps * v;
    if (!problem.jacobianDirectionalDerivative(u, lambda + delta, v, 0.0, D, Dl)) return false;
    Fvv.noalias() = D * v;
    Flv = Dl;
    return true;
  }
  // d/dt of (F_uu[v, v], F_uλ v) along (ε, δ) = t·(hu, hl): central differences at t = ±1 and
  // ±½, combined by one Richardson step (error O(h⁴)).
  bool derivative(double hu, double hl, Vector &dFvv, Vector &dFlv) {
    Vector pp, pl, mp, ml, hp, hlp, hm, hlm;
    if (!at(hu, hl, pp, pl) || !at(-hu, -hl, mp, ml) || !at(0.5 * hu, 0.5 * hl, hp, hlp) ||
        !at(-0.5 * hu, -0.5 * hl, hm, hlm))
      return false;
    dFvv = (4.0 * (hp - hm) - 0.5 * (pp - mp)) / 3.0;  // (4·D(½) − D(1))/3 with D(h) = (f(h) − f(−h))/2h, h = 1
    dFlv = (4.0 * (hlp - hlm) - 0.5 * (pl - ml)) / 3.0;
    return true;
  }
};
}  // namespace

bool bifurcationCoefficients(Problem &problem, ConstVectorRef u0, double lambdaC, ConstVectorRef v0, ConstVectorRef c,
                             BifurcationCoefficients &out, std::string *why) {
  const int n = problem.dimension();
  if (u0.size() != n || v0.size() != n || c.size() != n)
    return fail(why, "bifurcation coefficients: u0, v and c must have the problem's dimension " + std::to_string(n));
  const double cv = c.dot(v0);
  if (!(std::abs(cv) > 0.0) || !std::isfinite(cv))
    return fail(why, "bifurcation coefficients: the normalisation c is orthogonal to v");
  const ProblemScales s = problem.scales();
  const Vector v = v0 / cv;
  Matrix Fu(n, n), D(n, n);
  Vector Fl(n), Dl(n);
  if (!problem.jacobian(u0, lambdaC, Fu, Fl)) return fail(why, "bifurcation coefficients: the problem refused (u0, λc)");

  // ψ from [[F_uᵀ, c], [vᵀ, 0]] [ψ; s] = [0; 1]: ψᵀF_u = 0 at the branch point, ψᵀv = 1
  Matrix A = Matrix::Zero(n + 1, n + 1);
  A.topLeftCorner(n, n) = Fu.transpose();
  A.block(0, n, n, 1) = c;
  A.block(n, 0, 1, n) = v.transpose();
  Eigen::PartialPivLU<Matrix> lu(A);
  Vector rhs = Vector::Zero(n + 1);
  rhs[n] = 1.0;
  const Vector sol = lu.solve(rhs);
  const Vector psi = sol.head(n);
  if (!psi.allFinite()) return fail(why, "bifurcation coefficients: the null space of F_u is not one-dimensional");
  // F_uᵀψ = −c·s: s is the distance from singularity (0 at the branch point)
  if (std::abs(sol[n]) * c.norm() > 1e-6 * Fu.norm() * psi.norm())
    return fail(why, "bifurcation coefficients: F_u is not singular at λc (not a branch point)");

  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, v, 0.0, D, Dl))
    return fail(why, "bifurcation coefficients: no second derivatives at (u0, λc)");
  const Vector Fvv = D * v;  // F_uu[v, v]
  const Vector Flv = Dl;     // F_uλ v
  const double t = psi.dot(Flv);
  // ψᵀF_uλ v against its own size in the scaled variables: ψ̃ = D_F ψ, ṽ = D_u⁻¹ v, λ̃ = λ/λ₀
  const double tScale = psi.cwiseProduct(s.residuals).norm() * v.cwiseQuotient(s.unknowns).norm() / s.parameter;
  if (!(std::abs(t) > 1e-10 * tScale))
    return fail(why, "bifurcation coefficients: the zero eigenvalue does not cross transversally (ψᵀF_uλ v = 0)");
  const double a = -0.5 * psi.dot(Fvv) / t;

  // u2: [[F_u, ψ], [cᵀ, 0]] [u2; σ] = [−(a F_uλ v + ½F_uu[v, v]); 0] (σ = 0: the right side is in range F_u)
  Matrix B = Matrix::Zero(n + 1, n + 1);
  B.topLeftCorner(n, n) = Fu;
  B.block(0, n, n, 1) = psi;
  B.block(n, 0, 1, n) = c.transpose();
  Vector r2 = Vector::Zero(n + 1);
  r2.head(n) = -(a * Flv + 0.5 * Fvv);
  const Vector u2 = Eigen::PartialPivLU<Matrix>(B).solve(r2).head(n);
  if (!u2.allFinite()) return fail(why, "bifurcation coefficients: singular bordered system for u2");

  // third derivatives: along u (F_uuu[v, v, v]) and along λ (F_uuλ[v, v], F_uλλ v)
  SecondDerivatives second{problem, u0, lambdaC, v, Matrix(n, n), Vector(n), Vector(n)};
  const double hu = 1e-3 / v.cwiseQuotient(s.unknowns).norm();
  const double hl = 1e-3 * std::max(s.parameter, std::abs(lambdaC));
  Vector Fvvv, unused, Fvvl, Fvll;
  if (!second.derivative(hu, 0.0, Fvvv, unused) || !second.derivative(0.0, hl, Fvvl, Fvll))
    return fail(why, "bifurcation coefficients: the problem refused a point near (u0, λc)");
  Fvvv /= hu;
  Fvvl /= hl;
  Fvll /= hl;

  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, u2, 0.0, D, Dl))
    return fail(why, "bifurcation coefficients: no second derivatives at (u0, λc)");
  const Vector Flu2 = Dl;  // F_uλ u2
  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, v, 0.0, D, Dl))
    return fail(why, "bifurcation coefficients: no second derivatives at (u0, λc)");
  const Vector Fvu2 = D * u2;  // F_uu[v, u2]
  const Vector third = a * Flu2 + Fvu2 + Fvvv / 6.0 + 0.5 * a * Fvvl + 0.5 * a * a * Fvll;
  out.a = a;
  out.b = -psi.dot(third) / t;
  out.transversality = t;
  out.v = v;
  out.psi = psi;
  out.u2 = u2;
  return std::isfinite(out.b) ? true : fail(why, "bifurcation coefficients: not finite");
}

}  // namespace buckle::continuation
