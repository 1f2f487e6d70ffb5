// Integration of the dynamics models (dynamics.h, "integration"): options, odeint steppers with
// the rest / guard monitor, and simulate().
#include "buckle/mechanics/dynamics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <boost/numeric/odeint.hpp>

#include "buckle/continuation/root_finding.h"
#include <boost/numeric/ublas/matrix.hpp>
#include <boost/numeric/ublas/vector.hpp>

namespace buckle::mechanics {

namespace {

bool fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace

// ---- integration -----------------------------------------------------------------------------

bool IntegrationOptions::IsValid(std::string* why) const {
  if (!finite(absoluteTolerance) || !(absoluteTolerance > 0.0)) return fail(why, "absoluteTolerance must be > 0");
  if (!finite(relativeTolerance) || relativeTolerance < 0.0) return fail(why, "relativeTolerance must be >= 0");
  if (!finite(initialStep) || !(initialStep > 0.0)) return fail(why, "initialStep must be > 0");
  if (!finite(maxStep) || maxStep < 0.0) return fail(why, "maxStep must be >= 0 (0: unlimited)");
  if (!finite(minStep) || !(minStep > 0.0)) return fail(why, "minStep must be > 0");
  if (maxStep > 0.0 && maxStep < minStep) return fail(why, "maxStep must be >= minStep");
  if (!(maxTime > 0.0) || std::isnan(maxTime)) return fail(why, "maxTime must be > 0");
  if (maxSteps < 1) return fail(why, "maxSteps must be >= 1");
  if (!finite(velocityTolerance) || !(velocityTolerance > 0.0)) return fail(why, "velocityTolerance must be > 0");
  if (!finite(residualTolerance) || !(residualTolerance > 0.0)) return fail(why, "residualTolerance must be > 0");
  if (!finite(recordInterval) || recordInterval < 0.0) return fail(why, "recordInterval must be >= 0");
  if (maxSamples < 2) return fail(why, "maxSamples must be >= 2");
  if (!finite(settleResidual) || !(settleResidual > 0.0)) return fail(why, "settleResidual must be > 0");
  if (settleInterval < 1) return fail(why, "settleInterval must be >= 1");
  return true;
}

const char* toString(IntegrationStop reason) {
  switch (reason) {
    case IntegrationStop::Rest: return "rest";
    case IntegrationStop::MaxTime: return "max time";
    case IntegrationStop::MaxSteps: return "max steps";
    case IntegrationStop::JointLimit: return "joint limit";
    case IntegrationStop::StepSizeUnderflow: return "step size underflow";
    case IntegrationStop::NonFinite: return "non-finite state";
    case IntegrationStop::Interrupted: return "interrupted";
    case IntegrationStop::Settled: return "settled";
  }
  return "unknown";
}

namespace {

namespace odeint = boost::numeric::odeint;
namespace ublas = boost::numeric::ublas;
using ExplicitState = std::vector<double>;
using StiffState = ublas::vector<double>;

struct ExplicitSystem {
  DynamicsModel* model;
  void operator()(const ExplicitState& x, ExplicitState& dxdt, double) const { model->rhs(x.data(), dxdt.data()); }
};

struct StiffSystem {
  DynamicsModel* model;
  void operator()(const StiffState& x, StiffState& dxdt, double) const { model->rhs(&x.data()[0], &dxdt.data()[0]); }
};

struct StiffJacobian {
  DynamicsModel* model;
  void operator()(const StiffState& x, ublas::matrix<double>& J, const double&, StiffState& dfdt) const {
    // ublas::matrix is row-major by default: its storage is exactly the layout jacobian() fills.
    model->jacobian(&x.data()[0], &J.data()[0]);
    std::fill(dfdt.begin(), dfdt.end(), 0.0);  // autonomous
  }
};

/// The RMS norm of an error estimate e over atol·u_i + rtol·max(|x_i|, |x⁺_i|) (Hairer & Wanner
/// II.4, u_i the component's unit).
double weightedErrorNorm(const ExplicitState& e, const ExplicitState& x, const ExplicitState& xNew,
                         const std::vector<double>& unit, double atol, double rtol) {
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double w = e[i] / (atol * unit[i] + rtol * std::max(std::abs(x[i]), std::abs(xNew[i])));
    sum += w * w;
  }
  return std::sqrt(sum / double(x.size()));
}

/// Step-size control as odeint's rosenbrock4_controller (Hairer & Wanner IV.8): the factor
/// err^{1/p}/0.9 within [1/6, 5] and, after an accepted step, Gustafsson's predictive factor; no
/// growth right after a rejection. p = 4 for Rosenbrock4's order-3 estimate, 5 for Dormand–Prince.
struct StepSizeController {
  double exponent;  ///< 1/p
  bool haveOld = false, lastRejected = false;
  double dtOld = 0.0, errOld = 1.0;

