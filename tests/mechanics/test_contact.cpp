#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "buckle/continuation/bordered_solver.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/unloaded_shape.h"

#include "contact_cases.h"
#include "default_scene_path.h"
#include "random_segments.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

/// Independent formulation: Newton on the gradient of the total potential restricted to the
/// free joints (dense Eigen), the locked joints held at their limits. Returns q.
Eigen::VectorXd lockedNewton(const Chain& chain, const ContactSet& locked, Eigen::VectorXd q, const Wrench& F) {
  const int n = chain.size();
  std::vector<int> free;
  for (int i = 0; i < n; ++i)
    if (!locked.locked(i)) free.push_back(i);
  for (const LockedJoint& l : locked.joints()) q[l.joint] = limitAngle(chain, l.joint, l.side);
  const int nf = int(free.size());
  Eigen::VectorXd g(n), gf(nf);
  Eigen::MatrixXd H(n, n), Hf(nf, nf);
  for (int it = 0; it < 50; ++it) {
    totalPotentialGradient(chain, q, F, g);
    totalPotentialHessian(chain, q, F, H);
    for (int a = 0; a < nf; ++a) {
      gf[a] = g[free[size_t(a)]];
      for (int b = 0; b < nf; ++b) Hf(a, b) = H(free[size_t(a)], free[size_t(b)]);
    }
    const Eigen::VectorXd dq = Hf.fullPivLu().solve(gf);
    for (int a = 0; a < nf; ++a) q[free[size_t(a)]] -= dq[a];
    if (dq.cwiseAbs().maxCoeff() < 1e-15) break;
  }
  return q;
}

/// Lowest eigenvalues of H restricted to the free joints and ker of the held rows C (free
/// columns), by a dense self-adjoint eigen-solve.
Eigen::VectorXd reducedSpectrum(const Eigen::MatrixXd& H, const Eigen::MatrixXd& C, const ContactSet& locked) {
  const int n = int(H.rows());
  std::vector<int> free;
  for (int i = 0; i < n; ++i)
    if (!locked.locked(i)) free.push_back(i);
  const int nf = int(free.size());
  Eigen::MatrixXd Hf(nf, nf), Cf(C.rows(), nf);
  for (int a = 0; a < nf; ++a) {
    for (int b = 0; b < nf; ++b) Hf(a, b) = H(free[size_t(a)], free[size_t(b)]);
    Cf.col(a) = C.col(free[size_t(a)]);
  }
  Eigen::MatrixXd Z = Eigen::MatrixXd::Identity(nf, nf);
  if (Cf.rows() > 0) {
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Cf);
    Z = lu.kernel();
    Z = Eigen::HouseholderQR<Eigen::MatrixXd>(Z).householderQ() * Eigen::MatrixXd::Identity(nf, Z.cols());
  }
  const Eigen::MatrixXd R = Z.transpose() * Hf * Z;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (R + R.transpose())).eigenvalues();
}

const SpecialPointReport* firstOfType(const BranchReport& r, EventType type) {
  for (const SpecialPointReport& s : r.specialPoints)
    if (s.type == type) return &s;
  return nullptr;
}

int countType(const BranchReport& r, EventType type) {
  return int(std::count_if(r.specialPoints.begin(), r.specialPoints.end(),
                           [type](const SpecialPointReport& s) { return s.type == type; }));
}

/// The default scene's path and steps, on one thread.
EquilibriumBranchOptions defaultSceneOptions(int maxPoints) {
  EquilibriumBranchOptions o = testing::defaultScenePath();
  o.tracer.maxPoints = maxPoints;
  o.tree.threads = 1;
  return o;
}

/// A segment of the paper's chain whose joint stops at 0.6 rad.
SegmentParameters stoppedAt06() {
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.qMaxUser = 0.6;
  return p;
}

/// A pure end moment Me = λ from 0 to three times the load at which a joint reaches its stop,
/// steps up to 0.1, no switching.
EquilibriumBranchOptions momentToThrice(double limitLoad) {
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 3.0 * limitLoad;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  return o;
}

}  // namespace

TEST_CASE("ContactSet keeps its joints sorted, one side each, and labels them", "[contact]") {
  ContactSet s;
  s.lock(4, LimitSide::Lower);
  s.lock(2, LimitSide::Upper);
  s.lock(4, LimitSide::Upper);
  REQUIRE(s.count() == 2);
  CHECK(s.joints()[0].joint == 2);
  CHECK(s.side(4) == LimitSide::Upper);
  CHECK(s.label() == "3U 5U");
  s.release(2);
  CHECK(s.label() == "5U");
  CHECK_THROWS_WITH(s.check(3), Catch::Contains("joint 5 does not exist"));
  CHECK_THROWS_AS(s.lock(-1, LimitSide::Upper), std::invalid_argument);
  CHECK(toString(LimitSide::Lower) == std::string("lower"));
  CHECK(std::string(label(EventType::Contact)) == "CT");
  CHECK(std::string(label(EventType::Release)) == "RL");
}

