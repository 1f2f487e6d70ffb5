#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <limits>
#include <cmath>
#include <random>
#include <string>

#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"

#include "test_chains.h"

using namespace buckle::mechanics;

namespace {

using testing::stiffChain;
using testing::unevenInertia;

// κ = −0.3 < 0 with wells at q* = ±2 acos 0.8 inside the joint limits (see test_jump.cpp).
Chain bistableChain(int n = 3) { return Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2)); }

// Kinetic energy from first principles: centre-of-mass velocities by central differences of the
// COM positions along q̇, link angular rates θ̇ = prefix sums of q̇.
double kineticByDifferences(InertialModel& model, const InertiaData& data, const Vector& q, const Vector& qdot) {
  const int n = model.segments();
  const double h = 1e-6;
  Eigen::Matrix2Xd Gp(2, n), Gm(2, n);
  model.centresOfMass(q + h * qdot, Gp);
  model.centresOfMass(q - h * qdot, Gm);
  double T = 0.0, thetaDot = 0.0;
  for (int i = 0; i < n; ++i) {
    thetaDot += qdot[i];
    const Eigen::Vector2d v = (Gp.col(i) - Gm.col(i)) / (2 * h);
    T += 0.5 * data.links[size_t(i)].mass * v.squaredNorm() + 0.5 * data.links[size_t(i)].inertia * thetaDot * thetaDot;
  }
  return T;
}

}  // namespace

TEST_CASE("inertial mass matrix is SPD and matches the kinetic energy by finite differences", "[dynamics]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> Q(-1.5, 1.5);
  for (int n : {1, 3, 5}) {
    const Chain chain = bistableChain(n);
    const InertiaData data = unevenInertia(chain);
    InertialModel model(chain, EndCondition::freeEnd(), data, {}, 0.0, Vector::Zero(n));
    for (int trial = 0; trial < 5; ++trial) {
      Vector q(n);
      for (int i = 0; i < n; ++i) q[i] = Q(rng);
      Matrix M(n, n);
      model.massMatrix(q, M);
      CHECK((M - M.transpose()).cwiseAbs().maxCoeff() == 0.0);
      CHECK(Eigen::SelfAdjointEigenSolver<Matrix>(M).eigenvalues()[0] > 0.0);
      // M_ij by polarization of the independently computed kinetic energy
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Vector ei = Vector::Unit(n, i), ej = Vector::Unit(n, j);
          const double Mij = i == j ? 2.0 * kineticByDifferences(model, data, q, ei)
                                    : kineticByDifferences(model, data, q, ei + ej) -
                                          kineticByDifferences(model, data, q, ei) -
                                          kineticByDifferences(model, data, q, ej);
          CHECK(M(i, j) == Approx(Mij).margin(1e-7));
        }
    }
  }
}

TEST_CASE("velocity terms equal dM/dt qdot - 1/2 d(qdot'M qdot)/dq (Lagrange)", "[dynamics]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> Q(-1.5, 1.5), V(-2.0, 2.0);
  const int n = 4;
  const Chain chain = bistableChain(n);
  InertialModel model(chain, EndCondition::freeEnd(), unevenInertia(chain), {}, 0.0, Vector::Zero(n));
  for (int trial = 0; trial < 5; ++trial) {
    Vector q(n), v(n);
    for (int i = 0; i < n; ++i) {
      q[i] = Q(rng);
      v[i] = V(rng);
    }
    const double h = 1e-6;
    Matrix Mp(n, n), Mm(n, n);
    model.massMatrix(q + h * v, Mp);
    model.massMatrix(q - h * v, Mm);
    Vector expected = (Mp - Mm) / (2 * h) * v;
    for (int k = 0; k < n; ++k) {
      model.massMatrix(q + h * Vector::Unit(n, k), Mp);
      model.massMatrix(q - h * Vector::Unit(n, k), Mm);
      expected[k] -= 0.5 * v.dot((Mp - Mm) / (2 * h) * v);
    }
    Vector c(n);
    model.velocityTerms(q, v, c);
    for (int i = 0; i < n; ++i) CHECK(c[i] == Approx(expected[i]).margin(1e-6));
  }
}

TEST_CASE("a scene without masses never builds the inertial model", "[dynamics]") {
  const Chain chain = bistableChain();
  const long before = InertialModel::constructedCount();
  DynamicsScene scene;  // no inertia
  scene.jointDamping = {0.1, 0.1, 0.1};
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(), scene, Vector::Zero(3));
  CHECK(model->kind() == DynamicsKind::GradientFlow);
  CHECK(dynamic_cast<GradientFlowModel*>(model.get()) != nullptr);
  const DynamicsResult r = simulate(*model, Vector::Constant(3, 0.2), Vector(), IntegrationOptions());
  CHECK(r.kind == DynamicsKind::GradientFlow);
  CHECK(InertialModel::constructedCount() == before);

  scene.inertia = InertiaData::uniformRods(chain, 1.0);
  auto inertial = makeDynamicsModel(chain, EndCondition::freeEnd(), scene, Vector::Zero(3));
  CHECK(inertial->kind() == DynamicsKind::Inertial);
  CHECK(InertialModel::constructedCount() == before + 1);
}

