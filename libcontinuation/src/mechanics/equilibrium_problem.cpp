#include "buckle/mechanics/equilibrium_problem.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "buckle/mechanics/chain_solver.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/validation.h"

namespace buckle::mechanics {

using continuation::ConstVectorRef;
using continuation::MatrixRef;
using continuation::ProblemWorkspace;
using continuation::VectorRef;
using continuation::workspaceAs;

namespace {
// Up to this chain length stability() takes the inertia alone from smallDenseInertia (unrolled
// for n ≤ 4) rather than two robust Sturm counts: per call with one held row, n = 2: 0.7 k
// against 1.4 k instructions, n = 3: 1.1 k against 1.7 k, n = 4: 2.6 k against 2.0 k
// (benchmarks/RESULTS.md, "Cheaper points, round 5").
constexpr int kDenseInertiaUpTo = 3;
// Up to this chain length the eigenvalues (stability() with eigenvalues wanted, and the
// certified counting's stabilityEigenvalues()) come from one dense solve of all of them rather
// than Newton on the O(n) counts: the crossover of whole race runs lies between n = 15 and 20
// (benchmarks/RESULTS.md). Below kSmallDense, the size of the dense route's fixed storage.
constexpr int kDenseSpectrumUpTo = 16;
static_assert(kDenseSpectrumUpTo <= kSmallDense);

// The caches' bitwise key comparison. memcmp is a library call of ≈ 25 instructions, more than
// comparing the 2–8 words of a short chain's key one by one (each memcpy of 8 bytes is one load).
bool sameBits(const double* a, const double* b, size_t count) {
  if (count > 8) return std::memcmp(a, b, sizeof(double) * count) == 0;
  for (size_t i = 0; i < count; ++i) {
    std::uint64_t x, y;
    std::memcpy(&x, a + i, sizeof x);
    std::memcpy(&y, b + i, sizeof y);
    if (x != y) return false;
  }
  return true;
}
}  // namespace

std::string EquilibriumOptions::validate(const std::string& prefix) const {
  namespace cont = continuation;
  if (!heldRange.active()) return {};
  return cont::firstProblem(
      {cont::require(heldRange.coordinate <= 2, prefix, "heldRange.coordinate", "must be -1 (none), 0, 1 or 2"),
       cont::require(std::isfinite(heldRange.low) && std::isfinite(heldRange.high) && heldRange.low <= heldRange.high,
                     prefix, "heldRange.low", "must be finite and not exceed heldRange.high")});
}

EquilibriumProblem::EquilibriumProblem(const Chain& chain, const EndCondition& end, const Eigen::Vector3d& direction,
                                       EquilibriumOptions options, const ControlDirection& control,
                                       const BodyLoads& body)
    : chain_(chain),
      end_(end),
      direction_(direction),
      options_(options),
      held_(end.heldIndices()),
      loaded_(end.loadedIndices()),
      control_(control),
      domainUpper_(chain.size()),
      domainLower_(chain.size()),
      body_(body),
      bodyTerms_(chain, body) {
  static const char* names[3] = {"x", "y", "phi"};
  for (int c = 0; c < 3; ++c) {
    requireFinite(std::string("end value ") + names[c], end.value[c]);
    requireFinite(std::string("load path direction ") + names[c], direction[c]);
  }
  if (std::string why; !options_.IsValid(&why)) throw std::invalid_argument("EquilibriumOptions: " + why);
  if (control_.active()) {
    const int n = chain_.size();
    if (control_.rates.rows() != n)
      throw std::invalid_argument("control direction: rates for " + std::to_string(control_.rates.rows()) +
                                  " segments, the chain has " + std::to_string(n));
    requireFinite("control direction origin", control_.origin);
    for (int i = 0; i < n; ++i) {
      requireFinite("control direction rate dL1_0 of segment " + std::to_string(i + 1), control_.rates(i, 0));
      requireFinite("control direction rate dL2_0 of segment " + std::to_string(i + 1), control_.rates(i, 1));
    }
    freeLength1_.resize(n);
    freeLength2_.resize(n);
    for (int i = 0; i < n; ++i) {
      freeLength1_[i] = chain_.segment(i).parameters().L1_0;
      freeLength2_[i] = chain_.segment(i).parameters().L2_0;
    }
  }
  const double overshoot = options_.jointLimitsAsBoundaries ? kGeometricOvershoot : 0.0;
  for (int i = 0; i < chain_.size(); ++i) {
    domainUpper_[i] = chain_.segment(i).geometricUpperLimit() + overshoot;
    domainLower_[i] = chain_.segment(i).geometricLowerLimit() - overshoot;
  }
}

EquilibriumProblem::Workspace::Workspace(const EquilibriumProblem& problem)
    : data(problem.chain_),
      J(3, problem.segments()),
      grad(problem.segments()),
      stiff(problem.segments()),
      stiffRate(problem.segments()),
      cachedQ(problem.segments()),
      sinHalf(problem.segments()),
      cosHalf(problem.segments()),
      work(problem.segments()),
      structure(problem.segments()),
      heldRows(problem.heldCount(), problem.segments()),
      spectrumKey(problem.dimension() + 1),
      bodyTerms(problem.bodyTerms_),
      bodyWork(problem.segments()),
      rateKappa(problem.segments()),
      rateGenerator(problem.segments()),
      rateS(problem.segments()),
      rateC(problem.segments()),
      eigenvector(problem.segments()),
      hessianTimes(problem.segments()) {
  if (problem.controlled()) {
    controlGrad.resize(problem.segments());
    controlStiff.resize(problem.segments());
  }
  structure.typicalScale =
      problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();  // the inertia's zero floor
}

std::unique_ptr<ProblemWorkspace> EquilibriumProblem::createWorkspace() const {
  return std::make_unique<Workspace>(*this);
}

bool EquilibriumProblem::prepare(Workspace& d, const ConstVectorRef& u, double lambda) const {
  const int n = chain_.size();
  for (Eigen::Index k = n; k < u.size(); ++k)
    if (!std::isfinite(u[k])) return false;
  const auto q = u.head(n);
  // Bitwise: a q that merely compares equal (−0.0 vs 0.0) is evaluated afresh.
  const bool controlled = control_.active();
  if (d.cacheValid && sameBits(q.data(), d.cachedQ.data(), size_t(n)) &&
      (!controlled || sameBits(&lambda, &d.cachedLambda, 1)))
    return true;
  d.cacheValid = false;
  if (!inDomain(u)) return false;
  // One sincos per joint serves its springs and the link directions (chain.h).
  const double t = lambda - control_.origin;
  for (int i = 0; i < n; ++i) {
    const double sh = std::sin(0.5 * q[i]), ch = std::cos(0.5 * q[i]);  // one sincos call at -O2
    d.sinHalf[i] = sh;
    d.cosHalf[i] = ch;
    Jet3 e;
    if (controlled) {
      // The same sums as chainWithControls(): the point at λ is bit for bit the chain at λ.
      const double r1 = control_.rates(i, 0), r2 = control_.rates(i, 1);
      const double L1 = freeLength1_[i] + t * r1, L2 = freeLength2_[i] + t * r2;
      if (!(L1 > 0.0 && L2 > 0.0)) return false;  // no spring of non-positive free length (segment.cpp)
      Jet3 rate;
      e = chain_.segment(i).energyJet(q[i], sh, ch, L1, L2, r1, r2, rate);
      d.controlGrad[i] = rate.d1;
      d.controlStiff[i] = rate.d2;
    } else {
      e = chain_.segment(i).energyJet(q[i], sh, ch);
    }
    d.grad[i] = e.d1;
    d.stiff[i] = e.d2;
    d.stiffRate[i] = e.d3;
  }
  forwardKinematics(chain_, q, d.sinHalf.data(), d.cosHalf.data(), d.data);
  endJacobian(d.data, d.J);
  if (d.bodyTerms.active()) d.bodyTerms.update(d.data);
  d.cachedQ = q;
  d.cachedLambda = lambda;
  d.cacheValid = true;
  return true;
}

Vector EquilibriumProblem::initialGuess(ConstVectorRef q, double lambda) const {
  const int n = chain_.size();
  const int m = heldCount();
  Vector u(n + m);
  u.head(n) = q;
  if (m == 0) return u;
  ChainData data(chain_);
  forwardKinematics(chain_, q, data);
  Matrix J(3, n);
  endJacobian(data, J);
  // ∂E/∂q − J_lᵀ F_l = J_hᵀ r in the least-squares sense
  Vector rhs(n);
  energyGradient(controlled() ? chainAt(lambda) : chain_, q, rhs);
  const Eigen::Vector3d value = prescribed(lambda);
  for (int c : loaded_) rhs -= J.row(c).transpose() * value[c];
  if (bodyTerms_.active()) {  // ∂V/∂q = −τ (eq B2)
    BodyLoadTerms terms = bodyTerms_;
    terms.update(data);
    Vector tau(n);
    terms.torques(lambda, tau);
    rhs -= tau;
  }
  Matrix Jh(n, m);
  for (int k = 0; k < m; ++k) Jh.col(k) = J.row(held_[size_t(k)]).transpose();
  u.tail(m) = Jh.colPivHouseholderQr().solve(rhs);
  return u;
}

// The geometric limits: the spring model (segment.cpp) is smooth up to and at a geometric limit
// — the closing spring's length L → 0 is evaluated without 0/0 — and continues analytically a
// little beyond it. With the joint limits as boundaries the tracer needs that continuation: it
// detects a boundary by a step that ends on its far side and then locates the crossing exactly
// (boundary() below has no margin), so points up to kGeometricOvershoot past a geometric limit
// are evaluated; the branch stops at the located limit and never reports them. Farther out, or
// with the limits not traced as boundaries, points beyond a geometric limit are refused: there
// the triangles would overlap and the model no longer describes the mechanism.

bool EquilibriumProblem::inDomain(const ConstVectorRef& u) const {
  const int n = chain_.size();
  // Finite bounds: the negated test also refuses ±∞ and NaN.
  for (int i = 0; i < n; ++i)
    if (!(u[i] <= domainUpper_[i] && u[i] >= domainLower_[i])) return false;
  for (int k = n; k < u.size(); ++k)
    if (!std::isfinite(u[k])) return false;
  return true;
}

bool EquilibriumProblem::residual(ProblemWorkspace& ws, ConstVectorRef u, double lambda, VectorRef F) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  const Wrench W = wrench(u, lambda);
  auto top = F.head(n);
  top = d.grad;
  top.noalias() -= d.J.transpose() * W;
  if (d.bodyTerms.active()) {  // + ∂V/∂q = −τ(λ) (eq B2)
    d.bodyTerms.torques(lambda, d.bodyWork);
    top -= d.bodyWork;
  }
  const Eigen::Vector3d value = prescribed(lambda);
  for (size_t k = 0; k < held_.size(); ++k) F[n + int(k)] = value[held_[k]] - d.data.pose[held_[k]];
  return true;
}