  /// After a rollback or an event the step history no longer applies (as odeint's reset()).
  void reset() { haveOld = lastRejected = false; }
  /// A step that could not be evaluated: retry at half the size.
  void refuse(double& dt) {
    dt *= 0.5;
    lastRejected = true;
  }
  /// err: the weighted error norm of the step of size dt just tried. True: accepted, dt becomes
  /// the next step; false: rejected, dt becomes the retry's.
  bool accept(double err, double& dt) {
    constexpr double safe = 0.9, fac1 = 5.0, fac2 = 1.0 / 6.0;
    double fac = std::isfinite(err) ? std::max(fac2, std::min(fac1, std::pow(err, exponent) / safe)) : fac1;
    if (!(err <= 1.0)) {
      dt /= std::max(fac, 1.0 + 1e-3);
      lastRejected = true;
      return false;
    }
    if (haveOld) {
      const double pred = std::max(fac2, std::min(fac1, (dtOld / dt) * std::pow(err * err / errOld, exponent) / safe));
      fac = std::max(fac, pred);
    }
    haveOld = true;
    dtOld = dt;
    errOld = std::max(0.01, err);
    double dtNew = dt / fac;
    if (lastRejected) dtNew = std::min(dtNew, dt);
    lastRejected = false;
    dt = dtNew;
    return true;
  }
};

/// odeint's rosenbrock4 (Shampine's L-stable order-4 method with an embedded order-3 estimate,
/// odeint::default_rosenbrock_coefficients) with the model's O(n) structured solve
/// (DynamicsModel::solveLinearized) in place of the dense LU of (1/(γτ)) I − J: each stage
/// (1/(γτ) − J̃) g = r is (I − γτJ̃) g = γτ r. Autonomous (∂f/∂t = 0). Step-size control as
/// rosenbrock4_controller (Hairer & Wanner IV.8): the RMS norm of the estimate over
/// atol·u_i + rtol·max(|x_i|, |x⁺_i|), the step factor err^{1/4}/0.9 within [1/6, 5] and, after an
/// accepted step, Gustafsson's predictive factor. u_i is component i's unit (the model's:
/// radians for angles, the time unit for velocities, k̄b̄² for the dissipated energy), so that the
/// absolute tolerance means the same for the same chain in any units.
class StructuredRosenbrock4 {
 public:
  StructuredRosenbrock4(DynamicsModel& model, double absoluteTolerance, double relativeTolerance)
      : model_(model), atol_(absoluteTolerance), rtol_(relativeTolerance) {
    for (ExplicitState* v : {&f_, &r_, &xtmp_, &err_, &xout_, &g_[0], &g_[1], &g_[2], &g_[3], &g_[4]})
      v->assign(size_t(model.stateSize()), 0.0);
    const int n = model.segments(), N = model.stateSize();
    unit_.assign(size_t(N), 1.0);
    for (int i = n; i < N - 1; ++i) unit_[size_t(i)] = 1.0 / model.timeUnit();  // velocities
    unit_[size_t(N - 1)] = model.torqueUnit();                                   // dissipated energy
  }

  odeint::controlled_step_result try_step(const ExplicitSystem&, ExplicitState& x, double& t, double& dt) {
    if (!step(x, dt)) {
      control_.refuse(dt);
      return odeint::fail;
    }
    const double h = dt;
    if (!control_.accept(weightedErrorNorm(err_, x, xout_, unit_, atol_, rtol_), dt)) return odeint::fail;
    x.swap(xout_);
    t += h;
    return odeint::success;
  }

  /// After a rollback or an event the step history no longer applies (as odeint's reset()).
  void reset() { control_.reset(); }

  const std::vector<double>& units() const { return unit_; }
  /// The last step's sixth right-hand side's argument and value (after try_step: the new state
  /// minus the error estimate, and f there).
  const ExplicitState& lastStageState() const { return xtmp_; }
  const ExplicitState& lastStageRhs() const { return f_; }

  /// One step of size dt from x into out, without error control (the trial steps of the event
  /// location: shorter than a step the control accepted).
  bool advance(const ExplicitState& x, double dt, ExplicitState& out) {
    if (!step(x, dt)) return false;
    out = xout_;
    return true;
  }

