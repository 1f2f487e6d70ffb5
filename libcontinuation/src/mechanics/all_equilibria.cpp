#include "buckle/mechanics/all_equilibria.h"

#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "all_equilibria_sweep.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/shape_name.h"
#include "buckle/mechanics/unloaded_shape.h"

namespace buckle::mechanics {

namespace {

// Largest change of any joint angle in one Newton step (radians): the joint range is below 2π
// and a longer step only leaves the model's domain.
constexpr double kMaxAngleStep = 1.0;
// The deflated run hands over to the undeflated polish once the residual is this small in the
// chain's units: Newton's quadratic convergence takes it to rounding from there.
constexpr double kHandOver = 1e-8;
constexpr int kPolishIterations = 30;

bool withinLimits(const Chain& chain, const Vector& q) {
  for (int i = 0; i < chain.size(); ++i)
    if (q[i] < chain.lowerLimits()[i] || q[i] > chain.upperLimits()[i]) return false;
  return true;
}

// Newton on the equilibrium equations at λ = 0, deflated (FBF) or plain.
class DeflatedNewton {
 public:
  DeflatedNewton(EquilibriumProblem& problem, const AllEquilibriaOptions& options)
      : problem_(problem),
        bound_(problem),
        options_(options),
        n_(problem.segments()),
        N_(problem.dimension()),
        scale_(problem.scales().residuals),
        unknownScale_(problem.scales().unknowns),
        F_(N_),
        trial_(N_),
        Fu_(N_, N_),
        Fl_(N_),
        gradLog_(n_) {}

  const std::vector<Vector>& roots() const { return roots_; }
  void deflate(const Vector& q) { roots_.push_back(q); }
  bool known(const Vector& q) const {
    for (const Vector& r : roots_)
      if ((q - r).lpNorm<Eigen::Infinity>() <= options_.duplicateTolerance) return true;
    return false;
  }

  /// The Newton step −F_u⁻¹ F, solved in the problem's scaled variables (rows over their
  /// residual scales, unknowns over theirs): torque rows ~ k b², held rows ~ b and reactions ~ k b
  /// make F_u itself too badly scaled for a plain QR in extreme units.
  Vector newtonStep() {
    const Matrix scaled = scale_.cwiseInverse().asDiagonal() * Fu_ * unknownScale_.asDiagonal();
    return -unknownScale_.cwiseProduct(scaled.colPivHouseholderQr().solve(F_.cwiseQuotient(scale_)));
  }

  /// ‖F(u)‖∞ with each row in the chain's unit; +∞ outside the domain.
  double residualNorm(const Vector& u, Vector& F) {
    if (!bound_.residual(u, 0.0, F)) return std::numeric_limits<double>::infinity();
    const double r = (F.array() / scale_.array()).abs().maxCoeff();
    return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
  }

  /// m(q) = Π (‖q − q*‖^−p + σ) and ∇ ln m into gradLog_.
  double deflation(const Vector& q) {
    gradLog_.setZero();
    double m = 1.0;
    const double p = options_.deflationPower, sigma = options_.deflationShift;
    for (const Vector& r : roots_) {
      const Vector e = q - r;
      const double d2 = e.squaredNorm();
      if (d2 == 0.0) return std::numeric_limits<double>::infinity();
      const double dp = std::pow(d2, -0.5 * p), mi = dp + sigma;
      m *= mi;
      gradLog_ -= (p * dp / (d2 * mi)) * e;
    }
    return m;
  }