bool EquilibriumProblem::jacobian(ProblemWorkspace& ws, ConstVectorRef u, double lambda, MatrixRef Fu,
                                  VectorRef Flambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  loadGenerator(d, u, lambda, d.work);
  // Plain pointer loops (n + m is tiny in the hot path: Eigen's expressions on Refs, a max() per
  // entry and the vectorised fills' alias checks cost more than the arithmetic there; the
  // entries and their rounding are those of the textbook loops).
  double* const a = Fu.data();
  const Eigen::Index ld = Fu.outerStride();
  const double* const w = d.work.data();
  const double* const kq = d.stiff.data();
  // K_q − K_g with K_g(i, j) = h_max(i,j)  (eq 27): column j is −h_j down to the diagonal, −h_i below
  for (int j = 0; j < n; ++j) {
    double* const col = a + j * ld;
    const double wj = -w[j];
    for (int i = 0; i < j; ++i) col[i] = wj;
    col[j] = wj + kq[j];
    for (int i = j + 1; i < n; ++i) col[i] = -w[i];
  }
  const int m = heldCount();
  const double* const J = d.J.data();  // 3 × n, column-major
  for (int k = 0; k < m; ++k) {
    const int h = held_[size_t(k)];
    double* const col = a + (n + k) * ld;
    for (int i = 0; i < n; ++i) col[i] = a[i * ld + n + k] = -J[h + 3 * i];
    for (int l = 0; l < m; ++l) col[n + l] = 0.0;
    Flambda[n + k] = direction_[h];
  }
  // F_λ = −J_lᵀ d_l, summed over the loaded coordinates in their order for each i.
  double* const fl = Flambda.data();
  for (int i = 0; i < n; ++i) fl[i] = 0.0;
  for (int c : loaded_) {
    const double d = direction_[c];
    for (int i = 0; i < n; ++i) fl[i] -= J[c + 3 * i] * d;
  }
  if (control_.active())
    for (int i = 0; i < n; ++i) fl[i] += d.controlGrad[i];  // ∂²E/∂q∂λ of the moving free lengths
  if (d.bodyTerms.active())
    for (int i = 0; i < n; ++i) fl[i] -= d.bodyTerms.rateTorques()[i];  // ∂²V/∂q∂λ = −τ' (eq B2)
  return true;
}

