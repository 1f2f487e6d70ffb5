// EquilibriumProblem's body loads (body_loads.h): the generator h − γ every Hessian route uses,
// the rate dγ of the second derivatives, and the public γ and V for the analyses at a point.
#include <cmath>

#include "buckle/mechanics/equilibrium_problem.h"

namespace buckle::mechanics {

using continuation::ProblemWorkspace;
using continuation::workspaceAs;

using continuation::ConstVectorRef;

void EquilibriumProblem::loadGenerator(Workspace& d, const ConstVectorRef& u, double lambda, VectorRef h) const {
  loadHessianGenerator(d.data, wrench(u, lambda), h);  // eq 27
  if (!d.bodyTerms.active()) return;
  const int n = chain_.size();
  for (int m = 0; m < n; ++m) h[m] -= d.bodyTerms.gammaAt(m, lambda);  // eq (B3)
}

void EquilibriumProblem::bodyGeneratorDerivative(Workspace& d, const ConstVectorRef& dq, double lambda,
                                                 double dlambda) const {
  d.bodyTerms.generatorDerivative(lambda, dq, dlambda, d.bodyWork);  // eq (B5)
}

namespace {
// The body-load terms at q, on their own kinematics (the problem's cache is left alone).
BodyLoadTerms termsAt(const Chain& chain, const BodyLoadTerms& terms, ConstVectorRef q) {
  BodyLoadTerms at = terms;
  ChainData data(chain);
  forwardKinematics(chain, q.head(chain.size()), data);
  at.update(data);
  return at;
}
}  // namespace

Vector EquilibriumProblem::bodyLoadGenerator(ConstVectorRef q, double lambda) const {
  if (!bodyTerms_.active()) return Vector();
  Vector gamma(chain_.size());
  termsAt(chain_, bodyTerms_, q).generator(lambda, gamma);
  return gamma;
}

Vector EquilibriumProblem::bodyLoadGeneratorRate(ConstVectorRef q, double lambda, ConstVectorRef dq,
                                                 double dlambda) const {
  if (!bodyTerms_.active()) return Vector();
  Vector dgamma(chain_.size());
  termsAt(chain_, bodyTerms_, q).generatorDerivative(lambda, dq.head(chain_.size()), dlambda, dgamma);
  return dgamma;
}

double EquilibriumProblem::bodyLoadPotential(ConstVectorRef q, double lambda) const {
  if (!bodyTerms_.active()) return 0.0;
  ChainData data(chain_);
  forwardKinematics(chain_, q.head(chain_.size()), data);
  return bodyTerms_.potential(data, lambda);
}

}  // namespace buckle::mechanics