 private:
  // One step: stages g1 … g5 and the error estimate, as odeint's rosenbrock4::do_step.
  bool step(const ExplicitState& x, double dt) {
    static const odeint::default_rosenbrock_coefficients<double> c;
    const size_t N = x.size();
    const double a = c.gamma * dt;
    auto stage = [&](ExplicitState& g) { return model_.solveLinearized(x.data(), a, r_.data(), g.data()); };
    auto combine = [&](const ExplicitState& fx, std::initializer_list<double> cs, ExplicitState& out) {
      for (size_t i = 0; i < N; ++i) {
        double v = 0.0;
        size_t k = 0;
        for (double ck : cs) v += ck * g_[k++][i];
        out[i] = a * (fx[i] + v / dt);  // γτ (f + Σ c_k g_k / τ)
      }
    };
    auto advance = [&](std::initializer_list<double> as) {
      for (size_t i = 0; i < N; ++i) {
        double v = x[i];
        size_t k = 0;
        for (double ak : as) v += ak * g_[k++][i];
        xtmp_[i] = v;
      }
      model_.rhs(xtmp_.data(), f_.data());
    };
    model_.rhs(x.data(), f_.data());
    combine(f_, {}, r_);
    if (!stage(g_[0])) return false;
    advance({c.a21});
    combine(f_, {c.c21}, r_);
    if (!stage(g_[1])) return false;
    advance({c.a31, c.a32});
    combine(f_, {c.c31, c.c32}, r_);
    if (!stage(g_[2])) return false;
    advance({c.a41, c.a42, c.a43});
    combine(f_, {c.c41, c.c42, c.c43}, r_);
    if (!stage(g_[3])) return false;
    advance({c.a51, c.a52, c.a53, c.a54});
    combine(f_, {c.c51, c.c52, c.c53, c.c54}, r_);
    if (!stage(g_[4])) return false;
    for (size_t i = 0; i < N; ++i) xtmp_[i] += g_[4][i];
    model_.rhs(xtmp_.data(), f_.data());
    combine(f_, {c.c61, c.c62, c.c63, c.c64, c.c65}, r_);
    if (!model_.solveLinearized(x.data(), a, r_.data(), err_.data())) return false;
    for (size_t i = 0; i < N; ++i) xout_[i] = xtmp_[i] + err_[i];
    return true;
  }

  DynamicsModel& model_;
  double atol_, rtol_;
  std::vector<double> unit_;
  StepSizeController control_{0.25};
  ExplicitState f_, r_, xtmp_, err_, xout_;
  ExplicitState g_[5];
};

/// Dormand–Prince 5(4) while the flow is not stiff, the structured Rosenbrock4 above while it is
/// (StepperKind::StructuredSwitching). Both control the same RMS error norm in the components'
/// units (StructuredRosenbrock4's), so a switch does not change what a step's accuracy means.
///
/// Stiffness test (Hairer & Wanner I, II.10 / dopri5.f): after an accepted Dormand–Prince step,
/// h·ρ with ρ = ‖f(x₊) − f(x₆)‖ / ‖x₊ − x₆‖ (x₆ the last stage's argument, x₊ the new state) is
/// a Rayleigh-quotient estimate of h|λ_max|; the method's stability boundary on the negative
/// axis is ≈ 3.3. Fifteen such steps with h·ρ > 3.25 without six consecutive ones below
/// switch to Rosenbrock4: there the explicit step is limited by stability, not accuracy. The way
/// back estimates ρ after an accepted Rosenbrock step the same way, between its last stage's
/// argument and the new state (x₊ − x₆ is the step's error estimate); `backAfter` consecutive
/// steps with h·ρ < 1 switch back, and every switch back that ends in stiffness again doubles
/// `backAfter` (no ping-pong where the estimate is poor). Measured (benchmarks/RESULTS.md): the
/// cascade of the straight chain's jump is accuracy-limited, and there Dormand–Prince's
/// order-4 error estimate allows steps about twice Rosenbrock4's (whose estimate is of order 3)
/// at a sixth of the cost per step (no factorization, no stage solves).
class SwitchingStepper {
 public:
  SwitchingStepper(DynamicsModel& model, double absoluteTolerance, double relativeTolerance)
      : model_(model), rosenbrock_(model, absoluteTolerance, relativeTolerance), atol_(absoluteTolerance),
        rtol_(relativeTolerance) {
    const size_t N = size_t(model.stateSize());
    for (ExplicitState* v : {&f0_, &f6_, &f7_, &x6_, &xout_, &err_, &k_[0], &k_[1], &k_[2], &k_[3], &k_[4]}) v->assign(N, 0.0);
    unit_ = rosenbrock_.units();
  }

  odeint::controlled_step_result try_step(const ExplicitSystem& system, ExplicitState& x, double& t, double& dt) {
    if (stiff_) {
      const double h = dt;
      const odeint::controlled_step_result res = rosenbrock_.try_step(system, x, t, dt);
      if (res == odeint::success) {
        ++stiffSteps_;
        // ρ between the last stage's argument and the new state (a Rayleigh quotient of J)
        const double hrho = h * lipschitzEstimate(rosenbrock_.lastStageState(), rosenbrock_.lastStageRhs(), x);
        nonStiffRun_ = hrho < 1.0 ? nonStiffRun_ + 1 : 0;
        if (nonStiffRun_ >= backAfter_) {
          stiff_ = false;
          switchedBack_ = true;
          stiffCount_ = nonStiffRun_ = 0;
          control_.reset();
        }
      }
      return res;
    }
    model_.rhs(x.data(), f0_.data());  // (the statics at x are cached from the monitor)
    dopri(x, dt);
    // order-4 estimate: the step factor err^{1/5}
    const double h = dt;
    if (!control_.accept(weightedErrorNorm(err_, x, xout_, unit_, atol_, rtol_), dt)) return odeint::fail;
    const double hrho = h * lipschitzEstimate(x6_, f6_, xout_);
    x.swap(xout_);
    t += h;
    if (hrho > 3.25) {
      nonStiffRun_ = 0;
      if (++stiffCount_ >= 15) {
        stiff_ = true;
        if (switchedBack_) backAfter_ *= 2;
        stiffCount_ = nonStiffRun_ = 0;
        rosenbrock_.reset();
      }
    } else if (++nonStiffRun_ >= 6) {
      stiffCount_ = 0;
    }
    return odeint::success;
  }