TEST_CASE("gradient flow: potential never increases, Pi + dissipation is conserved, rest is a stable equilibrium", "[dynamics]") {
  const Chain chain = bistableChain();
  const Wrench W(0.05, 0.02, 0.0);
  DynamicsScene scene;
  scene.flowDamping = 2.0;
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(W), scene, Vector::Zero(3));
  Vector q0(3);
  q0 << 0.1, -0.05, 0.02;
  for (StepperKind stepper : {StepperKind::DormandPrince5, StepperKind::CashKarp54, StepperKind::Rosenbrock4,
                              StepperKind::StructuredRosenbrock4, StepperKind::StructuredSwitching}) {
    IntegrationOptions options;
    options.stepper = stepper;
    const DynamicsResult r = simulate(*model, q0, Vector(), options);
    INFO("stepper " << int(stepper) << ": " << r.message);
    REQUIRE(r.reason == IntegrationStop::Rest);
    CHECK(r.residual <= options.residualTolerance);
    CHECK(r.speed <= options.velocityTolerance);
    CHECK(r.kinetic == 0.0);
    REQUIRE(r.trajectory.size() > 10);
    CHECK(r.trajectory.front().t == 0.0);
    CHECK(r.trajectory.back().t == r.time);
    for (size_t k = 1; k < r.trajectory.size(); ++k) {
      INFO("sample " << k);
      REQUIRE(r.trajectory[k].potential <= r.trajectory[k - 1].potential + 1e-12);
      REQUIRE(r.trajectory[k].dissipated >= r.trajectory[k - 1].dissipated);
    }
    // dΠ/dt = −c|q̇|²: potential released = energy dissipated
    CHECK(r.maxEnergyBalanceError < 1e-8);
    CHECK(r.potential + r.dissipated == Approx(r.initialEnergy).margin(1e-8));
    CHECK(r.dissipated > 0.3);
    // the rest point is an equilibrium of the EquilibriumProblem and stable
    EquilibriumProblem problem(chain, EndCondition::freeEnd(W), Eigen::Vector3d::Zero());
    Vector F(3);
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(r.q, 0.0, F));
    CHECK(F.cwiseAbs().maxCoeff() < 1e-8);
    buckle::continuation::StabilityInfo info;
    REQUIRE(buckle::continuation::BoundProblem(problem).stability(r.q, 0.0, 3, info));
    CHECK(info.stable());
    CHECK(r.q.cwiseAbs().minCoeff() > 1.0);  // left the unstable straight state
  }
}

TEST_CASE("all steppers agree on the landing", "[dynamics]") {
  const Chain chain = bistableChain();
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(Wrench(0.0, 0.01, 0.0)), DynamicsScene(), Vector::Zero(3));
  Vector q0(3);
  q0 << 0.3, 0.1, -0.2;
  IntegrationOptions options;
  const DynamicsResult a = simulate(*model, q0, Vector(), options);
  options.stepper = StepperKind::CashKarp54;
  const DynamicsResult b = simulate(*model, q0, Vector(), options);
  options.stepper = StepperKind::Rosenbrock4;
  options.absoluteTolerance = options.relativeTolerance = 1e-11;
  const DynamicsResult c = simulate(*model, q0, Vector(), options);
  REQUIRE(a.reason == IntegrationStop::Rest);
  REQUIRE(b.reason == IntegrationStop::Rest);
  options.stepper = StepperKind::StructuredRosenbrock4;
  const DynamicsResult d = simulate(*model, q0, Vector(), options);
  options.stepper = StepperKind::StructuredSwitching;
  const DynamicsResult e = simulate(*model, q0, Vector(), options);
  REQUIRE(c.reason == IntegrationStop::Rest);
  REQUIRE(d.reason == IntegrationStop::Rest);
  REQUIRE(e.reason == IntegrationStop::Rest);
  CHECK((a.q - b.q).cwiseAbs().maxCoeff() < 1e-7);
  CHECK((a.q - c.q).cwiseAbs().maxCoeff() < 1e-7);
  CHECK((a.q - d.q).cwiseAbs().maxCoeff() < 1e-7);
  CHECK((a.q - e.q).cwiseAbs().maxCoeff() < 1e-7);
  CHECK(a.steps > 0);
  CHECK(c.steps > 0);
}

TEST_CASE("exact gradient-flow Jacobian matches central differences", "[dynamics]") {
  const Chain chain = bistableChain(4);
  DynamicsScene scene;
  scene.flowDamping = 1.5;
  GradientFlowModel flow(chain, EndCondition::freeEnd(Wrench(0.2, -0.1, 0.05)), scene, Vector::Zero(4));
  const int N = flow.stateSize();
  Vector x(N);
  x << 0.3, -0.7, 1.1, 0.2, 0.4;
  Matrix exact(N, N);
  // the base-class finite-difference Jacobian through a held-free copy of the same scene
  flow.jacobian(x.data(), exact.data());  // row-major into a column-major buffer: transpose below
  Matrix exactRowMajor = exact.transpose();
  Matrix fd(N, N);
  Vector fp(N), fm(N);
  for (int j = 0; j < N; ++j) {
    Vector xp = x, xm = x;
    xp[j] += 1e-6;
    xm[j] -= 1e-6;
    flow.rhs(xp.data(), fp.data());
    flow.rhs(xm.data(), fm.data());
    fd.col(j) = (fp - fm) / 2e-6;
  }
  CHECK((exactRowMajor - fd).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("inertial with damping: kinetic + potential + dissipated = initial energy", "[dynamics]") {
  const Chain chain = bistableChain();
  DynamicsScene scene;
  scene.inertia = unevenInertia(chain);
  scene.jointDamping = {0.3, 0.2, 0.4};
  const Wrench W(0.02, 0.03, 0.0);
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(W), scene, Vector::Zero(3));
  Vector q0(3), v0(3);
  q0 << 0.2, 0.0, -0.1;
  v0 << 0.1, -0.3, 0.2;
  IntegrationOptions options;
  options.recordInterval = 0.05;
  const DynamicsResult r = simulate(*model, q0, v0, options);
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  CHECK(r.kind == DynamicsKind::Inertial);
  CHECK(r.initialEnergy == Approx(totalPotential(chain, q0, W) + r.trajectory.front().kinetic));
  CHECK(r.trajectory.front().kinetic > 0.0);
  double peakKinetic = 0.0;
  for (const TrajectorySample& s : r.trajectory) {
    REQUIRE(std::abs(s.kinetic + s.potential + s.dissipated - r.initialEnergy) < 1e-8);
    peakKinetic = std::max(peakKinetic, s.kinetic);
  }
  CHECK(peakKinetic > 0.1);  // a real dynamic event, not a crawl
  CHECK(r.maxEnergyBalanceError < 1e-8);
  CHECK(r.dissipated > 0.3);
  CHECK(r.kinetic < 1e-15);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(W), Eigen::Vector3d::Zero());
  buckle::continuation::StabilityInfo info;
  REQUIRE(buckle::continuation::BoundProblem(problem).stability(r.q, 0.0, 3, info));
  CHECK(info.stable());
}