TEST_CASE("contact: a single segment pushed past its limit carries applied torque minus spring torque", "[contact]") {
  const Chain chain = Chain::uniform(1, stoppedAt06());
  const double springAtLimit = chain.segment(0).energyJet(0.6).d1;  // E'(q̄): the limit load
  REQUIRE(springAtLimit > 0.0);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1));  // Me = λ
  EquilibriumBranchOptions o = momentToThrice(springAtLimit);
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(1), 0.0, cont::InitialDirection::increasingLambda(), o);
  const BranchReport& rep = r.reports[0];
  CHECK(r.tree.branches[0].stopReason == cont::StopReason::LambdaRange);
  REQUIRE(countType(rep, EventType::Contact) == 1);
  CHECK(countType(rep, EventType::Boundary) == 0);
  const SpecialPointReport& ct = *firstOfType(rep, EventType::Contact);
  CHECK(ct.joint == 0);
  CHECK(std::abs(ct.parameter - springAtLimit) <= 1e-12 * springAtLimit);
  CHECK(std::abs(ct.contactTorque) <= 1e-12 * springAtLimit);
  CHECK(ct.lockedAfter.label() == "1U");
  int locked = 0;
  ContactProblem contact(problem, ct.lockedAfter);
  for (const PointReport& pt : rep.points) {
    if (pt.locked.empty()) {
      CHECK(pt.parameter <= springAtLimit * (1.0 + 1e-12));
      continue;
    }
    ++locked;
    CHECK(pt.q[0] == Approx(0.6).margin(1e-14));
    // compression = applied torque − spring torque at the limit (closed form)
    CHECK(std::abs(pt.contactTorque - (pt.parameter - springAtLimit)) <= 1e-12 * springAtLimit);
    const cont::ContinuationPoint& cp = r.tree.branches[0].points[size_t(pt.index)];
    CHECK(std::abs(contact.contactTorque(*contact.createWorkspace(), cp.u, cp.lambda, 0) -
                   (springAtLimit - cp.lambda)) <= 1e-12 * springAtLimit);
    CHECK(pt.stable);
  }
  CHECK(locked >= 5);
  CHECK(rep.points.back().parameter == Approx(3.0 * springAtLimit).epsilon(1e-12));

  SECTION("a bound on the contact torque ends the locked stretch exactly there") {
    o.maxContactTorque = 0.5;  // torque units k̄b̄² = 1 here
    const EquilibriumBranches bounded =
        traceEquilibria(problem, Eigen::VectorXd::Zero(1), 0.0, cont::InitialDirection::increasingLambda(), o);
    CHECK(bounded.tree.branches[0].stopReason == cont::StopReason::Boundary);
    const BranchReport& br = bounded.reports[0];
    REQUIRE(countType(br, EventType::Boundary) == 1);
    CHECK(std::abs(br.points.back().contactTorque - 0.5) <= 1e-12);
    CHECK(std::abs(br.points.back().parameter - (springAtLimit + 0.5)) <= 1e-12 * springAtLimit);
    CHECK_THAT(br.specialPoints.back().note, Catch::Contains("bound"));
    CHECK_THROWS_AS(ContactProblem(problem, ContactSet(), 0.0), std::invalid_argument);
  }

  SECTION("switched off: the branch ends at the limit") {
    o.contact = false;
    const EquilibriumBranches off =
        traceEquilibria(problem, Eigen::VectorXd::Zero(1), 0.0, cont::InitialDirection::increasingLambda(), o);
    CHECK(off.tree.branches[0].stopReason == cont::StopReason::Boundary);
    CHECK(countType(off.reports[0], EventType::Contact) == 0);
    CHECK(countType(off.reports[0], EventType::Boundary) == 1);
  }
}

TEST_CASE("contact: joints that reach their limits at one point lock together and the branch goes on",
          "[contact]") {
  // Three equal segments under a pure end moment: every joint carries Me, so all three bend alike
  // and reach the limit 0.6 at the same load E'(0.6). The first contact's stretch meets the second
  // at once (and the second's the third); each is taken at that point, and the branch goes on with
  // all three locked to the end of the path, each carrying Me − E'(0.6).
  const Chain chain = Chain::uniform(3, stoppedAt06());
  const double springAtLimit = chain.segment(0).energyJet(0.6).d1;
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1));  // Me = λ
  const EquilibriumBranches r = traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0,
                                                cont::InitialDirection::increasingLambda(), momentToThrice(springAtLimit));
  const cont::Branch& b = r.tree.branches[0];
  INFO(b.stopMessage);
  CHECK(b.stopReason == cont::StopReason::LambdaRange);
  const BranchReport& rep = r.reports[0];
  CHECK(countType(rep, EventType::Contact) == 3);
  // each event names its own joint, and the contacts after it grow by that joint
  std::vector<int> joints;
  for (const SpecialPointReport& s : rep.specialPoints) {
    if (s.type != EventType::Contact) continue;
    CHECK(std::abs(s.parameter - springAtLimit) <= 1e-10 * springAtLimit);
    joints.push_back(s.joint);
    CHECK(int(s.lockedAfter.joints().size()) == int(joints.size()));
    CHECK(s.lockedAfter.locked(s.joint));
  }
  std::sort(joints.begin(), joints.end());
  CHECK(joints == std::vector<int>{0, 1, 2});
  REQUIRE(r.contact[0].size() == 4);
  CHECK(r.contact[0].back().locked.joints().size() == 3);
  const PointReport& last = rep.points.back();
  CHECK(last.parameter == Approx(3.0 * springAtLimit).epsilon(1e-12));
  REQUIRE(last.locked.joints().size() == 3);
  for (int i = 0; i < 3; ++i) CHECK(last.q[i] == Approx(0.6).margin(1e-14));
  // each stop carries the applied moment less the spring's torque at the limit (closed form)
  CHECK(std::abs(last.contactTorque - (last.parameter - springAtLimit)) <= 1e-10 * springAtLimit);
}

