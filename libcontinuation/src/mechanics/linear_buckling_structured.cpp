// The O(n) route of linear buckling (linear_buckling_structured.h): the definite pencil
// (K_q, G) on ker J_h counted on the chain structure and its loads finished by Rayleigh-quotient
// iteration (docs/mechanics.md, "The O(n) chain structure").
#include "linear_buckling_structured.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/shape_name.h"

namespace buckle::mechanics {

namespace {

// Long chains, first `count` modes (docs/mechanics.md, "The O(n) chain structure"). With K_q
// definite on ker J_h (sign s = ±1: s K_q positive definite) the pencil (K_q, G) is definite, so
// by Sylvester's law the number of critical loads in (0, λ) (or (λ, 0)) is the number of negative
// eigenvalues of s (K_q − λG) on ker J_h, an O(n) count on the tridiagonal T(λ) (chain_structure.h).
//
// The count alone cannot give the last digits: in absolute link angles T = U⁻¹K_qU⁻ᵀ − λ diag(Δg)
// carries K_q as a second-difference operator whose lowest eigenvalues are O(κ/n²) while its
// rounding is O(ε κ), so a load bisected on the count is only good to about ε n² relative (5e-12
// at n = 300). Each load is therefore only isolated by the count (one eigenvalue in the bracket,
// width 1e-7 relative) and then finished by Rayleigh-quotient iteration in joint angles:
//   x ← (K_q − σG)⁻¹ G z on ker J_h (the O(n) KKT solve),  σ ← ρ(x) = xᵀK_q x / xᵀG x,
// where xᵀK_q x = Σ κ_i x_i² and xᵀG x = Σ Δg_m (Uᵀx)_m² are formed without cancellation. The
// quotient's error is quadratic in the mode's (RQI converges cubically), so the ε n² error of the
// solve becomes ≈ ε² n⁴ relative: rounding level for every n where a dense solve is feasible.
// g: the load generator per unit λ (G(i, j) = g_max(i,j), eq 27).
class StructuredPencil {
 public:
  StructuredPencil(ConstVectorRef g, ConstVectorRef kq, const Matrix& C)
      : n_(int(g.size())),
        g_(g),
        kq_(kq),
        dg_(g.size()),
        ws_(n_),
        C_(C),
        t_(g.size()),
        res_(g.size()),
        dx_(g.size()),
        y_(ChainStructure::kMaxBorder),
        dy_(ChainStructure::kMaxBorder) {
    for (int i = 0; i < n_; ++i) dg_[i] = g_[i] - (i + 1 < n_ ? g_[i + 1] : 0.0);
  }

  /// Inertia of K_q on ker C; fixes the held rows (ws_.Q, ws_.B) for all later counts.
  Inertia unloadedInertia() {
    assemble(kq_, Vector::Zero(n_), ws_);
    const Inertia in = constrainedInertia(ws_, C_);
    Qt_ = ws_.Q.leftCols(ws_.rank).transpose();
    dim_ = in.size();
    return in;
  }
  /// Inertia of −G on ker C (its zeros: λ = ∞).
  Inertia loadInertia() {
    assemble(Vector::Zero(n_), g_, ws_);
    return constrainedInertia(ws_, C_, 1e-12);
  }
  void setSign(int s) { sign_ = s; }
  int dimension() const { return dim_; }

  /// Number of eigenvalues of s (K_q − λG) on ker C below 0 (T(λ) factorized in ws_ afterwards).
  int count(double lambda) {
    assemble(kq_, lambda * g_, ws_);
    const int below = constrainedCountBelow(ws_, 0.0);
    return sign_ > 0 ? below : dim_ - below;
  }

  /// xᵀK_q x / xᵀG x, both sums of squares weighted by the data (eq 26–27).
  double rayleigh(const Vector& x) {
    applyUTranspose(x, t_);
    return x.cwiseAbs2().dot(kq_) / t_.cwiseAbs2().dot(dg_);
  }
  /// G x (G(i, j) = g_max(i,j)): prefix sums, times Δg, tail sums (O(n)).
  void applyG(const Vector& x, Vector& out) {
    applyUTranspose(x, t_);
    t_.array() *= dg_.array();
    applyU(t_, out);
  }
  /// x = (K_q − σG)⁻¹ f on ker C (KKT), normalised; false if the solve broke down. The KKT
  /// solve works in link angles, where K_q's rounding is amplified by up to n² (above); two steps
  /// of iterative refinement with the residual formed in joint angles (K_q x exactly diagonal,
  /// G x by sums) bring the solution to the accuracy of the data.
  /// Far from convergence (refine = false) the refinement is skipped: only the direction matters.
  bool inverseStep(double sigma, const Vector& f, Vector& x, bool refine) {
    assemble(kq_, sigma * g_, ws_);
    const int r = int(Qt_.rows());
    if (!solveKKT(ws_, Qt_, f, Vector::Zero(r), x, y_.head(r))) return false;
    for (int pass = 0; pass < (refine ? 2 : 0); ++pass) {
      applyG(x, res_);
      res_ = f + sigma * res_ - kq_.cwiseProduct(x);
      res_.noalias() -= Qt_.transpose() * y_.head(r);
      ChainStructure::SmallVector rc = -(Qt_ * x);
      if (!solveFactoredBordered(ws_, ws_.X.leftCols(r), ws_.X.leftCols(r), ws_.zeroBorder.topLeftCorner(r, r), res_,
                                 rc, dx_, dy_.head(r)))
        return false;
      x += dx_;
      y_.head(r) += dy_.head(r);
    }
    // exactly on ker C (to rounding): the quotient is stationary only there
    for (int k = 0; k < r; ++k) x -= Qt_.row(k).dot(x) * Qt_.row(k).transpose();
    const double nrm = x.norm();
    if (!(nrm > 0.0) || !std::isfinite(nrm)) return false;
    x /= nrm;
    return true;
  }