bool EquilibriumProblem::jacobianDirectionalDerivative(ProblemWorkspace& ws, ConstVectorRef u, double lambda,
                                                       ConstVectorRef du, double dlambda, MatrixRef dFu,
                                                       VectorRef dFlambda) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  const int m = heldCount();
  const Wrench W = wrench(u, lambda);
  Wrench dW = dlambda * direction_;
  for (int k = 0; k < m; ++k) dW[held_[size_t(k)]] = du[n + k];
  // dJ rows: (−dS, dC, 0) with the tail-sum derivatives of stiffness.h
  Matrix dJ(3, n);
  endJacobianDerivative(chain_, d.data, du.head(n), dJ);
  const Vector dS = -dJ.row(0).transpose(), dC = dJ.row(1).transpose();
  // dh_m for h_m = −Fx C_m − Fy S_m
  Vector dh = -dW[0] * d.data.C - W[0] * dC - dW[1] * d.data.S - W[1] * dS;
  if (d.bodyTerms.active()) {  // − dγ (eq B5); F_λ's −τ' moves with q by Γ' dq
    bodyGeneratorDerivative(d, du.head(n), lambda, dlambda);
    dh -= d.bodyWork;
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) dFu(i, j) = -dh[std::max(i, j)];
  for (int i = 0; i < n; ++i) dFu(i, i) += d.stiffRate[i] * du[i];  // E‴ at (q, λ), from the cache
  for (int k = 0; k < m; ++k) {
    dFu.block(0, n + k, n, 1) = -dJ.row(held_[size_t(k)]).transpose();
    dFu.block(n + k, 0, 1, n) = -dJ.row(held_[size_t(k)]);
  }
  if (m > 0) dFu.bottomRightCorner(m, m).setZero();
  dFlambda.setZero();
  for (int cc : loaded_) dFlambda.head(n) -= dJ.row(cc).transpose() * direction_[cc];
  if (d.bodyTerms.active()) {
    maxIndexProduct(d.bodyTerms.rateGenerator(), du.head(n), d.bodyWork);
    dFlambda.head(n) += d.bodyWork;
  }
  if (control_.active()) {
    // K_q moves with λ; F_λ's control part ∂²E/∂q∂λ moves with q_i (∂/∂λ of it is zero)
    for (int i = 0; i < n; ++i) {
      dFu(i, i) += d.controlStiff[i] * dlambda;
      dFlambda[i] += d.controlStiff[i] * du[i];
    }
  }
  return true;
}

