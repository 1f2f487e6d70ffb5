// The loaded stiffness of a chain holding contacts (contact.h), dense: K_F = (J_p P J_pᵀ)⁻¹
// (eq 29) formed from the constrained operator itself, P = Z (Zᵀ H Z)⁻¹ Zᵀ with Z a basis of the
// joints' motions that keep every contact (and φ where it is held), a self contact's rank-2
// Hessian term included. O(n³): short chains and what structuredContactStiffness refuses.
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>
#include <limits>

#include "buckle/mechanics/contact.h"
#include "contact_stiffness.h"

namespace buckle::mechanics {

CartesianStiffness denseContactStiffness(const ContactProblem& problem, continuation::ConstVectorRef u, double lambda) {
  const EquilibriumProblem& base = problem.base();
  const int n = base.segments();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CartesianStiffness s;
  s.stiffness = s.compliance = s.complianceAccuracy = Eigen::Matrix2d::Constant(nan);
  s.rotationHeld = base.endCondition().isHeld(EndCoordinate::Phi);
  auto ws = problem.createWorkspace();
  Matrix H, C;
  const Vector full = u.size() == problem.dimension() ? Vector(u) : problem.withWallForces(*ws, u, lambda);
  if (!full.allFinite() || !problem.stabilityOperator(*ws, full, lambda, H, C)) return s;
  // the constraints of the stiffness: every row of C but the held x and y (forces applied there)
  const std::vector<int> held = base.endCondition().heldIndices();
  Matrix E(C.rows(), n);
  int rows = 0;
  for (int k = 0; k < int(C.rows()); ++k)
    if (k >= int(held.size()) || held[size_t(k)] == int(EndCoordinate::Phi)) E.row(rows++) = C.row(k);
  // Z: the orthonormal complement of the rows (rank-revealing QR of Eᵀ)
  Eigen::ColPivHouseholderQR<Matrix> qr(E.topRows(rows).transpose());
  qr.setThreshold(kConstraintRankTolerance);
  const int r = rows > 0 ? int(qr.rank()) : 0;
  const Matrix Q = rows > 0 ? Matrix(qr.householderQ()) : Matrix::Identity(n, n);
  const Matrix Z = Q.rightCols(n - r);
  Eigen::SelfAdjointEigenSolver<Matrix> eig(Z.transpose() * H * Z);
  if (eig.info() != Eigen::Success || n - r == 0) return s;
  const Vector& mu = eig.eigenvalues();
  s.smallestEigenvalue = mu[0];
  const double scale = std::max(base.stiffnessUnit() * base.lengthUnit() * base.lengthUnit(), mu.cwiseAbs().maxCoeff());
  const double zero = 1e-13 * scale;
  for (int i = 0; i < mu.size(); ++i) s.negativeDirections += mu[i] < -zero ? 1 : 0;
  if (mu.cwiseAbs().minCoeff() <= zero) {
    s.singular = true;
    return s;
  }
  // J (3×n) of the end pose: ∂x/∂q_j = −(y_e − y_j), ∂y/∂q_j = x_e − x_j, ∂φ/∂q_j = 1
  const Eigen::Matrix2Xd P = jointPositions(base.chain(), full.head(n));
  const Eigen::Vector2d end = P.col(n + 1);
  Matrix J(3, n);
  for (int j = 0; j < n; ++j) J.col(j) << -(end.y() - P(1, j + 1)), end.x() - P(0, j + 1), 1.0;
  const Matrix JV = J * Z * eig.eigenvectors();               // 3 × (n − r)
  const Matrix X = mu.cwiseInverse().asDiagonal() * JV.transpose();  // (Zᵀ H Z)⁻¹ (J Z)ᵀ in the eigenbasis
  const double condition = mu.cwiseAbs().maxCoeff() / mu.cwiseAbs().minCoeff();
  Eigen::Vector3d jNorms, xNorms;
  for (int i = 0; i < 3; ++i) jNorms[i] = JV.row(i).norm(), xNorms[i] = X.col(i).norm();
  finishContactStiffness(JV * X, jNorms, xNorms, condition, s);
  return s;
}

void finishContactStiffness(const Eigen::Ref<const Matrix>& C, const Eigen::Ref<const Vector>& jNorms,
                            const Eigen::Ref<const Vector>& xNorms, double condition, CartesianStiffness& s) {
  const double eps = std::numeric_limits<double>::epsilon();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      s.complianceAccuracy(i, j) = eps * condition * jNorms[i] * xNorms[j];
      s.compliance(i, j) = std::abs(C(i, j)) <= s.complianceAccuracy(i, j) ? 0.0 : C(i, j);
    }
  if (!s.rotationHeld) {
    s.rotationalComplianceAccuracy = eps * condition * jNorms[2] * xNorms[2];
    s.rotationalCompliance = std::abs(C(2, 2)) <= s.rotationalComplianceAccuracy ? 0.0 : C(2, 2);
    s.rotationalStiffness = s.rotationalCompliance == 0.0 ? std::numeric_limits<double>::infinity()
                                                          : 1.0 / s.rotationalCompliance;
  }
  const double det = s.compliance.determinant();
  if (std::abs(det) <= eps * condition * s.compliance.squaredNorm()) {
    s.rigid = true;
    return;
  }
  s.stiffness = s.compliance.inverse();
  s.positiveDefinite = s.stiffness(0, 0) > 0.0 && s.stiffness.determinant() > 0.0;
}

}  // namespace buckle::mechanics
