// ContactProblem's Jacobian products F_x x and F_xᵀ w and the second derivative F_xx[x, z] in O(n)
// (contact.h): what the locator's structured refinements and the branch points' coefficients
// evaluate with, instead of the dense Jacobian.
#include "buckle/mechanics/contact.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::ProblemWorkspace;
using continuation::VectorRef;
using continuation::workspaceAs;

namespace {

/// y_j += s·Σ_l g_max(j,l) x_l over j, l ≤ last (eq 27's generator form): g_j·(x_0 + … + x_j) plus
/// the tail Σ_{j<l≤last} g_l x_l, O(last).
void addGeneratorProduct(ConstVectorRef g, double s, int last, ConstVectorRef x, VectorRef y) {
  double tail = 0.0;
  for (int l = 0; l <= last; ++l) tail += g[l] * x[l];
  double head = 0.0;
  for (int j = 0; j <= last; ++j) {
    head += x[j];
    tail -= g[j] * x[j];
    y[j] += s * (g[j] * head + tail);
  }
}

/// y += (−Σ μ ∂²g) x for every held contact (symmetric: also the transpose's term), the wall's
/// generators up to their last joint, the self contacts' over the chain with their rank-2 terms
/// −μ(c wᵀ + w cᵀ) (self_contact.h).
void addContactHessianProduct(const ContactSet& contacts, const ContactProblem::Workspace& d, ConstVectorRef mu,
                              ConstVectorRef x, VectorRef y) {
  const int w = contacts.wallCount(), n = int(x.size());
  for (int k = 0; k < w; ++k) addGeneratorProduct(d.wallGen.col(k), mu[k], contacts.wall()[size_t(k)].lastJoint(), x, y);
  for (int k = 0; k < contacts.selfCount(); ++k) {
    addGeneratorProduct(d.wallGen.col(w + k), mu[w + k], n - 1, x, y);
    const auto c = d.selfCoupling.col(k), wt = d.selfWeights.col(k);
    y.noalias() -= (mu[w + k] * wt.dot(x)) * c;
    y.noalias() -= (mu[w + k] * c.dot(x)) * wt;
  }
}

}  // namespace

bool ContactProblem::jacobianApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                   VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), n = base_.segments(), w = locked_.gapCount();
  d.productIn.resize(N + 1);
  d.productIn.head(N) = x.head(N);
  d.productIn[N] = x[N + w];  // the λ component
  if (!base_.jacobianApply(*d.base, u.head(N), lambda, d.productIn, y.head(N))) return false;
  if (w > 0) {
    if (!wallKinematics(ws, u.head(n))) return false;
    addContactHessianProduct(locked_, d, u.segment(N, w), x.head(n), y.head(n));
    y.head(n).noalias() -= d.wallGrad * x.segment(N, w);
    y.tail(w).noalias() = -d.wallGrad.transpose() * x.head(n);
  }
  for (const LockedJoint& l : locked_.joints()) y[l.joint] = -x[l.joint];
  return true;
}

bool ContactProblem::jacobianTransposeApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                                            VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), n = base_.segments(), g = locked_.gapCount();
  d.productIn = w.head(N);  // the locked rows are −e_iᵀ, not the base's
  for (const LockedJoint& l : locked_.joints()) d.productIn[l.joint] = 0.0;
  d.productOut.resize(N + 1);
  if (!base_.jacobianTransposeApply(*d.base, u.head(N), lambda, d.productIn, d.productOut)) return false;
  y.head(N) = d.productOut.head(N);
  y[N + g] = d.productOut[N];
  if (g > 0) {
    if (!wallKinematics(ws, u.head(n))) return false;
    addContactHessianProduct(locked_, d, u.segment(N, g), d.productIn.head(n), y.head(n));
    y.segment(N, g).noalias() = -d.wallGrad.transpose() * d.productIn.head(n);
    y.head(n).noalias() -= d.wallGrad * w.segment(N, g);
  }
  for (const LockedJoint& l : locked_.joints()) y[l.joint] -= w[l.joint];
  return true;
}

bool ContactProblem::secondDerivativeApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                           ConstVectorRef z, VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (locked_.gapCount() > 0) return secondDerivativeApplyByDifferences(ws, u, lambda, x, z, y);
  if (!base_.secondDerivativeApply(*d.base, u, lambda, x, z, y)) return false;
  for (const LockedJoint& l : locked_.joints()) y[l.joint] = 0.0;  // the locked rows q_i − limit are linear
  return true;
}

}  // namespace buckle::mechanics