TEST_CASE("inertial without damping conserves total energy", "[dynamics]") {
  const Chain chain = stiffChain();
  DynamicsScene scene;
  scene.inertia = InertiaData::uniformRods(chain, 1.0);  // no jointDamping: undamped
  const Wrench W(0.0, 0.1, 0.0);  // a lateral load released on the straight stiff chain
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(W), scene, Vector::Zero(3));
  IntegrationOptions options;
  options.maxTime = 200.0;
  options.recordInterval = 0.1;
  const DynamicsResult r = simulate(*model, Vector::Zero(3), Vector(), options);
  INFO(r.message);
  CHECK(r.reason == IntegrationStop::MaxTime);  // never at rest without damping
  // maxTime is in the model's natural time unit √(Ī / k̄b̄²) (dynamics.h)
  CHECK(model->timeUnit() > 0.0);
  CHECK(r.time == Approx(200.0 * model->timeUnit()));
  CHECK(r.dissipated == 0.0);
  CHECK(r.maxEnergyBalanceError < 1e-8);
  double peakKinetic = 0.0;
  for (const TrajectorySample& s : r.trajectory) peakKinetic = std::max(peakKinetic, s.kinetic);
  CHECK(peakKinetic > 0.01);
}

TEST_CASE("held end coordinates stay held along the trajectory", "[dynamics]") {
  const Chain chain = bistableChain();
  // End held at (x, y) of a bent pose; rotation free.
  Vector qRef(3);
  qRef << 0.9, -0.4, 0.6;
  const Pose p = endPose(chain, qRef);
  const EndCondition held = EndCondition::heldPosition(p[0], p[1]);
  Vector q0 = qRef;
  q0[1] += 0.05;  // off the constraint: the model projects it back first
  for (int inertial = 0; inertial < 2; ++inertial) {
    DynamicsScene scene;
    if (inertial) {
      scene.inertia = InertiaData::uniformRods(chain, 1.0);
      scene.jointDamping = {0.5, 0.5, 0.5};
    }
    auto model = makeDynamicsModel(chain, held, scene, q0);
    Vector start = q0;
    REQUIRE(model->projectOntoConstraints(start));
    CHECK(model->constraintViolation(start) < 1e-13);
    Vector v0 = Vector::Zero(3);
    const DynamicsResult r = simulate(*model, start, v0, IntegrationOptions());
    INFO("inertial " << inertial << ": " << r.message);
    REQUIRE(r.reason == IntegrationStop::Rest);
    CHECK(r.maxConstraintViolation < 1e-8);
    for (const TrajectorySample& s : r.trajectory) REQUIRE(s.constraintViolation < 1e-8);
    CHECK(r.maxEnergyBalanceError < 1e-7);
    EquilibriumProblem problem(chain, held, Eigen::Vector3d::Zero());
    const Vector u = problem.initialGuess(r.q, 0.0);
    Vector F(problem.dimension());
    REQUIRE(buckle::continuation::BoundProblem(problem).residual(u, 0.0, F));
    CHECK(F.cwiseAbs().maxCoeff() < 1e-7);
    if (inertial) CHECK(dynamic_cast<InertialModel&>(*model).baumgarteRate() > 0.0);
  }
}

TEST_CASE("guards stop the integration with a reason", "[dynamics]") {
  // L0 = 0.5: the segment energy falls all the way to the geometric limit — without contact, a
  // joint limit stop.
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5));
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(), DynamicsScene(), Vector::Zero(3));
  Vector q0(3);
  q0 << 0.1, 0.05, -0.02;
  IntegrationOptions noContact;
  noContact.contact = false;
  const DynamicsResult a = simulate(*model, q0, Vector(), noContact);
  CHECK(a.reason == IntegrationStop::JointLimit);
  CHECK(std::string(toString(a.reason)) == "joint limit");
  CHECK(a.message.find("limit") != std::string::npos);
  CHECK(model->withinLimits(a.q));
  CHECK(a.q.cwiseAbs().maxCoeff() == Approx(chain.upperLimits()[0]).epsilon(1e-6));

  IntegrationOptions few;
  few.maxSteps = 5;
  const DynamicsResult b = simulate(*model, q0, Vector(), few);
  CHECK(b.reason == IntegrationStop::MaxSteps);
  CHECK(b.steps == 5);
  IntegrationOptions shortTime;
  shortTime.maxTime = 0.01;
  const DynamicsResult c = simulate(*model, q0, Vector(), shortTime);
  CHECK(c.reason == IntegrationStop::MaxTime);
  CHECK(c.time == Approx(0.01));

  // A time limit or a signal (the run's Interrupt) stops the integration before the next step,
  // with the state reached: here after exactly the steps taken until the flag was raised.
  std::atomic<bool> flag{true};
  IntegrationOptions stopped;
  stopped.interrupt.watch(&flag, "SIGTERM received");
  const DynamicsResult d = simulate(*model, q0, Vector(), stopped);
  CHECK(d.reason == IntegrationStop::Interrupted);
  CHECK(d.steps == 0);
  CHECK(d.message.find("SIGTERM received") != std::string::npos);
  CHECK((d.q - q0).norm() == 0.0);
  IntegrationOptions expired;
  expired.interrupt = buckle::continuation::Interrupt::after(0.0);
  const DynamicsResult e = simulate(*model, q0, Vector(), expired);
  CHECK(e.reason == IntegrationStop::Interrupted);
  CHECK(e.message.find("time limit") != std::string::npos);
}

