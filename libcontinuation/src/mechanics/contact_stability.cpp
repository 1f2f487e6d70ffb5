// The stability of ContactProblem (contact.h) on the reduced chain structure: the inertia and
// lowest eigenvalues of K_q − K_g − Σ μ ∂²g on the free joints and ker of the held and gap rows,
// the self contacts' rank-2 terms bordered (setCoupling), O(n) a point.
#include <algorithm>

#include "buckle/mechanics/contact.h"
#include "held_multipliers.h"

namespace buckle::mechanics {

namespace cont = continuation;

namespace {

// Inertia and lowest eigenvalues of the reduced H on ker of the held rows (as
// EquilibriumProblem::stability, on the reduced structure), with the self contacts' rank-2 terms
// R E Rᵀ when R has columns (setCoupling; the small dense route takes none).
void reducedStability(ChainStructure& ws, const Matrix& heldRows, const Matrix& R, const Vector& E, int lowestCount,
                      Vector& lastLowest, cont::StabilityInfo& info) {
  const int wanted = std::max(0, std::min(lowestCount, EquilibriumProblem::kMaxLowest));
  if (ws.n <= kSmallDense && wanted > 0 && R.cols() == 0) {
    Eigen::Matrix<double, EquilibriumProblem::kMaxLowest, 1> low;
    int found = 0;
    const Inertia in = smallDenseInertia(ws, heldRows, wanted, low.head(wanted), found);
    info.negative = in.negative;
    info.zero = in.zero;
    info.lowest = low.head(found);
  } else {
    if (heldRows.rows() > 0)
      setConstraints(ws, heldRows);
    else
      ws.rank = 0;
    if (R.cols() > 0)
      setCoupling(ws, R, E);
    else
      ws.couplingCount = 0;
    const Inertia in = borderedInertia(ws);
    info.negative = in.negative;
    info.zero = in.zero;
    info.lowest.resize(std::min(wanted, in.size()));
    if (info.lowest.size() > 0) {
      lowestEigenvalues(ws, ws.rank + ws.couplingCount > 0, int(info.lowest.size()), info.lowest, 1e-13,
                        lastLowest.size() == info.lowest.size() ? &lastLowest : nullptr);
      lastLowest = info.lowest;
    }
  }
  info.smallest = info.lowest.size() > 0 ? info.lowest[0] : 0.0;
}

}  // namespace

bool ContactProblem::stability(cont::ProblemWorkspace& ws, cont::ConstVectorRef u, double lambda, int lowestCount,
                               cont::StabilityInfo& info) const {
  Workspace& d = cont::workspaceAs<Workspace>(ws);
  if (free_.empty()) {  // every joint locked: nothing can move
    if (!residual(ws, u, lambda, d.residual)) return false;
    info = cont::StabilityInfo();
    info.negative = 0;
    return true;
  }
  if (!structuredSpectrum(locked_.selfCount() > 0 ? kSmallDense : 0))
    return Problem::stability(ws, u, lambda, lowestCount, info);
  if (!reducedOperator(ws, u, lambda)) return false;
  reducedStability(d.reduced, d.heldRows, d.selfColumnsFree, d.selfSigns, lowestCount, d.lastLowest, info);
  return true;
}

bool ContactProblem::stabilityEigenvalues(cont::ProblemWorkspace& ws, cont::ConstVectorRef u, double lambda, int first,
                                          cont::VectorRef values) const {
  Workspace& d = cont::workspaceAs<Workspace>(ws);
  if (first < 0 || values.size() > ChainStructure::kMaxBorder || !structuredSpectrum(kSmallDense))
    return Problem::stabilityEigenvalues(ws, u, lambda, first, values);
  if (!reducedOperator(ws, u, lambda)) return false;
  ChainStructure& structure = d.reduced;
  if (d.heldRows.rows() > 0)
    setConstraints(structure, d.heldRows);
  else
    structure.rank = 0;
  if (d.selfColumnsFree.cols() > 0)
    setCoupling(structure, d.selfColumnsFree, d.selfSigns);
  else
    structure.couplingCount = 0;
  // warm starts as EquilibriumProblem's (eigenvalue_memory.h): the counts still certify the values
  const bool guessed = d.found.guesses(first, d.guess.head(values.size()));
  if (eigenvaluesFrom(structure, structure.rank + structure.couplingCount > 0, first, int(values.size()), values, 1e-13,
                      guessed ? &d.guess : nullptr) != values.size())
    return false;
  d.found.remember(first, values);
  return true;
}

bool ContactProblem::stabilityRateBound(cont::ProblemWorkspace& ws, cont::ConstVectorRef u, double lambda,
                                        cont::ConstVectorRef du, double dlambda, double& bound) const {
  Workspace& d = cont::workspaceAs<Workspace>(ws);
  const int N = base_.dimension();
  if (locked_.gapCount() > 0 || free_.empty() || !reducedOperator(ws, u, lambda)) return false;
  return base_.stabilityRateBoundOn(*d.base, u.head(N), lambda, du.head(N), dlambda, free_, d.heldRows, bound);
}

bool ContactProblem::stabilitySlopes(cont::ProblemWorkspace& ws, cont::ConstVectorRef u, double lambda,
                                     cont::ConstVectorRef du, double dlambda, int first, cont::ConstVectorRef values,
                                     cont::VectorRef slopes) const {
  Workspace& d = cont::workspaceAs<Workspace>(ws);
  const int N = base_.dimension(), m = int(held_.size());
  if (locked_.gapCount() > 0 || first < 0 || values.size() != slopes.size() || !values.allFinite() ||
      !structuredSpectrum(kSmallDense) || !reducedOperator(ws, u, lambda))
    return false;
  ChainStructure& structure = d.reduced;
  // rank-deficient held rows on the free joints: ker C jumps along the tangent (no derivative)
  if ((m > 0 ? setConstraints(structure, d.heldRows) : (structure.rank = 0)) < m) return false;
  structure.couplingCount = 0;
  Vector &v = d.slopeFree, &Hv = d.slopeHv;
  for (Eigen::Index j = 0; j < values.size(); ++j) {
    Eigen::Vector3d zeta;  // of the held rows on the free joints
    if (!eigenvectorAt(structure, m > 0, values[j], v) ||
        !heldMultipliers(structure, d.heldRows, m, values[j], v, Hv, zeta))
      return false;
    for (size_t a = 0; a < free_.size(); ++a) d.slopeFull[free_[a]] = v[Eigen::Index(a)];
    if (!base_.eigenvalueRate(*d.base, u.head(N), lambda, du.head(N), dlambda, d.slopeFull, zeta, slopes[j]))
      return false;
  }
  return true;
}

// The chain structure's counts take at most 3 constraint rows (setConstraints) and kMaxBorder
// borders with the self contacts' two coupling columns each; chains of up to `denseUpTo` free
// joints take the dense route too (the small dense route takes no coupling).
bool ContactProblem::structuredSpectrum(int denseUpTo) const {
  const Eigen::Index rows = Eigen::Index(held_.size()) + locked_.gapCount();
  return !free_.empty() && rows <= 3 && rows + 2 * locked_.selfCount() <= ChainStructure::kMaxBorder &&
         int(free_.size()) > denseUpTo;
}

// The reduced structure, the constraint rows (held coordinates, then ∇gᵀ of the gaps) and the self
// contacts' coupling columns on the free joints, in the workspace.
bool ContactProblem::reducedOperator(cont::ProblemWorkspace& ws, cont::ConstVectorRef u, double lambda) const {
  Workspace& d = cont::workspaceAs<Workspace>(ws);
  if (!assembleReduced(ws, u, lambda, d.reduced, d.Jf)) return false;
  for (size_t k = 0; k < held_.size(); ++k) d.heldRows.row(Eigen::Index(k)) = d.Jf.row(held_[k]);
  for (int k = 0; k < locked_.gapCount(); ++k)
    for (size_t a = 0; a < free_.size(); ++a)
      d.heldRows(Eigen::Index(held_.size()) + k, Eigen::Index(a)) = d.wallGrad(free_[a], k);
  for (size_t a = 0; a < free_.size(); ++a) d.selfColumnsFree.row(Eigen::Index(a)) = d.selfColumns.row(free_[a]);
  return true;
}

}  // namespace buckle::mechanics