  void reset() {
    control_.reset();
    rosenbrock_.reset();
  }

  /// Accepted steps taken by Rosenbrock4.
  long stiffSteps() const { return stiffSteps_; }

 private:
  /// ‖f(b) − f_a‖ / ‖b − a‖ over the angles (f_a = f(a); f(b) evaluated here: the statics at b
  /// are the monitor's next ones, cached).
  double lipschitzEstimate(const ExplicitState& a, const ExplicitState& fa, const ExplicitState& b) {
    model_.rhs(b.data(), f7_.data());
    const size_t n = size_t(model_.segments());
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; ++i) {
      num += (f7_[i] - fa[i]) * (f7_[i] - fa[i]);
      den += (b[i] - a[i]) * (b[i] - a[i]);
    }
    return den > 0.0 ? std::sqrt(num / den) : 0.0;
  }

  // One Dormand–Prince 5(4) step (odeint's runge_kutta_dopri5 tableau) from x with f0_ = f(x):
  // xout_, the error estimate err_ (uses f(xout_), into f7_), x6_ and f6_ = f(x6_).
  void dopri(const ExplicitState& x, double h) {
    static constexpr double b21 = 1.0 / 5, b31 = 3.0 / 40, b32 = 9.0 / 40, b41 = 44.0 / 45, b42 = -56.0 / 15,
                            b43 = 32.0 / 9, b51 = 19372.0 / 6561, b52 = -25360.0 / 2187, b53 = 64448.0 / 6561,
                            b54 = -212.0 / 729, b61 = 9017.0 / 3168, b62 = -355.0 / 33, b63 = 46732.0 / 5247,
                            b64 = 49.0 / 176, b65 = -5103.0 / 18656, c1 = 35.0 / 384, c3 = 500.0 / 1113,
                            c4 = 125.0 / 192, c5 = -2187.0 / 6784, c6 = 11.0 / 84;
    static constexpr double dc1 = c1 - 5179.0 / 57600, dc3 = c3 - 7571.0 / 16695, dc4 = c4 - 393.0 / 640,
                            dc5 = c5 - -92097.0 / 339200, dc6 = c6 - 187.0 / 2100, dc7 = -1.0 / 40;
    const size_t N = x.size();
    ExplicitState& y = x6_;  // stage arguments (the last one is x₆)
    const ExplicitState &k1 = f0_;
    ExplicitState &k2 = k_[0], &k3 = k_[1], &k4 = k_[2], &k5 = k_[3], &k6 = f6_;
    for (size_t i = 0; i < N; ++i) y[i] = x[i] + h * b21 * k1[i];
    model_.rhs(y.data(), k2.data());
    for (size_t i = 0; i < N; ++i) y[i] = x[i] + h * (b31 * k1[i] + b32 * k2[i]);
    model_.rhs(y.data(), k3.data());
    for (size_t i = 0; i < N; ++i) y[i] = x[i] + h * (b41 * k1[i] + b42 * k2[i] + b43 * k3[i]);
    model_.rhs(y.data(), k4.data());
    for (size_t i = 0; i < N; ++i) y[i] = x[i] + h * (b51 * k1[i] + b52 * k2[i] + b53 * k3[i] + b54 * k4[i]);
    model_.rhs(y.data(), k5.data());
    for (size_t i = 0; i < N; ++i) y[i] = x[i] + h * (b61 * k1[i] + b62 * k2[i] + b63 * k3[i] + b64 * k4[i] + b65 * k5[i]);
    model_.rhs(y.data(), k6.data());
    for (size_t i = 0; i < N; ++i) xout_[i] = x[i] + h * (c1 * k1[i] + c3 * k3[i] + c4 * k4[i] + c5 * k5[i] + c6 * k6[i]);
    model_.rhs(xout_.data(), f7_.data());
    for (size_t i = 0; i < N; ++i)
      err_[i] = h * (dc1 * k1[i] + dc3 * k3[i] + dc4 * k4[i] + dc5 * k5[i] + dc6 * k6[i] + dc7 * f7_[i]);
  }

