#include "buckle/mechanics/vibration.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/wall_constraint.h"

namespace buckle::mechanics {

namespace {

/// Symmetric tridiagonal T (diagonal d, off-diagonal e) minus σI, factored by Gaussian elimination
/// with partial pivoting (LAPACK dgttrf): U has two superdiagonals, L unit lower bidiagonal
/// with row interchanges. Zero pivots (σ an exact eigenvalue) are replaced by a tiny one of
/// T's scale: inverse iteration only needs the direction of the huge solution.
class ShiftedTridiagonal {
 public:
  ShiftedTridiagonal(const Vector& d, const Vector& e, double sigma) : p_(int(d.size())) {
    dd_ = d.array() - sigma;
    dl_ = e;
    du_ = e;
    du2_ = Vector::Zero(std::max(p_ - 2, 0));
    swap_.assign(size_t(std::max(p_ - 1, 0)), false);
    const double scale = std::max(d.cwiseAbs().maxCoeff() + 2.0 * (e.size() ? e.cwiseAbs().maxCoeff() : 0.0),
                                  std::numeric_limits<double>::min());
    tiny_ = scale * std::numeric_limits<double>::epsilon();
    for (int i = 0; i + 1 < p_; ++i) {
      if (std::abs(dd_[i]) >= std::abs(dl_[i])) {
        if (dd_[i] == 0.0) dd_[i] = tiny_;
        const double f = dl_[i] / dd_[i];
        dl_[i] = f;
        dd_[i + 1] -= f * du_[i];
      } else {
        const double f = dd_[i] / dl_[i];
        dd_[i] = dl_[i];
        dl_[i] = f;
        const double t = du_[i];
        du_[i] = dd_[i + 1];
        dd_[i + 1] = t - f * dd_[i + 1];
        if (i + 2 < p_) {
          du2_[i] = du_[i + 1];
          du_[i + 1] = -f * du_[i + 1];
        }
        swap_[size_t(i)] = true;
      }
    }
    if (p_ > 0 && dd_[p_ - 1] == 0.0) dd_[p_ - 1] = tiny_;
  }

  void solve(Vector& b) const {
    for (int i = 0; i + 1 < p_; ++i) {
      if (swap_[size_t(i)]) std::swap(b[i], b[i + 1]);
      b[i + 1] -= dl_[i] * b[i];
    }
    for (int i = p_ - 1; i >= 0; --i) {
      double s = b[i];
      if (i + 1 < p_) s -= du_[i] * b[i + 1];
      if (i + 2 < p_) s -= du2_[i] * b[i + 2];
      b[i] = s / dd_[i];
    }
  }

 private:
  int p_;
  Vector dd_, dl_, du_, du2_;
  std::vector<bool> swap_;
  double tiny_;
};

/// Eigenvectors of the tridiagonal (d, e) for the given eigenvalues (ascending) by inverse
/// iteration, each orthogonalised against the previous ones (repeated or close eigenvalues
/// span their invariant subspace). Columns of unit length.
Matrix tridiagonalVectors(const Vector& d, const Vector& e, const Vector& values) {
  const int p = int(d.size());
  const int k = int(values.size());
  Matrix Y(p, k);
  unsigned long long seed = 0x9E3779B97F4A7C15ull;
  for (int j = 0; j < k; ++j) {
    const ShiftedTridiagonal T(d, e, values[j]);
    Vector y(p);
    for (int i = 0; i < p; ++i) {  // a fixed pseudo-random start: no mode is orthogonal to it
      seed = seed * 6364136223846793005ull + 1442695040888963407ull;
      y[i] = double(seed >> 11) / double(1ull << 53) - 0.5;
    }
    for (int it = 0; it < 3; ++it) {
      T.solve(y);
      for (int c = 0; c < j; ++c) y -= Y.col(c).dot(y) * Y.col(c);
      y /= y.norm();
    }
    Y.col(j) = y;
  }
  return Y;
}

}  // namespace

double signedFrequency(double omegaSquared) {
  return omegaSquared >= 0.0 ? std::sqrt(omegaSquared) : -std::sqrt(-omegaSquared);
}

VibrationAnalysis::VibrationAnalysis(const Chain& chain, const InertiaData& inertia)
    : chain_(chain),
      inertia_(inertia),
      model_(chain, EndCondition::freeEnd(), inertia, {}, 1.0, Vector::Zero(chain.size())) {}

void VibrationAnalysis::checkArguments(ConstVectorRef q, int count, const Vector& bodyGenerator) const {
  const int n = chain_.size();
  if (q.size() != n) throw std::invalid_argument("VibrationAnalysis::modes: q must have one angle per joint");
  if (count < 0) throw std::invalid_argument("VibrationAnalysis::modes: count must be >= 0");
  if (bodyGenerator.size() != 0 && bodyGenerator.size() != n)
    throw std::invalid_argument("body loads: the generator must have one entry per joint");
}

VibrationModes VibrationAnalysis::modes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                        const std::vector<int>& lockedJoints, int count, bool shapes,
                                        const Vector& bodyGenerator) {
  checkArguments(q, count, bodyGenerator);
  return route(q, F, held, lockedJoints, Matrix(), count, shapes, bodyGenerator);
}