TEST_CASE("dynamics options and scenes are validated with a reason", "[dynamics]") {
  const Chain chain = bistableChain();
  std::string why;
  IntegrationOptions o;
  CHECK(o.IsValid(&why));
  o.absoluteTolerance = 0.0;
  CHECK_FALSE(o.IsValid(&why));
  CHECK(why.find("absoluteTolerance") != std::string::npos);
  o = IntegrationOptions();
  o.maxStep = 1e-20;
  CHECK_FALSE(o.IsValid(&why));
  CHECK(why.find("maxStep") != std::string::npos);
  o = IntegrationOptions();
  o.maxSamples = 1;
  CHECK_FALSE(o.IsValid(&why));
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(), DynamicsScene(), Vector::Zero(3));
  CHECK_THROWS_AS(simulate(*model, Vector::Zero(3), Vector(), o), std::invalid_argument);
  CHECK_THROWS_AS(simulate(*model, Vector::Zero(2), Vector(), IntegrationOptions()), std::invalid_argument);

  DynamicsScene s;
  CHECK(s.IsValid(chain, &why));
  s.jointDamping = {0.1, 0.1};
  CHECK_FALSE(s.IsValid(chain, &why));
  CHECK(why.find("jointDamping") != std::string::npos);
  s = DynamicsScene();
  s.inertia = InertiaData::uniformRods(chain, 1.0);
  s.inertia->links[1].mass = 0.0;
  CHECK_FALSE(s.IsValid(chain, &why));
  CHECK(why.find("link 2") != std::string::npos);
  s.inertia->links[1].mass = 1.0;
  s.inertia->links[2].comOffset = 10.0;
  CHECK_FALSE(s.IsValid(chain, &why));
  CHECK(why.find("comOffset") != std::string::npos);
  CHECK_THROWS_AS(makeDynamicsModel(chain, EndCondition::freeEnd(), s, Vector::Zero(3)), std::invalid_argument);
  s.inertia->links.pop_back();
  CHECK_FALSE(s.IsValid(chain, &why));
}

