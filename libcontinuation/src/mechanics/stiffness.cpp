#include "buckle/mechanics/stiffness.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "buckle/continuation/problem.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain_structure.h"

namespace buckle::mechanics {

namespace {

// Relative conditioning of a symmetric 2×2 matrix: min |eig| / max |eig| (0 for the zero matrix).
double conditioning(const Eigen::Matrix2d& A) {
  const Eigen::Vector2d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(A, Eigen::EigenvaluesOnly).eigenvalues();
  const double big = ev.cwiseAbs().maxCoeff();
  if (!(big > 0.0) || !std::isfinite(big)) return 0.0;
  return ev.cwiseAbs().minCoeff() / big;
}

// Solves the symmetric bordered system [[H, Cᵀ], [C, 0]] X = R; false if it is singular. `rcond`
// (if given) receives the LU's estimate of the reciprocal condition number.
bool borderedSolve(const Matrix& H, const Matrix& C, const Matrix& R, double tolerance, Matrix& X,
                   double* rcond = nullptr) {
  const Eigen::Index n = H.rows(), m = C.rows();
  Matrix B = Matrix::Zero(n + m, n + m);
  B.topLeftCorner(n, n) = H;
  if (m > 0) {
    B.topRightCorner(n, m) = C.transpose();
    B.bottomLeftCorner(m, n) = C;
  }
  const Eigen::PartialPivLU<Matrix> lu(B);
  if (rcond) *rcond = lu.rcond();
  if (!(lu.rcond() > tolerance)) return false;
  X = lu.solve(R);
  if (!X.allFinite()) return false;
  const double scale = std::max(1.0, B.cwiseAbs().maxCoeff()) * std::max(1.0, X.cwiseAbs().maxCoeff());
  return (B * X - R).cwiseAbs().maxCoeff() <= 1e-9 * scale;
}

}  // namespace

std::string StiffnessOptions::validate(int segments, const std::string& prefix) const {
  namespace cont = continuation;
  auto generator = [&](const Vector& g, const char* field) {
    return cont::require((g.size() == 0 || g.size() == segments) && g.allFinite(), prefix, field,
                         "must be empty or hold one finite value per segment");
  };
  return cont::firstProblem({cont::require(singularTolerance > 0.0 && singularTolerance < 1.0, prefix,
                                           "singularTolerance", "must lie in (0, 1)"),
                             generator(bodyGenerator, "bodyGenerator"),
                             generator(bodyGeneratorRate, "bodyGeneratorRate")});
}

CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   const StiffnessOptions& options) {
  return loadedStiffness(chain, q, F, rotationHeld, Matrix(0, chain.size()), options);
}