VibrationModes VibrationAnalysis::modes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                        const ContactSet& contacts, ConstVectorRef forces, int count, bool shapes,
                                        const Vector& bodyGenerator) {
  const int n = chain_.size(), w = contacts.wallCount(), s = contacts.selfCount();
  contacts.check(n);
  std::vector<int> locked;
  for (const LockedJoint& j : contacts.joints()) locked.push_back(j.joint);
  checkArguments(q, count, bodyGenerator);
  if (forces.size() != w + s)
    throw std::invalid_argument("VibrationAnalysis::modes: one force per wall vertex (" + std::to_string(w) +
                                ") and per self contact (" + std::to_string(s) + "), got " +
                                std::to_string(forces.size()));
  Matrix rows(w + s, n), columns;
  Vector signs;
  Vector gamma = bodyGenerator;  // as lockedLoadedStiffness: the contacts' rows and their forces' generator
  wallConstraintTerms(chain_, q, contacts, forces.head(w), "VibrationAnalysis::modes", rows.topRows(w), gamma);
  selfConstraintTerms(chain_, q, contacts, forces.tail(s), "VibrationAnalysis::modes", rows.bottomRows(s), gamma,
                      columns, signs);
  return route(q, F, held, locked, rows, count, shapes, gamma, columns, signs);
}

VibrationModes VibrationAnalysis::route(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                        const std::vector<int>& lockedJoints, const Matrix& wallRows, int count,
                                        bool shapes, const Vector& bodyGenerator, const Matrix& couplingColumns,
                                        const Vector& couplingSigns) {
  const bool structured = route_ == VibrationRoute::Structured ||
                          (route_ == VibrationRoute::Automatic && chain_.size() >= kStructuredFrom);
  if (structured)
    return structuredModes(q, F, held, lockedJoints, wallRows, count, shapes, bodyGenerator, couplingColumns,
                           couplingSigns);
  return denseModes(q, F, held, lockedJoints, wallRows, count, shapes, bodyGenerator, couplingColumns, couplingSigns);
}

void VibrationAnalysis::massMatrix(ConstVectorRef q, MatrixRef M) {
  if (q.size() != chain_.size() || M.rows() != chain_.size() || M.cols() != chain_.size())
    throw std::invalid_argument("VibrationAnalysis::massMatrix: q must have n entries and M be n×n");
  model_.massMatrix(q, M);
}

