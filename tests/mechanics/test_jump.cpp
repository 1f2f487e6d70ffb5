#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/jump.h"
#include "heavy_newton.h"

using namespace buckle::mechanics;

namespace {

// L0 = 1.2 with a = 0.5, b = 1, k = 1: κ = b·L0 − 2(b² − a²) = −0.3 < 0, so the straight segment
// is unstable, and each segment's energy 4a² + 4(b² − a²)c² − 4bL0 c + L0² (c = cos(q/2)) has its
// wells at c* = bL0 / (2(b² − a²)) = 0.8, q* = ±2 acos 0.8 ≈ ±1.287 — inside the geometric limit
// ±2.214. A multistable chain: folds on stable branches, snap-through to other stable shapes.
Chain bistableChain() { return Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2)); }
// n of those segments straight, clamped–pinned with y held: a degenerate start whose lowest
// eigenvalue is repeated n − 1 times (jump_timing's "degenerate" case; the cascade).
struct DegenerateChain {
  explicit DegenerateChain(int n)
      : chain(Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2))),
        problem(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0)),
        u0(problem.initialGuess(Vector::Zero(n), 0.0)) {}
  buckle::continuation::SpecialPoint start() const {
    buckle::continuation::SpecialPoint s;
    s.u = u0;
    s.lambda = 0.0;
    return s;
  }
  Chain chain;
  EquilibriumProblem problem;
  Vector u0;
};
// AUTO's I_up case (shared/peers/auto07p): L0 = 0.5, κ = −1, wells beyond the joint limits.
Chain autoIupChain() { return Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5)); }

const double kWellAngle = 2.0 * std::acos(0.8);

// Independent Newton on ∇Π(q) = 0 for a free end: exact Hessian from chain.h, full steps; no
// KINSOL, no line search, nothing from dynamics.h / jump.h.
bool independentNewton(const Chain& chain, const Wrench& F, Vector& q, double tol = 1e-12) {
  const int n = chain.size();
  Vector g(n);
  Matrix H(n, n);
  for (int it = 0; it < 50; ++it) {
    totalPotentialGradient(chain, q, F, g);
    if (g.cwiseAbs().maxCoeff() <= tol) return true;
    totalPotentialHessian(chain, q, F, H);
    q -= H.fullPivLu().solve(g);
    if (!q.allFinite()) return false;
  }
  return false;
}

Eigen::VectorXd hessianEigenvalues(const Chain& chain, const Vector& q, const Wrench& F) {
  Matrix H(chain.size(), chain.size());
  totalPotentialHessian(chain, q, F, H);
  return Eigen::SelfAdjointEigenSolver<Matrix>(H).eigenvalues();
}

// Fold of the free chain in Fx at fixed Fy: unknowns z = (q, v, Fx), equations ∇Π = 0, H v = 0,
// v·v0 = 1 (the extended system of AUTO's ref.py), Newton with a central-difference Jacobian.
bool locateFold(const Chain& chain, double Fy, Vector& q, double& Fx) {
  const int n = chain.size();
  const int N = 2 * n + 1;
  Matrix H(n, n);
  totalPotentialHessian(chain, q, Wrench(Fx, Fy, 0), H);
  Eigen::SelfAdjointEigenSolver<Matrix> es(H);
  Eigen::Index k;
  es.eigenvalues().cwiseAbs().minCoeff(&k);
  const Vector v0 = es.eigenvectors().col(k);
  Vector z(N);
  z << q, v0, Fx;
  auto residual = [&](const Vector& zz) {
    Vector r(N), g(n);
    const Wrench W(zz[N - 1], Fy, 0);
    totalPotentialGradient(chain, zz.head(n), W, g);
    Matrix HH(n, n);
    totalPotentialHessian(chain, zz.head(n), W, HH);
    r.head(n) = g;
    r.segment(n, n) = HH * zz.segment(n, n);
    r[N - 1] = zz.segment(n, n).dot(v0) - 1.0;
    return r;
  };
  for (int it = 0; it < 40 && residual(z).cwiseAbs().maxCoeff() >= 1e-13; ++it) {
    Matrix Jz(N, N);
    for (int j = 0; j < N; ++j) {
      Vector zp = z, zm = z;
      zp[j] += 1e-6;
      zm[j] -= 1e-6;
      Jz.col(j) = (residual(zp) - residual(zm)) / 2e-6;
    }
    z -= Jz.fullPivLu().solve(residual(z));
  }
  q = z.head(n);
  Fx = z[N - 1];
  return residual(z).cwiseAbs().maxCoeff() < 1e-11;
}

// Natural-parameter continuation in Fx (step dFx) along a stable branch from q, until the next
// point is unstable or far away: returns the last stable point, near the fold.
void followStableBranch(const Chain& chain, double Fy, double dFx, Vector& q, double& Fx) {
  for (int k = 1; k < 1000; ++k) {
    Vector qt = q;
    const double Ft = Fx + dFx;
    if (!independentNewton(chain, Wrench(Ft, Fy, 0), qt)) return;
    if (hessianEigenvalues(chain, qt, Wrench(Ft, Fy, 0))[0] <= 0.0 || (qt - q).cwiseAbs().maxCoeff() > 0.2) return;
    q = qt;
    Fx = Ft;
  }
}

// The fold of the bistable chain under increasing tension, Fy = 0.01, on the branch of the
// all-positive bent shape.
struct Fold {
  Vector q;
  double Fx = 0.0;
};
Fold bistableFold() {
  const Chain chain = bistableChain();
  Fold f;
  f.q = Vector::Constant(3, kWellAngle);
  REQUIRE(independentNewton(chain, Wrench(0, 0.01, 0), f.q));
  REQUIRE(hessianEigenvalues(chain, f.q, Wrench(0, 0.01, 0))[0] > 0.0);
  followStableBranch(chain, 0.01, 0.005, f.q, f.Fx);
  REQUIRE(locateFold(chain, 0.01, f.q, f.Fx));
  return f;
}