TEST_CASE("contact: a chain's locked branch agrees with an independent Newton solve with the joint fixed",
          "[contact]") {
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  p.qMinUser = -0.6;
  p.qMaxUser = 0.6;
  const Chain chain = Chain::uniform(3, p);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));  // Fy = λ
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 6.0;
  o.tracer.step.maxStep = 0.1;
  o.tracer.corrector.tolerance = 1e-14;  // the traced points themselves to the comparison's accuracy
  o.maxContactTorque = 1e3;          // Fy = 6 presses the locked joints with ~40 torque units
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
  const BranchReport& rep = r.reports[0];
  const cont::Branch& b = r.tree.branches[0];
  CHECK(b.stopReason == cont::StopReason::LambdaRange);
  REQUIRE(countType(rep, EventType::Contact) >= 1);
  const SpecialPointReport& ct = *firstOfType(rep, EventType::Contact);
  CHECK(ct.joint == 0);  // the largest moment arm
  int checked = 0;
  for (const PointReport& pt : rep.points) {
    if (pt.locked.empty()) continue;
    const Wrench F(0.0, pt.parameter, 0.0);
    const Eigen::VectorXd q = lockedNewton(chain, pt.locked, pt.q, F);
    CHECK((q - pt.q).cwiseAbs().maxCoeff() <= 1e-12 * std::max(1.0, q.cwiseAbs().maxCoeff()));
    Eigen::VectorXd g(3);
    totalPotentialGradient(chain, q, F, g);
    for (const LockedJoint& l : pt.locked.joints()) {
      ContactProblem contact(problem, pt.locked);
      const cont::ContinuationPoint& cp = b.points[size_t(pt.index)];
      CHECK(std::abs(contact.contactTorque(*contact.createWorkspace(), cp.u, cp.lambda, l.joint) - g[l.joint]) <=
            1e-11 * std::max(1.0, std::abs(g[l.joint])));
      CHECK(contact.compression(*contact.createWorkspace(), cp.u, cp.lambda, l.joint) >= 0.0);
    }
    ++checked;
  }
  CHECK(checked >= 5);

  SECTION("the O(n) solver of the locked problem matches the dense LU") {
    const cont::ContinuationPoint& cp = b.points.back();
    ContactProblem contact(problem, rep.points.back().locked);
    const buckle::continuation::BoundProblem solverBound(contact);  // outlives the solver
    auto structured = solverBound.makeStructuredSolver();
    cont::DenseBorderedSolver dense(contact);
    std::mt19937 rng(7);
    std::normal_distribution<double> N(0.0, 1.0);
    const int dim = contact.dimension() + 1;
    cont::Vector c(dim), rhs(dim), x1(dim), x2(dim);
    for (int i = 0; i < dim; ++i) c[i] = N(rng), rhs[i] = N(rng);
    REQUIRE(structured->factor(cp.u, cp.lambda, c) == cont::Factorization::Regular);
    REQUIRE(dense.factor(cp.u, cp.lambda, c) == cont::Factorization::Regular);
    REQUIRE(structured->solve(rhs, x1));
    REQUIRE(dense.solve(rhs, x2));
    CHECK((x1 - x2).norm() <= 1e-11 * x2.norm());
    CHECK(structured->determinantSign() == dense.determinantSign());
  }
}

TEST_CASE("contact: constrained stability equals a dense eigen-solve of the reduced Hessian", "[contact]") {
  std::mt19937 rng(2024);
  for (int n : {6, 40}) {
    std::vector<SegmentParameters> segs;
    for (int i = 0; i < n; ++i) segs.push_back(testing::randomSegment(rng));
    const Chain chain(segs);
    for (const EndCondition& end : {EndCondition::freeEnd(Eigen::Vector3d(-0.3, 0.2, 0.1)), EndCondition::clampedPinned(-0.4),
                                    EndCondition::heldPosition(0.8 * chain.length(), 0.5)}) {
      EquilibriumProblem problem(chain, end, Eigen::Vector3d(1.0, 0.0, 0.0));
      ContactSet locked;
      locked.lock(1, LimitSide::Upper);
      locked.lock(n - 2, LimitSide::Lower);
      ContactProblem contact(problem, locked);
      Eigen::VectorXd u(problem.dimension());
      std::uniform_real_distribution<double> W(-0.5, 0.5);
      for (int i = 0; i < u.size(); ++i) u[i] = W(rng);
      for (const LockedJoint& l : locked.joints()) u[l.joint] = limitAngle(chain, l.joint, l.side);
      const double lambda = -0.7;
      cont::StabilityInfo info;
      REQUIRE(buckle::continuation::BoundProblem(contact).stability(u, lambda, 3, info));
      Matrix H, C;
      REQUIRE(buckle::continuation::BoundProblem(problem).stabilityOperator(u, lambda, H, C));
      const Eigen::VectorXd ev = reducedSpectrum(H, C, locked);
      const double scale = std::max(1.0, ev.cwiseAbs().maxCoeff());
      INFO("n = " << n << ", held " << end.heldCount());
      CHECK(info.negative == int((ev.array() < 0.0).count()));
      const int wanted = std::min(3, int(ev.size()));  // n − |L| − rank(C_F) eigenvalues in all
      REQUIRE(info.lowest.size() == wanted);
      for (int k = 0; k < wanted; ++k) CHECK(std::abs(info.lowest[k] - ev[k]) <= 1e-10 * scale);
      // the same through the convenience function and the dense operator of the problem
      const cont::StabilityInfo again = constrainedStability(problem, locked, u, lambda, 1);
      CHECK(again.negative == info.negative);
      Matrix Hc, Cc;
      REQUIRE(buckle::continuation::BoundProblem(contact).stabilityOperator(u, lambda, Hc, Cc));
      const cont::StabilityInfo dense = cont::projectedInertia(Hc, Cc, 1e-13, 3);
      CHECK(dense.negative == info.negative);
    }
  }
}

