// The integrators of simulate() (dynamics_integration.cpp), apart from its event and contact
// loop: the odeint system adaptors, the error norm and step-size control in the components'
// units, the O(n) structured Rosenbrock4 and the Dormand–Prince / Rosenbrock4 switching stepper
// (dynamics.h, "integration"). Internal: included by dynamics_integration.cpp only.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <vector>

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/ublas/matrix.hpp>
#include <boost/numeric/ublas/vector.hpp>

#include "buckle/mechanics/dynamics.h"

namespace buckle::mechanics::steppers {

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
inline double weightedErrorNorm(const ExplicitState& e, const ExplicitState& x, const ExplicitState& xNew,
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
struct StepOptionsler {
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
  StepOptionsler control_{0.25};
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
  StepOptionsler control_{0.2};
  ExplicitState f0_, f6_, f7_, x6_, xout_, err_;
  ExplicitState k_[5];
};

}  // namespace buckle::mechanics::steppers