bool EquilibriumProblem::jacobianApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                       VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  const int m = heldCount();
  Vector h(n);
  loadGenerator(d, u, lambda, h);
  const double xl = x[n + m];  // the λ component
  // (K_g x)_i = h_i Σ_{j≤i} x_j + Σ_{j>i} h_j x_j  (K_g(i, j) = h_max(i,j), eq 27)
  double suffix = 0.0;
  for (int i = n - 1; i >= 0; --i) {
    y[i] = -suffix;
    suffix += h[i] * x[i];
  }
  double prefix = 0.0;
  for (int i = 0; i < n; ++i) {
    prefix += x[i];
    y[i] += d.stiff[i] * x[i] - h[i] * prefix;
  }
  for (int c : loaded_) y.head(n) -= (xl * direction_[c]) * d.J.row(c).transpose();
  if (control_.active()) y.head(n) += xl * d.controlGrad;
  if (d.bodyTerms.active()) y.head(n) -= xl * d.bodyTerms.rateTorques();
  for (int k = 0; k < m; ++k) {
    const int c = held_[size_t(k)];
    y.head(n) -= x[n + k] * d.J.row(c).transpose();
    y[n + k] = -d.J.row(c).dot(x.head(n)) + direction_[c] * xl;
  }
  return y.allFinite();
}

