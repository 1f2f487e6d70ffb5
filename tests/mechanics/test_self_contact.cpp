// Self contact's gap and its derivatives (self_contact.h) against the test's own geometry: the
// gap from wall_statics.h's vertices, its gradient and Hessian by central differences of that
// gap; the touching pair against a brute-force scan of every vertex–edge distance.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <atomic>
#include <limits>
#include <random>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/contact_geometry.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/self_contact.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "buckle/mechanics/vibration.h"
#include "hook_chain.h"
#include "random_segments.h"
#include "wall_statics.h"

namespace mech = buckle::mechanics;
using buckle::test::Hook;
using buckle::test::hookStatics;
using Eigen::Vector2d;
using Eigen::VectorXd;

namespace {

// The gap n_e·(p_v − p_e0) from the test's own vertices.
double testGap(const mech::Chain& chain, const VectorXd& q, const mech::SelfContact& c) {
  const int s = c.edge.segment;
  const Vector2d e0 = buckle::test::vertexAt(chain, q, {s, c.edge.corner(0)});
  const Vector2d e1 = buckle::test::vertexAt(chain, q, {s, c.edge.corner(1)});
  const Vector2d third = buckle::test::vertexAt(chain, q, {s, c.edge.corner(2)});
  Vector2d n(e1.y() - e0.y(), e0.x() - e1.x());
  n.normalize();
  if (n.dot(third - e0) > 0.0) n = -n;
  return n.dot(buckle::test::vertexAt(chain, q, c.vertex) - e0);
}

mech::Chain randomChain(std::mt19937& rng, int n) {
  std::vector<mech::SegmentParameters> p;
  for (int i = 0; i < n; ++i) p.push_back(mech::testing::randomSegment(rng));
  return mech::Chain(p);
}

}  // namespace

TEST_CASE("self contact: gap, gradient and Hessian against the test's own geometry", "[self_contact]") {
  std::mt19937 rng(20261207);
  const int n = 7;
  const mech::Chain chain = randomChain(rng, n);
  using V = mech::WallVertex;
  using E = mech::TriangleEdge;
  // the vertex's body distal (σ = +1) and proximal (σ = −1), the clamped triangle's corner, a joint
  const std::vector<mech::SelfContact> contacts = {
      {V{5, 3}, E{1, true, 0}}, {V{6, 4}, E{2, false, 1}}, {V{1, 3}, E{5, false, 2}}, {V{0, 1}, E{4, true, 1}},
      {V{5, 0}, E{2, true, 2}}, {V{2, 2}, E{6, true, 0}}};
  for (int trial = 0; trial < 4; ++trial) {
    const VectorXd q = mech::testing::randomState(rng, chain, n);
    const Eigen::Matrix2Xd P = mech::jointPositions(chain, q);
    for (const mech::SelfContact& c : contacts) {
      INFO(c.label() << ", trial " << trial);
      REQUIRE_NOTHROW(mech::checkSelfContact(c, n));
      const mech::SelfContactGap g = mech::selfContactGap(chain, q, P, c);
      CHECK(g.gap == Approx(testGap(chain, q, c)).margin(1e-13));
      VectorXd grad(n), gen(n), coupling(n), weights(n);
      mech::selfContactDerivatives(P, c, g, grad, gen, coupling, weights);
      // −∂²g assembled from the generator form and the rank-2 term
      Eigen::MatrixXd minusHessian(n, n);
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          minusHessian(j, k) = gen[std::max(j, k)] - coupling[j] * weights[k] - weights[j] * coupling[k];
      const double h = 1e-5, h2 = 1e-3;
      double gradError = 0.0, hessError = 0.0;
      for (int j = 0; j < n; ++j) {
        VectorXd qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        gradError = std::max(gradError, std::abs(grad[j] - (testGap(chain, qp, c) - testGap(chain, qm, c)) / (2 * h)));
        for (int k = 0; k < n; ++k) {
          VectorXd a = q, b = q, cc = q, d = q;
          a[j] += h2, a[k] += h2;
          b[j] += h2, b[k] -= h2;
          cc[j] -= h2, cc[k] += h2;
          d[j] -= h2, d[k] -= h2;
          const double fd = (testGap(chain, a, c) - testGap(chain, b, c) - testGap(chain, cc, c) + testGap(chain, d, c)) /
                            (4 * h2 * h2);
          hessError = std::max(hessError, std::abs(-minusHessian(j, k) - fd));
        }
      }
      CHECK(gradError < 1e-8);
      CHECK(hessError < 1e-5);
      // the joints that move both bodies or neither do not enter
      const int lo = std::min(c.vertex.lastJoint(), c.edge.lastJoint());
      const int hi = std::max(c.vertex.lastJoint(), c.edge.lastJoint());
      for (int j = 0; j < n; ++j)
        if (j <= lo || j > hi) CHECK(grad[j] == 0.0);
    }
  }
}

