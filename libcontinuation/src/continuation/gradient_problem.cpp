#include "buckle/continuation/gradient_problem.h"

namespace buckle::continuation {

bool GradientProblem::stabilityOperator(ProblemWorkspace &ws, ConstVectorRef u, double lambda, Matrix &H,
                                        Matrix &C) const {
  const int n = dimension();
  H.setZero(n, n);  // a Jacobian may write its nonzeros only
  C.resize(0, n);
  Vector flambda(n);  // F_λ, computed with F_u and not needed
  if (!jacobian(ws, u, lambda, H, flambda)) return false;
  if (residual_ == Residual::RestoringForce) H = -H;
  // the Hessian's symmetric part: F_u of a gradient is symmetric up to rounding
  H = (0.5 * (H + H.transpose())).eval();
  return true;
}

}  // namespace buckle::continuation