bool EquilibriumProblem::jacobianTransposeApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef w,
                                                VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  const int n = chain_.size();
  const int N = dimension();
  Vector x(N + 1);
  x.head(N) = w;
  x[N] = 0.0;
  if (!jacobianApply(ws, u, lambda, x, y.head(N))) return false;  // F_u is symmetric
  // F_λ · w: −Σ_loaded dir_c J_c·w_q + Σ_held dir_c w_r
  double dot = 0.0;
  for (int c : loaded_) dot -= direction_[c] * d.J.row(c).dot(w.head(n));
  for (int k = 0; k < heldCount(); ++k) dot += direction_[held_[size_t(k)]] * w[n + k];
  if (control_.active()) dot += d.controlGrad.dot(w.head(n));  // jacobianApply prepared (q, λ)
  if (d.bodyTerms.active()) dot -= d.bodyTerms.rateTorques().dot(w.head(n));
  y[N] = dot;
  return std::isfinite(dot);
}

bool EquilibriumProblem::secondDerivativeApply(ProblemWorkspace& ws, ConstVectorRef u, double lambda, ConstVectorRef x,
                                               ConstVectorRef z, VectorRef y) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  const int m = heldCount();
  const Wrench W = wrench(u, lambda);
  Wrench dW = x[n + m] * direction_;  // the wrench along x: loads with x_λ, reactions with x_r
  for (int k = 0; k < m; ++k) dW[held_[size_t(k)]] = x[n + k];
  Matrix dJ(3, n);
  endJacobianDerivative(chain_, d.data, x.head(n), dJ);
  // dh_m along x for h_m = −Fx C_m − Fy S_m, with dC = dJ_y, dS = −dJ_x (as in
  // jacobianDirectionalDerivative)
  Vector dh = -dW[0] * d.data.C - W[0] * dJ.row(1).transpose() - dW[1] * d.data.S + W[1] * dJ.row(0).transpose();
  if (d.bodyTerms.active()) {  // − dγ along x (eq B5, x_λ included)
    bodyGeneratorDerivative(d, x.head(n), lambda, x[n + m]);
    dh -= d.bodyWork;
  }
  maxIndexProduct(dh, z.head(n), y.head(n));
  y.head(n) = -y.head(n);
  if (d.bodyTerms.active()) {  // F_λ's −τ' along x_q, times z_λ: Γ' x_q z_λ
    maxIndexProduct(d.bodyTerms.rateGenerator(), x.head(n), d.bodyWork);
    y.head(n) += z[n + m] * d.bodyWork;
  }
  y.head(n) += d.stiffRate.cwiseProduct(x.head(n)).cwiseProduct(z.head(n));  // E‴ at (q, λ)
  if (control_.active())  // ∂K_q/∂λ (x_q z_λ + x_λ z_q); ∂²F/∂λ² = 0
    y.head(n) += d.controlStiff.cwiseProduct(z[n + m] * x.head(n) + x[n + m] * z.head(n));
  for (int c : loaded_) y.head(n) -= (z[n + m] * direction_[c]) * dJ.row(c).transpose();
  for (int k = 0; k < m; ++k) {
    const int c = held_[size_t(k)];
    y.head(n) -= z[n + k] * dJ.row(c).transpose();
    y[n + k] = -dJ.row(c).dot(z.head(n));
  }
  return y.allFinite();
}

bool EquilibriumProblem::stabilityOperator(ProblemWorkspace& ws, ConstVectorRef u, double lambda, Matrix& H,
                                           Matrix& C) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!prepare(d, u, lambda)) return false;
  const int n = chain_.size();
  H.resize(n, n);
  C.resize(heldCount(), n);
  // totalPotentialHessian() from the cached kinematics and K_q
  loadGenerator(d, u, lambda, d.work);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) H(i, j) = -d.work[std::max(i, j)];
  H.diagonal() += d.stiff;
  for (int k = 0; k < heldCount(); ++k) C.row(k) = d.J.row(held_[size_t(k)]);
  return true;
}

void EquilibriumProblem::assembleFromCache(Workspace& d, const ConstVectorRef& u, double lambda,
                                           ChainStructure& ws) const {
  loadGenerator(d, u, lambda, ws.h);
  assemble(d.stiff, ws.h, ws);
}

bool EquilibriumProblem::assembleStructure(ProblemWorkspace& ws, ConstVectorRef u, double lambda,
                                           ChainStructure& structure, MatrixRef J) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!std::isfinite(lambda) || !prepare(d, u, lambda)) return false;
  assembleFromCache(d, u, lambda, structure);
  J = d.J;
  return true;
}

