// The loaded stiffness of a chain holding contacts (contact.h) in O(n): the quantities of
// denseContactStiffness (eq 29: C_F = J_p P J_pᵀ, P = Z (ZᵀHZ)⁻¹ Zᵀ on the motions that keep every
// contact and φ where it is held) through the reduced chain structure of ContactProblem — the
// locked joints left out, the gap rows (and J_φ) as constraint borders, each self contact's
// rank-2 term as two coupling borders (setCoupling) — instead of a dense eigen-solve:
//  - the inertia by the counts, the lowest, highest and the two eigenvalues next to zero of ZᵀHZ
//    by the certified searches (the condition number and the accuracy of each entry as the dense
//    route's, ε·κ·|Zᵀ J_iᵀ|·|X_j|);
//  - X_j = P J_jᵀ from the bordered system [[H, Q, R], [Qᵀ, 0, 0], [Rᵀ, 0, −E]] (Q the
//    orthonormalised constraint rows), O(n) per column;
//  - where ZᵀHZ is singular (a located fold or branch point), K_F from the position-held system,
//    J_p's rows bordered too: −K_F is the multiplier corner of its inverse (stiffness.h).
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "buckle/mechanics/contact.h"
#include "contact_stiffness.h"

namespace buckle::mechanics {

namespace {

/// The eigenvalue of ZᵀHZ at index `index` by the certified search (0 ≤ index < dimension).
double eigenvalueAt(ChainStructure& ws, bool constrained, int index) {
  Eigen::Matrix<double, 1, 1> value;
  return eigenvaluesFrom(ws, constrained, index, 1, value) == 1 ? value[0] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

bool structuredContactStiffness(const ContactProblem& problem, continuation::ConstVectorRef u, double lambda,
                                CartesianStiffness& s) {
  const EquilibriumProblem& base = problem.base();
  const std::vector<int>& free = problem.freeJoints();
  const int nf = int(free.size()), gaps = problem.contacts().gapCount(), z = 2 * problem.contacts().selfCount();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s = CartesianStiffness();
  s.stiffness = s.compliance = s.complianceAccuracy = Eigen::Matrix2d::Constant(nan);
  s.rotationHeld = base.endCondition().isHeld(EndCoordinate::Phi);
  const int rows = gaps + (s.rotationHeld ? 1 : 0);
  if (nf == 0 || rows > 3 || rows + z + 2 > ChainStructure::kMaxBorder) return false;
  auto workspace = problem.createWorkspace();
  const Vector full = u.size() == problem.dimension() ? Vector(u) : problem.withWallForces(*workspace, u, lambda);
  ChainStructure ws(nf);
  ws.typicalScale = base.stiffnessUnit() * base.lengthUnit() * base.lengthUnit();
  Matrix J(3, nf);
  if (!full.allFinite() || !problem.assembleReduced(*workspace, full, lambda, ws, J)) return false;
  // the constraint rows on the free joints: the gaps' ∇gᵀ, and J_φ where the rotation is held
  Matrix C(rows, nf), R(nf, z);
  const Matrix& grad = ContactProblem::wallGradients(*workspace);
  const Matrix& columns = ContactProblem::selfColumns(*workspace);
  for (int a = 0; a < nf; ++a) {
    for (int k = 0; k < gaps; ++k) C(k, a) = grad(free[size_t(a)], k);
    if (s.rotationHeld) C(gaps, a) = J(2, a);
    R.row(a) = columns.row(free[size_t(a)]);
  }
  const Vector& E = ContactProblem::selfSigns(*workspace);
  const int r = rows > 0 ? setConstraints(ws, C) : (ws.rank = 0);
  if (z > 0) setCoupling(ws, R, E);
  const bool constrained = r + z > 0;
  const int dim = nf - r;
  if (dim == 0) return false;
  // the spectrum of ZᵀHZ: its inertia, lowest, highest and the two next to zero
  const Inertia inertia = borderedInertia(ws);
  s.negativeDirections = inertia.negative;
  s.smallestEigenvalue = eigenvalueAt(ws, constrained, 0);
  const double largest = std::max(std::abs(s.smallestEigenvalue), std::abs(eigenvalueAt(ws, constrained, dim - 1)));
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = std::max(0, inertia.negative - 1); k < std::min(dim, inertia.negative + 1); ++k)
    nearest = std::min(nearest, std::abs(eigenvalueAt(ws, constrained, k)));
  if (!std::isfinite(largest) || !(nearest == nearest)) return false;
  const Matrix Q = ws.Q.leftCols(r);  // a copy: the bordered factorization below reuses the workspace
  const int p = r + z;
  Matrix V(nf, p + 2), D = Matrix::Zero(p + 2, p + 2);
  V.leftCols(r) = Q;
  V.middleCols(r, z) = R;
  for (int k = 0; k < z; ++k) D(r + k, r + k) = -E[k];
  Vector x(nf), y(p + 2), zero = Vector::Zero(p + 2);
  if (inertia.zero > 0 || nearest <= 1e-13 * std::max(ws.typicalScale, largest)) {
    // singular on the constraints: K_F from the position-held system (J_p bordered as well)
    s.singular = true;
    V.rightCols(2) = J.topRows(2).transpose();
    if (!factorBordered(ws, V, V, D)) return true;
    Eigen::Matrix2d K;
    for (int c = 0; c < 2; ++c) {
      Vector g = Vector::Zero(p + 2);
      g[p + c] = 1.0;
      if (!solveFactoredBordered(ws, V, V, D, Vector::Zero(nf), g, x, y)) return true;
      K.col(c) = -y.tail(2);
    }
    s.stiffness = 0.5 * (K + K.transpose());
    return true;
  }
  const auto Vp = V.leftCols(p);
  const auto Dp = D.topLeftCorner(p, p);
  if (!factorBordered(ws, Vp, Vp, Dp)) return false;
  const int columnsWanted = s.rotationHeld ? 2 : 3;
  Matrix X(nf, columnsWanted);
  for (int j = 0; j < columnsWanted; ++j)
    if (!solveFactoredBordered(ws, Vp, Vp, Dp, J.row(j).transpose(), zero.head(p), X.col(j), y.head(p))) return false;
  // as the dense route: |Zᵀ J_iᵀ| (J_i's part in ker C, Q orthonormal) and |X_j| with κ = max|ν| / min|ν|
  Vector projected(columnsWanted), xNorms(columnsWanted);
  for (int i = 0; i < columnsWanted; ++i) {
    projected[i] = (J.row(i).transpose() - Q * (Q.transpose() * J.row(i).transpose())).norm();
    xNorms[i] = X.col(i).norm();
  }
  finishContactStiffness(J.topRows(columnsWanted) * X, projected, xNorms, largest / nearest, s);
  return true;
}

}  // namespace buckle::mechanics