  /// Damped Newton on G = m F from u: the step of G is the step of F times
  /// τ = 1 / (1 − ∇ln m · δ_F) (Sherman–Morrison on ∇G = m ∇F + F ∇mᵀ), backtracked on m‖F‖.
  bool deflatedRun(Vector& u) {
    for (int it = 0; it < options_.maxIterations; ++it) {
      const double norm = residualNorm(u, F_);
      if (!std::isfinite(norm)) return false;
      if (norm <= kHandOver) return true;
      if (!bound_.jacobian(u, 0.0, Fu_, Fl_)) return false;
      Vector du = newtonStep();
      const double m = deflation(u.head(n_));
      const double tau = 1.0 / (1.0 - gradLog_.dot(du.head(n_)));
      du *= tau;
      if (!du.allFinite() || !std::isfinite(m)) return false;
      const double big = du.head(n_).lpNorm<Eigen::Infinity>();
      if (big > kMaxAngleStep) du *= kMaxAngleStep / big;
      const double merit = m * norm;
      bool accepted = false;
      for (double alpha = 1.0; alpha > 1e-6 && !accepted; alpha *= 0.5) {
        const Vector next = u + alpha * du;
        const double nt = residualNorm(next, trial_);
        if (std::isfinite(nt) && deflation(next.head(n_)) * nt < (1.0 - 1e-4 * alpha) * merit) {
          u = next;
          accepted = true;
        }
      }
      if (!accepted) return false;
    }
    return false;
  }

  /// Plain Newton on F from u (near a root): the best residual reached, u moved there.
  double polish(Vector& u) {
    double best = residualNorm(u, F_);
    for (int it = 0; it < kPolishIterations && std::isfinite(best) && best > 0.0; ++it) {
      if (!bound_.jacobian(u, 0.0, Fu_, Fl_)) break;
      const Vector next = u + newtonStep();
      const double nt = residualNorm(next, trial_);
      if (!(nt < best)) break;
      u = next;
      best = nt;
      F_ = trial_;
    }
    return best;
  }