// Π never increases along the gradient flow (D1): dΠ/dt = −c|q̇|² on the held manifold. Off it
// (integrator drift δh of the held coordinates, pulled back by the κ_h term) Π moves by at most
// |reaction|·|δh| to first order, which the bound allows for (zero without held coordinates).
void requirePotentialNonIncreasing(const DynamicsResult& d, double reactionBound = 0.0) {
  REQUIRE(d.trajectory.size() > 10);
  for (size_t k = 1; k < d.trajectory.size(); ++k) {
    const TrajectorySample &a = d.trajectory[k - 1], &b = d.trajectory[k];
    INFO("sample " << k << " t = " << b.t << " increase " << b.potential - a.potential << " drift "
                   << b.constraintViolation);
    REQUIRE(b.potential <= a.potential + 1e-12 + reactionBound * (a.constraintViolation + b.constraintViolation));
  }
}

}  // namespace

TEST_CASE("fold of the bistable chain is a true fold on a stable branch", "[jump]") {
  const Chain chain = bistableChain();
  const Fold f = bistableFold();
  const Eigen::VectorXd mu = hessianEigenvalues(chain, f.q, Wrench(f.Fx, 0.01, 0));
  CHECK(std::abs(mu[0]) < 1e-9);  // the critical eigenvalue
  CHECK(mu[1] > 0.1);             // the rest positive: the branch was stable up to here
  CHECK(f.Fx == Approx(0.0426468434679).epsilon(1e-9));
  CHECK(f.q[0] > 0.0);  // still the all-positive bent shape
}

TEST_CASE("from just past a fold the chain snaps to a distinct stable equilibrium", "[jump]") {
  const Chain chain = bistableChain();
  const Fold f = bistableFold();
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench(0, 0.01, 0)), Eigen::Vector3d(1, 0, 0));
  const double lambda = f.Fx + 1e-4;  // just past the fold: no equilibrium nearby any more
  JumpOptions options;
  const JumpResult r = simulateJump(problem, f.q, lambda, options);
  INFO(r.message);
  REQUIRE(r.success);
  CHECK(r.stopReason == IntegrationStop::Rest);
  CHECK(r.polishConverged);
  CHECK(r.residual < 1e-11);
  CHECK(r.stable);
  CHECK(r.stabilityTo.smallest > 0.1);
  CHECK(r.prescribed.isApprox(Eigen::Vector3d(lambda, 0.01, 0)));
  // distinct from the fold state: joint 1 snapped through to the other well
  CHECK(r.distance > 1.0);
  CHECK(r.to[0] < -1.0);
  CHECK(r.energyReleased > 0.1);
  CHECK(r.energyReleased == Approx(r.potentialFrom - r.potentialTo));
  CHECK(r.polishShift < 1e-8);  // the rest point already was the equilibrium to ~tolerance
  CHECK(r.steps > 10);
  requirePotentialNonIncreasing(r.dynamics);

  // Independent confirmation: plain Newton on ∇Π from the landing point stays there and the
  // dense Hessian there is positive definite.
  Vector q = r.to.head(3);
  REQUIRE(independentNewton(chain, Wrench(lambda, 0.01, 0), q));
  CHECK((q - r.to.head(3)).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(hessianEigenvalues(chain, q, Wrench(lambda, 0.01, 0))[0] > 0.1);
}

TEST_CASE("jump from the fold itself: the cubic term picks the side", "[jump]") {
  const Chain chain = bistableChain();
  const Fold f = bistableFold();
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench(0, 0.01, 0)), Eigen::Vector3d(1, 0, 0));
  JumpOptions options;
  const JumpResult r = simulateJump(problem, f.q, f.Fx, options);
  INFO(r.message);
  REQUIRE(r.success);
  CHECK(std::abs(r.directionEigenvalue) < 1e-9);  // the fold's null direction
  CHECK(r.direction.norm() == Approx(1.0));
  // the chosen sign lowers Π; the opposite side goes back up the fold's cubic
  Vector plus = f.q + 1e-3 * r.direction, minus = f.q - 1e-3 * r.direction;
  CHECK(totalPotential(chain, plus, Wrench(f.Fx, 0.01, 0)) < totalPotential(chain, minus, Wrench(f.Fx, 0.01, 0)));
  CHECK(r.to[0] < -1.0);
  CHECK(r.energyReleased > 0.1);
  requirePotentialNonIncreasing(r.dynamics);

  // The inertial model (rods, light joint damping) lands on the same equilibrium here.
  JumpOptions inertial;
  inertial.scene.inertia = InertiaData::uniformRods(chain, 1.0);
  inertial.scene.jointDamping = {0.5, 0.5, 0.5};
  const JumpResult ri = simulateJump(problem, f.q, f.Fx, inertial);
  INFO(ri.message);
  REQUIRE(ri.success);
  CHECK(ri.dynamics.kind == DynamicsKind::Inertial);
  CHECK((ri.to - r.to).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(ri.dynamics.maxEnergyBalanceError < 1e-8);
}

