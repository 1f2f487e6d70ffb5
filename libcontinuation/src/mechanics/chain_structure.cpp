// The chain structure (chain_structure.h): the workspace, assembly of T from κ and h, and the
// O(n) products with U and H = U T Uᵀ. Factorization, spectrum and bordered solves live in
// chain_structure_factorization.cpp, chain_structure_spectrum.cpp, chain_structure_bordered.cpp.
#include "buckle/mechanics/chain_structure.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

namespace buckle::mechanics {

ChainStructure::ChainStructure(int size)
    : n(size),
      kappa(Vector::Zero(size)),
      h(Vector::Zero(size)),
      diag(Vector::Zero(size)),
      off(Vector::Zero(std::max(size, 1))),
      blockStart(size_t(std::max(size, 1)), 1),
      pivA(Vector::Zero(size)),
      pivE(Vector::Zero(size)),
      l1(Vector::Zero(size)),
      l2(Vector::Zero(size)),
      Q(Matrix::Zero(size, kMaxBorder)),
      B(Matrix::Zero(size, kMaxBorder)),
      X(Matrix::Zero(size, kMaxBorder)),
      V2(Matrix::Zero(size, kMaxBorder)),
      W2(Matrix::Zero(size, kMaxBorder)),
      t1(Vector::Zero(size)),
      t2(Vector::Zero(size)),
      t3(Vector::Zero(size)),
      zeroBorder(Matrix::Zero(kMaxBorder, kMaxBorder)) {
  if (size < 1) throw std::invalid_argument("ChainStructure: n must be >= 1");
}

void assemble(ConstVectorRef kappa, ConstVectorRef h, ChainStructure& ws) {
  const int n = ws.n;
  assert(kappa.size() == n && h.size() == n);
  double fro2 = 0.0;
  for (int m = 0; m < n; ++m) {
    const double km = kappa[m], hm = h[m];
    const double kn = m + 1 < n ? kappa[m + 1] : 0.0;
    const double hn = m + 1 < n ? h[m + 1] : 0.0;
    ws.diag[m] = km + kn - (hm - hn);
    if (m + 1 < n) ws.off[m] = -kn;
    fro2 += (km - hm) * (km - hm) + 2.0 * m * hm * hm;
  }
  if (ws.kappa.data() != kappa.data()) ws.kappa = kappa;
  if (ws.h.data() != h.data()) ws.h = h;
  ws.frobeniusH = std::sqrt(fro2);
}

void assemble(const Chain& chain, const ChainData& data, ConstVectorRef q, const Wrench& F, ChainStructure& ws) {
  jointStiffness(chain, q, ws.kappa);
  loadHessianGenerator(data, F, ws.h);
  assemble(ws.kappa, ws.h, ws);
}

void applyU(ConstVectorRef x, VectorRef y) {
  double s = 0.0;
  for (Eigen::Index i = x.size() - 1; i >= 0; --i) {
    s += x[i];
    y[i] = s;
  }
}

void applyUInverse(ConstVectorRef x, VectorRef y) {
  const Eigen::Index n = x.size();
  for (Eigen::Index i = 0; i + 1 < n; ++i) y[i] = x[i] - x[i + 1];
  y[n - 1] = x[n - 1];
}

void applyUTranspose(ConstVectorRef x, VectorRef y) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    s += x[i];
    y[i] = s;
  }
}

void applyUInverseTranspose(ConstVectorRef x, VectorRef y) {
  for (Eigen::Index i = x.size() - 1; i > 0; --i) y[i] = x[i] - x[i - 1];
  y[0] = x[0];
}

void applyHessian(const ChainStructure& ws, ConstVectorRef x, VectorRef y) {
  const int n = ws.n;
  applyUTranspose(x, y);
  // y ← T y in place, keeping the previous original entry
  double prev = 0.0;
  for (int i = 0; i < n; ++i) {
    const double cur = y[i];
    double v = ws.diag[i] * cur;
    if (i > 0) v += ws.off[i - 1] * prev;
    if (i + 1 < n) v += ws.off[i] * y[i + 1];
    prev = cur;
    y[i] = v;
  }
  applyU(y, y);
}

Matrix tridiagonalMatrix(const ChainStructure& ws) {
  const int n = ws.n;
  Matrix T = Matrix::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    T(i, i) = ws.diag[i];
    if (i + 1 < n) T(i, i + 1) = T(i + 1, i) = ws.off[i];
  }
  return T;
}

}  // namespace buckle::mechanics