TEST_CASE("contact: scaled units give the same contact events after rescaling", "[contact]") {
  const double Ls = 1e-3, Ks = 1e6;  // lengths ×1e−3, stiffness ×1e6: forces ×1e3, torques ×1
  auto run = [](double ls, double ks) {
    SegmentParameters p = SegmentParameters::symmetric(0.5 * ls, 1.0 * ls, 1.0 * ks, 2.25 * ls);
    p.qMinUser = -0.6;
    p.qMaxUser = 0.6;
    const Chain chain = Chain::uniform(3, p);
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
    EquilibriumBranchOptions o;
    o.tracer.lambdaMax = 6.0 * ks * ls;
    o.tracer.step.maxStep = 0.1;
    o.tree.branchSwitching = 0;
    return traceEquilibria(problem, Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda(), o);
  };
  const EquilibriumBranches a = run(1.0, 1.0), b = run(Ls, Ks);
  std::vector<const SpecialPointReport*> ea, eb;
  for (const SpecialPointReport& s : a.reports[0].specialPoints)
    if (s.type == EventType::Contact || s.type == EventType::Release) ea.push_back(&s);
  for (const SpecialPointReport& s : b.reports[0].specialPoints)
    if (s.type == EventType::Contact || s.type == EventType::Release) eb.push_back(&s);
  REQUIRE(ea.size() >= 1);
  REQUIRE(ea.size() == eb.size());
  for (size_t k = 0; k < ea.size(); ++k) {
    CHECK(ea[k]->type == eb[k]->type);
    CHECK(ea[k]->joint == eb[k]->joint);
    CHECK(std::abs(eb[k]->parameter / (Ks * Ls) - ea[k]->parameter) <= 1e-10 * std::abs(ea[k]->parameter));
    CHECK((eb[k]->q - ea[k]->q).cwiseAbs().maxCoeff() <= 1e-10);
  }
  CHECK(a.reports[0].points.back().locked == b.reports[0].points.back().locked);
  CHECK(std::abs(b.reports[0].points.back().contactTorque / (Ks * Ls * Ls) - a.reports[0].points.back().contactTorque) <=
        1e-9 * std::abs(a.reports[0].points.back().contactTorque));
}

TEST_CASE("contact: a long chain (n = 50) continues locked, O(n) solver and independent Newton agree", "[contact]") {
  const int n = 50;
  SegmentParameters p = SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25);
  std::vector<SegmentParameters> segs(size_t(n), p);
  segs[0].qMaxUser = 0.02;  // the root joint carries the largest moment and locks first
  const Chain chain(segs);
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 0.01;
  o.tracer.step.maxStep = 0.1;
  o.tracer.corrector.tolerance = 1e-14;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
  const BranchReport& rep = r.reports[0];
  REQUIRE(countType(rep, EventType::Contact) >= 1);
  CHECK(firstOfType(rep, EventType::Contact)->joint == 0);
  CHECK(r.tree.branches[0].stopReason == cont::StopReason::LambdaRange);
  const PointReport& last = rep.points.back();
  REQUIRE(last.locked.locked(0));
  const Eigen::VectorXd q = lockedNewton(chain, last.locked, last.q, Wrench(0.0, last.parameter, 0.0));
  CHECK((q - last.q).cwiseAbs().maxCoeff() <= 1e-12 * std::max(1.0, q.cwiseAbs().maxCoeff()));
  // the constrained equilibrium polish (contact.h) from a perturbed start lands on the same point
  Eigen::VectorXd u0 = r.tree.branches[0].points.back().u;
  u0.head(n) += 1e-3 * Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
  const ConstrainedEquilibrium polished = solveConstrainedEquilibrium(problem, last.locked, u0, last.parameter);
  REQUIRE(polished.converged);
  CHECK((polished.u.head(n) - q).cwiseAbs().maxCoeff() <= 1e-12 * std::max(1.0, q.cwiseAbs().maxCoeff()));
  CHECK(polished.minCompression == Approx(last.contactTorque).epsilon(1e-9));
  CHECK(polished.minCompression > 0.0);
}

TEST_CASE("contact: a curled chain's root joint locks and releases where the free branch touches the limit",
          "[contact]") {
  // Five segments curled by their unloaded shape (q0 = 0.2, 1.3, 1.3, 1.3, 1.3) so that the end
  // lies behind the root's moment arm: a growing Fy first bends joint 1 down onto its limit 0.1,
  // then, as the free joints swing the end round, pulls it back up (data/scenes/contact_release.json).
  std::vector<SegmentParameters> segs(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  segs[0].qMinUser = 0.1;
  Eigen::VectorXd q0(5);
  q0 << 0.2, 1.3, 1.3, 1.3, 1.3;
  const Chain chain(preloadsForShape(segs, q0));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));  // Fy = λ
  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 1.0;
  o.tracer.step.maxStep = 0.1;
  o.tree.branchSwitching = 0;
  const EquilibriumBranches r = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::increasingLambda(), o);
  const BranchReport& rep = r.reports[0];
  REQUIRE(countType(rep, EventType::Contact) == 1);
  REQUIRE(countType(rep, EventType::Release) == 1);
  const SpecialPointReport& ct = *firstOfType(rep, EventType::Contact);
  const SpecialPointReport& rl = *firstOfType(rep, EventType::Release);
  CHECK(ct.joint == 0);
  CHECK(rl.joint == 0);
  CHECK(ct.parameter < rl.parameter);
  CHECK(rl.lockedAfter.empty());
  CHECK(r.tree.branches[0].stopReason == cont::StopReason::LambdaRange);
  const double torqueUnit = problem.stiffnessUnit() * problem.lengthUnit() * problem.lengthUnit();
  for (const SpecialPointReport* e : {&ct, &rl}) {
    INFO(label(e->type));
    // Both events are points of the free branch too: τ_c = 0 there and joint 1 exactly at its
    // limit. An independent dense Newton of the *free* equilibrium at that load converges to it.
    CHECK(std::abs(e->contactTorque) <= 1e-11 * torqueUnit);
    CHECK(e->q[0] == Approx(0.1).margin(1e-14));
    const Eigen::VectorXd q = lockedNewton(chain, ContactSet(), e->q, Wrench(0.0, e->parameter, 0.0));
    CHECK(std::abs(q[0] - 0.1) <= 1e-10);
    CHECK((q - e->q).cwiseAbs().maxCoeff() <= 1e-10);
  }
  // The locked stretch lies between the two events and pushes (compression > 0); before and
  // after, joint 1 is free and inside its range.
  for (const PointReport& pt : rep.points) {
    if (pt.parameter < ct.parameter * (1 - 1e-12) || pt.parameter > rl.parameter * (1 + 1e-12)) {
      CHECK(pt.locked.empty());
      CHECK(pt.q[0] >= 0.1 - 1e-14);
    } else if (!pt.locked.empty()) {
      CHECK(pt.contactTorque >= -1e-12 * torqueUnit);
      CHECK(pt.q[0] == Approx(0.1).margin(1e-14));
    }
  }
  // the release load is where the locked branch's compression returns to zero: the contact
  // torque of the locked problem, by the independent Newton, changes sign across it
  ContactSet locked;
  locked.lock(0, LimitSide::Lower);
  for (double f : {0.999, 1.001}) {
    const double lambda = f * rl.parameter;
    const Eigen::VectorXd q = lockedNewton(chain, locked, rl.q, Wrench(0.0, lambda, 0.0));
    Eigen::VectorXd g(5);
    totalPotentialGradient(chain, q, Wrench(0.0, lambda, 0.0), g);
    CHECK((f < 1.0 ? g[0] > 0.0 : g[0] < 0.0));  // lower limit: compression = +τ_c
  }
}