TEST_CASE("AUTO's I_up fold is reproduced, the chain lands against its joint limits, confirmed independently", "[jump]") {
  const Chain chain = autoIupChain();
  Vector q(3);
  q << -1.40916, -0.508436, -0.152072;
  double Fx = 0.1777;
  REQUIRE(locateFold(chain, 0.01, q, Fx));
  CHECK(Fx == Approx(0.1777097421507).epsilon(1e-10));  // AUTO-07p, refined by ref.py
  CHECK(q[0] == Approx(-1.40916).epsilon(1e-5));
  // Index 2 at the fold (AUTO: 3 before, 2 after): the path is unstable throughout.
  const Eigen::VectorXd mu = hessianEigenvalues(chain, q, Wrench(Fx, 0.01, 0));
  CHECK(mu[1] < 0.0);
  CHECK(std::abs(mu[2]) < 1e-9);

  const double lambda = Fx + 1e-3;
  const Wrench W(lambda, 0.01, 0);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Wrench(0, 0.01, 0)), Eigen::Vector3d(1, 0, 0));
  const JumpResult r = simulateJump(problem, q, lambda, JumpOptions());
  INFO(r.message);
  // With L0 = 0.5 each segment's energy decreases all the way to the geometric limit (its wells
  // lie beyond it): the chain runs into its limits, which hold it (one-sided contact), and comes
  // to rest on a stable constrained equilibrium.
  REQUIRE(r.success);
  CHECK(r.stopReason == IntegrationStop::Rest);
  REQUIRE(r.contactSides.size() == 3);
  int locked = 0;
  for (int i = 0; i < 3; ++i) {
    if (r.contactSides[size_t(i)] == 0) continue;
    ++locked;
    const double limit = r.contactSides[size_t(i)] > 0 ? chain.upperLimits()[i] : chain.lowerLimits()[i];
    CHECK(r.to[i] == limit);                               // exactly on the limit
    CHECK(-r.contactSides[size_t(i)] * r.contactTorques[i] > 0.0);  // compressive
  }
  REQUIRE(locked >= 1);
  CHECK_FALSE(r.dynamics.contactEvents.empty());
  // Independent check: Newton on the free joints' rows of ∇Π = 0 (chain.h only), the locked
  // joints fixed, from a perturbed landing; the contact torques are ∇Π at the locked joints.
  Vector qi = r.to.head(3);
  std::vector<int> freeJoints;
  for (int i = 0; i < 3; ++i)
    if (r.contactSides[size_t(i)] == 0) freeJoints.push_back(i);
    else qi[i] = r.contactSides[size_t(i)] > 0 ? chain.upperLimits()[i] : chain.lowerLimits()[i];
  const int nf = int(freeJoints.size());
  for (int a = 0; a < nf; ++a) qi[freeJoints[size_t(a)]] += 1e-3;
  Vector g(3);
  Matrix H(3, 3);
  for (int it = 0; it < 50; ++it) {
    totalPotentialGradient(chain, qi, W, g);
    totalPotentialHessian(chain, qi, W, H);
    Vector gf(nf);
    Matrix Hf(nf, nf);
    for (int a = 0; a < nf; ++a) {
      gf[a] = g[freeJoints[size_t(a)]];
      for (int b = 0; b < nf; ++b) Hf(a, b) = H(freeJoints[size_t(a)], freeJoints[size_t(b)]);
    }
    if (nf == 0 || gf.cwiseAbs().maxCoeff() < 1e-14) break;
    const Vector d = Hf.fullPivLu().solve(gf);
    for (int a = 0; a < nf; ++a) qi[freeJoints[size_t(a)]] -= d[a];
  }
  CHECK((qi - r.to.head(3)).cwiseAbs().maxCoeff() <= 1e-10 * qi.cwiseAbs().maxCoeff());
  totalPotentialGradient(chain, qi, W, g);
  totalPotentialHessian(chain, qi, W, H);
  for (int i = 0; i < 3; ++i)
    if (r.contactSides[size_t(i)] != 0) CHECK(r.contactTorques[i] == Approx(g[i]).epsilon(1e-9));
  // the reduced Hessian (free joints) positive definite
  if (nf > 0) {
    Matrix Hf(nf, nf);
    for (int a = 0; a < nf; ++a)
      for (int b = 0; b < nf; ++b) Hf(a, b) = H(freeJoints[size_t(a)], freeJoints[size_t(b)]);
    CHECK(Eigen::SelfAdjointEigenSolver<Matrix>(Hf).eigenvalues()[0] > 0.0);
  }
  CHECK(r.stabilityTo.stable());
  CHECK(r.energyReleased > 0.0);
  // Π never increases along the projected gradient flow, across the contact events too
  requirePotentialNonIncreasing(r.dynamics);
  CHECK(r.dynamics.maxEnergyBalanceError < 1e-8);

  // Without contact the integration stops at the first limit reached, as the smooth model did.
  JumpOptions stop;
  stop.integration.contact = false;
  const JumpResult s = simulateJump(problem, q, lambda, stop);
  CHECK_FALSE(s.success);
  CHECK(s.stopReason == IntegrationStop::JointLimit);
  CHECK_FALSE(s.polishConverged);
}

TEST_CASE("an unstable near-straight start (kappa < 0, Fx = 0, tiny Fy) jumps to a stable bent shape", "[jump]") {
  const Chain chain = bistableChain();
  const Wrench W(0, 1e-4, 0);
  Vector q0 = Vector::Zero(3);
  REQUIRE(independentNewton(chain, W, q0));  // the unstable equilibrium next to the straight state
  REQUIRE(hessianEigenvalues(chain, q0, W)[0] < 0.0);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(W), Eigen::Vector3d(1, 0, 0));
  const JumpResult r = simulateJump(problem, q0, 0.0, JumpOptions());
  INFO(r.message);
  REQUIRE(r.success);
  CHECK(r.directionEigenvalue < -0.1);
  CHECK(r.stabilityFrom.negative >= 1);
  CHECK(r.stable);
  CHECK(r.residual < 1e-11);
  // every joint ends near a well of its segment (|q*| ≈ 1.287): a bent shape
  for (int i = 0; i < 3; ++i) CHECK(std::abs(r.to[i]) == Approx(kWellAngle).epsilon(0.05));
  CHECK(r.energyReleased > 0.3);
  requirePotentialNonIncreasing(r.dynamics);
  Vector q = r.to.head(3);
  REQUIRE(independentNewton(chain, W, q));
  CHECK((q - r.to.head(3)).cwiseAbs().maxCoeff() < 1e-10);

  // A caller-given direction is honoured up to the Π-lowering sign: the opposite mode lands on
  // a different shape.
  JumpOptions other;
  other.direction = Vector::Zero(3);
  other.direction[1] = 1.0;
  const JumpResult r2 = simulateJump(problem, q0, 0.0, other);
  INFO(r2.message);
  REQUIRE(r2.success);
  CHECK(std::isnan(r2.directionEigenvalue));
  CHECK(std::abs(std::abs(r2.direction[1]) - 1.0) < 1e-12);
  CHECK((r2.to - r.to).cwiseAbs().maxCoeff() > 0.5);
}