 private:
  EquilibriumProblem& problem_;
  const continuation::BoundProblem bound_;  // the search's workspace
  const AllEquilibriaOptions& options_;
  int n_, N_;
  Vector scale_, unknownScale_, F_, trial_;
  Matrix Fu_;
  Vector Fl_, gradLog_;
  std::vector<Vector> roots_;
};

FoundEquilibrium describe(EquilibriumProblem& problem, const Vector& u, double accuracy) {
  const Chain& chain = problem.chain();
  const int n = chain.size();
  FoundEquilibrium e;
  e.q = u.head(n);
  e.reactions = u.tail(problem.heldCount());
  e.wrench = problem.wrench(u, 0.0);
  continuation::StabilityInfo info;
  if (continuation::BoundProblem(problem).stability(u, 0.0, 1, info)) {
    e.index = info.negative;
    e.zeroEigenvalues = info.zero;
    e.stable = info.stable();
  }
  e.pose = endPose(chain, e.q);
  // Π = E − work of the given loads; a held coordinate's reaction does no work (it does not move).
  e.potential = energy(chain, e.q);
  for (int c : problem.endCondition().loadedIndices()) e.potential -= problem.endCondition().value[c] * e.pose[c];
  if (problem.bodyLoads().active()) {  // + V (eq B1)
    BodyLoadTerms body(chain, problem.bodyLoads());
    ChainData data(chain);
    forwardKinematics(chain, e.q, data);
    body.update(data);
    e.potential += body.potential(data, 0.0);
  }
  e.shape = shapeName(e.q);
  e.accuracy = accuracy;
  return e;
}

std::vector<Vector> startingShapes(const Chain& chain, const AllEquilibriaOptions& options,
                                   const detail::SweepResult* sweep) {
  const int n = chain.size();
  const Vector lo = chain.lowerLimits(), hi = chain.upperLimits();
  std::vector<Vector> starts;
  starts.push_back(Vector::Zero(n).cwiseMax(lo).cwiseMin(hi));  // the straight shape
  const UnloadedShape unloaded = unloadedShape(chain);
  if (unloaded.allFound) starts.push_back(unloaded.q);
  for (const Vector& q : options.starts) starts.push_back(q.cwiseMax(lo).cwiseMin(hi));
  if (sweep && options.landscapeStarts)
    for (const detail::SweepPoint& p : sweep->equilibria) starts.push_back(p.q);
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < options.randomStarts; ++k) {
    const double amplitude = unit(rng);  // small shapes near the straight one as often as large ones
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = amplitude * (lo[i] + (hi[i] - lo[i]) * unit(rng));
    starts.push_back(q.cwiseMax(lo).cwiseMin(hi));
  }
  // Smooth shapes: a total turn T of up to ±2π spread over the joints with a slow cosine
  // modulation of m half-waves. The equilibria of a long chain bend it smoothly, and a joint-by-
  // joint random shape of n ≫ 1 joints is far from every one of them.
  for (int k = 0; k < options.smoothStarts; ++k) {
    const double turn = 2.0 * M_PI * (2.0 * unit(rng) - 1.0), weight = 2.0 * unit(rng) - 1.0;
    const int halfWaves = int(4.0 * unit(rng));
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = turn / n * (1.0 + weight * std::cos(M_PI * halfWaves * (i + 0.5) / n));
    starts.push_back(q.cwiseMax(lo).cwiseMin(hi));
  }
  return starts;
}

// Every start: deflated runs until one fails (FBF), each new root polished and deflated.
void deflationSearch(EquilibriumProblem& problem, DeflatedNewton& solver, const std::vector<Vector>& starts,
                     const AllEquilibriaOptions& options, AllEquilibria& result) {
  const int n = problem.segments();
  for (const Vector& start : starts) {
    if (options.interrupt.requested()) break;
    ++result.starts;
    for (int k = 0; k < options.maxRootsPerStart && !options.interrupt.requested(); ++k) {
      Vector u = problem.initialGuess(start, 0.0);
      ++result.newtonRuns;
      if (!solver.deflatedRun(u)) {
        ++result.newtonFailures;
        break;
      }
      const double accuracy = solver.polish(u);
      if (!(accuracy <= options.tolerance)) {
        ++result.newtonFailures;
        break;
      }
      const Vector q = u.head(n);
      if (solver.known(q)) {
        ++result.duplicates;
        break;
      }
      solver.deflate(q);
      if (!withinLimits(problem.chain(), q)) {
        ++result.outsideLimits;
        continue;
      }
      result.equilibria.push_back(describe(problem, u, accuracy));
      result.equilibria.back().byDeflation = true;
    }
  }
  if (options.interrupt.requested()) {
    result.interrupted = true;
    result.stopReason = options.interrupt.describe();
  }
}

// The sweep's equilibria merged into the list: each polished by plain Newton (the points found
// next to a junction are only near their root), de-duplicated, then matched by q or added.
void mergeSweep(EquilibriumProblem& problem, DeflatedNewton& solver, const detail::SweepResult& sweep,
                const AllEquilibriaOptions& options, AllEquilibria& result) {
  const int n = problem.segments();
  std::vector<Vector> seen;
  for (const detail::SweepPoint& p : sweep.equilibria) {
    Vector u = problem.initialGuess(p.q, 0.0);
    const double accuracy = solver.polish(u);
    const Vector q = u.head(n);
    if (!(accuracy <= options.tolerance) || !withinLimits(problem.chain(), q)) {
      ++result.sweepUnresolved;
      continue;
    }
    auto near = [&](const Vector& other) {
      return (other - q).lpNorm<Eigen::Infinity>() <= options.duplicateTolerance;
    };
    if (std::any_of(seen.begin(), seen.end(), near)) continue;
    seen.push_back(q);
    if (p.refined) ++result.sweepRefined;
    auto match = std::find_if(result.equilibria.begin(), result.equilibria.end(),
                              [&](const FoundEquilibrium& e) { return near(e.q); });
    if (match != result.equilibria.end()) {
      match->bySweep = true;
      continue;
    }
    result.equilibria.push_back(describe(problem, u, accuracy));
    result.equilibria.back().bySweep = true;
    ++result.sweepOnly;
  }
  result.sweepCount = int(seen.size());
  for (const FoundEquilibrium& e : result.equilibria)
    if (e.byDeflation && !e.bySweep) ++result.deflationOnly;
}

std::string guaranteeText(const AllEquilibria& r, bool sweep) {
  const std::string deflation = "deflated Newton from " + std::to_string(r.starts) +
                                " starts: every equilibrium it reached, no completeness proof (a root whose deflated "
                                "basin holds none of the starts is missed)";
  if (!sweep) return deflation;
  return "1-D sweep of E(q1) (n = 3, end held, Me = 0): every equilibrium on the configuration set except a pair of "
         "roots of dE/dq1 within one sweep cell where dE/dq1 has two extrema, or one exactly at an inverse-kinematics "
         "junction (sin q3 = 0); " +
         std::string(r.sweepOnly == 0 && r.deflationOnly == 0 ? "deflation found the same set"
                                                              : "deflation and the sweep disagree") +
         "; " + deflation;
}

}  // namespace