 private:
  int n_;
  Vector g_, kq_, dg_;
  ChainStructure ws_;
  Matrix C_, Qt_;
  Vector t_, res_, dx_, y_, dy_;
  int sign_ = 1, dim_ = 0;
};

/// Start vector for inverse iteration: smooth, with no symmetry that could hide a mode.
Vector startVector(int n) {
  Vector z(n);
  for (int k = 0; k < n; ++k) z[k] = 1.0 + 0.1 * std::sin(1.3 * k) + 0.05 * std::cos(0.37 * k);
  return z / z.norm();
}

/// Rayleigh-quotient iteration for a load of one side from σ (|λ|), starting from `x`; the
/// quotient and the mode at convergence (cubic, then the rounding floor: steps stop shrinking).
bool rayleighIteration(StructuredPencil& p, int side, double& sigma, Vector& x, Vector& f) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 10; ++it) {
    p.applyG(x, f);
    if (!p.inverseStep(side * sigma, f, x, previous <= 1e-6 * sigma)) return false;
    const double rho = side * p.rayleigh(x);
    if (!std::isfinite(rho) || rho <= 0.0) return false;
    const double step = std::abs(rho - sigma);
    sigma = rho;
    if (step <= 8.0 * eps * rho || (it >= 2 && step >= 0.5 * previous && step <= 1e-12 * rho)) {
      // The mode from a solve that close to the load carries the link-angle rounding of the
      // factorization undamped (refinement cannot remove it from a nearly singular system):
      // two more inverse steps a little off the load, where the joint-angle refinement
      // converges, each shrink the other modes by ≈ 1e-3 / (relative gap).
      for (int polish = 0; polish < 2; ++polish) {
        p.applyG(x, f);
        if (!p.inverseStep(side * sigma * (1.0 - 1e-3), f, x, true)) return false;
      }
      return true;
    }
    previous = step;
  }
  return false;
}

/// The j-th critical load on one side: bracket by counts, then Rayleigh-quotient iteration.
/// `samples` holds (|λ|, count) pairs from earlier counts on this side (reused as brackets).
bool criticalLoad(StructuredPencil& p, int side, int j, double hi, std::vector<std::pair<double, int>>& samples,
                  double& lambda, Vector& mode) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const int n = int(mode.size());
  auto bisect = [&](double& a, double& b, int& ca, int& cb) {
    const double mid = 0.5 * (a + b);
    const int c = p.count(side * mid);
    samples.emplace_back(mid, c);
    if (c >= j) {
      b = mid;
      cb = c;
    } else {
      a = mid;
      ca = c;
    }
  };
  // bracket: count(a) < j <= count(b), from the samples so far
  double a = 0.0, b = hi;
  int ca = 0, cb = j;
  for (const auto& [mag, c] : samples) {
    if (c < j && mag > a) { a = mag; ca = c; }
    if (c >= j && mag < b) { b = mag; cb = c; }
  }
  // isolate: count(a) = j − 1, count(b) = j, and narrow to 1 % (RQI then converges to this load)
  for (int it = 0; it < 200 && (ca != j - 1 || cb != j || b - a > 1e-2 * b) && b - a > 4.0 * eps * b; ++it)
    bisect(a, b, ca, cb);
  // The counts themselves are reliable only to about ε n² relative (see above): the converged
  // quotient must lie in the bracket up to that, else the bracket is narrowed and RQI retried.
  const double resolution = 16.0 * eps * double(n) * double(n);
  Vector x(n), f(n);
  for (int attempt = 0; attempt < 12; ++attempt) {
    double sigma = 0.5 * (a + b);
    x = startVector(n);
    const double slack = std::max(b - a, resolution * b);
    if (rayleighIteration(p, side, sigma, x, f) && sigma >= a - slack && sigma <= b + slack) {
      lambda = side * sigma;
      mode = x;
      return true;
    }
    if (b - a <= resolution * b) break;
    for (int k = 0; k < 4 && b - a > 4.0 * eps * b; ++k) bisect(a, b, ca, cb);
  }
  // No convergence (a cluster closer than the counts resolve): the bisected load, its mode by
  // inverse iteration.
  for (int it = 0; it < 200 && b - a > 4.0 * eps * b; ++it) bisect(a, b, ca, cb);
  const double sigma = 0.5 * (a + b);
  x = startVector(n);
  for (int it = 0; it < 2; ++it) {
    p.applyG(x, f);
    if (!p.inverseStep(side * sigma, f, x, true)) return false;
  }
  lambda = side * sigma;
  mode = x;
  return true;
}