  DynamicsModel& model_;
  StructuredRosenbrock4 rosenbrock_;
  double atol_, rtol_;
  std::vector<double> unit_;
  bool stiff_ = false, switchedBack_ = false;
  int stiffCount_ = 0, nonStiffRun_ = 0, backAfter_ = 15;
  long stiffSteps_ = 0;
  StepSizeController control_{0.2};
  ExplicitState f0_, f6_, f7_, x6_, xout_, err_;
  ExplicitState k_[5];
};

/// The accepted-step loop shared by all steppers: guards, monitoring, recording, rest.
class Monitor {
 public:
  Monitor(DynamicsModel& model, const IntegrationOptions& options, DynamicsResult& result)
      : model_(model), options_(options), result_(result), qdot_(model.segments()) {}

  void start(const double* x) {
    result_.initialEnergy = energy(x);
    record(0.0, x, true);
  }

  /// After an accepted step: true to stop (reason set).
  bool accepted(double t, const double* x) {
    Eigen::Map<const Vector> q(x, model_.segments());
    result_.maxConstraintViolation = std::max(result_.maxConstraintViolation, model_.constraintViolation(q));
    result_.maxEnergyBalanceError = std::max(result_.maxEnergyBalanceError, std::abs(energy(x) - result_.initialEnergy));
    record(t, x, false);
    const double speed = model_.restSpeed(x);
    // (the residual is another sweep: only when it can end the integration)
    const bool slow = speed <= options_.velocityTolerance;
    const double residual = slow || options_.settled ? model_.naturalResidual(q) : 0.0;
    if (slow && residual <= options_.residualTolerance)
      return stop(IntegrationStop::Rest, "at rest: |qdot| and the equilibrium residual are below tolerance at t = " + num(t));
    ++sinceSettleCheck_;
    if (options_.settled && model_.lockedCount() == 0 && residual <= options_.settleResidual &&
        sinceSettleCheck_ >= options_.settleInterval) {
      sinceSettleCheck_ = 0;
      if (options_.settled(q))
        return stop(IntegrationStop::Settled, "settled at t = " + num(t) + " (equilibrium residual " + num(residual) +
                                                  "): handed over to the caller's certified solve");
    }
    return false;
  }

  bool stop(IntegrationStop reason, const std::string& message) {
    result_.reason = reason;
    result_.message = message;
    return true;
  }

  void finish(double t, const double* x) {
    const int n = model_.segments();
    Eigen::Map<const Vector> q(x, n);
    result_.time = t;
    result_.q = q;
    model_.velocity(x, qdot_);
    result_.qdot = qdot_;
    result_.speed = qdot_.cwiseAbs().maxCoeff();
    result_.potential = model_.potential(q);
    result_.kinetic = model_.kineticEnergy(x);
    result_.dissipated = model_.dissipated(x);
    result_.residual = model_.equilibriumResidual(q);
    result_.contactSides = model_.contactSides();
    result_.contactTorques = Vector::Zero(n);
    model_.contactTorques(x, result_.contactTorques);
    if (options_.recordTrajectory && (result_.trajectory.empty() || result_.trajectory.back().t < t)) forceRecord(t, x);
  }

 private:
  static std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }

  double energy(const double* x) {
    Eigen::Map<const Vector> q(x, model_.segments());
    return model_.potential(q) + model_.kineticEnergy(x) + model_.dissipated(x);
  }

  void record(double t, const double* x, bool first) {
    if (!options_.recordTrajectory) return;
    if (!first && t - lastRecorded_ < options_.recordInterval) return;
    forceRecord(t, x);
  }

  void forceRecord(double t, const double* x) {
    if (result_.trajectory.size() >= options_.maxSamples) {
      result_.trajectoryTruncated = true;
      return;
    }
    const int n = model_.segments();
    Eigen::Map<const Vector> q(x, n);
    TrajectorySample s;
    s.t = t;
    s.q = q;
    model_.velocity(x, qdot_);
    s.qdot = qdot_;
    s.potential = model_.potential(q);
    s.kinetic = model_.kineticEnergy(x);
    s.dissipated = model_.dissipated(x);
    s.residual = model_.equilibriumResidual(q);
    s.constraintViolation = model_.constraintViolation(q);
    result_.trajectory.push_back(std::move(s));
    lastRecorded_ = t;
  }

  DynamicsModel& model_;
  const IntegrationOptions& options_;
  DynamicsResult& result_;
  Vector qdot_;
  double lastRecorded_ = 0.0;
  long sinceSettleCheck_ = 0;
};

// FSAL controllers keep dx/dt of the last accepted state: after a rollback it must be dropped.
template <class C>
auto resetController(C& controller, int) -> decltype(controller.reset(), void()) {
  controller.reset();
}
template <class C>
void resetController(C&, long) {}