TEST_CASE("self contact: contacts between the same or adjacent links are refused", "[self_contact]") {
  using V = mech::WallVertex;
  using E = mech::TriangleEdge;
  const int n = 5;
  CHECK_THROWS_AS(mech::checkSelfContact({V{2, 3}, E{2, true, 0}}, n), std::invalid_argument);   // the same triangle
  CHECK_THROWS_AS(mech::checkSelfContact({V{2, 3}, E{3, true, 0}}, n), std::invalid_argument);   // adjacent links
  CHECK_THROWS_AS(mech::checkSelfContact({V{3, 0}, E{2, true, 1}}, n), std::invalid_argument);   // joint 4 is on link 3
  CHECK_THROWS_AS(mech::checkSelfContact({V{7, 3}, E{0, true, 0}}, n), std::invalid_argument);   // no segment 8
  CHECK_THROWS_AS(mech::checkSelfContact({V{4, 3}, E{0, true, 5}}, n), std::invalid_argument);   // no edge 5
  CHECK_NOTHROW(mech::checkSelfContact({V{3, 3}, E{1, true, 0}}, n));
  CHECK(mech::SelfContact{V{3, 3}, E{1, true, 1}}.label() == "4d+ on 2d[j,+]");
}

TEST_CASE("self contact: the touching pair is the nearest vertex over an edge (brute force)", "[self_contact]") {
  std::mt19937 rng(7);
  const int n = 6;
  const mech::Chain chain = randomChain(rng, n);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd q = mech::testing::randomState(rng, chain, n);
    const int a = 1, b = 4;
    // every corner of link a's and link b's triangles against every edge of the other's, by the test's geometry
    double best = std::numeric_limits<double>::infinity();
    const auto triangles = [&](int link) {
      std::vector<std::pair<int, bool>> t;
      if (link >= 1) t.push_back({link - 1, true});
      if (link <= n - 1) t.push_back({link, false});
      return t;
    };
    for (const auto& [vl, el] : {std::pair{a, b}, std::pair{b, a}})
      for (const auto& [vs, vd] : triangles(vl))
        for (const int corner : vd ? std::vector<int>{0, 3, 4} : std::vector<int>{0, 1, 2})
          for (const auto& [es, ed] : triangles(el))
            for (int edge = 0; edge < 3; ++edge) {
              const mech::SelfContact c{{vs, corner}, {es, ed, edge}};
              const Vector2d p = buckle::test::vertexAt(chain, q, c.vertex);
              const Vector2d e0 = buckle::test::vertexAt(chain, q, {es, c.edge.corner(0)});
              const Vector2d e1 = buckle::test::vertexAt(chain, q, {es, c.edge.corner(1)});
              const double t = (p - e0).dot(e1 - e0) / (e1 - e0).squaredNorm();
              if (t < 0.0 || t > 1.0) continue;
              best = std::min(best, std::abs(testGap(chain, q, c)));
            }
    INFO("trial " << trial);
    if (!std::isfinite(best)) {  // no vertex over an edge of the other link
      CHECK_THROWS_AS(mech::touchingPair(chain, q, a, b), std::invalid_argument);
      continue;
    }
    const mech::SelfContact found = mech::touchingPair(chain, q, a, b);
    INFO(found.label());
    CHECK(std::abs(testGap(chain, q, found)) == Approx(best).margin(1e-12));
  }
  CHECK_THROWS_AS(mech::touchingPair(chain, VectorXd::Zero(n), 2, 3), std::invalid_argument);
}