TEST_CASE("contact: the loaded stiffness with locked joints is the free joints' compliance inverted", "[contact]") {
  std::mt19937 rng(99);
  std::vector<SegmentParameters> segs;
  for (int i = 0; i < 6; ++i) segs.push_back(testing::randomSegment(rng));
  const Chain chain(segs);
  Eigen::VectorXd q(6);
  q << 0.3, -0.2, 0.5, 0.1, -0.4, 0.2;
  const Wrench F(-0.2, 0.15, 0.05);
  ContactSet locked;
  locked.lock(1, LimitSide::Upper);
  locked.lock(4, LimitSide::Lower);
  const CartesianStiffness k = lockedLoadedStiffness(chain, q, F, EndCondition::freeEnd(), locked);
  // independent: C_F = J_p,F H_FF⁻¹ J_p,Fᵀ on the free joints F = {0, 2, 3, 5}
  ChainData data(chain);
  forwardKinematics(chain, q, data);
  Matrix J(3, 6), H(6, 6);
  endJacobian(data, J);
  totalPotentialHessian(chain, q, F, H);
  const std::vector<int> free{0, 2, 3, 5};
  Matrix Hf(4, 4), Jf(2, 4);
  for (int a = 0; a < 4; ++a) {
    Jf.col(a) = J.col(free[size_t(a)]).head(2);
    for (int b = 0; b < 4; ++b) Hf(a, b) = H(free[size_t(a)], free[size_t(b)]);
  }
  const Eigen::Matrix2d C = Jf * Hf.fullPivLu().solve(Jf.transpose());
  const Eigen::Matrix2d K = C.inverse();
  CHECK((k.stiffness - K).cwiseAbs().maxCoeff() <= 1e-10 * K.cwiseAbs().maxCoeff());
  CHECK((k.compliance - C).cwiseAbs().maxCoeff() <= 1e-10 * C.cwiseAbs().maxCoeff());
  // no joint locked: the plain loaded stiffness
  const CartesianStiffness plain = lockedLoadedStiffness(chain, q, F, EndCondition::freeEnd(), ContactSet());
  CHECK((plain.stiffness - loadedStiffness(chain, q, F, false).stiffness).cwiseAbs().maxCoeff() == 0.0);
  CHECK_THROWS_AS(loadedStiffness(chain, q, F, false, Matrix::Zero(1, 5)), std::invalid_argument);
}