TEST_CASE("jump with a held end coordinate keeps it held (clamped-pinned, gradient flow and inertial)", "[jump]") {
  const Chain chain = bistableChain();
  // y held at 0, rotation free, Fx = 0: start next to the straight state (unstable, κ < 0).
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0));
  const Vector u0 = problem.initialGuess(Vector::Zero(3), 0.0);
  for (int inertial = 0; inertial < 2; ++inertial) {
    JumpOptions options;
    if (inertial) {
      options.scene.inertia = InertiaData::uniformRods(chain, 1.0);
      options.scene.jointDamping = {1.0, 1.0, 1.0};
    }
    const JumpResult r = simulateJump(problem, u0, 0.0, options);
    INFO("inertial " << inertial << ": " << r.message);
    REQUIRE(r.success);
    CHECK(r.from.size() == 4);
    CHECK(r.to.size() == 4);
    CHECK(r.stabilityFrom.negative >= 1);
    CHECK(r.stable);
    CHECK(std::abs(endPose(chain, r.to.head(3))[1]) < 1e-12);
    CHECK(r.dynamics.maxConstraintViolation < 1e-8);
    for (const TrajectorySample& s : r.dynamics.trajectory) REQUIRE(s.constraintViolation < 1e-8);
    CHECK(r.energyReleased > 0.1);
    if (!inertial) requirePotentialNonIncreasing(r.dynamics, 1.0 + 2.0 * std::abs(r.to[3]));
    else CHECK(r.dynamics.maxEnergyBalanceError < 1e-7);
  }
}

TEST_CASE("sudden load: gradient flow equals the quasi-static answer, inertia can overshoot into another well", "[jump]") {
  const Chain chain = bistableChain();
  const Vector qUnloaded = Vector::Constant(3, kWellAngle);  // each segment in its well: unloaded, stable
  const Wrench W(0.0, 0.1, 0.0);
  // Quasi-static answer: ramp the load in 100 increments with Newton, staying on the stable branch.
  Vector qStatic = qUnloaded;
  for (int k = 1; k <= 100; ++k) {
    Vector qt = qStatic;
    REQUIRE(independentNewton(chain, (k / 100.0) * W, qt));
    REQUIRE(hessianEigenvalues(chain, qt, (k / 100.0) * W)[0] > 0.0);
    REQUIRE((qt - qStatic).cwiseAbs().maxCoeff() < 0.05);
    qStatic = qt;
  }

  const long before = InertialModel::constructedCount();
  const SuddenLoadResult flow = simulateSuddenLoad(chain, EndCondition::freeEnd(W), qUnloaded, qStatic, SuddenLoadOptions());
  INFO(flow.message);
  CHECK(InertialModel::constructedCount() == before);  // no masses: the inertial model is never built
  REQUIRE(flow.success);
  CHECK_FALSE(flow.inertial);
  CHECK(flow.compared);
  CHECK_FALSE(flow.differs);
  CHECK(flow.maxDifference < 1e-9);
  CHECK(flow.lower == LowerPotential::Equal);
  CHECK(flow.residual < 1e-11);
  requirePotentialNonIncreasing(flow.dynamics);

  SuddenLoadOptions options;
  options.scene.inertia = InertiaData::uniformRods(chain, 1.0);
  options.scene.jointDamping = {0.05, 0.05, 0.05};
  options.integration.recordInterval = 0.5;
  const SuddenLoadResult dyn = simulateSuddenLoad(chain, EndCondition::freeEnd(W), qUnloaded, qStatic, options);
  INFO(dyn.message);
  CHECK(InertialModel::constructedCount() == before + 1);
  REQUIRE(dyn.success);
  CHECK(dyn.inertial);
  CHECK(dyn.stable);
  CHECK(dyn.differs);
  CHECK(dyn.maxDifference > 1.0);
  CHECK(dyn.rest[1] < 0.0);  // joint 2 was thrown into its other well
  CHECK(dyn.lower == LowerPotential::Dynamic);
  CHECK(dyn.potentialDynamic < dyn.potentialStatic);
  CHECK(dyn.peakKinetic > 0.0);
  CHECK(dyn.maxExcursion > dyn.maxDifference * 0.5);
  CHECK(dyn.dynamics.maxEnergyBalanceError < 1e-7);
  // the record interval is honoured (first and last samples excepted)
  for (size_t k = 2; k + 1 < dyn.dynamics.trajectory.size(); ++k)
    REQUIRE(dyn.dynamics.trajectory[k].t - dyn.dynamics.trajectory[k - 1].t >= 0.5);
  Vector q = dyn.rest;
  REQUIRE(independentNewton(chain, W, q));
  CHECK((q - dyn.rest).cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("jump and sudden-load options are validated with a reason", "[jump]") {
  const Chain chain = bistableChain();
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(1, 0, 0));
  std::string why;
  JumpOptions o;
  CHECK(o.IsValid(problem, &why));
  o.perturbation = -1.0;
  CHECK_FALSE(o.IsValid(problem, &why));
  CHECK(why.find("perturbation") != std::string::npos);
  o = JumpOptions();
  o.direction = Vector::Zero(3);
  CHECK_FALSE(o.IsValid(problem, &why));
  CHECK(why.find("direction") != std::string::npos);
  o = JumpOptions();
  o.scene.flowDamping = 0.0;
  CHECK_FALSE(o.IsValid(problem, &why));
  CHECK(why.find("flowDamping") != std::string::npos);
  CHECK_THROWS_AS(simulateJump(problem, Vector::Zero(3), 0.0, o), std::invalid_argument);
  CHECK_THROWS_AS(simulateJump(problem, Vector::Zero(5), 0.0, JumpOptions()), std::invalid_argument);

  SuddenLoadOptions s;
  CHECK(s.IsValid(chain, &why));
  s.sameStateTolerance = 0.0;
  CHECK_FALSE(s.IsValid(chain, &why));
  CHECK(why.find("sameStateTolerance") != std::string::npos);
  CHECK_THROWS_AS(simulateSuddenLoad(chain, EndCondition::freeEnd(), Vector::Zero(2), Vector(), SuddenLoadOptions()),
                  std::invalid_argument);
}

TEST_CASE("long chain: the structured Rosenbrock method lands where dense Rosenbrock4 does (n = 50, y held)", "[jump]") {
  const int n = 50;
  DegenerateChain c(n);  // κ < 0
  const Chain &chain = c.chain;
  EquilibriumProblem &problem = c.problem;
  const Vector &u0 = c.u0;
  JumpOptions options;
  options.integration = jumpIntegrationDefaults(n);
  REQUIRE(options.integration.stepper == StepperKind::Rosenbrock4);
  const JumpResult dense = simulateJump(problem, u0, 0.0, options);
  options.integration.stepper = StepperKind::StructuredRosenbrock4;
  const JumpResult structured = simulateJump(problem, u0, 0.0, options);
  INFO(dense.message << " / " << structured.message);
  REQUIRE(dense.success);
  REQUIRE(structured.success);
  CHECK(structured.stopReason == IntegrationStop::Rest);
  CHECK(structured.stable);
  // the same rest point (both polished to the equilibrium), reached along the same flow
  CHECK((structured.to - dense.to).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(structured.energyReleased == Approx(dense.energyReleased).epsilon(1e-9));
  CHECK(std::abs(endPose(chain, structured.to.head(n))[1]) < 1e-12);
  // drift of y_end: the per-step tolerance 1e-10 on each joint angle, summed over the chain's length
  CHECK(structured.dynamics.maxConstraintViolation < 1e-9 * chain.length());
  requirePotentialNonIncreasing(structured.dynamics, 1.0 + 2.0 * std::abs(structured.to[n]));
  CHECK(jumpIntegrationDefaults(kStructuredJumpFrom + 1).stepper == StepperKind::StructuredSwitching);
}

namespace {

// Dense reference for unstableDirection(): the stability operator H and held rows C of the
// problem, Z from a full QR of Cᵀ, the eigen-decomposition of ZᵀHZ (O(n³); what the function did
// for every n before the structured route).
UnstableDirection denseUnstableDirection(EquilibriumProblem& problem, const Vector& u, double lambda) {
  UnstableDirection d;
  Matrix H, C;
  REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
  const Eigen::Index n = H.rows();
  Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
  const Matrix Q = qr.householderQ() * Matrix::Identity(n, n);
  const Matrix Z = Q.rightCols(n - qr.rank());
  Eigen::SelfAdjointEigenSolver<Matrix> es(Z.transpose() * H * Z);
  d.eigenvalue = es.eigenvalues()[0];
  d.direction = (Z * es.eigenvectors().col(0)).normalized();
  d.valid = true;
  return d;
}

}  // namespace

TEST_CASE("long chains: the O(n) unstable direction and polish equal the dense ones (n = 50, 200)", "[jump]") {
  for (int n : {50, 200}) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0));
    // a slightly bent chain under a compression beyond its lowest critical loads (~κ/n²): unstable,
    // y held (C = [J_y])
    const double lambda = -1e-3 * (n == 50 ? 10.0 : 1.0);
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = 1e-3 * std::sin(0.37 * i);
    const Vector u = problem.initialGuess(q, lambda);
    INFO("n = " << n);
    REQUIRE(n > kSmallDense);  // the structured route
    const UnstableDirection s = unstableDirection(problem, u, lambda);
    const UnstableDirection d = denseUnstableDirection(problem, u, lambda);
    REQUIRE(s.valid);
    CHECK(s.eigenvalue < 0.0);
    // the same simple eigenvalue and eigenvector (up to sign), in ker J_h
    const double scale = 1.0;  // k̄b̄² of these segments
    CHECK(std::abs(s.eigenvalue - d.eigenvalue) < 1e-11 * scale);
    CHECK(std::abs(std::abs(s.direction.dot(d.direction)) - 1.0) < 1e-10);
    Matrix H, C;
    REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
    CHECK((C * s.direction).cwiseAbs().maxCoeff() < 1e-12 * C.norm());
    // the eigen-equation on ker C: P(H v − μ v) = 0
    Vector res = H * s.direction - s.eigenvalue * s.direction;
    Eigen::ColPivHouseholderQR<Matrix> qr(C.transpose());
    const Matrix Q = (qr.householderQ() * Matrix::Identity(n, n)).leftCols(qr.rank());
    res -= Q * (Q.transpose() * res);
    CHECK(res.cwiseAbs().maxCoeff() < 1e-9 * H.norm() / std::sqrt(double(n)));

    // polish (structured KKT solve) from a perturbed point lands on the equilibrium that dense
    // Newton on the full KKT system (problem.jacobian, LU) finds from the same start
    Vector start = u;
    for (int i = 0; i < n; ++i) start[i] += 1e-4 * std::cos(0.11 * i);
    const PolishResult p = polishEquilibrium(problem, start.head(n), lambda);
    REQUIRE(p.converged);
    Vector ref = problem.initialGuess(start.head(n), lambda);
    const int N = problem.dimension();
    Matrix Fu(N, N);
    Vector F(N), Fl(N);
    for (int it = 0; it < 30; ++it) {
      REQUIRE(buckle::continuation::BoundProblem(problem).residual(ref, lambda, F));
      if (F.cwiseAbs().maxCoeff() < 1e-14) break;
      REQUIRE(buckle::continuation::BoundProblem(problem).jacobian(ref, lambda, Fu, Fl));
      ref -= Fu.fullPivLu().solve(F);
    }
    CHECK((p.u - ref).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(p.residual <= 1e-12);
  }
}

