// Integration of the dynamics models (dynamics.h, "integration"): options, the accepted-step loop
// with the rest / guard monitor and the contacts as events (dynamics_contacts.h), and simulate(). The steppers
// themselves are in dynamics_steppers.h.
#include "buckle/mechanics/dynamics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "buckle/continuation/root_finding.h"
#include "dynamics_contacts.h"
#include "dynamics_steppers.h"

namespace buckle::mechanics {

// ---- integration -----------------------------------------------------------------------------

std::string IntegrationOptions::validate(const std::string& prefix) const {
  if (!std::isfinite(absoluteTolerance) || !(absoluteTolerance > 0.0)) return prefix + "absoluteTolerance must be > 0";
  if (!std::isfinite(relativeTolerance) || relativeTolerance < 0.0) return prefix + "relativeTolerance must be >= 0";
  if (!std::isfinite(initialStep) || !(initialStep > 0.0)) return prefix + "initialStep must be > 0";
  if (!std::isfinite(maxStep) || maxStep < 0.0) return prefix + "maxStep must be >= 0 (0: unlimited)";
  if (!std::isfinite(minStep) || !(minStep > 0.0)) return prefix + "minStep must be > 0";
  if (maxStep > 0.0 && maxStep < minStep) return prefix + "maxStep must be >= minStep";
  if (!(maxTime > 0.0) || std::isnan(maxTime)) return prefix + "maxTime must be > 0";
  if (maxSteps < 1) return prefix + "maxSteps must be >= 1";
  if (!std::isfinite(velocityTolerance) || !(velocityTolerance > 0.0)) return prefix + "velocityTolerance must be > 0";
  if (!std::isfinite(residualTolerance) || !(residualTolerance > 0.0)) return prefix + "residualTolerance must be > 0";
  if (!std::isfinite(recordInterval) || recordInterval < 0.0) return prefix + "recordInterval must be >= 0";
  if (maxSamples < 2) return prefix + "maxSamples must be >= 2";
  if (!std::isfinite(settleResidual) || !(settleResidual > 0.0)) return prefix + "settleResidual must be > 0";
  if (settleInterval < 1) return prefix + "settleInterval must be >= 1";
  return {};
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
    case IntegrationStop::Barrier: return "barrier";
  }
  return "unknown";
}

namespace {

using namespace steppers;  // the integrators (dynamics_steppers.h)

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
    if (options_.settled && model_.lockedCount() == 0 && model_.wallCount() == 0 && model_.selfCount() == 0 &&
        residual <= options_.settleResidual &&
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
    result_.wallContacts = model_.wallContacts();
    result_.wallForces = Vector::Zero(model_.wallCount());
    result_.selfContacts = model_.selfContacts();
    result_.selfForces = Vector::Zero(model_.selfCount());
    model_.contactForces(x, result_.contactTorques, result_.wallForces, result_.selfForces);
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

/// The stop after the step size fell below minStep while steps kept leaving the admissible states
/// at x (the last accepted state): at the barrier when the last trial was finite and within the
/// limits (only IntegrationOptions::admissible rejected it), else at the nearest joint limit, or
/// a model failure for a non-finite trial far from every limit.
void stopOutside(DynamicsModel& model, const IntegrationOptions& options, Monitor& monitor, const double* x, double t,
                 bool finiteTrial, bool withinLimits) {
  if (finiteTrial && withinLimits) {
    monitor.stop(IntegrationStop::Barrier, "reached the barrier at t = " + std::to_string(t));
    return;
  }
  const int n = model.segments();
  int joint = 0;
  double margin = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    const double mi = std::min(x[i] - model.chain().lowerLimits()[i], model.chain().upperLimits()[i] - x[i]);
    if (mi < margin) {
      margin = mi;
      joint = i;
    }
  }
  // A trial that only failed by being non-finite far from every limit is a model failure.
  if (!finiteTrial && (options.contact || margin > 1e-6)) {
    monitor.stop(IntegrationStop::NonFinite, "the right-hand side became non-finite at t = " + std::to_string(t));
  } else {
    monitor.stop(IntegrationStop::JointLimit, "joint " + std::to_string(joint + 1) + " reached its limit (q = " +
                                                 std::to_string(x[joint]) + ") at t = " + std::to_string(t));
  }
}

template <class Controller, class System, class State, class SubStep>
void runLoop(Controller& controller, System system, State& x, const double* (*data)(const State&), SubStep subStep,
             DynamicsModel& model, const IntegrationOptions& options, Monitor& monitor, DynamicsResult& result) {
  double t = 0.0, dt = options.initialStep;
  const int n = model.segments();
  auto mutableData = [&](State& s) { return const_cast<double*>(data(s)); };
  ContactTracker contacts(model, options, result);
  std::vector<double> gPrevious;
  if (contacts.active()) {
    model.impact(mutableData(x));  // the caller's locked joints sit on their limits
    if (!contacts.settle(mutableData(x), t)) {
      monitor.stop(IntegrationStop::JointLimit, "the contact set at the start did not settle");
      monitor.finish(t, data(x));
      return;
    }
    gPrevious = contacts.events(data(x));
  }
  monitor.start(data(x));
  if (options.admissible && !options.admissible(Eigen::Map<const Vector>(data(x), n))) {
    monitor.stop(IntegrationStop::Barrier, "the start is beyond the barrier");
    monitor.finish(t, data(x));
    return;
  }
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
    // limit (its analytic continuation, segment.cpp) and the crossing is located as an event. A
    // step past the caller's barrier (IntegrationOptions::admissible) is bisected the same way.
    const double* xs = data(x);
    bool finiteState = true;
    for (int i = 0; finiteState && i < model.stateSize(); ++i) finiteState = std::isfinite(xs[i]);
    const bool inside = finiteState && (options.contact || model.withinLimits(Eigen::Map<const Vector>(xs, n)));
    if (!inside || (options.admissible && !options.admissible(Eigen::Map<const Vector>(xs, n)))) {
      x = previous;
      t = tPrevious;
      resetController(controller, 0);
      ++result.rejectedSteps;
      dt = 0.5 * dtTried;
      if (dt < options.minStep) {
        stopOutside(model, options, monitor, data(x), t, finiteState, inside);
        break;
      }
      continue;
    }
    if (contacts.active()) {
      // Events in the step: an event function that went from >= 0 to < 0. Each crossing is
      // located by Illinois iteration on the step length τ in (0, t − tPrevious], each trial a
      // step of the integrator's method from the last accepted state; the earliest one is taken.
      const std::vector<double> gNow = contacts.events(data(x));
      const double h = t - tPrevious;
      int joint = -1;  // the event's index (contacts.events())
      double at = h;
      for (int i = 0; i < contacts.size(); ++i) {
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
        if (eventsWithoutProgress > 2 * contacts.size() + 2) {
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
  const std::vector<WallVertex> initialWall = model.wallContacts();
  const std::vector<SelfContact> initialSelf = model.selfContacts();

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
  model.setWallContacts(initialWall);
  model.setSelfContacts(initialSelf);
  result.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
  return result;
}

}  // namespace buckle::mechanics