TEST_CASE("contact: a branch point on a locked stretch is switched, its children locked as the stretch",
          "[contact][switching]") {
  // data/scenes/locked_branch_point.json. Five segments, the second bent by its unloaded shape
  // (q0 = 0, 0.8, 0, 0, 0), joint 1 with the lower limit −0.05, pushed by a force along the axis
  // the links 2–5 have once joint 1 sits on that limit (θ* = −0.05 + 0.8). Before the contact the
  // force bends joint 1 down (its line passes above joint 1); at the limit the links 2–5 are
  // straight along it, so with joint 1 locked q* = (−0.05, 0.8, 0, 0, 0) is an equilibrium for
  // every load (the load's moment vanishes at joints 2–5, the stop carries joint 1's), and the
  // free part, a cantilever of four joints compressed along its axis, buckles: a branch point
  // on the locked stretch.
  std::vector<SegmentParameters> segs(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  segs[0].qMinUser = -0.05;
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(5);
  q0[1] = 0.8;
  const Chain chain(preloadsForShape(segs, q0));
  const double theta = -0.05 + 0.8;
  const Wrench unit(-std::cos(theta), -std::sin(theta), 0.0);  // λ = P, the compressive force
  EquilibriumProblem problem(chain, EndCondition::freeEnd(), unit);
  Eigen::VectorXd qStar = q0;
  qStar[0] = -0.05;

  // Independent numbers at q*: the gradient of Π is affine in P; joint 1's row vanishes at the
  // contact load, the others at every load; K_q − K_g on joints 2–5 is singular at the loads
  // P = eig(−B⁻¹A), H(P) = A + P·B.
  Eigen::VectorXd g0(5), g1(5);
  totalPotentialGradient(chain, qStar, 0.0 * unit, g0);
  totalPotentialGradient(chain, qStar, 1.0 * unit, g1);
  REQUIRE(g0.tail(4).cwiseAbs().maxCoeff() < 1e-12);
  REQUIRE(g1.tail(4).cwiseAbs().maxCoeff() < 1e-12);
  const double contactLoad = -g0[0] / (g1[0] - g0[0]);
  Eigen::MatrixXd H0(5, 5), H1(5, 5);
  totalPotentialHessian(chain, qStar, 0.0 * unit, H0);
  totalPotentialHessian(chain, qStar, 1.0 * unit, H1);
  const Eigen::MatrixXd A = H0.bottomRightCorner(4, 4), B = H1.bottomRightCorner(4, 4) - A;
  const Eigen::VectorXcd critical = Eigen::MatrixXd(-B.fullPivLu().solve(A)).eigenvalues();
  double firstCritical = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < critical.size(); ++i)
    if (std::abs(critical[i].imag()) < 1e-12 && critical[i].real() > 0.0)
      firstCritical = std::min(firstCritical, critical[i].real());
  REQUIRE(contactLoad > 0.0);
  REQUIRE(firstCritical > 1.5 * contactLoad);  // the stop is reached well before the free part buckles

  EquilibriumBranchOptions o;
  o.tracer.lambdaMax = 1.5 * firstCritical;
  o.tracer.step.maxStep = 0.05;
  o.tracer.maxPoints = 300;
  o.tree.branchSwitching = 1;
  const EquilibriumBranches r = traceEquilibria(problem, q0, 0.0, cont::InitialDirection::increasingLambda(), o);
  const cont::Branch& root = r.tree.branches[0];
  const BranchReport& rep = r.reports[0];
  REQUIRE(countType(rep, EventType::Contact) == 1);
  const SpecialPointReport& ct = *firstOfType(rep, EventType::Contact);
  CHECK(ct.joint == 0);
  CHECK(ct.parameter == Approx(contactLoad).epsilon(1e-10));

  // The branch point on the locked stretch, on the trivial branch q* at the first critical load.
  int bpIndex = -1;
  for (size_t k = 0; k < root.specialPoints.size(); ++k)
    if (root.specialPoints[k].type == cont::SpecialPointType::BranchPoint &&
        !lockedAt(r.contact[0], root.specialPoints[k].index + 1).empty())
      bpIndex = int(k);
  REQUIRE(bpIndex >= 0);
  const cont::SpecialPoint& bp = root.specialPoints[size_t(bpIndex)];
  INFO("BP at P = " << bp.lambda << ": " << bp.note);
  CHECK(bp.lambda == Approx(firstCritical).epsilon(1e-9));
  CHECK((bp.u.head(5) - qStar).cwiseAbs().maxCoeff() < 1e-10);

  // Switched: both sides traced on the locked problem, leaving q* while joint 1 stays on its stop
  // and pushes (compression > 0); every point an equilibrium of the free joints.
  int children = 0;
  for (size_t b = 1; b < r.tree.branches.size(); ++b) {
    const cont::Branch& child = r.tree.branches[b];
    if (child.parentId != 0 || child.parentSpecialPoint != bpIndex) continue;
    ++children;
    REQUIRE(child.points.size() > 3);
    const ContactSet& first = r.contact[b].front().locked;
    CHECK(first.locked(0));
    CHECK(first.side(0) == LimitSide::Lower);
    const cont::ContinuationPoint& p = child.points[2];
    CHECK((p.u.head(5) - qStar).cwiseAbs().maxCoeff() > 1e-4);
    CHECK(p.u[0] == -0.05);
    Eigen::VectorXd g(5);
    totalPotentialGradient(chain, p.u.head(5), p.lambda * unit, g);
    CHECK(g.tail(4).cwiseAbs().maxCoeff() < 1e-9);
    CHECK(g[0] > 0.0);  // the lower stop pushes joint 1 up: compression = τ_c = ∂Π/∂q1 > 0
  }
  CHECK(children == 2);
  CHECK(bp.note.find("switched (") != std::string::npos);  // by the tree driver itself, like a traced BP
}

TEST_CASE("contact: a branch that comes back to one of its contact events, same contacts and direction, ends there "
          "as a closed loop",
          "[contact][switching]") {
  // The default scene's chain with 20 segments (a = 0.5, b = 1, k = 1, L0 = 2.25, clamped–pinned,
  // compressed by Fx to −2.5): a child of the trivial branch locks and releases joints 9, 11 and 13
  // in a cycle of contact events, its second half the mirror image of the first. Traced on, it
  // would go round until its budget of points; it ends where it is back at an event it has passed.
  const int n = 20;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = defaultSceneOptions(4000);
  o.tracer.detection.lowestEigenvalues = 1;
  const EquilibriumBranches r =
      traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
  int loops = 0;
  for (size_t b = 0; b < r.tree.branches.size(); ++b) {
    const cont::Branch& branch = r.tree.branches[b];
    if (branch.stopReason != cont::StopReason::ClosedLoop) continue;
    ++loops;
    const std::vector<ContactStretch>& stretches = r.contact[b];
    INFO("branch " << b << ": " << branch.stopMessage);
    CHECK(int(branch.points.size()) < o.tracer.maxPoints);  // ended by the loop, before the budget
    // The stretch that started at the point the branch came back to: the same point to far below
    // the test's 1e-6 (a loop, not a near miss).
    const cont::ContinuationPoint& last = branch.points.back();
    int from = -1;
    for (size_t k = 1; k + 1 < stretches.size() && from < 0; ++k) {
      const cont::ContinuationPoint& p = branch.points[size_t(stretches[k].firstPoint - 1)];
      if ((p.u - last.u).cwiseAbs().maxCoeff() <= 1e-6 && std::abs(p.lambda - last.lambda) <= 1e-6) from = int(k);
    }
    REQUIRE(from > 0);
    const cont::ContinuationPoint& back = branch.points[size_t(stretches[size_t(from)].firstPoint - 1)];
    CHECK((back.u - last.u).cwiseAbs().maxCoeff() < 1e-9);
    CHECK(std::abs(back.lambda - last.lambda) < 1e-9);
    // One period: at least two events; a contact set may come back inside it, but elsewhere (not
    // the same point: no loop there, and the branch went on); the mirror image of the loop's first
    // half in its second (joint j upper ↔ lower at the same load).
    const int period = int(stretches.size()) - from;
    REQUIRE(period >= 2);
    int setsAgain = 0;
    for (int k = from; k < int(stretches.size()); ++k)
      for (int l = k + 1; l < int(stretches.size()); ++l)
        if (stretches[size_t(k)].locked == stretches[size_t(l)].locked) {
          ++setsAgain;
          const cont::ContinuationPoint& pk = branch.points[size_t(stretches[size_t(k)].firstPoint - 1)];
          const cont::ContinuationPoint& pl = branch.points[size_t(stretches[size_t(l)].firstPoint - 1)];
          CHECK((pk.u - pl.u).cwiseAbs().maxCoeff() + std::abs(pk.lambda - pl.lambda) > 1e-3);
        }
    CHECK(setsAgain > 0);
    if (period % 2 == 0)
      for (int k = from; k < from + period / 2; ++k) {
        const ContactSet &a = stretches[size_t(k)].locked, &m = stretches[size_t(k + period / 2)].locked;
        REQUIRE(a.joints().size() == m.joints().size());
        for (size_t j = 0; j < a.joints().size(); ++j) {
          CHECK(a.joints()[j].joint == m.joints()[j].joint);
          CHECK(a.joints()[j].side != m.joints()[j].side);
        }
        const double la = branch.points[size_t(stretches[size_t(k)].firstPoint - 1)].lambda;
        const double lm = branch.points[size_t(stretches[size_t(k + period / 2)].firstPoint - 1)].lambda;
        CHECK(std::abs(la - lm) < 1e-9);
      }
  }
  CHECK(loops >= 1);
}

