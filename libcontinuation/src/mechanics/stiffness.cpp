#include "buckle/mechanics/stiffness.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "buckle/continuation/problem.h"

namespace buckle::mechanics {

namespace {

// Relative conditioning of a symmetric 2×2 matrix: min |eig| / max |eig| (0 for the zero matrix).
double conditioning(const Eigen::Matrix2d& A) {
  const Eigen::Vector2d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(A, Eigen::EigenvaluesOnly).eigenvalues();
  const double big = ev.cwiseAbs().maxCoeff();
  if (!(big > 0.0) || !std::isfinite(big)) return 0.0;
  return ev.cwiseAbs().minCoeff() / big;
}

// Solves the symmetric bordered system [[H, Cᵀ], [C, 0]] X = R; false if it is singular.
bool borderedSolve(const Matrix& H, const Matrix& C, const Matrix& R, double tolerance, Matrix& X) {
  const Eigen::Index n = H.rows(), m = C.rows();
  Matrix B = Matrix::Zero(n + m, n + m);
  B.topLeftCorner(n, n) = H;
  if (m > 0) {
    B.topRightCorner(n, m) = C.transpose();
    B.bottomLeftCorner(m, n) = C;
  }
  const Eigen::PartialPivLU<Matrix> lu(B);
  if (!(lu.rcond() > tolerance)) return false;
  X = lu.solve(R);
  if (!X.allFinite()) return false;
  const double scale = std::max(1.0, B.cwiseAbs().maxCoeff()) * std::max(1.0, X.cwiseAbs().maxCoeff());
  return (B * X - R).cwiseAbs().maxCoeff() <= 1e-9 * scale;
}

}  // namespace

CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   const StiffnessOptions& options) {
  const int n = chain.size();
  if (q.size() != n) throw std::invalid_argument("q must have one angle per segment (size " + std::to_string(n) + ")");
  if (!q.allFinite()) throw std::invalid_argument("q must be finite");
  if (!F.allFinite()) throw std::invalid_argument("F must be finite");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CartesianStiffness out;
  out.rotationHeld = rotationHeld;

  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  Matrix H(n, n);
  totalPotentialHessian(chain, q, F, H);
  const Matrix Jp = J.topRows(2);
  Matrix Cphi(rotationHeld ? 1 : 0, n);
  if (rotationHeld) Cphi.row(0) = J.row(2);

  // Force control: (K_q − K_g) δq = J_pᵀ δF (+ J_φᵀ δMe with J_φ δq = 0).
  Matrix R = Matrix::Zero(n + Cphi.rows(), 2);
  R.topRows(n) = Jp.transpose();
  Matrix X;
  if (borderedSolve(H, Cphi, R, options.singularTolerance, X)) {
    Eigen::Matrix2d C = Jp * X.topRows(n);
    C = 0.5 * (C + C.transpose());
    out.compliance = C;
    if (conditioning(C) > options.singularTolerance) {
      out.stiffness = C.inverse();
      out.stiffness = 0.5 * (out.stiffness + out.stiffness.transpose());
    } else {
      out.rigid = true;
      out.stiffness.setConstant(nan);
    }
  } else {
    // Infinite compliance: K_F from the position-held system, B⁻¹ multiplier corner = −K.
    out.singular = true;
    out.compliance.setConstant(nan);
    const Matrix Ch = J.topRows(rotationHeld ? 3 : 2);
    Matrix Rp = Matrix::Zero(n + Ch.rows(), 2);
    Rp(n, 0) = 1.0;
    Rp(n + 1, 1) = 1.0;
    Matrix Xp;
    if (borderedSolve(H, Ch, Rp, options.singularTolerance, Xp)) {
      Eigen::Matrix2d K = -Xp.block(n, 0, 2, 2);
      out.stiffness = 0.5 * (K + K.transpose());
    } else {
      out.stiffness.setConstant(nan);
    }
  }
  if (!out.singular && !out.rigid)
    out.positiveDefinite =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(out.stiffness, Eigen::EigenvaluesOnly).eigenvalues()[0] > 0.0;

  if (options.computeInertia) {
    const continuation::StabilityInfo info = continuation::projectedInertia(H, Cphi);
    out.negativeDirections = info.negative;
    out.smallestEigenvalue = info.smallest;
  }
  return out;
}

CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, const EndCondition& end,
                                   const StiffnessOptions& options) {
  return loadedStiffness(chain, q, F, end.isHeld(EndCoordinate::Phi), options);
}

CartesianStiffness unloadedStiffness(const Chain& chain, ConstVectorRef q, bool rotationHeld,
                                     const StiffnessOptions& options) {
  return loadedStiffness(chain, q, Wrench::Zero(), rotationHeld, options);
}

}  // namespace buckle::mechanics