// Returns false (the caller goes dense) when K_q is not definite on ker J_h.
bool structuredModes(ConstVectorRef g, ConstVectorRef kq, const Matrix& Ch, const LinearBucklingOptions& options,
                     double force, std::vector<std::pair<double, Vector>>& pairs, LinearBucklingResult& out) {
  const int n = int(g.size());
  const double gmax = std::max(1e-300, g.cwiseAbs().maxCoeff());
  const double kmax = kq.cwiseAbs().maxCoeff();
  if (kmax <= 1e-13 * gmax * force) return false;  // κ ≈ 0: every load is 0, the dense path says so
  StructuredPencil pencil(g, kq, Ch.transpose());
  const Inertia unloaded = pencil.unloadedInertia();
  if (unloaded.zero != 0 || (unloaded.negative != 0 && unloaded.positive != 0)) return false;
  const int sign = unloaded.negative == 0 ? 1 : -1;
  pencil.setSign(sign);
  out.unloadedStable = sign > 0;
  out.constrainedDimension = unloaded.size();
  // Finite critical loads on each side: the inertia of −G on ker J_h; its zero eigenvalues are
  // the directions with λ = ∞.
  const Inertia loadInertia = pencil.loadInertia();
  out.droppedInfinite = loadInertia.zero;
  for (int side : {+1, -1}) {
    // λ > 0 buckles along s zᵀG z > 0: −G's negative eigenvalues for s = 1, its positive ones for s = −1.
    const int available = side * sign > 0 ? loadInertia.negative : loadInertia.positive;
    const int wanted = std::min(options.count, available);
    if (wanted <= 0) continue;
    std::vector<std::pair<double, int>> samples;
    double hi = kmax / gmax;
    int chi = pencil.count(side * hi);
    for (int it = 0; it < 200 && chi < wanted; ++it) chi = pencil.count(side * (hi *= 2.0));
    samples.emplace_back(hi, chi);
    for (int j = 1; j <= wanted; ++j) {
      double lambda = 0.0;
      Vector z(n);
      if (!criticalLoad(pencil, side, j, hi, samples, lambda, z)) return false;
      pairs.emplace_back(lambda, std::move(z));
    }
  }
  return true;
}

}  // namespace

bool structuredBuckling(const ChainData& data, const Vector& kq, const Matrix& Ch, const LinearBucklingOptions& options,
                        double force, LinearBucklingResult& fast) {
  const int n = int(kq.size());
  std::vector<std::pair<double, Vector>> fastPairs;
  Vector gvec(n);
  loadHessianGenerator(data, Wrench(options.direction[0], options.direction[1], 0.0), gvec);
  if (!structuredModes(gvec, kq, Ch, options, force, fastPairs, fast)) return false;
  Vector Gz(n), t(n);
  for (auto& [lambda, z] : fastPairs) {
    Eigen::Index imax = 0;
    z.cwiseAbs().maxCoeff(&imax);
    if (z[imax] < 0) z = -z;
    // G z with G(i, j) = g_max(i,j): prefix sums, times g_m − g_{m+1}, tail sums (O(n)).
    applyUTranspose(z, t);
    for (int i = 0; i < n; ++i) t[i] *= gvec[i] - (i + 1 < n ? gvec[i + 1] : 0.0);
    applyU(t, Gz);
    BucklingMode mode;
    mode.lambda = lambda;
    mode.mode = z;
    mode.shape = modeShapeName(z);
    mode.shortening = -0.5 * z.dot(Gz);
    fast.modes.push_back(std::move(mode));
  }
  std::stable_sort(fast.modes.begin(), fast.modes.end(), [](const BucklingMode& a, const BucklingMode& b) {
    return std::abs(a.lambda) < std::abs(b.lambda);
  });
  if (int(fast.modes.size()) > options.count) fast.modes.resize(size_t(options.count));
  return true;
}

}  // namespace buckle::mechanics