/// The one-sided joint limits during an integration (dynamics.h, file comment): event functions,
/// their location inside an accepted step, and the contact set's update at an event.
class ContactTracker {
 public:
  ContactTracker(DynamicsModel& model, DynamicsResult& result)
      : model_(model), result_(result), g_(size_t(model.segments())), torques_(model.segments()) {}

  /// Event functions at x, in the chain's own units: for a free joint the distance to its nearer
  /// limit (radians, > 0 inside), for a locked one its compression −side·τ_c / k̄b̄² (> 0 while
  /// the contact pushes).
  const std::vector<double>& events(const double* x) {
    const int n = model_.segments();
    const Vector& lo = model_.chain().lowerLimits();
    const Vector& hi = model_.chain().upperLimits();
    model_.contactTorques(x, torques_);
    for (int i = 0; i < n; ++i) {
      const int side = model_.contactSides()[size_t(i)];
      g_[size_t(i)] = side == 0 ? std::min(x[i] - lo[i], hi[i] - x[i]) : -side * torques_[i] / model_.torqueUnit();
    }
    return g_;
  }

  /// Locks `joint` at its nearer limit (side 0) or releases it, at time t; x is made admissible.
  void toggle(double* x, double t, int joint) {
    std::vector<int> sides = model_.contactSides();
    const bool lock = sides[size_t(joint)] == 0;
    ContactEvent e;
    e.t = t;
    e.joint = joint;
    if (lock) {
      const double lo = model_.chain().lowerLimits()[joint], hi = model_.chain().upperLimits()[joint];
      sides[size_t(joint)] = hi - x[joint] <= x[joint] - lo ? 1 : -1;
    } else {
      model_.contactTorques(x, torques_);
      e.torque = torques_[joint];
      sides[size_t(joint)] = 0;
    }
    e.side = lock ? sides[size_t(joint)] : model_.contactSides()[size_t(joint)];
    e.contact = lock;
    model_.setContacts(sides);
    if (lock) {
      e.kineticLost = model_.impact(x);
      model_.contactTorques(x, torques_);
      e.torque = torques_[joint];
    }
    result_.contactEvents.push_back(e);
  }

  /// The contact set consistent at x (after an event or at the start): free joints beyond a
  /// limit are locked, then the locked joint pulling hardest is released, one at a time (an
  /// active-set iteration; at most 2n + 2 changes). False when it does not settle.
  bool settle(double* x, double t) {
    const int n = model_.segments();
    for (int change = 0; change <= 2 * n + 2; ++change) {
      const std::vector<double>& g = events(x);
      int beyond = -1, pulling = -1;
      double worst = 0.0;
      for (int i = 0; i < n; ++i) {
        if (model_.contactSides()[size_t(i)] == 0) {
          if (g[size_t(i)] < 0.0 && beyond < 0) beyond = i;
        } else if (g[size_t(i)] < worst) {
          worst = g[size_t(i)];
          pulling = i;
        }
      }
      if (beyond >= 0) toggle(x, t, beyond);
      else if (pulling >= 0) toggle(x, t, pulling);
      else return true;
    }
    return false;
  }

 private:
  DynamicsModel& model_;
  DynamicsResult& result_;
  std::vector<double> g_;
  Vector torques_;
};