TEST_CASE("structured jump in scaled units: the same steps and landing angles (n = 80)", "[jump]") {
  // lengths × 1e-3 and spring stiffnesses × 1e4: the chain's units b̄ and k̄b̄² change, the
  // natural-unit options and the unit-weighted error norm make the integration the same
  const int n = 80;
  auto run = [&](double L, double k) {
    SegmentParameters p = SegmentParameters::symmetric(0.5 * L, 1.0 * L, k, 1.2 * L);
    const Chain chain = Chain::uniform(n, p);
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0));
    JumpOptions options;
    options.integration = jumpIntegrationDefaults(n);
    options.integration.recordTrajectory = false;
    REQUIRE(options.integration.stepper == StepperKind::StructuredSwitching);
    return simulateJump(problem, problem.initialGuess(Vector::Zero(n), 0.0), 0.0, options);
  };
  const JumpResult base = run(1.0, 1.0), scaled = run(1e-3, 1e4);
  INFO(base.message << " / " << scaled.message);
  REQUIRE(base.success);
  REQUIRE(scaled.success);
  CHECK(std::abs(scaled.steps - base.steps) <= base.steps / 50);
  CHECK((scaled.to.head(n) - base.to.head(n)).cwiseAbs().maxCoeff() < 1e-10);
  // energy in units of k̄b̄² (1e4 · 1e-6 = 1e-2)
  CHECK(scaled.energyReleased / 1e-2 == Approx(base.energyReleased).epsilon(1e-9));
}