CartesianStiffness loadedStiffness(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   const Eigen::Ref<const Matrix>& jointConstraints, const StiffnessOptions& options) {
  const int n = chain.size();
  if (jointConstraints.cols() != n)
    throw std::invalid_argument("joint constraints must have one column per segment (" + std::to_string(n) + ")");
  if (q.size() != n) throw std::invalid_argument("q must have one angle per segment (size " + std::to_string(n) + ")");
  if (!q.allFinite()) throw std::invalid_argument("q must be finite");
  if (!F.allFinite()) throw std::invalid_argument("F must be finite");
  if (std::string why; !options.IsValid(n, &why)) throw std::invalid_argument("StiffnessOptions: " + why);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CartesianStiffness out;
  out.rotationHeld = rotationHeld;

  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  Matrix H(n, n);
  totalPotentialHessian(chain, q, F, H);
  addBodyLoadHessian(options.bodyGenerator, H);
  const Matrix Jp = J.topRows(2);
  // the constraints on δq: E δq = 0 (jointConstraints), and J_φ δq = 0 when the rotation is held
  const Eigen::Index e = jointConstraints.rows();
  Matrix Cphi(e + (rotationHeld ? 1 : 0), n);
  Cphi.topRows(e) = jointConstraints;
  if (rotationHeld) Cphi.row(e) = J.row(2);

  // Force control: (K_q − K_g) δq = J_pᵀ δF (+ J_φᵀ δMe with J_φ δq = 0); with the rotation free
  // a third column J_φᵀ for the end's rotational compliance.
  Matrix R = Matrix::Zero(n + Cphi.rows(), rotationHeld ? 2 : 3);
  R.topRows(n) = J.topRows(R.cols()).transpose();
  Matrix X;
  double rcond = 0.0;
  if (borderedSolve(H, Cphi, R, options.singularTolerance, X, &rcond)) {
    Eigen::Matrix2d C = Jp * X.topLeftCorner(n, 2);
    C = 0.5 * (C + C.transpose());
    // A backward-stable solve perturbs X by ε κ(B) |X| per column, so C_ij = J_i·X_j by
    // ε κ |J_i| |X_j|: an entry below that is a zero of C_F (e.g. C_yy of a chain whose end is
    // held laterally, at its critical load: the pole of the lateral stiffness), set to 0.
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        out.complianceAccuracy(i, j) = 16.0 * std::numeric_limits<double>::epsilon() / rcond *
                                       0.5 * (Jp.row(i).norm() * X.col(j).head(n).norm() +
                                              Jp.row(j).norm() * X.col(i).head(n).norm());
    C = (C.cwiseAbs().array() <= out.complianceAccuracy.array()).select(0.0, C);
    out.compliance = C;
    if (!rotationHeld) {
      const double cpp = J.row(2).dot(X.col(2).head(n));
      out.rotationalComplianceAccuracy =
          16.0 * std::numeric_limits<double>::epsilon() / rcond * J.row(2).norm() * X.col(2).head(n).norm();
      out.rotationalCompliance = std::abs(cpp) <= out.rotationalComplianceAccuracy ? 0.0 : cpp;
      out.rotationalStiffness = out.rotationalCompliance == 0.0 ? std::numeric_limits<double>::infinity()
                                                                : 1.0 / out.rotationalCompliance;
    }
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
    Matrix Ch(Cphi.rows() + 2, n);  // J_p first: its multipliers are the corner read below
    Ch.topRows(2) = Jp;
    Ch.bottomRows(Cphi.rows()) = Cphi;
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

void endJacobianDerivative(const Chain& chain, const ChainData& data, ConstVectorRef dq, MatrixRef dJ) {
  const int n = chain.size();
  const Vector& l = chain.linkLengths();
  double thetaDot = 0.0, s = 0.0, c = 0.0;
  for (int p = 0; p < n; ++p) {  // θ̇ first (head sums), then the tail sums from the end
    thetaDot += dq[p];
    dJ(2, p) = thetaDot;
  }
  for (int p = n - 1; p >= 0; --p) {
    s += l[p + 1] * std::cos(data.theta[p]) * dJ(2, p);
    c -= l[p + 1] * std::sin(data.theta[p]) * dJ(2, p);
    dJ(0, p) = -s;
    dJ(1, p) = c;
  }
  dJ.row(2).setZero();
}

bool loadedStiffnessDerivative(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                               ConstVectorRef dq, const Wrench& dF, Eigen::Matrix2d& K, Eigen::Matrix2d& dK,
                               const StiffnessOptions& options) {
  const int n = chain.size();
  if (q.size() != n || dq.size() != n)
    throw std::invalid_argument("q and dq must have one angle per segment (size " + std::to_string(n) + ")");
  if (!q.allFinite() || !dq.allFinite() || !F.allFinite() || !dF.allFinite())
    throw std::invalid_argument("q, dq, F and dF must be finite");
  if (std::string why; !options.IsValid(n, &why)) throw std::invalid_argument("StiffnessOptions: " + why);
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n), dJ(3, n);
  endJacobian(data, J);
  endJacobianDerivative(chain, data, dq, dJ);
  Matrix H(n, n);
  totalPotentialHessian(chain, q, F, H);
  // dH = diag(dK_q ⊙ dq) − dK_g, dK_g(i, j) = dh_max(i,j) (eq 27), with S = −J_x, C = J_y.
  Vector dkq(n);
  jointStiffnessDerivative(chain, q, dkq);
  const Vector dh = -dF[0] * data.C - F[0] * dJ.row(1).transpose() - dF[1] * data.S + F[1] * dJ.row(0).transpose();
  Matrix dH(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) dH(i, j) = -dh[std::max(i, j)];
  dH.diagonal() += dkq.cwiseProduct(dq);
  addBodyLoadHessian(options.bodyGenerator, H);
  addBodyLoadHessian(options.bodyGeneratorRate, dH);

  Matrix Cphi(rotationHeld ? 1 : 0, n);
  if (rotationHeld) Cphi.row(0) = J.row(2);
  Matrix R = Matrix::Zero(n + Cphi.rows(), 2);
  R.topRows(n) = J.topRows(2).transpose();
  Matrix X;
  if (!borderedSolve(H, Cphi, R, options.singularTolerance, X)) return false;
  const Matrix Xq = X.topRows(n);
  Eigen::Matrix2d C = J.topRows(2) * Xq;
  C = 0.5 * (C + C.transpose());
  if (!(conditioning(C) > options.singularTolerance)) return false;
  K = C.inverse();
  K = 0.5 * (K + K.transpose());
  const Eigen::Matrix2d dJXq = dJ.topRows(2) * Xq;
  const Eigen::Matrix2d dC = dJXq + dJXq.transpose() - Xq.transpose() * dH * Xq;
  dK = -K * dC * K;
  dK = 0.5 * (dK + dK.transpose());
  return K.allFinite() && dK.allFinite();
}

namespace {

/// xᵀ G(g) y with G(g)_ij = g_max(i,j) (eq 27's generator form) in O(n): the entries with
/// max(i, j) = m are row m up to m and column m above it, x_m Y_m + X_{m−1} y_m = X_m Y_m − X_{m−1} Y_{m−1}
/// with X, Y the prefix sums.
double generatorForm(ConstVectorRef g, ConstVectorRef x, ConstVectorRef y) {
  double sum = 0.0, X = 0.0, Y = 0.0;
  for (Eigen::Index m = 0; m < g.size(); ++m) {
    const double before = X * Y;
    X += x[m];
    Y += y[m];
    sum += g[m] * (X * Y - before);
  }
  return sum;
}

}  // namespace

bool structuredStiffnessDerivative(const Chain& chain, ConstVectorRef q, const Wrench& F, bool rotationHeld,
                                   ConstVectorRef dq, const Wrench& dF, Eigen::Matrix2d& K, Eigen::Matrix2d* dK,
                                   const StiffnessOptions& options) {
  const int n = chain.size();
  if (q.size() != n || (dK && dq.size() != n))
    throw std::invalid_argument("q and dq must have one angle per segment (size " + std::to_string(n) + ")");
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  ChainStructure ws(n);
  jointStiffness(chain, q, ws.kappa);
  loadHessianGenerator(data, F, ws.h);
  if (options.bodyGenerator.size() == n) ws.h -= options.bodyGenerator;  // H + G(γ): the generator h − γ
  assemble(ws.kappa, ws.h, ws);
  // X = P J_pᵀ: [[H, J_φᵀ], [J_φ, 0]] where the rotation is held, H alone where it is free
  const int p = rotationHeld ? 1 : 0;
  const Matrix V = rotationHeld ? Matrix(J.row(2).transpose()) : Matrix(n, 0);
  const Matrix D = Matrix::Zero(p, p);
  if (!factorBordered(ws, V, V, D)) return false;
  Matrix X(n, 2);
  Vector y(p), zero = Vector::Zero(p);
  for (int j = 0; j < 2; ++j)
    if (!solveFactoredBordered(ws, V, V, D, J.row(j).transpose(), zero, X.col(j), y)) return false;
  Eigen::Matrix2d C = J.topRows(2) * X;
  C = 0.5 * (C + C.transpose());
  if (!(conditioning(C) > options.singularTolerance)) return false;
  K = C.inverse();
  K = 0.5 * (K + K.transpose());
  if (!dK) return K.allFinite();
  // dC = dJ_p X + Xᵀ dJ_pᵀ − Xᵀ dH X with dH = diag(dK_q ⊙ dq) − G(dh − dγ) (loadedStiffnessDerivative)
  Matrix dJ(3, n);
  endJacobianDerivative(chain, data, dq, dJ);
  Vector dkq(n);
  jointStiffnessDerivative(chain, q, dkq);
  Vector dh = -dF[0] * data.C - F[0] * dJ.row(1).transpose() - dF[1] * data.S + F[1] * dJ.row(0).transpose();
  if (options.bodyGeneratorRate.size() == n) dh -= options.bodyGeneratorRate;
  const Vector diagonal = dkq.cwiseProduct(dq);
  Eigen::Matrix2d XdHX;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b <= a; ++b)
      XdHX(a, b) = XdHX(b, a) =
          (diagonal.array() * X.col(a).array() * X.col(b).array()).sum() - generatorForm(dh, X.col(a), X.col(b));
  const Eigen::Matrix2d dJX = dJ.topRows(2) * X;
  const Eigen::Matrix2d dC = dJX + dJX.transpose() - XdHX;
  *dK = -K * dC * K;
  *dK = 0.5 * (*dK + dK->transpose());
  return K.allFinite() && dK->allFinite();
}

CartesianStiffness unloadedStiffness(const Chain& chain, ConstVectorRef q, bool rotationHeld,
                                     const StiffnessOptions& options) {
  return loadedStiffness(chain, q, Wrench::Zero(), rotationHeld, options);
}

}  // namespace buckle::mechanics