TEST_CASE("self contact: a hook curled by an end moment is held on its own link, in any units", "[self_contact]") {
  namespace cont = buckle::continuation;
  double reference = 0.0;
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}, std::pair{1e-4, 1e8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    Hook hook(sL, sK);
    const double torqueUnit = sK * sL * sL;
    const mech::EquilibriumBranchOptions o = hook.upTo(0.25);
    const mech::EquilibriumBranches t = hook.trace(o);
    REQUIRE(t.tree.branches.size() == 1);
    const cont::Branch& b = t.tree.branches[0];
    REQUIRE(t.contact[0].size() == 2);  // free, then the self contact held to the range end
    const mech::ContactSet& held = t.contact[0][1].locked;
    REQUIRE(held.selfCount() == 1);
    const mech::SelfContact c = held.self()[0];
    CHECK(c.label() == "8d- on 3p[j,+]");
    CHECK(b.stopReason == cont::StopReason::LambdaRange);
    // the touch: located where the test's own gap of the pair is zero, at the same load in any units
    const int e = t.contact[0][1].firstPoint - 1;
    const double Mc = b.points[size_t(e)].lambda / torqueUnit;
    CHECK(std::abs(testGap(hook.chain, b.points[size_t(e)].u.head(8), c)) < 1e-10 * sL);
    if (reference == 0.0) reference = Mc;
    CHECK(Mc == Approx(reference).epsilon(1e-9));
    // every held point: on the edge, pushing, in equilibrium by the test's own statics, and the
    // library's force the same
    mech::ContactProblem problem(hook.problem, held);
    auto ws = problem.createWorkspace();
    int heldPoints = 0;
    for (size_t i = size_t(e) + 1; i < b.points.size(); ++i, ++heldPoints) {
      const VectorXd q = b.points[i].u.head(8);
      const double Me = b.points[i].lambda;
      CHECK(std::abs(testGap(hook.chain, q, c)) < 1e-9 * sL);
      const auto [imbalance, mu] = hookStatics(hook.chain, q, Me, c);
      CHECK(imbalance < 1e-9 * torqueUnit);
      CHECK(mu > 0.0);
      CHECK(problem.selfForces(*ws, b.points[i].u, Me)[0] == Approx(mu).epsilon(1e-7));
    }
    CHECK(heldPoints >= 3);
    // back down from the range end: the contact releases at the load where it began (SR at Mc)
    const cont::ContinuationPoint& last = b.points.back();
    const std::unique_ptr<mech::ContactProblem> stretch = mech::lockedProblem(hook.problem, held, 10.0);
    cont::TracerOptions down = o.tracer;
    down.lambdaMin = 0.0;
    cont::Tracer tracer(*stretch, down);
    cont::Branch back = tracer.trace(stretch->withWallForces(*stretch->createWorkspace(), last.u, last.lambda), last.lambda,
                                     cont::InitialDirection::decreasingLambda());
    const std::vector<mech::ContactStretch> stretches = mech::continueUnderContact(hook.problem, back, down, 10.0, held);
    REQUIRE(stretches.size() == 2);
    CHECK(stretches[1].locked.empty());
    const double released = back.points[size_t(stretches[1].firstPoint - 1)].lambda / torqueUnit;
    CHECK(released == Approx(Mc).epsilon(1e-9));
    CHECK(back.stopReason == cont::StopReason::LambdaRange);
  }
}

