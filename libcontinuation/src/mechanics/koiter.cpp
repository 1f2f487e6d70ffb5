#include "buckle/mechanics/koiter.h"

#include <cmath>
#include <string>

#include "buckle/continuation/branch_point_coefficients.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* toString(KoiterKind kind) {
  switch (kind) {
    case KoiterKind::Supercritical: return "supercritical";
    case KoiterKind::Subcritical: return "subcritical";
    case KoiterKind::Asymmetric: return "asymmetric";
  }
  return "?";
}

std::string postBucklingName(const KoiterCoefficients& k) {
  if (!k.degenerate) return toString(k.kind);
  if (!k.decided) return "degenerate (undecided)";
  return std::string("degenerate ") + toString(k.kind);
}

namespace {

// b = 0 to its accuracy: the quartic term of the child decides (same rule, c₄ for b).
void classifyDegenerate(EquilibriumProblem& problem, const cont::SpecialPoint& bp, const Eigen::VectorXd& c,
                        const cont::BranchPointCoefficients& g, KoiterCoefficients& k) {
  k.degenerate = true;
  k.decided = false;
  cont::ChildBranchExpansion ex;
  std::string why;
  if (!cont::childBranchExpansion(problem, bp.u, bp.lambda, g, c, ex, &why)) {
    k.message = "degenerate pitchfork (|b| below its accuracy); " + why;
    return;
  }
  k.c4 = ex.c4;
  k.c4Accuracy = ex.c4Accuracy;
  if (std::abs(ex.c4) <= ex.c4Accuracy) return;
  k.decided = true;
  k.kind = ex.c4 * k.transversality < 0.0 ? KoiterKind::Supercritical : KoiterKind::Subcritical;
}

}  // namespace

KoiterCoefficients koiterCoefficients(EquilibriumProblem& problem, const cont::SpecialPoint& bp,
                                      cont::CoefficientAlgebra algebra) {
  KoiterCoefficients k;
  const int N = problem.dimension(), n = problem.segments();
  if (bp.type != cont::SpecialPointType::BranchPoint || bp.nullVectors.rows() != N + 1 || bp.nullVectors.cols() != 2) {
    k.message = "Koiter coefficients: not a located simple branch point";
    return k;
  }
  // the joint part of ker F_u (the λ-free combination of ker F_x), unit, largest entry positive
  const Eigen::VectorXd t = bp.nullVectors.col(0), phi = bp.nullVectors.col(1);
  Eigen::VectorXd m = (t[N] * phi.head(N) - phi[N] * t.head(N)).head(n);
  if (!(m.norm() > 0.0) || !m.allFinite()) {
    k.message = "Koiter coefficients: the null vector has no joint part";
    return k;
  }
  Eigen::Index big = 0;
  m.cwiseAbs().maxCoeff(&big);
  m *= (m[big] < 0.0 ? -1.0 : 1.0) / m.norm();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(N);
  c.head(n) = m;
  cont::BranchPointCoefficients g;
  if (!cont::branchPointCoefficients(problem, bp, c, g, &k.message, algebra)) {
    // A branch point reached along a bifurcated branch, at its tip (the traced branch turns in λ
    // there, touching the other without crossing it): the coefficients are the pitchfork's, with
    // the other branch through the point, the one that is not vertical, as the parent.
    const double tl = std::abs(bp.tangent.size() == N + 1 ? bp.tangent[N] : 1.0);
    if (!(tl <= 1e-6 * bp.tangent.norm()) || !(std::abs(phi[N]) > 1e-6 * phi.norm())) return k;
    cont::SpecialPoint other = bp;
    other.nullVectors.col(0) = phi;
    other.nullVectors.col(1) = t;
    other.tangent = phi;
    std::string why;
    if (!cont::branchPointCoefficients(problem, other, c, g, &why, algebra)) return k;
    k.message.clear();
    k.parentIsOther = true;
  }
  k.valid = true;
  k.lambda = bp.lambda;
  k.a = g.a;
  k.b = g.b;
  k.transversality = g.transversality;
  k.bAccuracy = g.bAccuracy;
  k.mode = g.v.head(n) / g.v.head(n).norm();
  k.v = g.v;
  k.psi = g.psi;
  k.parentSlope = g.parentSlope;
  // a is zero by symmetry at a symmetric point; its rounding is relative to b times the
  // amplitude's unit (1 rad) and λ's own scale
  const double lambdaScale = std::max(problem.scales().parameter, std::abs(bp.lambda));
  if (std::abs(k.a) > 1e-8 * std::max(lambdaScale, std::abs(k.b)))
    k.kind = KoiterKind::Asymmetric;
  else
    k.kind = k.b * k.transversality < 0.0 ? KoiterKind::Supercritical : KoiterKind::Subcritical;
  if (k.kind != KoiterKind::Asymmetric && std::abs(k.b) <= k.bAccuracy) classifyDegenerate(problem, bp, c, g, k);
  return k;
}

}  // namespace buckle::mechanics