Matrix VibrationAnalysis::constraintRows(ConstVectorRef q, const std::vector<int>& held,
                                         const std::vector<int>& lockedJoints) const {
  const int n = chain_.size();
  ChainData data(chain_);
  forwardKinematics(chain_, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  Matrix C = Matrix::Zero(int(held.size() + lockedJoints.size()), n);
  int row = 0;
  for (int c : held) {
    if (c < 0 || c > 2) throw std::invalid_argument("held end coordinate " + std::to_string(c) + " outside 0…2");
    C.row(row++) = J.row(c);
  }
  for (int j : lockedJoints) {
    if (j < 0 || j >= n)
      throw std::invalid_argument("locked joint " + std::to_string(j) + " outside 0…" + std::to_string(n - 1));
    C(row++, j) = 1.0;
  }
  return C;
}

VibrationModes VibrationAnalysis::denseModes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                             const std::vector<int>& lockedJoints, const Matrix& wallRows, int count,
                                             bool shapes, const Vector& bodyGenerator, const Matrix& couplingColumns,
                                             const Vector& couplingSigns) {
  const int n = chain_.size();
  Matrix H(n, n), M(n, n);
  totalPotentialHessian(chain_, q, F, H);  // K_q − K_g(F), eq 27
  addBodyLoadHessian(bodyGenerator, H);     // the body loads' Γ (eq B3)
  if (couplingColumns.cols() > 0)  // the self contacts' rank-2 term R E Rᵀ (self_contact.h)
    H.noalias() += couplingColumns * couplingSigns.asDiagonal() * couplingColumns.transpose();
  model_.massMatrix(q, M);
  Matrix C = constraintRows(q, held, lockedJoints);
  if (wallRows.rows() > 0) {
    C.conservativeResize(C.rows() + wallRows.rows(), n);
    C.bottomRows(wallRows.rows()) = wallRows;
  }

  // Z: the trailing columns of the reflectors of a rank-revealing QR of Cᵀ (ker C_h).
  Eigen::ColPivHouseholderQR<Matrix> qr(n, std::max(int(C.rows()), 1));
  int rank = 0;
  if (C.rows() > 0) {
    qr.setThreshold(kConstraintRankTolerance);
    qr.compute(C.transpose());
    rank = qr.rank();
    H.applyOnTheLeft(qr.householderQ().adjoint());
    H.applyOnTheRight(qr.householderQ());
    M.applyOnTheLeft(qr.householderQ().adjoint());
    M.applyOnTheRight(qr.householderQ());
  }
  const int p = n - rank;
  VibrationModes out;
  out.dimension = p;
  const int k = std::min(count, p);
  out.omegaSquared.resize(k);
  if (p == 0 || k == 0) return out;

  Matrix A = H.bottomRightCorner(p, p);
  const Eigen::LLT<Matrix> llt(M.bottomRightCorner(p, p));
  if (llt.info() != Eigen::Success)
    throw std::runtime_error("the mass matrix is not positive definite on the constraints at this point");
  // standard form L⁻¹ A L⁻ᵀ (Eigen's GeneralizedSelfAdjointEigenSolver does the same)
  llt.matrixL().solveInPlace<Eigen::OnTheLeft>(A);
  llt.matrixU().solveInPlace<Eigen::OnTheRight>(A);
  const Matrix S = 0.5 * (A + A.transpose());
  const Eigen::Tridiagonalization<Matrix> tri(S);
  const Vector d = tri.diagonal(), e = tri.subDiagonal();
  Eigen::SelfAdjointEigenSolver<Matrix> es;
  es.computeFromTridiagonal(d, e, Eigen::EigenvaluesOnly);
  if (es.info() != Eigen::Success) throw std::runtime_error("the tridiagonal eigenvalue iteration did not converge");
  out.omegaSquared = es.eigenvalues().head(k);
  if (!shapes) return out;

  // y (tridiagonal) → Q_tri y (standard form) → L⁻ᵀ (generalized, M-orthonormal on ker C_h) → Z
  Matrix Y = Matrix::Zero(n, k);
  Y.bottomRows(p) = tridiagonalVectors(d, e, out.omegaSquared);
  Y.bottomRows(p).applyOnTheLeft(tri.matrixQ());
  llt.matrixU().solveInPlace(Y.bottomRows(p));
  if (C.rows() > 0) Y.applyOnTheLeft(qr.householderQ());
  for (int j = 0; j < k; ++j) {
    Eigen::Index at = 0;
    Y.col(j).cwiseAbs().maxCoeff(&at);
    if (Y(at, j) < 0.0) Y.col(j) = -Y.col(j);
  }
  out.shapes = Y;
  return out;
}

}  // namespace buckle::mechanics
