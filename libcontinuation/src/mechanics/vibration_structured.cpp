// The structured O(n) route of the vibration analysis (vibration.h, pencil_structure.h): the
// pencil of the free joints, its lowest eigenvalues by certified counts and the mode shapes by
// inverse iteration with the pencil's O(n) solves.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/pencil_structure.h"
#include "buckle/mechanics/vibration.h"

namespace buckle::mechanics {

namespace {

// The search's tolerance unit: 1e-6 of the pencil's scale, so that the low frequencies of a long
// chain (ω₁² ≪ max ω²) are still resolved to many digits; isolation by counts does not depend on
// it and the polish converges superlinearly, so it costs a few more evaluations, not more bisection.
constexpr double kSearchUnit = 1e-6;
constexpr double kSearchTolerance = 1e-13;
// Inverse iteration: a shift this far below ω² relative to the gap to the neighbouring ω²
// (the error shrinks by about this factor per step), moved away while a pivot of the unpivoted
// LDLᵀ is below kPivotFloor of the δ/scale expected there.
constexpr double kShiftGap = 1e-3;
constexpr double kPivotFloor = 1e-6;
constexpr int kMaxIterations = 8;

}  // namespace

struct VibrationAnalysis::Structured {
  explicit Structured(const Chain& chain, const InertiaData& inertia)
      : pencil(chain.size()),
        mass(massGenerators(chain, inertia)),
        data(chain),
        kappa(chain.size()),
        h(chain.size()),
        J(3, chain.size()),
        C(3, chain.size()),
        locked(size_t(chain.size()), 0),
        xi(chain.size()),
        z(chain.size()),
        Mz(chain.size()),
        BtB(3, 3) {
    freeJoints.reserve(size_t(chain.size()));
  }