bool EquilibriumProblem::smallDenseSpectrum(Workspace& d, const ConstVectorRef& u, double lambda) const {
  const size_t N = size_t(u.size());
  // Bitwise, like prepare(d, ): the key was stored after prepare(d, u) accepted these very bits, so a
  // hit needs neither the domain check nor the q-cache (which may hold another q by now, e.g.
  // the certified counting's point off the branch).
  if (d.spectrumSize >= 0 && size_t(d.spectrumKey.size()) == N + 1 && sameBits(u.data(), d.spectrumKey.data(), N) &&
      sameBits(&lambda, d.spectrumKey.data() + N, 1))
    return true;
  d.spectrumSize = -1;
  if (!prepare(d, u, lambda)) return false;
  // The dense route reads h and κ alone (smallDenseInertia), not the tridiagonal form assemble()
  // adds for the O(n) counts (every structured route assembles for itself).
  loadGenerator(d, u, lambda, d.structure.h);
  d.structure.kappa = d.stiff;
  const int n = chain_.size();
  for (int k = 0; k < heldCount(); ++k) d.heldRows.row(k) = d.J.row(held_[size_t(k)]);
  // All n − rank values: the eigen-solve computes them anyway (`count` only limits the copy), so
  // any later request at this point is served bit for bit as a fresh solve would serve it.
  int found = 0;
  d.spectrumInertia = smallDenseInertia(d.structure, d.heldRows, n, d.spectrum.head(n), found);
  if (size_t(d.spectrumKey.size()) != N + 1) d.spectrumKey.resize(Eigen::Index(N) + 1);  // sized in the constructor
  d.spectrumKey.head(Eigen::Index(N)) = u;
  d.spectrumKey[Eigen::Index(N)] = lambda;
  d.spectrumSize = found;
  return true;
}

bool EquilibriumProblem::stability(ProblemWorkspace& ws, ConstVectorRef u, double lambda, int lowestCount,
                                   continuation::StabilityInfo& info) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!options_.structuredStability) return Problem::stability(ws, u, lambda, lowestCount, info);
  const int n = chain_.size();
  const int wanted = std::max(0, std::min(lowestCount, kMaxLowest));
  if (n <= kDenseSpectrumUpTo && (wanted > 0 || n <= kDenseInertiaUpTo)) {
    // Small chains: one heap-free dense eigen-solve beats the counts + eigenvalue isolation,
    // and for n ≤ kDenseInertiaUpTo even the two Sturm counts of the inertia alone.
    if (!smallDenseSpectrum(d, u, lambda)) return false;
    const int found = std::min(wanted, d.spectrumSize);
    info.negative = d.spectrumInertia.negative;
    info.zero = d.spectrumInertia.zero;
    info.lowest = d.spectrum.head(found);
    info.smallest = found > 0 ? d.spectrum[0] : 0.0;
    return true;
  }
  if (!prepare(d, u, lambda)) return false;
  assembleFromCache(d, u, lambda, d.structure);
  for (int k = 0; k < heldCount(); ++k) d.heldRows.row(k) = d.J.row(held_[size_t(k)]);
  // Inertia by two O(n) Sturm counts (Sylvester); eigenvalues only when asked for.
  const Inertia in = constrainedInertia(d.structure, d.heldRows);
  info.negative = in.negative;
  info.zero = in.zero;
  const int dim = in.size();
  info.lowest.resize(std::min(wanted, dim));
  if (info.lowest.size() > 0) {
    if (d.guess.size() != ChainStructure::kMaxBorder) d.guess.resize(ChainStructure::kMaxBorder);
    const bool guessed = d.found.guesses(0, d.guess.head(info.lowest.size()));
    lowestEigenvalues(d.structure, d.structure.rank > 0, int(info.lowest.size()), info.lowest, 1e-13,
                      guessed ? &d.guess : nullptr);
    d.found.remember(0, info.lowest);
  }
  info.smallest = info.lowest.size() > 0 ? info.lowest[0] : 0.0;
  return true;
}

