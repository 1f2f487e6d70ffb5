#include "buckle/continuation/bifurcation_coefficients.h"

#include "buckle/continuation/branch_point_coefficients.h"

namespace buckle::continuation {

bool bifurcationCoefficients(const BoundProblem &problem, ConstVectorRef u0, double lambdaC, ConstVectorRef v,
                             ConstVectorRef c, BifurcationCoefficients &out, std::string *why) {
  // the trivial branch is the parent with tangent (0, 1): p1 = p2 = 0 (branch_point_coefficients.h)
  const int n = problem.dimension();
  if (u0.size() != n || v.size() != n || c.size() != n) {
    if (why) *why = "bifurcation coefficients: u0, v and c must have the problem's dimension " + std::to_string(n);
    return false;
  }
  Vector trivial = Vector::Zero(n + 1);
  trivial[n] = 1.0;
  BranchPointCoefficients g;
  if (!branchPointCoefficients(problem, u0, lambdaC, trivial, v, c, g, why)) return false;
  out.a = g.a;
  out.b = g.b;
  out.transversality = g.transversality;
  out.v = g.v;
  out.psi = g.psi;
  out.u2 = g.u2;
  return true;
}

}  // namespace buckle::continuation