TEST_CASE("structured linearized solve equals the dense (I - a J)^-1 b, J is the flow's Jacobian (differences)",
          "[dynamics]") {
  const int n = 12;
  const Chain chain = bistableChain(n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  Vector q(n);
  for (int i = 0; i < n; ++i) q[i] = U(rng);
  DynamicsScene scene;
  scene.flowDamping = 1.5;
  for (const EndCondition& end : {EndCondition::freeEnd(Wrench(0.2, -0.1, 0.05)),
                                  EndCondition::clampedPinned(0.3, 0.1), EndCondition::heldPosition(10.0, 2.0)}) {
    GradientFlowModel flow(chain, end, scene, q);
    const int N = n + 1, m = flow.heldCount();
    Vector x(N), b(N), k(N);
    x.head(n) = q;
    x[n] = 0.0;
    for (int i = 0; i < N; ++i) b[i] = U(rng);
    // Dense J̃ from the chain's own Hessian and Jacobian: −(P H_r + κ_h J_h⁺ J_h)/c, H_r the Hessian
    // under the loads plus the reactions r = A⁻¹(J_h ∇Π − κ_h h) on the held coordinates; the
    // energy row 2c q̇ᵀ J̃ with c q̇ = −(∇Π − J_hᵀ r).
    const double c = scene.flowDamping;
    Matrix H(n, n), J(3, n);
    Vector grad(n);
    Wrench loads = Wrench::Zero();  // held coordinates do no work
    for (int co : end.loadedIndices()) loads[co] = end.value[co];
    totalPotentialGradient(chain, q, loads, grad);
    ChainData data(chain);
    forwardKinematics(chain, q, data);
    endJacobian(data, J);
    Matrix Jh(m, n);
    Vector hgap(m);
    for (int r = 0; r < m; ++r) {
      const int co = end.heldIndices()[size_t(r)];
      Jh.row(r) = J.row(co);
      hgap[r] = data.pose[co] - end.value[co];
    }
    const Matrix A = Jh * Jh.transpose();
    const Vector reactions = m > 0 ? Vector(A.ldlt().solve(Jh * grad - flow.constraintStiffness() * hgap)) : Vector();
    Wrench total = loads;
    for (int r = 0; r < m; ++r) total[end.heldIndices()[size_t(r)]] += reactions[r];
    totalPotentialHessian(chain, q, total, H);
    const Vector qdot = -(grad - Jh.transpose() * reactions) / c;
    Matrix Jt = -H;
    if (m > 0) {
      // E_k = −c (∇²p_k q̇)ᵀ with ∇²p_k from totalPotentialHessian's load part (unit end force)
      Matrix E(m, n), K0(n, n), Kc(n, n);
      totalPotentialHessian(chain, q, Wrench::Zero(), K0);
      for (int r = 0; r < m; ++r) {
        Wrench unit = Wrench::Zero();
        unit[end.heldIndices()[size_t(r)]] = 1.0;
        totalPotentialHessian(chain, q, unit, Kc);
        E.row(r) = -c * ((K0 - Kc) * qdot).transpose();  // ∇²p = K_q − (K_q − ∇²p)
      }
      const Matrix pinv = Jh.transpose() * A.inverse();
      Jt = -((Matrix::Identity(n, n) - pinv * Jh) * H + flow.constraintStiffness() * pinv * Jh - pinv * E);
    }
    Jt /= c;
    Matrix Jfull = Matrix::Zero(N, N);
    Jfull.topLeftCorner(n, n) = Jt;
    Jfull.bottomLeftCorner(1, n) = 2.0 * c * qdot.transpose() * Jt;
    for (double a : {1e-3, 0.1, 10.0}) {
      INFO("held " << m << ", a = " << a);
      REQUIRE(flow.solveLinearized(x.data(), a, b.data(), k.data()));
      const Vector residual = k - a * Jfull * k - b;
      CHECK(residual.norm() <= 1e-10 * (b.norm() + (a * Jfull).norm() * k.norm()));
    }
    {
      // J̃ is the flow's exact Jacobian, so it equals central differences of rhs()
      Vector fp(N), fm(N);
      const double h = 1e-6;
      for (int j = 0; j < n; ++j) {
        Vector xp = x, xm = x;
        xp[j] += h;
        xm[j] -= h;
        flow.rhs(xp.data(), fp.data());
        flow.rhs(xm.data(), fm.data());
        const Vector column = (fp - fm) / (2.0 * h);
        CHECK((column - Jfull.col(j)).norm() <= 1e-7 * std::max(1.0, Jfull.norm()));
      }
    }
  }
}

namespace {

// One segment with identical triangles (a, b), springs k, free lengths L0: c = √(a² + b²),
// β = 2 atan(a/b), L1 = 2c cos((β + q)/2), L2 = 2c cos((β − q)/2) (eq 1 with Δ = 0), so
// E′(q) = k c [(L1 − L0) (−sin((β + q)/2)) + (L2 − L0) sin((β − q)/2)], closed form.
struct ClosedFormSegment {
  double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;
  double c() const { return std::hypot(a, b); }
  double beta() const { return 2.0 * std::atan(a / b); }
  double upperLimit() const { return M_PI - beta(); }
  double dE(double q) const {
    const double L1 = 2.0 * c() * std::cos(0.5 * (beta() + q)), L2 = 2.0 * c() * std::cos(0.5 * (beta() - q));
    return k * c() * (-(L1 - L0) * std::sin(0.5 * (beta() + q)) + (L2 - L0) * std::sin(0.5 * (beta() - q)));
  }
  /// At the limit L1 = 0: E′(q̄) = k c [L0 (1 + cos β) − c sin 2β].
  double dEAtLimit() const { return k * c() * (L0 * (1.0 + std::cos(beta())) - c() * std::sin(2.0 * beta())); }
};

}  // namespace

TEST_CASE("one-sided joint limit: a segment driven past its limit locks there at the located contact instant",
          "[dynamics][contact]") {
  const ClosedFormSegment seg;
  const Chain chain = Chain::uniform(1, SegmentParameters::symmetric(seg.a, seg.b, seg.k, seg.L0));
  const double qbar = seg.upperLimit();
  REQUIRE(chain.upperLimits()[0] == Approx(qbar).epsilon(1e-15));
  CHECK(seg.dE(qbar) == Approx(seg.dEAtLimit()).epsilon(1e-12));
  // an end torque above the largest spring torque on [0, q̄]: no equilibrium before the limit
  double most = 0.0;
  for (int k = 0; k <= 1000; ++k) most = std::max(most, seg.dE(qbar * k / 1000.0));
  const double Me = 1.5 * most + 0.1;
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(Wrench(0, 0, Me)), DynamicsScene(), Vector::Zero(1));
  const DynamicsResult r = simulate(*model, Vector::Zero(1), Vector(), IntegrationOptions());
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  REQUIRE(r.contactEvents.size() == 1);
  const ContactEvent& e = r.contactEvents[0];
  CHECK(e.contact);
  CHECK(e.joint == 0);
  CHECK(e.side == 1);
  CHECK(r.q[0] == qbar);  // exactly on the limit
  REQUIRE(r.contactSides == std::vector<int>{1});
  // contact torque: it balances the applied torque against the spring's, τ_c = E′(q̄) − Me < 0
  CHECK(r.contactTorques[0] == Approx(seg.dEAtLimit() - Me).epsilon(1e-12));
  CHECK(e.torque == Approx(seg.dEAtLimit() - Me).epsilon(1e-12));
  // the contact instant against quadrature of the 1-D flow c dq/dt = Me − E′(q) (c = 1):
  // t* = ∫₀^q̄ dq / (Me − E′(q)), composite Simpson with 4000 intervals
  const int m = 4000;
  double t = 0.0;
  for (int k = 0; k <= m; ++k) {
    const double q = qbar * k / m, w = (k == 0 || k == m) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    t += w / (Me - seg.dE(q));
  }
  t *= qbar / m / 3.0;
  CHECK(e.t == Approx(t).epsilon(1e-8));
  // the switching stepper (explicit steps, Rosenbrock trials for the event) locates the same instant
  IntegrationOptions switching;
  switching.stepper = StepperKind::StructuredSwitching;
  const DynamicsResult sw = simulate(*model, Vector::Zero(1), Vector(), switching);
  INFO(sw.message);
  REQUIRE(sw.reason == IntegrationStop::Rest);
  REQUIRE(sw.contactEvents.size() == 1);
  CHECK(sw.contactEvents[0].t == Approx(t).epsilon(1e-8));
  CHECK(sw.q[0] == qbar);
  CHECK(sw.maxEnergyBalanceError < 1e-8);
  // Π + W_d conserved across the event (the lock moves q by the located instant's error only)
  CHECK(r.maxEnergyBalanceError < 1e-8);
  // the model's own contact set is left as it was: a second run is identical
  CHECK(model->lockedCount() == 0);
  const DynamicsResult again = simulate(*model, Vector::Zero(1), Vector(), IntegrationOptions());
  CHECK(again.contactEvents.size() == 1);
  CHECK(again.contactEvents[0].t == e.t);

  // Without contact the integration stops at the limit instead.
  IntegrationOptions noContact;
  noContact.contact = false;
  CHECK(simulate(*model, Vector::Zero(1), Vector(), noContact).reason == IntegrationStop::JointLimit);

  // A start locked on the limit under a torque that pulls it back is released at once.
  std::vector<int> locked{1};
  auto back = makeDynamicsModel(chain, EndCondition::freeEnd(Wrench(0, 0, -0.5)), DynamicsScene(), Vector::Zero(1));
  back->setContacts(locked);
  Vector q0(1);
  q0 << 2.0;  // moved onto the limit by the lock
  const DynamicsResult rel = simulate(*back, q0, Vector(), IntegrationOptions());
  REQUIRE(rel.contactEvents.size() >= 1);
  CHECK_FALSE(rel.contactEvents[0].contact);
  CHECK(rel.contactEvents[0].t == 0.0);
  CHECK(rel.contactEvents[0].torque > 0.0);  // the contact would have to pull: released
  CHECK(rel.q[0] < qbar);
}