namespace {

/// The default scene's chain with 50 segments (a = 0.5, b = 1, k = 1, L0 = 2.25, clamped–pinned,
/// compressed by Fx to −2.5), switched only at the 24th simple branch point of the trivial
/// branch: its + side child locks and releases joints well over a hundred times before it closes
/// into a loop (the default scene at 50 segments, `buckle run`). `childPoints` > 0: the children's
/// budget of points.
EquilibriumBranches manyEventsTree(int childPoints) {
  const int n = 50;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions o = defaultSceneOptions(20000);
  o.tree.branchSwitching = 1;
  o.tree.switchAt = [](const cont::Branch& branch, const cont::SpecialPoint& bp) {
    int before = 0;
    for (const cont::SpecialPoint& sp : branch.specialPoints)
      if (sp.type == cont::SpecialPointType::BranchPoint && sp.multiplicity == 1 && sp.arclength < bp.arclength)
        ++before;
    return branch.parentId < 0 && before == 23;
  };
  if (childPoints > 0) {
    o.tree.childTracer = o.tracer;
    o.tree.childTracer->maxPoints = childPoints;
  }
  return traceEquilibria(problem, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::decreasingLambda(), o);
}

const EquilibriumBranches& manyEventsTreeOnce() {
  static const EquilibriumBranches r = manyEventsTree(0);
  return r;
}

}  // namespace

TEST_CASE("contact: a branch goes through as many contact events as its budget of points allows", "[contact]") {
  // No count of events ends a branch (a fixed count of 50 used to end such children as if at a
  // regular boundary): this one passes more than a hundred and ends as a closed loop.
  const EquilibriumBranches& r = manyEventsTreeOnce();
  REQUIRE(r.tree.branches.size() == 3);
  const cont::Branch& child = r.tree.branches[1];
  const std::vector<ContactStretch>& stretches = r.contact[1];
  INFO(child.stopMessage);
  CHECK(int(stretches.size()) - 1 > 100);
  CHECK(child.stopReason == cont::StopReason::ClosedLoop);
  CHECK(int(child.points.size()) < 20000);
}

