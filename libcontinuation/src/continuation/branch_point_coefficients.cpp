#include "buckle/continuation/branch_point_coefficients.h"

#include <Eigen/LU>
#include <cmath>
#include <limits>

namespace buckle::continuation {

namespace {
bool fail(std::string *why, const std::string &reason) {
  if (why) *why = reason;
  return false;
}

/// The exact second derivatives F_xx[e, e], F_xx[e, d], F_xx[d, d] (e = (v, 0), d = (p1, 1)) at
/// x0 + ε·w, and their derivatives along w by central differences (the third derivatives).
class SecondDerivatives {
 public:
  SecondDerivatives(Problem &problem, ConstVectorRef u0, double lambda, const Vector &v, const Vector &p1)
      : problem_(problem), u0_(u0), lambda_(lambda), v_(v), p1_(p1), D_(v.size(), v.size()), Dl_(v.size()) {}

  /// At x0 + ε(wu, wl): ee = F_xx[e, e], ed = F_xx[e, d], dd = F_xx[d, d] (dd only when asked).
  bool at(double eps, const Vector &wu, double wl, Vector &ee, Vector &ed, Vector *dd) {
    u_ = u0_ + eps * wu;
    const double l = lambda_ + eps * wl;
    if (!problem_.jacobianDirectionalDerivative(u_, l, v_, 0.0, D_, Dl_)) return false;
    ee.noalias() = D_ * v_;
    ed.noalias() = D_ * p1_;
    ed += Dl_;
    if (!dd) return true;
    if (!problem_.jacobianDirectionalDerivative(u_, l, p1_, 1.0, D_, Dl_)) return false;
    dd->noalias() = D_ * p1_;
    *dd += Dl_;
    return true;
  }

  /// d/dε of (F_xx[e, e], F_xx[e, d], F_xx[d, d]) at ε = 0 along h·(wu, wl): central differences
  /// at ±h and ±h/2, one Richardson step (error O(h⁴)), divided by h.
  bool along(double h, const Vector &wu, double wl, Vector &dee, Vector &ded, Vector *ddd) {
    const double t[4] = {h, -h, 0.5 * h, -0.5 * h};
    Vector ee[4], ed[4], dd[4];
    for (int k = 0; k < 4; ++k)
      if (!at(t[k], wu, wl, ee[k], ed[k], ddd ? &dd[k] : nullptr)) return false;
    auto richardson = [h](const Vector *f) -> Vector {
      return (4.0 * (f[2] - f[3]) - 0.5 * (f[0] - f[1])) / (3.0 * h);
    };
    dee = richardson(ee);
    ded = richardson(ed);
    if (ddd) *ddd = richardson(dd);
    return true;
  }