TEST_CASE("one-sided joint limit, inertial: the inelastic impact's energy is counted, the chain rests locked",
          "[dynamics][contact]") {
  const ClosedFormSegment seg;
  const Chain chain = Chain::uniform(2, SegmentParameters::symmetric(seg.a, seg.b, seg.k, seg.L0));
  DynamicsScene scene;
  scene.inertia = InertiaData::uniformRods(chain, 1.0);
  scene.jointDamping = {0.3, 0.3};
  const double Me = 3.0;
  auto model = makeDynamicsModel(chain, EndCondition::freeEnd(Wrench(0, 0, Me)), scene, Vector::Zero(2));
  const DynamicsResult r = simulate(*model, Vector::Zero(2), Vector(), IntegrationOptions());
  INFO(r.message);
  REQUIRE(r.reason == IntegrationStop::Rest);
  REQUIRE_FALSE(r.contactEvents.empty());
  double lost = 0.0;
  for (const ContactEvent& e : r.contactEvents) lost += e.kineticLost;
  CHECK(lost > 0.0);  // the joints hit their limits with speed
  // K + Π + W_d (W_d including the impacts' losses) stays at the initial energy
  CHECK(r.maxEnergyBalanceError < 1e-7 * std::abs(r.initialEnergy - r.potential));
  // at rest, the joints in contact carry compressive torques that close the static balance:
  // τ_c = ∂Π/∂q at the locked joints, and the free joints are in equilibrium
  Vector g(2);
  totalPotentialGradient(chain, r.q, Wrench(0, 0, Me), g);
  for (int i = 0; i < 2; ++i) {
    if (r.contactSides[size_t(i)] != 0) {
      CHECK(r.q[i] == (r.contactSides[size_t(i)] > 0 ? chain.upperLimits()[i] : chain.lowerLimits()[i]));
      CHECK(r.contactTorques[i] == Approx(g[i]).epsilon(1e-6));
      CHECK(-r.contactSides[size_t(i)] * r.contactTorques[i] > 0.0);
    } else {
      CHECK(std::abs(g[i]) < 1e-8);
    }
  }
}

TEST_CASE("inertial O(n) right-hand side equals the dense mass-matrix solve (n = 50, 200)", "[dynamics]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> Q(-0.8, 0.8), V(-1.0, 1.0);
  for (int n : {50, 200}) {
    const Chain chain = bistableChain(n);
    const InertiaData data = unevenInertia(chain);
    const std::vector<double> damping(size_t(n), 0.3);
    for (int held = 0; held < 2; ++held) {
      const EndCondition end = held ? EndCondition::clampedPinned(0.0, 0.0) : EndCondition::freeEnd();
      InertialModel model(chain, end, data, damping, 0.0, Vector::Zero(n));
      Vector q(n), v(n);
      for (int i = 0; i < n; ++i) {
        q[i] = Q(rng) / std::sqrt(double(n));
        v[i] = V(rng);
      }
      Vector x(2 * n + 1), dx(2 * n + 1);
      model.packState(q, v, x);
      model.rhs(x.data(), dx.data());
      // dense reference: M from massMatrix(), c from the O(n²) Lagrange sum in absolute angles
      Matrix M(n, n);
      model.massMatrix(q, M);
      Vector theta(n), thetaDot(n);
      double a = 0.0, b = 0.0;
      for (int i = 0; i < n; ++i) {
        theta[i] = (a += q[i]);
        thetaDot[i] = (b += v[i]);
      }
      // μ_ij from M_θ = T⁻ᵀ M T⁻¹ at this q (T⁻¹ = Tinv), divided by cos(θ_i − θ_j)
      Matrix Tinv = Matrix::Identity(n, n);
      for (int i = 1; i < n; ++i) Tinv(i, i - 1) = -1.0;
      const Matrix Mtheta = Tinv.transpose() * M * Tinv;
      Vector cTheta = Vector::Zero(n);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          if (i != j) cTheta[i] += Mtheta(i, j) / std::cos(theta[i] - theta[j]) * std::sin(theta[i] - theta[j]) * thetaDot[j] * thetaDot[j];
      Vector c(n);
      for (int i = n - 1; i >= 0; --i) c[i] = cTheta[i] + (i + 1 < n ? c[i + 1] : 0.0);
      Vector cFast(n);
      model.velocityTerms(q, v, cFast);
      INFO("n = " << n << " held " << held);
      CHECK((cFast - c).cwiseAbs().maxCoeff() < 1e-9 * std::max(1.0, c.cwiseAbs().maxCoeff()));
      // kinetic energy ½ q̇ᵀ M q̇
      CHECK(model.kineticEnergy(x.data()) == Approx(0.5 * v.dot(M * v)).epsilon(1e-12));
      // accelerations: KKT [[M, −J_hᵀ], [J_h, 0]] (q̈, r) = (f, γ) densely, γ from the model's rows
      Vector grad(n);
      model.potentialGradient(q, grad);
      const Vector f = -c - Eigen::Map<const Vector>(damping.data(), n).cwiseProduct(v) - grad;
      // The chain's M is ill-conditioned (cond grows like a power of n), so two solvers agree only
      // to cond·ε in the forward error: check the backward error of the O(n) solution instead,
      // M q̈ − f = J_hᵀ r with J_h q̈ = γ, to rounding relative to the terms' sizes.
      const Vector accFast = Eigen::Map<const Vector>(dx.data() + n, n);
      const Vector e = M * accFast - f;
      const double size = M.cwiseAbs().rowwise().sum().maxCoeff() * accFast.cwiseAbs().maxCoeff() + f.cwiseAbs().maxCoeff();
      if (!held) {
        CHECK(e.cwiseAbs().maxCoeff() < 1e-12 * size);
      } else {
        // the held row J_y = cos θ summed over the tail; γ = −J̇ q̇ − 2ω J q̇ − ω² h (h = y_end)
        const Vector& l = chain.linkLengths();
        Vector Jy(n);
        double s = 0.0, ydot2 = 0.0, y = 0.0;
        for (int i = n - 1; i >= 0; --i) {
          s += l[i + 1] * std::cos(theta[i]);
          Jy[i] = s;
        }
        for (int i = 0; i < n; ++i) {
          ydot2 += l[i + 1] * std::sin(theta[i]) * thetaDot[i] * thetaDot[i];
          y += l[i + 1] * std::sin(theta[i]);
        }
        const double w = model.baumgarteRate();
        const double gamma = ydot2 - 2.0 * w * Jy.dot(v) - w * w * y;
        const double r = Jy.dot(e) / Jy.squaredNorm();
        CHECK((e - r * Jy).cwiseAbs().maxCoeff() < 1e-12 * size);
        CHECK(std::abs(Jy.dot(accFast) - gamma) <
              1e-12 * (Jy.cwiseAbs().dot(accFast.cwiseAbs()) + std::abs(ydot2) + 2.0 * w * Jy.cwiseAbs().dot(v.cwiseAbs()) + w * w * std::abs(y)));
      }
    }
  }
}