TEST_CASE("contact: a budget of points spent at a contact event ends the branch for the budget, not at a boundary",
          "[contact]") {
  const EquilibriumBranches& full = manyEventsTreeOnce();
  REQUIRE(full.tree.branches.size() == 3);
  const cont::Branch& child = full.tree.branches[1];
  const std::vector<ContactStretch>& stretches = full.contact[1];
  REQUIRE(stretches.size() > 10);
  // the event that starts the tenth stretch is the last point the budget allows
  const int event = stretches[10].firstPoint - 1;
  const EquilibriumBranches cut = manyEventsTree(event + 1);
  REQUIRE(cut.tree.branches.size() == 3);
  const cont::Branch& b = cut.tree.branches[1];
  INFO(b.stopMessage);
  CHECK(b.stopReason == cont::StopReason::MaxPoints);
  CHECK(b.stopMessage.find("at a contact event") != std::string::npos);
  REQUIRE(int(b.points.size()) == event + 1);
  CHECK(cut.contact[1].size() == 10);
  // the same curve as the branch with the larger budget, up to that event
  for (int i = 0; i <= event; ++i) {
    CHECK((b.points[size_t(i)].u - child.points[size_t(i)].u).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(b.points[size_t(i)].lambda == Approx(child.points[size_t(i)].lambda).margin(1e-12));
  }
}

TEST_CASE("contact: self contacts' rank-2 terms on the O(n) solver, products and counts equal the dense LU, "
          "Jacobian and eigen-solve",
          "[contact]") {
  // n = 450: past the solver's dense fallback (400 unknowns), so every factorization checked here
  // is the structured one; q, μ and the held forces random (the algebra holds at any point)
  const int n = 450;
  std::mt19937 rng(451);
  const Chain chain(testing::randomSegments(rng, n));
  const auto [distalOnProximal, proximalOnDistal] = testing::crossingSelfContacts(n);
  std::uniform_real_distribution<double> W(-1.0, 1.0), Q(-0.4, 0.4);
  const std::vector<testing::ContactCase> cases = {
      {"free end, one self contact", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))), false, {distalOnProximal}},
      {"free end, two", EndCondition::freeEnd(Eigen::Vector3d(W(rng), W(rng), W(rng))), false,
       {distalOnProximal, proximalOnDistal}},
      {"clamped-pinned, wall, one", EndCondition::clampedPinned(W(rng), 0.1 * W(rng)), true, {proximalOnDistal}}};
  testing::forEachContactCase(rng, chain, cases, {{5, LimitSide::Upper}, {200, LimitSide::Lower}, {290, LimitSide::Upper}},
                              [&](const testing::ContactCase& k, const ContactProblem& contact) {
    INFO(k.name);
    const int N = contact.dimension();
    Eigen::VectorXd u(N);
    for (int i = 0; i < N; ++i) u[i] = i < n ? Q(rng) : W(rng);
    u[N - 1] = -0.5;  // one force pulling: E's signs both ways across the cases
    const double lambda = W(rng);
    const cont::BoundProblem bound(contact);
    auto structured = bound.makeStructuredSolver();
    cont::DenseBorderedSolver dense(contact);
    Eigen::VectorXd c(N + 1), b(N + 1), x1(N + 1), x2(N + 1);
    for (int i = 0; i <= N; ++i) c[i] = W(rng), b[i] = W(rng);
    REQUIRE(structured->factor(u, lambda, c) == cont::Factorization::Regular);
    REQUIRE(dense.factor(u, lambda, c) == cont::Factorization::Regular);
    CHECK(structured->determinantSign() == dense.determinantSign());
    CHECK(structured->logAbsDeterminant() == Approx(dense.logAbsDeterminant()).epsilon(1e-9));
    REQUIRE(structured->solve(b, x1));
    REQUIRE(dense.solve(b, x2));
    // backward errors (the random points' A is as ill-conditioned as 1e10: x itself agrees to the
    // condition number only), against the problem's own Jacobian
    Eigen::MatrixXd Fu(N, N);
    Eigen::VectorXd Fl(N);
    REQUIRE(bound.jacobian(u, lambda, Fu, Fl));
    const auto backward = [](const Eigen::MatrixXd& A, const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
      return (A * x - r).norm() / (A.norm() * x.norm() + r.norm());
    };
    Eigen::MatrixXd A(N + 1, N + 1);
    A << Fu, Fl, c.transpose();
    CHECK(backward(A, x1, b) <= 1e-14);
    CHECK(backward(A, x2, b) <= 1e-14);
    CHECK((x1 - x2).norm() <= 1e-7 * x2.norm());
    // the locator's general borders, both ways
    for (int kb = 1; kb <= std::min(2, structured->maxGeneralBorder()); ++kb)
      for (bool transposed : {false, true}) {
        INFO("general borders k = " << kb << ", transposed " << transposed);
        Eigen::MatrixXd B(N, kb), C(N, kb), D(kb, kb);
        for (int j = 0; j < kb; ++j) {
          for (int i = 0; i < N; ++i) B(i, j) = W(rng), C(i, j) = W(rng);
          for (int i = 0; i < kb; ++i) D(i, j) = W(rng);
        }
        Eigen::VectorXd g(N + kb), y1(N + kb), y2(N + kb);
        for (int i = 0; i < N + kb; ++i) g[i] = W(rng);
        REQUIRE(dense.factorGeneral(u, lambda, B, C, D, transposed) == cont::Factorization::Regular);
        REQUIRE(structured->factorGeneral(u, lambda, B, C, D, transposed) == cont::Factorization::Regular);
        CHECK(structured->determinantSign() == dense.determinantSign());
        REQUIRE(dense.solve(g, y2));
        REQUIRE(structured->solve(g, y1));
        Eigen::MatrixXd G(N + kb, N + kb);
        if (transposed)
          G << Fu.transpose(), B, C.transpose(), D;
        else
          G << Fu, B, C.transpose(), D;
        CHECK(backward(G, y1, g) <= 1e-14);
        CHECK(backward(G, y2, g) <= 1e-14);
      }
    // the O(n) products against the dense Jacobian's (Problem's defaults)
    {
      auto ws = contact.createWorkspace();
      Eigen::VectorXd x(N + 1), w(N), y1(N), y2(N), z1(N + 1), z2(N + 1);
      for (int i = 0; i <= N; ++i) x[i] = W(rng);
      for (int i = 0; i < N; ++i) w[i] = W(rng);
      REQUIRE(contact.jacobianApply(*ws, u, lambda, x, y1));
      REQUIRE(contact.cont::Problem::jacobianApply(*ws, u, lambda, x, y2));
      CHECK((y1 - y2).norm() <= 1e-12 * (A.norm() * x.norm()));
      REQUIRE(contact.jacobianTransposeApply(*ws, u, lambda, w, z1));
      REQUIRE(contact.cont::Problem::jacobianTransposeApply(*ws, u, lambda, w, z2));
      CHECK((z1 - z2).norm() <= 1e-12 * (A.norm() * w.norm()));
    }
    // the stability: the counts with the coupling bordered against the dense projection of the
    // problem's own operator (self contact rank-2 terms included: ContactProblem::stabilityOperator)
    cont::StabilityInfo info;
    REQUIRE(bound.stability(u, lambda, 3, info));
    Matrix Hc, Cc;
    REQUIRE(bound.stabilityOperator(u, lambda, Hc, Cc));
    const cont::StabilityInfo reference = cont::projectedInertia(Hc, Cc, 1e-13, 3);
    CHECK(info.negative == reference.negative);
    CHECK(info.zero == reference.zero);
    REQUIRE(info.lowest.size() == reference.lowest.size());
    const double scale = std::max(1.0, Hc.norm());
    for (int j = 0; j < int(info.lowest.size()); ++j) CHECK(std::abs(info.lowest[j] - reference.lowest[j]) <= 1e-9 * scale);
    // the eigenvalues from an index on (the certified counting's), O(n) against the dense default
    {
      auto ws = contact.createWorkspace();
      Eigen::VectorXd mu(2), dense(2);
      const int first = std::max(0, reference.negative - 1);
      REQUIRE(contact.stabilityEigenvalues(*ws, u, lambda, first, mu));
      REQUIRE(contact.cont::Problem::stabilityEigenvalues(*ws, u, lambda, first, dense));
      CHECK((mu - dense).cwiseAbs().maxCoeff() <= 1e-9 * scale);
    }
  });
}