  PencilStructure pencil;
  MassGenerators mass;
  ChainData data;
  Vector kappa, h;
  Matrix J, C;
  std::vector<char> locked;
  std::vector<int> freeJoints;
  // the previous call's constraints and values: the warm start of the eigenvalue search
  std::vector<int> lastHeld, lastLocked;
  Eigen::Index lastWallRows = 0;
  Vector lastValues, values;
  // inverse iteration: the current iterate, the next and its mass product; the modes' M ξ
  Vector xi, z, Mz;
  Matrix modesTheta, massModes;
  PencilStructure::SmallMatrix BtB;
  Matrix couplingFree;  // the self contacts' coupling columns on the free joints
};

void VibrationAnalysis::StructuredDeleter::operator()(Structured* p) const { delete p; }

namespace {

/// The pencil of the free joints (pencil_structure.h) at the kinematics in `data`. Locking joint
/// f fixes q_f = 0, so the links from one free joint to the next turn as one body: with groups
/// I_c = [f_c, f_{c+1}) of links, M_θ'(c, c) = Σ_{k,l ∈ I_c} M_θ(k, l), M_θ'(c, c') = P_cᵀR_{c'}
/// (c > c') with P_c = Σ_{k∈I_c} p_k, R_c = Σ_{k∈I_c} r_k; the links before the first free joint
/// do not move. H restricted keeps K_q diagonal and K_g(i, j) = h_max(i,j) (eq 27), so T' is
/// assembled from κ and h at the free joints as in chain_structure.h.
void assembleFreePencil(const std::vector<int>& free, const Vector& kappa, const Vector& h,
                        const MassGenerators& mass, const ChainData& data, PencilStructure& ws) {
  const int m = int(free.size());
  const int n = int(kappa.size());
  ws.n = m;
  for (int c = 0; c < m; ++c) {
    const double kc = kappa[free[size_t(c)]], hc = h[free[size_t(c)]];
    const double kn = c + 1 < m ? kappa[free[size_t(c) + 1]] : 0.0;
    const double hn = c + 1 < m ? h[free[size_t(c) + 1]] : 0.0;
    ws.t[c] = kc + kn - (hc - hn);
    if (c + 1 < m) ws.e[c] = -kn;
    const int end = c + 1 < m ? free[size_t(c) + 1] : n;
    double A = 0.0, P0 = 0.0, P1 = 0.0, R0 = 0.0, R1 = 0.0;
    for (int k = free[size_t(c)]; k < end; ++k) {
      const double ck = std::cos(data.theta[k]), sk = std::sin(data.theta[k]);
      const double p0 = mass.weight[k] * ck, p1 = mass.weight[k] * sk;
      A += mass.diagonal[k] + 2.0 * (p0 * R0 + p1 * R1);  // M_θ(k, l) = p_kᵀ r_l for the l < k of the group
      P0 += p0;
      P1 += p1;
      R0 += mass.length[k] * ck;
      R1 += mass.length[k] * sk;
    }
    ws.a[c] = A;
    ws.p(c, 0) = P0;
    ws.p(c, 1) = P1;
    ws.r(c, 0) = R0;
    ws.r(c, 1) = R1;
  }
  double scale = 0.0;
  for (int c = 0; c < m; ++c) {
    double row = std::abs(ws.t[c]);
    if (c > 0) row += std::abs(ws.e[c - 1]);
    if (c + 1 < m) row += std::abs(ws.e[c]);
    scale = std::max(scale, row / ws.a[c]);
  }
  ws.scale = scale > 0.0 ? scale : 1.0 / ws.a.head(m).maxCoeff();  // T = 0: every ω² is zero
}

/// Inverse iteration for mode j of the pencil on ker Bᵀ at the converged ω² = values[j], the
/// shift below it by kShiftGap of the gap to its neighbours (values has the next one when known).
/// The iterate is M_θ-orthogonalised against the modes before it (columns of modes, their M ξ in
/// massModes), so close or repeated ω² span their invariant subspace. False if it did not converge.
bool inverseIteration(PencilStructure& ws, const Vector& values, int j, double floor, Matrix& modes,
                      Matrix& massModes, PencilStructure::SmallMatrix& BtB, Vector& xi, Vector& z, Vector& Mz) {
  // r constraint columns, b with the coupling's (its rows Bᵀz − E y = 0: S gains diag(0, E))
  const int n = ws.n, r = ws.rank, b = ws.rank + ws.couplingCount;
  double gap = std::numeric_limits<double>::infinity();
  if (j > 0) gap = std::min(gap, values[j] - values[j - 1]);
  if (j + 1 < values.size()) gap = std::min(gap, values[j + 1] - values[j]);
  if (!std::isfinite(gap)) gap = ws.scale;
  double delta = std::max(kShiftGap * gap, floor);
  for (int attempt = 0;; ++attempt) {
    factorizePencil(ws, values[j] - delta, false);
    // near ω² the smallest pivot is naturally ~δ/scale; one far below that is a singular leading block
    if (!ws.singular && ws.minPivotRatio >= kPivotFloor * delta / ws.scale) break;
    if (attempt == 8) return false;
    delta *= 16.0;  // a moved shift: the unpivoted LDLᵀ met a (nearly) singular leading block
  }
  auto xiH = xi.head(n), zH = z.head(n), MzH = Mz.head(n);
  Eigen::PartialPivLU<PencilStructure::SmallMatrix> schur, gram;
  if (b > 0) {
    for (int c = 0; c < b; ++c) {
      ws.X.col(c).head(n) = ws.B.col(c).head(n);
      solvePencil(ws, ws.X.col(c).head(n));
    }
    ws.S.noalias() = ws.B.topLeftCorner(n, b).transpose() * ws.X.topLeftCorner(n, b);
    for (int c = 0; c < ws.couplingCount; ++c) ws.S(r + c, r + c) += ws.couplingSign[c];
    schur.compute(ws.S);
  }
  if (r > 0) {
    BtB.resize(r, r);
    BtB.noalias() = ws.B.topLeftCorner(n, r).transpose() * ws.B.topLeftCorner(n, r);
    gram.compute(BtB);
  }
  // the constraint Bᵀξ = 0 (C v = 0 for v = U⁻ᵀξ), restored after every solve
  auto project = [&](Eigen::Ref<Vector> x) {
    if (r == 0) return;
    const PencilStructure::SmallMatrix c = ws.B.topLeftCorner(n, r).transpose() * x;
    x.noalias() -= ws.B.topLeftCorner(n, r) * gram.solve(c);
  };
  auto orthonormalise = [&]() {
    for (int pass = 0; pass < 2; ++pass)
      for (int c = 0; c < j; ++c) zH -= massModes.col(c).head(n).dot(zH) * modes.col(c).head(n);
    applyPencilMass(ws, zH, MzH);
    const double norm = std::sqrt(std::max(zH.dot(MzH), 0.0));
    if (!(norm > 0.0) || !std::isfinite(norm)) return false;
    zH /= norm;
    MzH /= norm;
    return true;
  };
  for (int i = 0; i < n; ++i) zH[i] = 1.0 + 0.5 * std::sin(1.618 * (i + 1) + 0.3 * j);  // no mode is orthogonal to it
  project(zH);
  if (!orthonormalise()) return false;
  bool converged = false;
  for (int it = 0; it < kMaxIterations && !converged; ++it) {
    xiH = zH;
    zH = MzH;  // (G_σ with the border) z = M ξ
    solvePencil(ws, zH);
    if (b > 0) {
      const PencilStructure::SmallMatrix c = ws.B.topLeftCorner(n, b).transpose() * zH;
      zH.noalias() -= ws.X.topLeftCorner(n, b) * schur.solve(c);
      project(zH);
    }
    if (!orthonormalise()) return false;
    if (zH.dot(xiH) < 0.0) zH = -zH, MzH = -MzH;
    converged = (zH - xiH).cwiseAbs().maxCoeff() <= 1e-13 * zH.cwiseAbs().maxCoeff();
  }
  modes.col(j).head(n) = zH;
  massModes.col(j).head(n) = MzH;
  return zH.allFinite();
}

}  // namespace

VibrationModes VibrationAnalysis::structuredModes(ConstVectorRef q, const Wrench& F, const std::vector<int>& held,
                                                  const std::vector<int>& lockedJoints, const Matrix& wallRows,
                                                  int count, bool shapes, const Vector& bodyGenerator,
                                                  const Matrix& couplingColumns, const Vector& couplingSigns) {
  const int n = chain_.size(), coupled = int(couplingColumns.cols());
  for (int c : held)
    if (c < 0 || c > 2) throw std::invalid_argument("held end coordinate " + std::to_string(c) + " outside 0…2");
  const Eigen::Index rows = Eigen::Index(held.size()) + wallRows.rows();
  if (rows > 3 || rows + coupled > PencilStructure::kMaxBorder) {
    // the pencil is bordered by at most three rows, and kMaxBorder columns with the coupling's (pencil_structure.h)
    VibrationModes dense =
        denseModes(q, F, held, lockedJoints, wallRows, count, shapes, bodyGenerator, couplingColumns, couplingSigns);
    dense.fallback = std::to_string(rows) + " held and contact rows and " + std::to_string(coupled) +
                     " self-contact coupling columns (the structured route borders at most 3 rows and " +
                     std::to_string(PencilStructure::kMaxBorder) + " columns): the dense route";
    return dense;
  }
  if (!structured_) structured_.reset(new Structured(chain_, inertia_));
  Structured& s = *structured_;
  std::fill(s.locked.begin(), s.locked.end(), 0);
  for (int j : lockedJoints) {
    if (j < 0 || j >= n)
      throw std::invalid_argument("locked joint " + std::to_string(j) + " outside 0…" + std::to_string(n - 1));
    s.locked[size_t(j)] = 1;
  }
  s.freeJoints.clear();
  for (int i = 0; i < n; ++i)
    if (!s.locked[size_t(i)]) s.freeJoints.push_back(i);
  const int m = int(s.freeJoints.size());

  forwardKinematics(chain_, q, s.data);
  jointStiffness(chain_, q, s.kappa);
  loadHessianGenerator(s.data, F, s.h);  // K_q − K_g(F), eq 27
  if (bodyGenerator.size() == n) s.h -= bodyGenerator;  // the body loads' generator h − γ (eq B3)
  VibrationModes out;
  out.route = VibrationRoute::Structured;
  PencilStructure& ws = s.pencil;
  ws.rank = 0;
  if (m > 0) {
    assembleFreePencil(s.freeJoints, s.kappa, s.h, s.mass, s.data, ws);
    if (!pencilMassPositive(ws))
      throw std::runtime_error("the mass matrix is not positive definite on the constraints at this point");
    endJacobian(s.data, s.J);
    auto C = s.C.topLeftCorner(rows, m);
    for (size_t row = 0; row < held.size(); ++row)
      for (int c = 0; c < m; ++c) C(Eigen::Index(row), c) = s.J(held[row], s.freeJoints[size_t(c)]);
    for (Eigen::Index k = 0; k < wallRows.rows(); ++k)
      for (int c = 0; c < m; ++c) C(Eigen::Index(held.size()) + k, c) = wallRows(k, s.freeJoints[size_t(c)]);
    setPencilConstraints(ws, C, kConstraintRankTolerance);
    if (coupled > 0) {  // the self contacts' rank-2 terms on the free joints (selfConstraintTerms)
      s.couplingFree.resize(m, coupled);
      for (int c = 0; c < m; ++c) s.couplingFree.row(c) = couplingColumns.row(s.freeJoints[size_t(c)]);
      setPencilCoupling(ws, s.couplingFree, couplingSigns);
    }
  }
  const int p = m - ws.rank;
  out.dimension = p;
  const int k = std::min(count, p);
  out.omegaSquared.resize(k);
  if (k == 0) return out;

  // the next ω² too when shapes are wanted: the last shape's shift is placed by its gap
  const int want = shapes ? std::min(k + 1, p) : k;
  const bool warm = held == s.lastHeld && lockedJoints == s.lastLocked && wallRows.rows() == s.lastWallRows &&
                    s.lastValues.size() > 0;
  Vector& values = s.values;  // (workspace: sized once, resized only when `want` changes)
  values.resize(want);
  pencilEigenvalues(ws, 0, want, values, kSearchTolerance * kSearchUnit, warm ? &s.lastValues : nullptr);
  s.lastHeld = held;
  s.lastLocked = lockedJoints;
  s.lastWallRows = wallRows.rows();
  s.lastValues = values;
  out.omegaSquared = values.head(k);
  if (!shapes) return out;

  s.modesTheta.resize(n, k);
  s.massModes.resize(n, k);
  const double floor = 100.0 * kSearchTolerance * kSearchUnit * ws.scale;
  for (int j = 0; j < k; ++j) {
    if (!inverseIteration(ws, values, j, floor, s.modesTheta, s.massModes, s.BtB, s.xi, s.z, s.Mz)) {
      VibrationModes dense =
          denseModes(q, F, held, lockedJoints, wallRows, count, true, bodyGenerator, couplingColumns, couplingSigns);
      dense.fallback = "the structured inverse iteration did not converge for mode " + std::to_string(j + 1) +
                       ": shapes (and values) from the dense route";
      return dense;
    }
  }
  // v = U'⁻ᵀξ on the free joints (q_{f_c} = θ'_c − θ'_{c−1}), zero at the locked ones
  out.shapes = Matrix::Zero(n, k);
  for (int j = 0; j < k; ++j) {
    for (int c = 0; c < m; ++c)
      out.shapes(s.freeJoints[size_t(c)], j) = s.modesTheta(c, j) - (c > 0 ? s.modesTheta(c - 1, j) : 0.0);
    Eigen::Index at = 0;
    out.shapes.col(j).cwiseAbs().maxCoeff(&at);
    if (out.shapes(at, j) < 0.0) out.shapes.col(j) = -out.shapes.col(j);
  }
  return out;
}

}  // namespace buckle::mechanics
