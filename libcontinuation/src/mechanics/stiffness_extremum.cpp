#include "buckle/mechanics/stiffness_extremum.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "buckle/continuation/corrector.h"
#include "buckle/continuation/scaled_problem.h"
#include "buckle/mechanics/chain_structure.h"
#include "buckle/mechanics/stiffness.h"

namespace buckle::mechanics {

namespace cont = buckle::continuation;

const char* toString(StiffnessMeasure measure) {
  switch (measure) {
    case StiffnessMeasure::Kxx: return "Kxx";
    case StiffnessMeasure::Kyy: return "Kyy";
    case StiffnessMeasure::MinEigenvalue: return "Kmin";
  }
  return "?";
}

bool parseStiffnessMeasure(const std::string& name, StiffnessMeasure& measure) {
  for (StiffnessMeasure m : {StiffnessMeasure::Kxx, StiffnessMeasure::Kyy, StiffnessMeasure::MinEigenvalue})
    if (name == toString(m)) {
      measure = m;
      return true;
    }
  return false;
}

double stiffnessMeasure(const Eigen::Matrix2d& K, StiffnessMeasure measure) {
  switch (measure) {
    case StiffnessMeasure::Kxx: return K(0, 0);
    case StiffnessMeasure::Kyy: return K(1, 1);
    case StiffnessMeasure::MinEigenvalue:
      return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(K, Eigen::EigenvaluesOnly).eigenvalues()[0];
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double stiffnessMeasureDerivative(const Eigen::Matrix2d& K, const Eigen::Matrix2d& dK, StiffnessMeasure measure) {
  switch (measure) {
    case StiffnessMeasure::Kxx: return dK(0, 0);
    case StiffnessMeasure::Kyy: return dK(1, 1);
    case StiffnessMeasure::MinEigenvalue: {
      // Hellmann–Feynman: dμ = vᵀ dK v for a simple eigenvalue μ with unit eigenvector v.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(K);
      const Eigen::Vector2d v = es.eigenvectors().col(0);
      return v.dot(dK * v);
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

StiffnessRate stiffnessRate(const EquilibriumProblem& problem, cont::ConstVectorRef u, double lambda,
                            cont::ConstVectorRef du, double dlambda, StiffnessMeasure measure) {
  const int n = problem.segments();
  StiffnessRate r;
  const Wrench F = problem.wrench(u, lambda);
  // dF: the prescribed loads move with dλ, the reactions of held coordinates with their unknowns.
  Wrench dF = dlambda * problem.direction();
  const std::vector<int> held = problem.endCondition().heldIndices();
  for (size_t k = 0; k < held.size(); ++k) dF[held[k]] = du[n + int(k)];
  Eigen::Matrix2d dK;
  const bool rotationHeld = problem.endCondition().isHeld(EndCoordinate::Phi);
  StiffnessOptions body;  // the body loads' γ and dγ (eq B3, B5)
  body.bodyGenerator = problem.bodyLoadGenerator(u.head(n), lambda);
  body.bodyGeneratorRate = problem.bodyLoadGeneratorRate(u.head(n), lambda, du.head(n), dlambda);
  // O(n) for long chains; the dense solves where the structure's factorization fails
  const auto derivative = [&](const Chain& chain) {
    return (n >= kStructuredStiffnessFrom &&
            structuredStiffnessDerivative(chain, u.head(n), F, rotationHeld, du.head(n), dF, r.K, &dK, body)) ||
           loadedStiffnessDerivative(chain, u.head(n), F, rotationHeld, du.head(n), dF, r.K, dK, body);
  };
  const auto stiffnessAt = [&](const Chain& chain, const StiffnessOptions& o) {
    Eigen::Matrix2d K;
    if (n >= kStructuredStiffnessFrom &&
        structuredStiffnessDerivative(chain, u.head(n), F, rotationHeld, du.head(n), dF, K, nullptr, o))
      return K;
    return Eigen::Matrix2d(loadedStiffness(chain, u.head(n), F, rotationHeld, o).stiffness);
  };
  if (!problem.controlled()) {
    if (!derivative(problem.chain())) return r;
  } else {
    // Along a control path K_q also moves with λ at fixed (q, F): that part of dK by central
    // differences of K_F in λ (step 1e-5 of λ's unit: error ~1e-10 relative), the rest exact.
    try {
      if (!derivative(problem.chainAt(lambda))) return r;
      const double h = 1e-5 * problem.scales().parameter;
      StiffnessOptions fixed;  // K_q's own λ rate: γ held at its value (its rate is in dγ above)
      fixed.bodyGenerator = body.bodyGenerator;
      const Eigen::Matrix2d up = stiffnessAt(problem.chainAt(lambda + h), fixed);
      const Eigen::Matrix2d down = stiffnessAt(problem.chainAt(lambda - h), fixed);
      dK += (up - down) * (dlambda / (2.0 * h));
    } catch (const std::invalid_argument&) {
      return r;  // a free length not positive within the step: no rate
    }
  }
  r.value = stiffnessMeasure(r.K, measure);
  r.rate = stiffnessMeasureDerivative(r.K, dK, measure);
  r.valid = std::isfinite(r.value) && std::isfinite(r.rate);
  return r;
}

namespace {

/// One evaluation of g(τ): the branch point on the hyperplane τ and the measure's rate there.
struct Sample {
  double tau = 0.0;
  double g = 0.0;
  Vector x;                 // (ũ, λ̃), scaled
  StiffnessRate rate;
  double residual = 0.0;
  bool ok = false;
};

/// The branch between a and b, on the scaled problem: corrected points and exact rates.
class BranchSection {
 public:
  BranchSection(EquilibriumProblem& problem, const cont::ContinuationPoint& a, const cont::ContinuationPoint& b,
                StiffnessMeasure measure)
      : problem_(problem),
        units_(problem.scales()),
        scaledProblem_(cont::BoundProblem(problem), units_),
        scaled_(scaledProblem_.bound()),
        structured_(problem.segments() > kSmallDense ? scaled_.makeStructuredSolver() : nullptr),
        corrector_(scaled_, correctorOptions(), structured_.get()),
        measure_(measure),
        N_(problem.dimension()) {
    xa_ = toScaled(a);
    xb_ = toScaled(b);
    normal_ = (xb_ - xa_).normalized();
    if (!structured_) {
      border_.resize(N_ + 1, N_ + 1);
      Fu_.resize(N_, N_);
    }
    Flambda_.resize(N_);
  }

  bool degenerate() const { return !normal_.allFinite(); }

  Sample at(double tau) {
    Sample s;
    s.tau = tau;
    s.x.resize(N_ + 1);
    const Vector predictor = xa_ + tau * (xb_ - xa_);
    const cont::CorrectorSummary c = corrector_.correct(predictor, normal_, s.x);
    s.residual = c.residualNorm;
    if (!c.converged) return s;
    // Tangent: [[F̃_u, F̃_λ], [nᵀ]] t̃ = e (nᵀt̃ = 1 orients it from a to b), back to the user's
    // units for the derivative of K_F.
    Vector e = Vector::Zero(N_ + 1), t(N_ + 1);
    e[N_] = 1.0;
    if (structured_) {  // a long chain: the O(n) bordered solver (chain_solver.h)
      if (structured_->factor(s.x.head(N_), s.x[N_], normal_) == cont::Factorization::Refused ||
          !structured_->solve(e, t))
        return s;
    } else {
      if (!scaled_.jacobian(s.x.head(N_), s.x[N_], Fu_, Flambda_)) return s;
      border_.topLeftCorner(N_, N_) = Fu_;
      border_.topRightCorner(N_, 1) = Flambda_;
      border_.bottomRows(1) = normal_.transpose();
      t = Eigen::PartialPivLU<Matrix>(border_).solve(e);
    }
    if (!t.allFinite()) return s;
    for (int i = 0; i <= N_; ++i) t[i] *= units_.state(i);
    const Vector x = user(s.x);
    s.rate = stiffnessRate(problem_, x.head(N_), x[N_], t.head(N_), t[N_], measure_);
    s.g = s.rate.rate;
    s.ok = s.rate.valid;
    return s;
  }

  Vector user(const Vector& xs) const {
    Vector x = xs;
    for (int i = 0; i <= N_; ++i) x[i] *= units_.state(i);
    return x;
  }

 private:
  static cont::CorrectorOptions correctorOptions() {
    // Every evaluation of g must sit on the branch to rounding: g's error moves the root.
    cont::CorrectorOptions o;
    o.tolerance = 1e-14;
    o.stepTolerance = 1e-15;
    o.maxIterations = 30;
    o.stagnationFactor = 1e3;
    return o;
  }
  Vector toScaled(const cont::ContinuationPoint& p) const {
    Vector x(N_ + 1);
    x.head(N_) = p.u;
    x[N_] = p.lambda;
    for (int i = 0; i <= N_; ++i) x[i] /= units_.state(i);
    return x;
  }

  EquilibriumProblem& problem_;
  cont::UnitScaling units_;
  cont::BoundScaledProblem scaledProblem_;
  cont::BoundProblem scaled_;  // the section's one workspace
  std::unique_ptr<cont::BorderedSolver> structured_;
  cont::Corrector corrector_;
  StiffnessMeasure measure_;
  int N_;
  Vector xa_, xb_, normal_;
  Matrix border_, Fu_;
  Vector Flambda_;
};

}  // namespace

std::string StiffnessExtremumOptions::validate(const std::string& prefix) const {
  return cont::firstProblem({cont::require(tolerance > 0.0 && tolerance < 1.0, prefix, "tolerance", "must lie in (0, 1)"),
                             cont::require(maxEvaluations >= 1, prefix, "maxEvaluations", "must be at least 1")});
}

StiffnessExtremum locateStiffnessMinimum(EquilibriumProblem& problem, const cont::ContinuationPoint& a,
                                         const cont::ContinuationPoint& b, StiffnessMeasure measure,
                                         const StiffnessExtremumOptions& options) {
  StiffnessExtremum out;
  const int N = problem.dimension();
  if (a.u.size() != N || b.u.size() != N) throw std::invalid_argument("bracket points must have the problem's dimension");
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("StiffnessExtremumOptions: " + why);
  BranchSection section(problem, a, b, measure);
  if (section.degenerate()) {
    out.message = "the bracket's two points coincide";
    return out;
  }
  // Brent's zeroin (Brent 1973, ch. 4) on g(τ): inverse quadratic / secant steps kept inside the
  // bracket, bisection when they are slow, so it converges for any sign-changing g.
  Sample sa = section.at(0.0), sb = section.at(1.0);
  out.evaluations = 2;
  if (!sa.ok || !sb.ok) {
    out.message = "the bracket's end points could not be corrected onto the branch or K_F is singular there";
    return out;
  }
  if (!(sa.g < 0.0 && sb.g > 0.0)) {
    out.message = "the measure's rate does not change from negative to positive in the bracket";
    return out;
  }
  Sample sc = sa;
  double d = sb.tau - sa.tau, e = d;
  const double eps = std::numeric_limits<double>::epsilon();
  for (;;) {
    if ((sb.g > 0.0) == (sc.g > 0.0)) {
      sc = sa;
      d = e = sb.tau - sa.tau;
    }
    if (std::abs(sc.g) < std::abs(sb.g)) {
      sa = sb;
      sb = sc;
      sc = sa;
    }
    const double tol = 2.0 * eps * std::abs(sb.tau) + 0.5 * options.tolerance;
    const double xm = 0.5 * (sc.tau - sb.tau);
    if (std::abs(xm) <= tol || sb.g == 0.0) break;
    if (out.evaluations >= options.maxEvaluations) {
      out.message = "no convergence in " + std::to_string(options.maxEvaluations) + " evaluations";
      return out;
    }
    if (std::abs(e) >= tol && std::abs(sa.g) > std::abs(sb.g)) {
      const double s = sb.g / sa.g;
      double p, q;
      if (sa.tau == sc.tau) {
        p = 2.0 * xm * s;
        q = 1.0 - s;
      } else {
        const double qa = sa.g / sc.g, r = sb.g / sc.g;
        p = s * (2.0 * xm * qa * (qa - r) - (sb.tau - sa.tau) * (r - 1.0));
        q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0.0) q = -q;
      p = std::abs(p);
      if (2.0 * p < std::min(3.0 * xm * q - std::abs(tol * q), std::abs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = xm;
        e = d;
      }
    } else {
      d = xm;
      e = d;
    }
    sa = sb;
    const double next = sb.tau + (std::abs(d) > tol ? d : std::copysign(tol, xm));
    sb = section.at(next);
    ++out.evaluations;
    if (!sb.ok) {
      out.message = "a point of the bracket could not be corrected onto the branch (tau = " + std::to_string(next) + ")";
      return out;
    }
  }
  const Vector xb = section.user(sb.x), xc = section.user(sc.x);
  out.located = true;
  out.u = xb.head(N);
  out.lambda = xb[N];
  out.value = sb.rate.value;
  out.rate = sb.g;
  out.K = sb.rate.K;
  out.accuracy = std::abs(xb[N] - xc[N]);
  out.residual = sb.residual;
  return out;
}

}  // namespace buckle::mechanics