bool sweepApplies(const Chain& chain, const EndCondition& end) {
  return chain.size() == 3 && end.isHeld(EndCoordinate::X) && end.isHeld(EndCoordinate::Y) &&
         !end.isHeld(EndCoordinate::Phi) && end.value[2] == 0.0;
}

std::string AllEquilibriaOptions::validate(int segments, const std::string& prefix) const {
  namespace cont = continuation;
  auto inUnitInterval = [](double v) { return std::isfinite(v) && v > 0.0 && v < 1.0; };
  std::string problem = cont::firstProblem(
      {cont::require(randomStarts >= 0, prefix, "randomStarts", "must be >= 0"),
       cont::require(smoothStarts >= 0, prefix, "smoothStarts", "must be >= 0"),
       cont::require(maxRootsPerStart >= 1, prefix, "maxRootsPerStart", "must be at least 1"),
       cont::require(maxIterations >= 1, prefix, "maxIterations", "must be at least 1"),
       cont::require(std::isfinite(deflationPower) && deflationPower >= 1.0, prefix, "deflationPower", "must be >= 1"),
       cont::require(std::isfinite(deflationShift) && deflationShift >= 0.0, prefix, "deflationShift", "must be >= 0"),
       cont::require(inUnitInterval(tolerance), prefix, "tolerance", "must lie in (0, 1)"),
       cont::require(inUnitInterval(duplicateTolerance), prefix, "duplicateTolerance", "must lie in (0, 1)"),
       cont::require(landscapeSamples >= 2, prefix, "landscapeSamples", "must be at least 2")});
  for (size_t k = 0; k < starts.size() && problem.empty(); ++k)
    if (starts[k].size() != segments || !starts[k].allFinite())
      problem = prefix + "starts[" + std::to_string(k) + "] must have " + std::to_string(segments) +
                " finite joint angles";
  return problem;
}

AllEquilibria allEquilibria(const Chain& chain, const EndCondition& end, const AllEquilibriaOptions& options) {
  if (std::string why; !options.IsValid(chain.size(), &why)) throw std::invalid_argument("AllEquilibriaOptions: " + why);
  const auto begin = std::chrono::steady_clock::now();
  EquilibriumOptions equilibriumOptions;
  equilibriumOptions.jointLimitsAsBoundaries = false;  // the domain is the geometric limits exactly
  EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero(), equilibriumOptions, {},
                             options.body.atParameter(0.0));
  DeflatedNewton solver(problem, options);
  AllEquilibria result;
  result.endCondition = end;
  const bool sweep = options.landscape && sweepApplies(chain, end);
  detail::SweepResult swept;
  if (sweep)
    swept = detail::sweepEquilibria(chain, end.value[0], end.value[1], options.landscapeSamples,
                                    options.body.atParameter(0.0));
  deflationSearch(problem, solver, startingShapes(chain, options, sweep ? &swept : nullptr), options, result);
  if (sweep) mergeSweep(problem, solver, swept, options, result);
  std::sort(result.equilibria.begin(), result.equilibria.end(),
            [](const FoundEquilibrium& a, const FoundEquilibrium& b) { return a.potential < b.potential; });
  result.morse = sweep ? swept.morse : MorseCheck{};
  if (!sweep)
    result.morse.basis = "no topological count for this end condition (configuration set with corners at the joint "
                         "limits): only the sum is reported";
  for (const FoundEquilibrium& e : result.equilibria)
    if (e.index >= 0) result.morse.sum += (e.index % 2 == 0) ? 1 : -1;
  result.method = sweep ? "deflated Newton + 1-D sweep" : "deflated Newton";
  result.guarantee = guaranteeText(result, sweep);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return result;
}

}  // namespace buckle::mechanics