TEST_CASE("direction rule for a multiple lowest eigenvalue: the dense and O(n) routes agree (n = 20, 50)", "[jump]") {
  // The straight chain of identical segments at Fx = 0 with y held: H = κI and ker J_y has
  // dimension n − 1, so the lowest eigenvalue κ is (n − 1)-fold and the rule (jump.h, step 1)
  // gives the reference vector projected onto ker J_y in closed form: z − (cᵀz / cᵀc) c with
  // c = J_yᵀ, c_i = x_end − x_i (eq 11).
  for (int n : {20, 50}) {
    INFO("n = " << n);
    DegenerateChain straight(n);
    const Chain &chain = straight.chain;
    EquilibriumProblem &problem = straight.problem;
    const Vector &u = straight.u0;
    const UnstableDirection dense = unstableDirection(problem, u, 0.0, DirectionRoute::Dense);
    const UnstableDirection fast = unstableDirection(problem, u, 0.0, DirectionRoute::Structured);
    REQUIRE(dense.valid);
    REQUIRE(fast.valid);
    const double kappa = chain.segment(0).energyJet(0.0).d2;
    CHECK(kappa < 0.0);
    CHECK(dense.eigenvalue == Approx(kappa).epsilon(1e-12));
    CHECK(fast.eigenvalue == Approx(kappa).epsilon(1e-12));
    Matrix H, C;
    REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, 0.0, H, C));
    REQUIRE(C.rows() == 1);
    CHECK((H - kappa * Matrix::Identity(n, n)).cwiseAbs().maxCoeff() < 1e-14);
    const Vector c = C.row(0).transpose();
    Vector expected = directionReference(n);
    expected -= (c.dot(expected) / c.squaredNorm()) * c;
    expected.normalize();
    // the same vector, sign included (both are the projection of z, not −z)
    CHECK((dense.direction - expected).cwiseAbs().maxCoeff() < 1e-10);
    CHECK((fast.direction - expected).cwiseAbs().maxCoeff() < 1e-10);
    // a slightly bent, compressed chain splits the eigenvalue: the simple lowest one's
    // eigenvector on both routes
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = 1e-3 * std::sin(0.37 * i);
    const Vector ub = problem.initialGuess(q, -1e-2);
    const UnstableDirection d2 = unstableDirection(problem, ub, -1e-2, DirectionRoute::Dense);
    const UnstableDirection f2 = unstableDirection(problem, ub, -1e-2, DirectionRoute::Structured);
    REQUIRE(d2.valid);
    REQUIRE(f2.valid);
    CHECK((d2.direction - f2.direction).cwiseAbs().maxCoeff() < 1e-8);
  }
}