template <class Controller, class System, class State, class SubStep>
void runLoop(Controller& controller, System system, State& x, const double* (*data)(const State&), SubStep subStep,
             DynamicsModel& model, const IntegrationOptions& options, Monitor& monitor, DynamicsResult& result) {
  double t = 0.0, dt = options.initialStep;
  const int n = model.segments();
  auto mutableData = [&](State& s) { return const_cast<double*>(data(s)); };
  ContactTracker contacts(model, result);
  std::vector<double> gPrevious;
  if (options.contact) {
    model.impact(mutableData(x));  // the caller's locked joints sit on their limits
    if (!contacts.settle(mutableData(x), t)) {
      monitor.stop(IntegrationStop::JointLimit, "the contact set at the start did not settle");
      monitor.finish(t, data(x));
      return;
    }
    gPrevious = contacts.events(data(x));
  }
  monitor.start(data(x));
  State previous = x, trial = x;
  int eventsWithoutProgress = 0;
  for (;;) {
    if (options.interrupt.requested()) {
      monitor.stop(IntegrationStop::Interrupted, options.interrupt.describe() + " at t = " + std::to_string(t));
      break;
    }
    if (result.steps >= options.maxSteps) {
      monitor.stop(IntegrationStop::MaxSteps, "maximum number of steps (" + std::to_string(options.maxSteps) + ") reached");
      break;
    }
    if (t >= options.maxTime * (1.0 - 1e-15)) {
      monitor.stop(IntegrationStop::MaxTime, "maximum time reached before rest");
      break;
    }
    dt = std::min(dt, options.maxTime - t);
    if (options.maxStep > 0.0) dt = std::min(dt, options.maxStep);
    previous = x;
    const double tPrevious = t, dtTried = dt;
    const odeint::controlled_step_result res = controller.try_step(system, x, t, dt);
    if (res == odeint::fail) {
      ++result.rejectedSteps;
      if (!(dt >= options.minStep)) {
        monitor.stop(IntegrationStop::StepSizeUnderflow, "the step size fell below minStep at t = " + std::to_string(t));
        break;
      }
      continue;
    }
    // The error control cannot see a step that leaves the model's domain (a NaN error estimate
    // compares false and is accepted). Such a step is rolled back and retried at half the size.
    // Without contact, a step past a joint limit is too (past a geometric limit a spring would
    // pass through zero length), which bisects the time at which a joint reaches its limit down
    // to minStep; the chain then stops there. With contact the model is evaluated just past a
    // limit (its analytic continuation, segment.cpp) and the crossing is located as an event.
    const double* xs = data(x);
    bool finiteState = true;
    for (int i = 0; finiteState && i < model.stateSize(); ++i) finiteState = std::isfinite(xs[i]);
    const bool inside = finiteState && (options.contact || model.withinLimits(Eigen::Map<const Vector>(xs, n)));
    if (!inside) {
      x = previous;
      t = tPrevious;
      resetController(controller, 0);
      ++result.rejectedSteps;
      dt = 0.5 * dtTried;
      if (dt < options.minStep) {
        const double* xp = data(x);
        int joint = 0;
        double margin = std::numeric_limits<double>::infinity();
        for (int i = 0; i < n; ++i) {
          const double mi = std::min(xp[i] - model.chain().lowerLimits()[i], model.chain().upperLimits()[i] - xp[i]);
          if (mi < margin) {
            margin = mi;
            joint = i;
          }
        }
        // A trial that only failed by being non-finite far from every limit is a model failure.
        if (!finiteState && (options.contact || margin > 1e-6)) {
          monitor.stop(IntegrationStop::NonFinite, "the right-hand side became non-finite at t = " + std::to_string(t));
        } else {
          monitor.stop(IntegrationStop::JointLimit, "joint " + std::to_string(joint + 1) + " reached its limit (q = " +
                                                   std::to_string(xp[joint]) + ") at t = " + std::to_string(t));
        }
        break;
      }
      continue;
    }
    if (options.contact) {
      // Events in the step: an event function that went from >= 0 to < 0. Each crossing is
      // located by Illinois iteration on the step length τ in (0, t − tPrevious], each trial a
      // step of the integrator's method from the last accepted state; the earliest one is taken.
      const std::vector<double> gNow = contacts.events(data(x));
      const double h = t - tPrevious;
      int joint = -1;
      double at = h;
      for (int i = 0; i < n; ++i) {
        const double g0 = gPrevious[size_t(i)], g1 = gNow[size_t(i)];
        if (!(g0 >= 0.0 && g1 < 0.0)) continue;
        double root = 0.0;
        if (g0 > 0.0) {
          continuation::IllinoisBracket bracket{0.0, h, g0, g1};
          for (int it = 0; it < 200 && bracket.width() > 1e-13 * std::max(t, h); ++it) {
            const double s = std::min(bracket.next(), at);  // no later than the earliest so far
            if (!subStep(previous, tPrevious, s, trial)) break;
            const double gs = contacts.events(data(trial))[size_t(i)];
            if (gs == 0.0) {
              bracket.left = bracket.right = s;
              break;
            }
            if (s >= at && gs >= 0.0) {  // not before the earliest event found: not this one
              bracket.left = at;
              break;
            }
            bracket.update(s, gs);
          }
          root = bracket.left;  // the admissible side (g >= 0) of the located instant
        }
        if (root < at || joint < 0) {
          at = root;
          joint = i;
        }
      }
      if (joint >= 0) {
        if (at < h) {  // back to the located instant
          if (at > 0.0 && subStep(previous, tPrevious, at, trial)) {
            x = trial;
          } else {
            x = previous;
            at = 0.0;
          }
          t = tPrevious + at;
        }
        contacts.toggle(mutableData(x), t, joint);
        if (!contacts.settle(mutableData(x), t)) {
          monitor.stop(IntegrationStop::JointLimit, "the contact set did not settle at t = " + std::to_string(t));
          break;
        }
        resetController(controller, 0);
        eventsWithoutProgress = at > 0.0 ? 0 : eventsWithoutProgress + 1;
        if (eventsWithoutProgress > 2 * n + 2) {
          monitor.stop(IntegrationStop::JointLimit, "contacts keep changing without progress at t = " + std::to_string(t));
          break;
        }
        dt = std::max(dt, options.minStep);
        gPrevious = contacts.events(data(x));
      } else {
        gPrevious = gNow;
      }
    }
    ++result.steps;
    if (monitor.accepted(t, data(x))) break;
  }
  monitor.finish(t, data(x));
}

