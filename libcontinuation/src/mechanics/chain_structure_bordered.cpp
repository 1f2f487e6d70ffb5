// Solves with H and with the bordered matrix [[H, V], [Wᵀ, D]] through the chain structure
// (chain_structure.h, "solves"): block elimination plus one step of iterative refinement.
#include "buckle/mechanics/chain_structure.h"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace buckle::mechanics {

namespace {

/// Solve (T − σM)ξ and the bordered elimination for one right-hand side, with the Schur LU.
template <class LU>
void borderedElimination(ChainStructure& ws, int p, const LU& lu, ConstVectorRef f, ConstVectorRef g, VectorRef x,
                         VectorRef y) {
  const int n = ws.n;
  Vector& t = ws.t1;
  applyUInverse(f, t);
  solveFactored(ws, t);
  ChainStructure::SmallVector rhs(p);
  for (int j = 0; j < p; ++j) rhs[j] = g[j] - ws.W2.col(j).dot(t);
  const ChainStructure::SmallVector yy = lu.solve(rhs);
  for (int j = 0; j < p; ++j) {
    y[j] = yy[j];
    t.noalias() -= yy[j] * ws.V2.col(j);
  }
  applyUInverseTranspose(t, x.head(n));
}

}  // namespace

bool solve(ChainStructure& ws, ConstVectorRef r, VectorRef x) {
  factorize(ws, 0.0);
  if (ws.singular) return false;
  applyUInverse(r, x);
  solveFactored(ws, x);
  applyUInverseTranspose(x, x);
  return x.allFinite();
}

bool factorBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                    const Eigen::Ref<const Matrix>& D) {
  const int n = ws.n;
  const int p = int(V.cols());
  if (p > ChainStructure::kMaxBorder || W.cols() != p || D.rows() != p || D.cols() != p || V.rows() != n ||
      W.rows() != n)
    throw std::invalid_argument("factorBordered: V, W must be n×p and D p×p with p <= kMaxBorder");
  ws.borderSize = -1;
  factorize(ws, 0.0);
  if (ws.singular) return false;
  for (int j = 0; j < p; ++j) {
    applyUInverse(V.col(j), ws.V2.col(j));
    applyUInverse(W.col(j), ws.W2.col(j));
  }
  solveFactored(ws, ws.V2, p);
  // det [[H, V], [Wᵀ, D]] = det H · det S with det H = det T (det U = 1).
  ws.schur.resize(p, p);
  if (p > 0) {  // (an empty matrix is not valid LU input)
    // p² dot products of length n, coefficient-wise (not a packed general matrix product)
    ws.schur.noalias() = D - ws.W2.leftCols(p).transpose().lazyProduct(ws.V2.leftCols(p));
    ws.schurLU.compute(ws.schur);
    if (!ws.schurLU.isInvertible()) return false;
  }
  ws.borderSize = p;
  ws.borderedLogAbsDet = ws.logAbsDet;
  ws.borderedDetSign = ws.detSign;
  if (p > 0) {
    const double detS = ws.schurLU.determinant();
    ws.borderedLogAbsDet += std::log(std::abs(detS));
    if (detS < 0.0) ws.borderedDetSign = -ws.borderedDetSign;
  }
  return true;
}

bool solveFactoredBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                           const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x,
                           VectorRef y) {
  const int n = ws.n;
  const int p = int(V.cols());
  if (ws.borderSize != p) throw std::logic_error("solveFactoredBordered: factorBordered was not called for this border");
  if (p == 0) {
    applyUInverse(f, x);
    solveFactored(ws, x);
    applyUInverseTranspose(x, x);
    return x.allFinite();
  }
  borderedElimination(ws, p, ws.schurLU, f, g, x, y);
  // One step of iterative refinement with the exact O(n) residual.
  Vector& r1 = ws.t2;
  applyHessian(ws, x.head(n), r1);
  r1 = f - r1;
  r1.noalias() -= V * y.head(p);
  ChainStructure::SmallVector r2 = g.head(p);
  r2.noalias() -= W.transpose() * x.head(n);
  r2.noalias() -= D * y.head(p);
  Vector& dx = ws.t3;
  ChainStructure::SmallVector dy(p);
  borderedElimination(ws, p, ws.schurLU, r1, r2, dx, dy);
  x.head(n) += dx;
  y.head(p) += dy;
  return x.allFinite() && y.allFinite();
}

bool solveBordered(ChainStructure& ws, const Eigen::Ref<const Matrix>& V, const Eigen::Ref<const Matrix>& W,
                   const Eigen::Ref<const Matrix>& D, ConstVectorRef f, ConstVectorRef g, VectorRef x, VectorRef y) {
  return factorBordered(ws, V, W, D) && solveFactoredBordered(ws, V, W, D, f, g, x, y);
}

bool solveKKT(ChainStructure& ws, const Eigen::Ref<const Matrix>& C, ConstVectorRef f, ConstVectorRef g, VectorRef x,
              VectorRef y) {
  const int m = int(C.rows());
  if (m > ChainStructure::kMaxBorder) throw std::invalid_argument("solveKKT: at most 4 constraint rows");
  ws.X.leftCols(m) = C.transpose();
  ws.zeroBorder.setZero();
  return solveBordered(ws, ws.X.leftCols(m), ws.X.leftCols(m), ws.zeroBorder.topLeftCorner(m, m), f, g, x, y);
}

}  // namespace buckle::mechanics