TEST_CASE("self contact: the loaded stiffness of the held hook against differences of its equilibria", "[self_contact]") {
  namespace cont = buckle::continuation;
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    Hook hook(sL, sK);
    const double forceUnit = sK * sL;
    const mech::EquilibriumBranchOptions o = hook.upTo(0.25);
    const mech::EquilibriumBranches t = hook.trace(o);
    REQUIRE(t.contact[0].size() == 2);
    const mech::ContactSet& held = t.contact[0][1].locked;
    const cont::ContinuationPoint& p = t.tree.branches[0].points.back();
    const mech::ContactProblem problem(hook.problem, held);
    const mech::CartesianStiffness K = mech::denseContactStiffness(problem, p.u, p.lambda);
    REQUIRE(K.compliance.allFinite());
    CHECK(K.negativeDirections == 0);
    CHECK_FALSE(K.rotationHeld);
    // C_F column c: the end's displacement per force δF e_c, the contact kept, by central
    // differences of the constrained equilibria under the end wrench (±δ e_c, 0, Me)
    const double delta = 1e-5 * forceUnit;
    for (int c = 0; c < 2; ++c) {
      Eigen::Vector2d moved[2];
      for (int side = 0; side < 2; ++side) {
        Eigen::Vector3d wrench = Eigen::Vector3d::Zero();
        wrench[c] = side == 0 ? delta : -delta;
        mech::EquilibriumProblem pushed(hook.chain, mech::EndCondition::freeEnd(wrench), Eigen::Vector3d(0, 0, 1),
                                        Hook::options());
        const mech::ConstrainedEquilibrium e = mech::solveConstrainedEquilibrium(pushed, held, p.u, p.lambda);
        REQUIRE(e.converged);
        moved[side] = buckle::test::geometry(hook.chain, e.u.head(8)).end;
      }
      const Eigen::Vector2d column = (moved[0] - moved[1]) / (2 * delta);
      for (int r = 0; r < 2; ++r) CHECK(K.compliance(r, c) == Approx(column[r]).epsilon(1e-6).margin(1e-9 * sL / forceUnit));
    }
    CHECK((K.stiffness * K.compliance - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("self contact: natural frequencies of the held hook against a generalized eigen-solve, in any units",
          "[self_contact][vibration]") {
  namespace cont = buckle::continuation;
  double reference = 0.0;
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}, std::pair{1e-4, 1e8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    Hook hook(sL, sK);
    const mech::EquilibriumBranches t = hook.trace(hook.upTo(0.25));
    REQUIRE(t.contact[0].size() == 2);
    const mech::ContactSet& held = t.contact[0][1].locked;
    const cont::ContinuationPoint& p = t.tree.branches[0].points.back();
    const mech::ContactProblem problem(hook.problem, held);
    auto ws = problem.createWorkspace();
    const VectorXd u = problem.withWallForces(*ws, p.u, p.lambda);
    const VectorXd q = u.head(8), mu = problem.contactForces(*ws, p.u, p.lambda);
    // uniform rods of unit mass per length: ω² scales as k / (ρ b)
    mech::VibrationAnalysis va(hook.chain, mech::InertiaData::uniformRods(hook.chain, 1.0));
    const mech::VibrationModes m = va.modes(q, mech::Wrench(0.0, 0.0, p.lambda), {}, held, mu, 4, true);
    REQUIRE(m.dimension == 7);  // eight joints, one contact row
    // the same pencil from the continuation's own constrained operator: H with −μ ∂²g, C with ∇gᵀ
    Eigen::MatrixXd H, C, M(8, 8);
    REQUIRE(problem.stabilityOperator(*ws, u, p.lambda, H, C));
    va.massMatrix(q, M);
    const Eigen::MatrixXd Z = Eigen::FullPivLU<Eigen::MatrixXd>(C).kernel();
    REQUIRE(Z.cols() == 7);
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> pencil(Z.transpose() * H * Z,
                                                                          Z.transpose() * M * Z);
    const double scale = pencil.eigenvalues().cwiseAbs().maxCoeff();
    for (int i = 0; i < 4; ++i) CHECK(std::abs(m.omegaSquared[i] - pencil.eigenvalues()[i]) < 1e-10 * scale);
    CHECK(m.omegaSquared[0] > 0.0);  // the held hook is stable
    // each shape keeps the contact (∇g·v = 0) and solves H v = ω² M v on it
    for (int i = 0; i < 4; ++i) {
      const VectorXd v = m.shapes.col(i);
      CHECK(std::abs(C.row(0).dot(v)) < 1e-10 * C.row(0).norm() * v.norm());
      const VectorXd r = Z.transpose() * (H * v - m.omegaSquared[i] * M * v);
      CHECK(r.norm() < 1e-9 * scale * (M * v).norm());
    }
    // without the contact's row and its −μ ∂²g the lowest frequency is another one
    const mech::VibrationModes free = va.modes(q, mech::Wrench(0.0, 0.0, p.lambda), {}, std::vector<int>{}, 1, false);
    CHECK(std::abs(free.omegaSquared[0] - m.omegaSquared[0]) > 1e-3 * m.omegaSquared[0]);
    const double invariant = m.omegaSquared[0] * sL / sK;
    if (reference == 0.0) reference = invariant;
    CHECK(invariant == Approx(reference).epsilon(1e-8));
  }
}

TEST_CASE("self contact: a vertex at its edge's corner is pinned there on both edges and leaves along one",
          "[self_contact]") {
  namespace cont = buckle::continuation;
  // fifty segments, the last forty curled by 4.5/40 rad: the end's corner reaches the straight
  // part, slides along link 9 to its corner, is pinned there, slides on along the link's other
  // edge and reaches the joint, where the branch ends (a vertex at a joint is not followed)
  for (const auto& [sL, sK] : {std::pair{1.0, 1.0}, std::pair{1e4, 1e-8}}) {
    INFO("lengths x" << sL << ", stiffnesses x" << sK);
    const int n = 50;
    VectorXd q0 = VectorXd::Zero(n);
    q0.tail(40).setConstant(4.5 / 40);
    const mech::Chain chain(mech::preloadsForShape(
        std::vector<mech::SegmentParameters>(size_t(n), mech::SegmentParameters::symmetric(0.3 * sL, sL, sK, 2.25 * sL)), q0));
    mech::EquilibriumProblem problem(chain, mech::EndCondition::freeEnd(), Eigen::Vector3d(0, 0, 1), Hook::options());
    mech::EquilibriumBranchOptions o;
    o.tracer.lambdaMax = 0.03 * sK * sL * sL;
    o.tracer.step.initialStep = 0.01;
    o.tracer.step.maxStep = 0.02;
    o.tree.branchSwitching = 0;
    const mech::EquilibriumBranches t =
        mech::traceEquilibria(problem, q0, 0.0, cont::InitialDirection::increasingLambda(), o);
    const cont::Branch& b = t.tree.branches[0];
    const std::vector<mech::ContactStretch>& stretches = t.contact[0];
    int pins = 0, slides = 0;
    for (size_t k = 0; k < stretches.size(); ++k) {
      const mech::ContactSet& held = stretches[k].locked;
      const size_t first = size_t(stretches[k].firstPoint), last = k + 1 < stretches.size()
                                                                       ? size_t(stretches[k + 1].firstPoint)
                                                                       : b.points.size();
      mech::ContactProblem stretch(problem, held);
      auto ws = stretch.createWorkspace();
      for (size_t i = first; i < last; ++i) {
        const VectorXd q = b.points[i].u.head(n);
        // no two links pass into each other anywhere on the branch, but for a second vertex of a
        // pair of links already holding a contact (not traced: self_contact.h)
        CHECK(mech::selfClearanceApart(chain, q, held.self()) >= -1e-9 * sL);
        const VectorXd mu = stretch.selfForces(*ws, b.points[i].u, b.points[i].lambda);
        for (int c = 0; c < held.selfCount(); ++c) {
          const mech::SelfContact& contact = held.self()[size_t(c)];
          CHECK(std::abs(testGap(chain, q, contact)) < 1e-9 * sL);
          CHECK(mu[c] > -1e-12 * sK * sL);
          if (!mech::heldAtCorner(chain, contact, held.self())) continue;
          // pinned: the vertex at the corner the two edges share
          ++pins;
          mech::SelfContact other;
          REQUIRE(mech::cornerNeighbour(chain, contact, other));
          const Vector2d p = buckle::test::vertexAt(chain, q, contact.vertex);
          double nearest = std::numeric_limits<double>::infinity();
          for (int e = 0; e < 2; ++e)
            for (int f = 0; f < 2; ++f)
              if (buckle::test::vertexAt(chain, q, {contact.edge.segment, contact.edge.corner(e)})
                      .isApprox(buckle::test::vertexAt(chain, q, {other.edge.segment, other.edge.corner(f)}), 1e-12))
                nearest = std::min(nearest, (p - buckle::test::vertexAt(chain, q, {contact.edge.segment, contact.edge.corner(e)})).norm());
          CHECK(nearest < 1e-9 * sL);
        }
      }
      // a stretch that leaves a pin along one edge: its vertex moves away from the shared corner
      if (k == 0 || held.selfCount() == 0) continue;
      const mech::ContactSet& before = stretches[k - 1].locked;
      for (const mech::SelfContact& c : before.self())
        if (mech::heldAtCorner(chain, c, before.self()) && !held.holding(c) && last > first + 1) ++slides;
    }
    CHECK(pins >= 2);
    CHECK(slides >= 1);
    // past the corner (at Me = 0.0166 k b², where the vertex once chattered between the two edges
    // and the branch ended as a false closed loop) to the joint
    double reached = 0.0;
    for (const cont::ContinuationPoint& p : b.points) reached = std::max(reached, p.lambda);
    CHECK(reached > 0.0171 * sK * sL * sL);
    CHECK(b.stopReason != cont::StopReason::ClosedLoop);
  }
}

TEST_CASE("self contact: a time limit or signal at the contact event ends the branch interrupted, not finished",
          "[self_contact]") {
  // the interrupt raised on the step that lands on SH: the branch must not end there as if the
  // contact boundary were a regular end
  namespace cont = buckle::continuation;
  Hook hook(1.0, 1.0);
  mech::EquilibriumBranchOptions o = hook.upTo(0.25);
  std::atomic<bool> stop{false};
  o.tracer.interrupt.watch(&stop, "signal");
  o.tracer.onStep = [&stop, &hook](const cont::StepInfo& step) {  // the step landed on the touch
    if (mech::selfClearance(hook.chain, step.point.u.head(8)).distance < 1e-9) stop = true;
    return cont::StepAction::Continue;
  };
  const mech::EquilibriumBranches t = hook.trace(o);
  REQUIRE(stop);
  const cont::Branch& b = t.tree.branches[0];
  CHECK(b.stopReason == cont::StopReason::Interrupted);
  CHECK(b.points.back().lambda < 0.25);
}