const double* explicitData(const ExplicitState& x) { return x.data(); }
const double* stiffData(const StiffState& x) { return &x.data()[0]; }

}  // namespace

DynamicsResult simulate(DynamicsModel& model, ConstVectorRef q0, ConstVectorRef qdot0, const IntegrationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("IntegrationOptions: " + why);
  const int n = model.segments();
  if (q0.size() != n) throw std::invalid_argument("q0 must have one entry per joint");
  if (qdot0.size() != 0 && qdot0.size() != n) throw std::invalid_argument("qdot0 must be empty or have one entry per joint");
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(q0[i]) || (qdot0.size() == n && !std::isfinite(qdot0[i])))
      throw std::invalid_argument("the initial state must be finite");

  // The options' times and rest tolerances are in the model's natural units (dynamics.h).
  const double T = model.timeUnit();
  IntegrationOptions natural = options;
  natural.initialStep *= T;
  natural.maxStep *= T;
  natural.minStep *= T;
  natural.maxTime *= T;
  natural.recordInterval *= T;
  natural.velocityTolerance /= T;
  const auto wallStart = std::chrono::steady_clock::now();
  DynamicsResult result;
  result.kind = model.kind();
  const int N = model.stateSize();
  Vector x0(N);
  model.packState(q0, qdot0, x0);
  Monitor monitor(model, natural, result);
  const std::vector<int> initialSides = model.contactSides();

  // The structured Rosenbrock method runs on the model's solveLinearized() (both models have it).
  const bool structured = natural.stepper == StepperKind::StructuredRosenbrock4;
  if (natural.stepper == StepperKind::StructuredSwitching) {
    ExplicitState x(x0.data(), x0.data() + N);
    SwitchingStepper controller(model, natural.absoluteTolerance, natural.relativeTolerance);
    // event trials: one Rosenbrock4 step (L-stable: valid whatever the stiffness)
    StructuredRosenbrock4 trial(model, natural.absoluteTolerance, natural.relativeTolerance);
    auto subStep = [&](const ExplicitState& from, double, double h, ExplicitState& to) { return trial.advance(from, h, to); };
    runLoop(controller, ExplicitSystem{&model}, x, explicitData, subStep, model, natural, monitor, result);
    result.stiffSteps = controller.stiffSteps();
  } else if (structured) {
    ExplicitState x(x0.data(), x0.data() + N);
    StructuredRosenbrock4 controller(model, natural.absoluteTolerance, natural.relativeTolerance);
    StructuredRosenbrock4 trial(model, natural.absoluteTolerance, natural.relativeTolerance);
    auto subStep = [&](const ExplicitState& from, double, double h, ExplicitState& to) { return trial.advance(from, h, to); };
    runLoop(controller, ExplicitSystem{&model}, x, explicitData, subStep, model, natural, monitor, result);
  } else if (natural.stepper == StepperKind::Rosenbrock4) {
    StiffState x(static_cast<size_t>(N));
    std::copy(x0.data(), x0.data() + N, x.begin());
    odeint::rosenbrock4_controller<odeint::rosenbrock4<double>> controller(natural.absoluteTolerance,
                                                                           natural.relativeTolerance);
    odeint::rosenbrock4<double> trial;
    StiffState error(static_cast<size_t>(N));
    auto subStep = [&](const StiffState& from, double t0, double h, StiffState& to) {
      to = from;
      trial.do_step(std::make_pair(StiffSystem{&model}, StiffJacobian{&model}), to, t0, h, error);
      return true;
    };
    runLoop(controller, std::make_pair(StiffSystem{&model}, StiffJacobian{&model}), x, stiffData, subStep, model,
            natural, monitor, result);
  } else {
    ExplicitState x(x0.data(), x0.data() + N);
    // event trials: one Cash–Karp step (fifth order, no first-same-as-last state to keep)
    odeint::runge_kutta_cash_karp54<ExplicitState> trial;
    auto subStep = [&](const ExplicitState& from, double t0, double h, ExplicitState& to) {
      trial.do_step(ExplicitSystem{&model}, from, t0, to, h);
      return true;
    };
    if (natural.stepper == StepperKind::DormandPrince5) {
      auto controller = odeint::make_controlled(natural.absoluteTolerance, natural.relativeTolerance,
                                                odeint::runge_kutta_dopri5<ExplicitState>());
      runLoop(controller, ExplicitSystem{&model}, x, explicitData, subStep, model, natural, monitor, result);
    } else {
      auto controller = odeint::make_controlled(natural.absoluteTolerance, natural.relativeTolerance,
                                                odeint::runge_kutta_cash_karp54<ExplicitState>());
      runLoop(controller, ExplicitSystem{&model}, x, explicitData, subStep, model, natural, monitor, result);
    }
  }
  // the contacts found are the result's; the model is left as the caller set it (repeatable runs)
  model.setContacts(initialSides);
  result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
  return result;
}

}  // namespace buckle::mechanics
