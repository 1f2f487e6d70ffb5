// The multipliers of an eigenvector of H on ker C, shared by the Hellmann–Feynman rates of the
// free chain (equilibrium_problem_rate_bound.cpp) and of a chain with locked joints
// (contact_stability.cpp). Private to libcontinuation/src/mechanics.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

/// ζ = −(C Cᵀ)⁻¹ C H v for the unit eigenvector v of H (the structure `ws`) on ker C, C the first
/// m ≤ 3 rows of `rows` (H v + Cᵀζ = μ v with C v = 0), into zeta; Hv is scratch of v's size.
/// False when the pair's residual ‖H v + Cᵀζ − μ v‖ exceeds 1e−8 of the operator's scale: an
/// eigenvalue given wrong, or one of a cluster tighter than its accuracy, leaves v no eigenvector
/// to the accuracy a rate vᵀ dH v + 2 ζᵀ dC v needs (the caller then differences instead).
inline bool heldMultipliers(const ChainStructure& ws, const Matrix& rows, int m, double mu, ConstVectorRef v,
                            VectorRef Hv, Eigen::Vector3d& zeta) {
  applyHessian(ws, v, Hv);
  zeta.setZero();
  if (m > 0) {
    Eigen::Matrix3d gram = Eigen::Matrix3d::Identity();  // the unused diagonal padded: decoupled
    for (int k = 0; k < m; ++k) {
      for (int l = 0; l <= k; ++l) gram(k, l) = gram(l, k) = rows.row(k).dot(rows.row(l));
      zeta[k] = -rows.row(k).dot(Hv);
    }
    zeta = Eigen::LDLT<Eigen::Matrix3d>(gram).solve(zeta);
  }
  double residual2 = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    double ri = Hv[i] - mu * v[i];
    for (int k = 0; k < m; ++k) ri += rows(k, i) * zeta[k];
    residual2 += ri * ri;
  }
  return std::sqrt(residual2) <= 1e-8 * std::max(ws.typicalScale, ws.frobeniusH);
}

}  // namespace buckle::mechanics