namespace {

// A fold that a user meets: n bistable segments graded in L0 (1.3 at the base: the shallowest
// well, 1.2 at the end), free end under Fy = 0.01/n (its moment at the base stays below the
// wells' barriers whatever n) and an end moment M = λ, every joint in its
// negative well at M = 0; the tracer follows M up to the first fold (the base joint's barrier).
// As benchmarks/jump_timing.cpp, case "fold".
struct TracedFold {
  std::unique_ptr<EquilibriumProblem> problem;
  buckle::continuation::SpecialPoint fold;
};

TracedFold gradedChainFold(int n, double lengthScale = 1.0, double stiffnessScale = 1.0) {
  std::vector<SegmentParameters> segments;
  Vector q0(n);
  for (int i = 0; i < n; ++i) {
    const double L0 = 1.3 - 0.1 * i / (n - 1);
    segments.push_back(SegmentParameters::symmetric(0.5 * lengthScale, lengthScale, stiffnessScale, L0 * lengthScale));
    q0[i] = -2.0 * std::acos(L0 / 1.5);
  }
  const double force = stiffnessScale * lengthScale, moment = force * lengthScale;  // k̄b̄, k̄b̄²
  TracedFold t;
  t.problem = std::make_unique<EquilibriumProblem>(Chain(segments), EndCondition::freeEnd(Eigen::Vector3d(0, 0.01 * force / n, 0)),
                                                   Eigen::Vector3d(0, 0, moment));
  const PolishResult start = polishEquilibrium(*t.problem, q0, 0.0);
  REQUIRE(start.converged);
  buckle::continuation::TracerOptions o;
  o.maxPoints = 2000;
  o.lambdaMax = 2.0;
  o.detection.branchPoints = false;
  o.detection.lowestEigenvalues = 0;
  buckle::continuation::Tracer tracer(*t.problem, o);
  const auto branch = tracer.trace(start.u, 0.0, buckle::continuation::InitialDirection::increasingLambda());
  const auto folds = branch.specialPointsOfType(buckle::continuation::SpecialPointType::Fold);
  REQUIRE(!folds.empty());
  t.fold = *folds.front();
  return t;
}

JumpResult jumpWith(EquilibriumProblem& problem, const buckle::continuation::SpecialPoint& from, StepperKind stepper,
                    Handover handover) {
  JumpOptions options;
  options.integration = jumpIntegrationDefaults(problem.segments());
  options.integration.stepper = stepper;
  options.integration.recordTrajectory = false;
  options.handover = handover;
  return simulateJump(problem, from.u, from.lambda, options);
}

// `fewer` lands on the equilibrium `reference` lands on (both polished), in fewer steps.
void checkSameLandingFewerSteps(const JumpResult& reference, const JumpResult& fewer) {
  INFO(reference.message << " / " << fewer.message);
  REQUIRE(reference.success);
  REQUIRE(fewer.success);
  CHECK(fewer.steps < reference.steps);
  CHECK((fewer.to - reference.to).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(fewer.energyReleased == Approx(reference.energyReleased).epsilon(1e-10));
}

}  // namespace

TEST_CASE("jump from a traced fold of a long chain: structured with hand-over lands where dense integration to rest does (n = 50)",
          "[jump]") {
  const int n = 50;
  TracedFold t = gradedChainFold(n);
  // a simple fold: one zero eigenvalue, the base joint's mode
  const UnstableDirection ud = unstableDirection(*t.problem, t.fold.u, t.fold.lambda);
  REQUIRE(ud.valid);
  const JumpResult dense = jumpWith(*t.problem, t.fold, StepperKind::Rosenbrock4, Handover::Never);
  const JumpResult fast = jumpWith(*t.problem, t.fold, StepperKind::StructuredRosenbrock4, Handover::Always);
  INFO(dense.message << " / " << fast.message);
  REQUIRE(dense.success);
  REQUIRE(fast.success);
  CHECK(dense.stopReason == IntegrationStop::Rest);
  CHECK(fast.stopReason == IntegrationStop::Settled);
  CHECK(fast.basinTests >= 1);
  // the same landing equilibrium, polished to the same tolerance
  CHECK((fast.to - dense.to).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(fast.stable);
  // the base joint snapped over its barrier to the positive well; the others stayed negative
  CHECK(fast.to[0] > 0.0);
  for (int i = 1; i < n; ++i) CHECK(fast.to[i] < 0.0);
}

TEST_CASE("hand-over to Newton: the landing of integration to rest, in fewer steps (fold n = 200, cascade n = 80)", "[jump]") {
  auto compare = [](EquilibriumProblem& problem, const buckle::continuation::SpecialPoint& from) {
    const JumpResult full = jumpWith(problem, from, StepperKind::StructuredRosenbrock4, Handover::Never);
    const JumpResult handed = jumpWith(problem, from, StepperKind::StructuredRosenbrock4, Handover::Always);
    checkSameLandingFewerSteps(full, handed);
    CHECK(full.basinTests == 0);
    CHECK(handed.stopReason == IntegrationStop::Settled);
  };
  SECTION("fold of the graded chain, n = 200") {
    TracedFold t = gradedChainFold(200);
    compare(*t.problem, t.fold);
  }
  SECTION("degenerate straight chain, n = 80 (the cascade of the rule's direction)") {
    DegenerateChain c(80);
    compare(c.problem, c.start());
  }
}

TEST_CASE("hand-over in scaled units: the same steps, tests and landing angles (fold, n = 80)", "[jump]") {
  const int n = 80;
  TracedFold base = gradedChainFold(n), scaled = gradedChainFold(n, 1e-3, 1e4);
  CHECK(scaled.fold.lambda == Approx(base.fold.lambda).epsilon(1e-8));
  const JumpResult a = jumpWith(*base.problem, base.fold, StepperKind::StructuredRosenbrock4, Handover::Automatic);
  const JumpResult b = jumpWith(*scaled.problem, scaled.fold, StepperKind::StructuredRosenbrock4, Handover::Automatic);
  INFO(a.message << " / " << b.message);
  REQUIRE(a.success);
  REQUIRE(b.success);
  CHECK(a.stopReason == IntegrationStop::Settled);  // Automatic: on above kStructuredJumpFrom segments
  CHECK(b.stopReason == IntegrationStop::Settled);
  CHECK(std::abs(a.steps - b.steps) <= a.steps / 50);
  CHECK((a.to.head(n) - b.to.head(n)).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(b.energyReleased / 1e-2 == Approx(a.energyReleased).epsilon(1e-8));
}

TEST_CASE("long chains' basin tolerance: the landing of the 1e-10 integration, in fewer steps (fold and cascade, n = 100)",
          "[jump]") {
  // jumpIntegrationDefaults above kStructuredJumpFrom segments: kLongJumpTolerance (jump.h), the
  // shorter chains keep the IntegrationOptions default the regression baselines pin
  const IntegrationOptions shortChain = jumpIntegrationDefaults(kStructuredJumpFrom);
  const IntegrationOptions longChain = jumpIntegrationDefaults(kStructuredJumpFrom + 1);
  CHECK(shortChain.absoluteTolerance == IntegrationOptions().absoluteTolerance);
  CHECK(shortChain.relativeTolerance == IntegrationOptions().relativeTolerance);
  CHECK(longChain.absoluteTolerance == kLongJumpTolerance);
  CHECK(longChain.relativeTolerance == kLongJumpTolerance);
  REQUIRE(kLongJumpTolerance > IntegrationOptions().absoluteTolerance);
  auto compare = [](EquilibriumProblem& problem, const Vector& u, double lambda) {
    JumpOptions options;
    options.integration = jumpIntegrationDefaults(problem.segments());
    options.integration.recordTrajectory = false;
    const JumpResult basin = simulateJump(problem, u, lambda, options);
    // the reference: the same flow to rest at the tight default tolerance
    options.integration.absoluteTolerance = options.integration.relativeTolerance = IntegrationOptions().absoluteTolerance;
    options.handover = Handover::Never;
    const JumpResult tight = simulateJump(problem, u, lambda, options);
    checkSameLandingFewerSteps(tight, basin);
    CHECK(basin.stopReason == IntegrationStop::Settled);
    CHECK(tight.stopReason == IntegrationStop::Rest);
  };
  SECTION("fold of the graded chain") {
    TracedFold t = gradedChainFold(100);
    compare(*t.problem, t.fold.u, t.fold.lambda);
  }
  SECTION("degenerate straight chain (the cascade)") {
    DegenerateChain c(100);
    compare(c.problem, c.u0, 0.0);
  }
}

TEST_CASE("inertial jump from a traced fold: the structured method on the exact Jacobian lands where dense Rosenbrock4 does (n = 24)",
          "[jump]") {
  const int n = 24;
  TracedFold t = gradedChainFold(n);
  JumpOptions options;
  options.scene.inertia = InertiaData::uniformRods(t.problem->chain(), 1.0);
  options.scene.jointDamping.assign(size_t(n), 1.0);
  options.integration = jumpIntegrationDefaults(n);
  options.integration.recordTrajectory = false;
  options.integration.stepper = StepperKind::Rosenbrock4;
  const JumpResult dense = simulateJump(*t.problem, t.fold.u, t.fold.lambda, options);
  options.integration.stepper = StepperKind::StructuredRosenbrock4;
  options.handover = Handover::Always;  // ignored by the inertial model (jump.h)
  const JumpResult fast = simulateJump(*t.problem, t.fold.u, t.fold.lambda, options);
  INFO(dense.message << " / " << fast.message);
  REQUIRE(dense.success);
  REQUIRE(fast.success);
  CHECK(fast.stopReason == IntegrationStop::Rest);
  CHECK(fast.basinTests == 0);
  CHECK(fast.dynamics.kind == DynamicsKind::Inertial);
  CHECK((fast.to - dense.to).cwiseAbs().maxCoeff() < 1e-9);
  // the energy balance K + Π + W_d = const holds along the structured steps to the tolerance
  CHECK(fast.dynamics.maxEnergyBalanceError < 1e-6 * std::max(1.0, std::abs(fast.energyReleased)));
}

TEST_CASE("switching stepper: the cascade lands where the structured Rosenbrock method does, in fewer steps (n = 100)",
          "[jump]") {
  // the straight chain's cascade (jump_timing, case degenerate) is not stiff: Dormand–Prince's
  // steps, limited by accuracy, are longer than Rosenbrock4's at the same tolerance
  const int n = 100;
  DegenerateChain c(n);
  EquilibriumProblem &problem = c.problem;
  const buckle::continuation::SpecialPoint start = c.start();
  const JumpResult rosenbrock = jumpWith(problem, start, StepperKind::StructuredRosenbrock4, Handover::Automatic);
  const JumpResult switching = jumpWith(problem, start, StepperKind::StructuredSwitching, Handover::Automatic);
  checkSameLandingFewerSteps(rosenbrock, switching);
  CHECK((switching.to - rosenbrock.to).cwiseAbs().maxCoeff() < 1e-10 * rosenbrock.to.cwiseAbs().maxCoeff());
  CHECK(switching.stopReason == IntegrationStop::Settled);
  CHECK(switching.stable);
  CHECK(rosenbrock.dynamics.stiffSteps == 0);  // (counted by the switching stepper only)
  CHECK(switching.dynamics.stiffSteps < switching.steps / 2);
  // the flow's Lyapunov function along the explicit steps
  JumpOptions options;
  options.integration = jumpIntegrationDefaults(n);
  const JumpResult recorded = simulateJump(problem, start.u, 0.0, options);
  REQUIRE(recorded.success);
  CHECK(recorded.steps == switching.steps);
  requirePotentialNonIncreasing(recorded.dynamics, 1.0 + 2.0 * std::abs(recorded.to[n]));
}

TEST_CASE("switching stepper: the creep to rest is stiff, it switches to Rosenbrock4 (fold, n = 100)", "[jump]") {
  // integrated to rest (no hand-over) at the tight tolerance: near rest the explicit steps are
  // limited by stability (dopri5 alone: hundreds of thousands of steps, benchmarks/RESULTS.md);
  // the stiffness test hands them to Rosenbrock4, in about its own number of steps
  TracedFold t = gradedChainFold(100);
  auto run = [&](StepperKind stepper) {
    JumpOptions options;
    options.integration = jumpIntegrationDefaults(100);
    options.integration.stepper = stepper;
    options.integration.absoluteTolerance = options.integration.relativeTolerance = IntegrationOptions().absoluteTolerance;
    options.integration.recordTrajectory = false;
    options.handover = Handover::Never;
    return simulateJump(*t.problem, t.fold.u, t.fold.lambda, options);
  };
  const JumpResult rosenbrock = run(StepperKind::StructuredRosenbrock4), switching = run(StepperKind::StructuredSwitching);
  INFO(rosenbrock.message << " / " << switching.message);
  REQUIRE(rosenbrock.success);
  REQUIRE(switching.success);
  CHECK(switching.stopReason == IntegrationStop::Rest);
  CHECK(switching.dynamics.stiffSteps > 0);
  CHECK(switching.steps < 2 * rosenbrock.steps);
  CHECK((switching.to - rosenbrock.to).cwiseAbs().maxCoeff() < 1e-10 * rosenbrock.to.cwiseAbs().maxCoeff());
  CHECK(switching.energyReleased == Approx(rosenbrock.energyReleased).epsilon(1e-10));
}

TEST_CASE("a heavy column released past its critical weight falls to a bent stable equilibrium of that weight",
          "[jump][body_loads]") {
  // Gravity along −x compresses the chain standing on its clamp (λ = g): past the critical g the
  // straight column is an unstable equilibrium. Released along its softest mode, the dynamics with
  // the weight (dynamics.h, DynamicsScene::body) come to rest on a bent equilibrium of the same
  // weight: checked by an independent Newton solve on E + V (GravityPotential, absolute positions).
  for (const auto& [L, K] : {std::pair{1.0, 1.0}, std::pair{1e-4, 1e8}}) {
    INFO("lengths x" << L << ", stiffness x" << K);
    const int n = 4;
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, L, K, 2.25 * L));
    const InertiaData rods = InertiaData::uniformRods(chain, 1.0);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {}, {},
                               BodyLoads::weight(chain, rods, Eigen::Vector2d::Zero(), Eigen::Vector2d(-1.0, 0.0)));
    const Vector u = Vector::Zero(n);
    // the weight where the straight column has just lost its stability (doubling from far below)
    double g = 1e-3 * K;  // the weight torque ρ g ℓ² against κ ~ K L²: the critical g scales with K
    buckle::continuation::StabilityInfo info;
    for (int i = 0; i < 80; ++i, g *= 1.25) {
      REQUIRE(buckle::continuation::BoundProblem(problem).stability(u, g, 1, info));
      if (info.negative > 0) break;
    }
    REQUIRE(info.negative == 1);
    JumpOptions opt;
    const JumpResult r = simulateJump(problem, u, g, opt);
    INFO(r.message);
    REQUIRE(r.success);
    CHECK(r.stable);
    CHECK(r.energyReleased > 0.0);
    const Vector q = r.to.head(n);
    CHECK(q.cwiseAbs().maxCoeff() > 1e-2);  // bent, not the straight column
    // independent: Newton on E + V from the landing stays there
    const Vector qn = buckle::mechanics::testing::heavyNewton(chain, rods, Eigen::Vector2d(-g, 0.0), q);
    CHECK((qn - q).cwiseAbs().maxCoeff() < 1e-9);
    // and the weight mattered: the same release without it is no jump (the straight chain is stable)
    EquilibriumProblem weightless(chain, EndCondition::freeEnd(), Eigen::Vector3d::Zero());
    REQUIRE(buckle::continuation::BoundProblem(weightless).stability(u, 0.0, 1, info));
    CHECK(info.negative == 0);
  }
}