bool EquilibriumProblem::stabilityEigenvalues(ProblemWorkspace& ws, ConstVectorRef u, double lambda, int first,
                                              continuation::VectorRef values) const {
  Workspace& d = workspaceAs<Workspace>(ws);
  if (!options_.structuredStability) return Problem::stabilityEigenvalues(ws, u, lambda, first, values);
  if (first < 0) return false;
  const int n = chain_.size();
  const int wanted = first + int(values.size());
  if (n <= kDenseSpectrumUpTo) {
    // As stability(): one heap-free dense eigen-solve is cheaper than isolating on counts, and
    // at the point stability() was just asked about it is already done.
    if (!smallDenseSpectrum(d, u, lambda) || d.spectrumSize < wanted) return false;
    values = d.spectrum.segment(first, values.size());
    return true;
  }
  if (!prepare(d, u, lambda)) return false;
  assembleFromCache(d, u, lambda, d.structure);
  for (int k = 0; k < heldCount(); ++k) d.heldRows.row(k) = d.J.row(held_[size_t(k)]);
  const int rank = heldCount() > 0 ? setConstraints(d.structure, d.heldRows) : (d.structure.rank = 0);
  if (values.size() > ChainStructure::kMaxBorder) return false;  // the isolation's fixed-size brackets
  // Warm start from the values found lately (eigenvalue_memory.h): the monitor asks at a point
  // and then a step δ = 1e−6 along its tangent, then at the next point (spectral_monitor.h), the
  // locator at its samples, so the values found bracket the new ones within a few counts, also
  // where ν, and with it the indices asked for, changed. The counts still certify the
  // isolation; only the bisection from ±‖H‖_F is saved.
  if (d.guess.size() != ChainStructure::kMaxBorder) d.guess.resize(ChainStructure::kMaxBorder);
  const bool guessed = d.found.guesses(first, d.guess.head(values.size()));
  if (eigenvaluesFrom(d.structure, rank > 0, first, int(values.size()), values, 1e-13, guessed ? &d.guess : nullptr) !=
      values.size())
    return false;
  d.found.remember(first, values);
  return true;
}

std::unique_ptr<continuation::BorderedSolver> EquilibriumProblem::makeStructuredSolver(ProblemWorkspace& ws) const {
  return std::make_unique<ChainBorderedSolver>(*this, ws);
}

double EquilibriumProblem::lengthUnit() const {
  double b = 0.0;
  for (int i = 0; i < chain_.size(); ++i) b += 0.5 * (chain_.segment(i).parameters().b1 + chain_.segment(i).parameters().b2);
  return b / chain_.size();
}

double EquilibriumProblem::stiffnessUnit() const {
  double k = 0.0;
  for (int i = 0; i < chain_.size(); ++i) k += 0.5 * (chain_.segment(i).parameters().k1 + chain_.segment(i).parameters().k2);
  return k / chain_.size();
}

continuation::ProblemScales EquilibriumProblem::scales() const {
  const int n = chain_.size(), m = heldCount();
  const double length = lengthUnit(), force = stiffnessUnit() * length, torque = force * length;
  continuation::ProblemScales s = continuation::ProblemScales::ones(n + m);
  s.residuals.head(n).setConstant(torque);  // ∂E/∂q − JᵀF: torques
  for (int k = 0; k < m; ++k) {
    const bool angle = held_[size_t(k)] == 2;
    s.unknowns[n + k] = angle ? torque : force;   // the reaction of a held coordinate
    s.residuals[n + k] = angle ? 1.0 : length;    // value − pose
  }
  // λ moves value_c by λ·direction_c; value_c is a load where the coordinate is loaded, a
  // position or angle where it is held.
  double lambda = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    if (direction_[c] == 0.0) continue;
    const bool held = end_.isHeld(static_cast<EndCoordinate>(c));
    const double unit = held ? (c < 2 ? length : 1.0) : (c < 2 ? force : torque);
    lambda = std::min(lambda, unit / std::abs(direction_[c]));
  }
  // With body loads growing with λ (the weight along a gravity path): the λ that moves their
  // resultants by the force unit.
  if (bodyTerms_.active() && bodyTerms_.rateForce() > 0.0) lambda = std::min(lambda, force / bodyTerms_.rateForce());
  // Along a control path λ moves a free length by λ·rate: its unit b̄.
  if (control_.active()) {
    const double rate = control_.rates.cwiseAbs().maxCoeff();
    if (rate > 0.0) lambda = std::min(lambda, length / rate);
  }
  s.parameter = std::isfinite(lambda) && lambda > 0.0 ? lambda : force;
  s.stability = torque;  // K_q − K_g
  return s;
}

}  // namespace buckle::mechanics