 private:
  Problem &problem_;
  ConstVectorRef u0_;
  double lambda_;
  const Vector &v_, &p1_;
  Matrix D_;
  Vector Dl_, u_;
};
}  // namespace

bool branchPointCoefficients(Problem &problem, ConstVectorRef u0, double lambdaC, ConstVectorRef parentTangent,
                             ConstVectorRef v0, ConstVectorRef c, BranchPointCoefficients &out, std::string *why) {
  const int n = problem.dimension();
  if (u0.size() != n || v0.size() != n || c.size() != n || parentTangent.size() != n + 1)
    return fail(why, "branch-point coefficients: u0, v and c must have the problem's dimension " + std::to_string(n) +
                         ", the parent tangent " + std::to_string(n + 1));
  const double cv = c.dot(v0);
  if (!(std::abs(cv) > 0.0) || !std::isfinite(cv))
    return fail(why, "branch-point coefficients: the normalisation c is orthogonal to v");
  const ProblemScales s = problem.scales();
  const double tl = parentTangent[n];
  // the parent's slope in the scaled variables: a vertical parent (a fold) has no u_p(λ)
  if (!(std::abs(tl) / s.parameter > 1e-8 * parentTangent.head(n).cwiseQuotient(s.unknowns).norm()))
    return fail(why, "branch-point coefficients: the parent branch is vertical at the point (also a fold)");
  Matrix Fu(n, n), D(n, n), Dd(n, n);
  Vector Fl(n), Dl(n), Dld(n);
  if (!problem.jacobian(u0, lambdaC, Fu, Fl))
    return fail(why, "branch-point coefficients: the problem refused (u0, λc)");

  // ψ from [[F_uᵀ, c], [v̂ᵀ, 0]] [ψ; σ] = [0; 1]: ψᵀF_u = 0 at the branch point
  const Vector vHat = v0 / cv;
  Matrix A = Matrix::Zero(n + 1, n + 1);
  A.topLeftCorner(n, n) = Fu.transpose();
  A.block(0, n, n, 1) = c;
  A.block(n, 0, 1, n) = vHat.transpose();
  Vector rhs = Vector::Zero(n + 1);
  rhs[n] = 1.0;
  const Vector sol = Eigen::PartialPivLU<Matrix>(A).solve(rhs);
  Vector psi = sol.head(n);
  if (!psi.allFinite()) return fail(why, "branch-point coefficients: the null space of F_u is not one-dimensional");
  // F_uᵀψ = −c·σ: σ is the distance from singularity (0 at the branch point)
  if (std::abs(sol[n]) * c.norm() > 1e-6 * Fu.norm() * psi.norm())
    return fail(why, "branch-point coefficients: F_u is not singular at λc (not a branch point)");

  // one bordered matrix [[F_u, ψ], [cᵀ, 0]] for every solve with F_u (cᵀx = 0 fixes the null part)
  Matrix B = Matrix::Zero(n + 1, n + 1);
  B.topLeftCorner(n, n) = Fu;
  B.block(0, n, n, 1) = psi;
  B.block(n, 0, 1, n) = c.transpose();
  const Eigen::PartialPivLU<Matrix> lu(B);
  Vector r = Vector::Zero(n + 1);
  auto solve = [&](const Vector &right) -> Vector {
    r.head(n) = right;
    r[n] = 0.0;
    return lu.solve(r).head(n);
  };
  // the null vector itself, refined: F_u v ∝ ψ-residual only, cᵀv = 1
  r.setZero();
  r[n] = 1.0;
  const Vector v = lu.solve(r).head(n);
  psi /= psi.dot(v);
  if (!v.allFinite() || !psi.allFinite()) return fail(why, "branch-point coefficients: singular bordered system");

  // p1 = p1⊥ + κv: F_u p1⊥ = −F_λ (in range: ψᵀF_λ = 0 at a branch point), κ a root of the ABE
  // ψᵀF_xx[d, d] = P⊥⊥ + 2κP⊥e + κ²Pee = 0 (its two roots are the two branches' slopes)
  const Vector p1Perp = solve(-Fl);
  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, v, 0.0, D, Dl))
    return fail(why, "branch-point coefficients: no second derivatives at (u0, λc)");
  const Vector Fee = D * v;
  const double Pee = psi.dot(Fee);
  const double PperpE = psi.dot(D * p1Perp + Dl);
  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, p1Perp, 1.0, Dd, Dld))
    return fail(why, "branch-point coefficients: no second derivatives at (u0, λc)");
  const double PperpPerp = psi.dot(Dd * p1Perp + Dld);
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

  // transversality τ = ψᵀF_xx[e, d] against its own size in the scaled variables
  const double tau = PperpE + kappa * Pee;
  const double tScale = psi.cwiseProduct(s.residuals).norm() * v.cwiseQuotient(s.unknowns).norm() / s.parameter;
  if (!(std::abs(tau) > 1e-10 * tScale))
    return fail(why, "branch-point coefficients: the zero eigenvalue does not cross transversally (ψᵀF_xx[e, d] = 0)");
  const double a = -0.5 * Pee / tau;

  // second derivatives at the point: D = F_xx[e, ·], Dd = F_xx[d, ·] (u-columns)
  if (!problem.jacobianDirectionalDerivative(u0, lambdaC, p1, 1.0, Dd, Dld))
    return fail(why, "branch-point coefficients: no second derivatives at (u0, λc)");
  const Vector Fed = D * p1 + Dl;
  const Vector Fdd = Dd * p1 + Dld;
  const Vector u2 = solve(-(a * Fed + 0.5 * Fee));
  const Vector p2Perp = solve(-Fdd);
  if (!u2.allFinite() || !p2Perp.allFinite())
    return fail(why, "branch-point coefficients: singular bordered system for u2");

  // third derivatives D³F[e,e,e] along e; D³F[e,e,d], D³F[e,d,d], D³F[d,d,d] along d
  SecondDerivatives second(problem, u0, lambdaC, v, p1);
  const double pScaled = s.parameter * p1.cwiseQuotient(s.unknowns).norm();
  const double hu = 1e-3 / v.cwiseQuotient(s.unknowns).norm();
  const double hd = 1e-3 * std::max(s.parameter, std::abs(lambdaC)) / std::sqrt(1.0 + pScaled * pScaled);
  const Vector zero = Vector::Zero(n);
  Vector Teee, unused, Teed, Tedd, Tddd;
  if (!second.along(hu, v, 0.0, Teee, unused, nullptr) || !second.along(hd, p1, 1.0, Teed, Tedd, &Tddd))
    return fail(why, "branch-point coefficients: the problem refused a point near (u0, λc)");

  // p2's component along v from ψᵀ(D³F[d,d,d] + 3F_xx[d, (p2, 0)]) = 0
  const double sigma = -(psi.dot(Tddd) + 3.0 * psi.dot(Dd * p2Perp)) / (3.0 * tau);
  const Vector p2 = p2Perp + sigma * v;
  const Vector third =
      a * (Dd * u2) + D * u2 + Teee / 6.0 + 0.5 * a * Teed + 0.5 * a * a * (Tedd + D * p2);
  const double b = -psi.dot(third) / tau;
  if (!std::isfinite(a) || !std::isfinite(b)) return fail(why, "branch-point coefficients: not finite");

  // the ABE in the orthonormal basis t = d/|d|, φ ⊥ t of ker F_x (Euclidean in (u, λ))
  Vector d(n + 1), e = Vector::Zero(n + 1);
  d << p1, 1.0;
  e.head(n) = v;
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

bool branchPointCoefficients(Problem &problem, const SpecialPoint &bp, ConstVectorRef c, BranchPointCoefficients &out,
                             std::string *why) {
  const int n = problem.dimension();
  if (bp.type != SpecialPointType::BranchPoint || bp.u.size() != n || bp.tangent.size() != n + 1 ||
      bp.nullVectors.rows() != n + 1 || bp.nullVectors.cols() != 2)
    return fail(why, "branch-point coefficients: not a located simple branch point of this problem");
  // the combination of ker F_x = span{t, φ} with no λ-component is the null vector of F_u
  const Vector t = bp.nullVectors.col(0), phi = bp.nullVectors.col(1);
  const Vector v = t[n] * phi.head(n) - phi[n] * t.head(n);
  return branchPointCoefficients(problem, bp.u, bp.lambda, bp.tangent, v, c, out, why);
}

}  // namespace buckle::continuation