TEST_CASE("inertial exact Jacobian matches central differences of the right-hand side (free end, loaded, moving)",
          "[dynamics]") {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> Q(-0.7, 0.7), V(-1.0, 1.0);
  for (int n : {5, 30}) {
    const Chain chain = bistableChain(n);
    const InertiaData data = unevenInertia(chain);
    std::vector<double> damping(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) damping[size_t(i)] = 0.1 + 0.05 * i;
    InertialModel model(chain, EndCondition::freeEnd(Wrench(0.3, -0.2, 0.1)), data, damping, 0.0, Vector::Zero(n));
    const int N = 2 * n + 1;
    Vector q(n), v(n), x(N);
    for (int i = 0; i < n; ++i) {
      q[i] = Q(rng);
      v[i] = V(rng);
    }
    model.packState(q, v, x);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(N, N);
    model.jacobian(x.data(), J.data());
    // central differences, step 1e-6 (truncation ~1e-12 relative, rounding ~1e-10)
    Matrix Jfd(N, N);
    Vector xp(N), xm(N), fp(N), fm(N);
    for (int j = 0; j < N; ++j) {
      xp = x;
      xm = x;
      xp[j] += 1e-6;
      xm[j] -= 1e-6;
      model.rhs(xp.data(), fp.data());
      model.rhs(xm.data(), fm.data());
      Jfd.col(j) = (fp - fm) / 2e-6;
    }
    INFO("n = " << n);
    const double scale = Jfd.cwiseAbs().maxCoeff();
    CHECK((Matrix(J) - Jfd).cwiseAbs().maxCoeff() < 1e-7 * scale);
    // the structure: q rows (0, I, 0), no dependence on the dissipated energy
    CHECK(J.col(N - 1).cwiseAbs().maxCoeff() == 0.0);
    CHECK((J.block(0, n, n, n) - Matrix::Identity(n, n)).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("inertial O(n) stage solve equals the dense (I - a J)^-1 b with the exact Jacobian (n = 40)", "[dynamics]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> Q(-0.5, 0.5), V(-1.0, 1.0);
  const int n = 40, N = 2 * n + 1;
  const Chain chain = bistableChain(n);
  const InertiaData data = unevenInertia(chain);
  const std::vector<double> damping(size_t(n), 0.2);
  InertialModel model(chain, EndCondition::freeEnd(Wrench(-0.1, 0.05, 0.0)), data, damping, 0.0, Vector::Zero(n));
  Vector q(n), v(n), x(N), b(N), k(N);
  for (int i = 0; i < n; ++i) {
    q[i] = Q(rng);
    v[i] = V(rng);
  }
  model.packState(q, v, x);
  for (int i = 0; i < N; ++i) b[i] = V(rng);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(N, N);
  model.jacobian(x.data(), J.data());
  for (double a : {1e-3, 0.1, 10.0}) {
    INFO("a = " << a);
    const Matrix W = Matrix::Identity(N, N) - a * Matrix(J);
    REQUIRE(model.solveLinearized(x.data(), a, b.data(), k.data()));
    // backward error of the O(n) solution against the dense operator (the stage matrix of a large
    // step is ill-conditioned: compare residuals, not solutions)
    const Vector residual = W * k - b;
    CHECK(residual.cwiseAbs().maxCoeff() < 1e-10 * (W.cwiseAbs() * k.cwiseAbs() + b.cwiseAbs()).maxCoeff());
    // a second right-hand side reuses the factorization (same x and a)
    const Vector b2 = 0.5 * b.reverse();
    Vector k2(N);
    REQUIRE(model.solveLinearized(x.data(), a, b2.data(), k2.data()));
    CHECK((W * k2 - b2).cwiseAbs().maxCoeff() < 1e-10 * (W.cwiseAbs() * k2.cwiseAbs() + b2.cwiseAbs()).maxCoeff());
  }
  // with a held coordinate the stage solve is the dense one with the differenced Jacobian
  InertialModel held(chain, EndCondition::clampedPinned(0.0, 0.0), data, damping, 0.0, Vector::Zero(n));
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Jh(N, N);
  held.jacobian(x.data(), Jh.data());
  REQUIRE(held.solveLinearized(x.data(), 0.1, b.data(), k.data()));
  const Matrix Wh = Matrix::Identity(N, N) - 0.1 * Matrix(Jh);
  CHECK((Wh * k - b).cwiseAbs().maxCoeff() < 1e-9 * (Wh.cwiseAbs() * k.cwiseAbs() + b.cwiseAbs()).maxCoeff());
}

TEST_CASE("dynamics statics: one sincos per joint gives the chain functions' potential, gradient and end pose (n = 1000, scaled units)",
          "[dynamics]") {
  // The model's statics rotate each link direction from the previous one by the joint's own
  // half-angle sincos (dynamics.cpp, evaluateStatics); the chain functions (chain.cpp) take
  // sin θ, cos θ of every absolute angle. Both differ only by rounding: the bound is a few ulp
  // per rotation between re-anchors (≤ 16), scaled by the sums they enter.
  std::mt19937 rng(7);
  for (const double L : {1.0, 1e-3, 1e3}) {
    for (const double k : {1.0, 1e-6, 1e6}) {
      const int n = 1000;
      const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * L, 1.0 * L, k, 1.2 * L));
      const double F = 0.3 * k * L;  // a force of the chain's own scale k̄b̄²/b̄
      const Wrench loads(F, -0.7 * F, 0.2 * k * L * L);
      const EndCondition end = EndCondition::freeEnd(loads);
      GradientFlowModel model(chain, end, DynamicsScene(), Vector::Zero(n));
      for (const double spread : {0.01, 0.5, 1.5}) {  // nearly straight … coiled many times over
        std::uniform_real_distribution<double> angle(-spread, spread);
        Vector q(n);
        for (int i = 0; i < n; ++i) q[i] = std::clamp(angle(rng), chain.lowerLimits()[i] * 0.99, chain.upperLimits()[i] * 0.99);
        // the spring model with the half-angle given is the one energyJet(q) evaluates, bit for bit
        for (int i = 0; i < n; i += 97) {
          const Jet3 a = chain.segment(i).energyJet(q[i]);
          const Jet3 b = chain.segment(i).energyJet(q[i], std::sin(0.5 * q[i]), std::cos(0.5 * q[i]));
          CHECK(a.value == b.value);
          CHECK(a.d1 == b.d1);
          CHECK(a.d2 == b.d2);
          CHECK(a.d3 == b.d3);
        }
        Vector g(n), gRef(n);
        model.potentialGradient(q, g);
        totalPotentialGradient(chain, q, loads, gRef);
        const double eps = std::numeric_limits<double>::epsilon();
        // each S_i, C_i sums up to n link vectors of length ℓ: rounding ~ n ε ℓ per sum (both routes)
        const double forceScale = loads.head<2>().cwiseAbs().sum() * chain.length();
        const double torqueScale = forceScale + gRef.cwiseAbs().maxCoeff();
        CHECK((g - gRef).cwiseAbs().maxCoeff() <= 64.0 * eps * torqueScale);
        CHECK(model.potential(q) == Approx(totalPotential(chain, q, loads)).epsilon(0).margin(64.0 * n * eps * (k * L * L + forceScale)));
        CHECK(std::abs(model.equilibriumResidual(q) - gRef.cwiseAbs().maxCoeff()) <= 64.0 * eps * torqueScale);
        // the end pose: a model holding the end at the chain functions' pose sees it violated by rounding only
        const Pose p = endPose(chain, q);
        GradientFlowModel held(chain, EndCondition::heldPosition(p[0], p[1]), DynamicsScene(), q);
        CHECK(held.constraintViolation(q) <= 64.0 * eps * chain.length());
      }
    }
  }
}

TEST_CASE("body loads in the dynamics: gradient, exact Jacobians and stage solves against differences", "[dynamics][body_loads]") {
  // The links' weight along a tilted g and a point load at joint 2: Π gains V (eq B1), ∇Π −τ (B2),
  // the Hessian's generator −γ (B3); every derivative the integrators use is checked against
  // central differences of the model's own Π and right-hand side.
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> Q(-0.6, 0.6), V(-1.0, 1.0);
  const int n = 7;
  const Chain chain = bistableChain(n);
  const InertiaData rods = unevenInertia(chain);
  BodyLoads body = BodyLoads::weight(chain, rods, Eigen::Vector2d(-0.3, 0.2), Eigen::Vector2d(5.0, 5.0));
  body.points.push_back(PointLoad{2, Eigen::Vector2d(0.05, -0.1), Eigen::Vector2d::Zero()});
  Vector q(n), v(n);
  for (int i = 0; i < n; ++i) {
    q[i] = Q(rng);
    v[i] = V(rng);
  }
  const auto central = [&](auto&& f, Vector& at, int j) {
    const double h = 1e-6, keep = at[j];
    at[j] = keep + h;
    const auto fp = f(at);
    at[j] = keep - h;
    const auto fm = f(at);
    at[j] = keep;
    return (fp - fm) / (2 * h);
  };
  const EndCondition end = EndCondition::freeEnd(Wrench(0.1, -0.05, 0.02));
  // gradient flow
  DynamicsScene scene;
  scene.body = std::make_shared<const BodyLoads>(body);
  auto flow = makeDynamicsModel(chain, end, scene, Vector::Zero(n));
  REQUIRE(flow->hasBodyLoads());
  Vector grad(n);
  flow->potentialGradient(q, grad);
  Vector probe = q;
  for (int j = 0; j < n; ++j)
    CHECK(grad[j] == Approx(central([&](const Vector& x) { return flow->potential(x); }, probe, j)).margin(1e-8));
  // the rates of the body loads are ignored at a fixed state: the same as the loads at λ = 0
  DynamicsScene constant;
  constant.body = std::make_shared<const BodyLoads>(body.atParameter(0.0));
  auto same = makeDynamicsModel(chain, end, constant, Vector::Zero(n));
  CHECK(same->potential(q) == flow->potential(q));
  // without body loads Π differs (the check above is not vacuous)
  auto bare = makeDynamicsModel(chain, end, DynamicsScene(), Vector::Zero(n));
  CHECK(std::abs(bare->potential(q) - flow->potential(q)) > 1e-3);

  for (bool inertial : {false, true}) {
    INFO("inertial " << inertial);
    DynamicsScene s = scene;
    if (inertial) s.inertia = rods;
    auto model = makeDynamicsModel(chain, end, s, Vector::Zero(n));
    const int N = model->stateSize();
    Vector x(N), b(N), k(N), fp(N), fm(N);
    model->packState(q, v, x);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(N, N);
    model->jacobian(x.data(), J.data());
    Matrix Jfd(N, N);
    for (int j = 0; j < N; ++j) {
      Vector xp = x, xm = x;
      xp[j] += 1e-6;
      xm[j] -= 1e-6;
      model->rhs(xp.data(), fp.data());
      model->rhs(xm.data(), fm.data());
      Jfd.col(j) = (fp - fm) / 2e-6;
    }
    CHECK((Matrix(J) - Jfd).cwiseAbs().maxCoeff() < 1e-7 * Jfd.cwiseAbs().maxCoeff());
    for (int i = 0; i < N; ++i) b[i] = V(rng);
    for (double a : {1e-3, 0.1, 10.0}) {
      const Matrix W = Matrix::Identity(N, N) - a * Jfd;
      REQUIRE(model->solveLinearized(x.data(), a, b.data(), k.data()));
      CHECK((W * k - b).cwiseAbs().maxCoeff() < 1e-6 * (W.cwiseAbs() * k.cwiseAbs() + b.cwiseAbs()).maxCoeff());
    }
  }
}
