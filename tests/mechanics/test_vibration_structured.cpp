// The structured O(n) route of the vibration analysis (vibration_structured.cpp) against the dense
// route: free, held and locked, with the links' weight, at stable and unstable points, in extreme
// units; ω² through zero at located branch points and folds of a long chain; the automatic choice.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/contact.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/vibration.h"
#include "critical_loads.h"
#include "test_chains.h"
#include "sanitized_build.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

using testing::stiffChain;

InertiaData periodicInertia(const Chain& chain, double massScale) {
  InertiaData inertia;
  const int n = chain.size();
  const double L = chain.linkLengths()[1];
  for (int i = 0; i < n; ++i)
    inertia.links.push_back({massScale * (0.5 + 0.1 * (i % 5)), massScale * L * L * (0.01 + 0.002 * (i % 7)),
                             0.3 * chain.linkLengths()[i + 1]});
  return inertia;
}

// Both routes on the same analysis; values within `tol` of the spectrum's scale, shapes M-orthonormal
// and equal up to the sign convention (both sign the largest component positive).
struct Agreement {
  double values = 0.0;  // max |ω²_s − ω²_d| / max |ω²_d|
  double shapes = 0.0;  // max ‖v_s − v_d‖ / ‖v_d‖
  double shapesPerGap = 0.0;  // the same in units of ε·max|ω²|/gap, the eigenvectors' own accuracy
  int negative = 0;     // ω²_d < 0 among those compared
};

Agreement compareRoutes(VibrationAnalysis& va, const Vector& q, const Wrench& F, const std::vector<int>& held,
                        const std::vector<int>& locked, int count, const Vector& gamma = Vector()) {
  va.setRoute(VibrationRoute::Dense);
  const VibrationModes d = va.modes(q, F, held, locked, count, true, gamma);
  va.setRoute(VibrationRoute::Structured);
  const VibrationModes s = va.modes(q, F, held, locked, count, true, gamma);
  va.setRoute(VibrationRoute::Automatic);
  REQUIRE(d.route == VibrationRoute::Dense);
  REQUIRE(s.route == VibrationRoute::Structured);
  CHECK(s.fallback.empty());
  REQUIRE(s.dimension == d.dimension);
  REQUIRE(s.omegaSquared.size() == d.omegaSquared.size());
  Agreement a;
  if (d.omegaSquared.size() == 0) return a;
  // the dense route's whole spectrum sets the scale of the comparison
  const Vector all = va.modes(q, F, held, locked, d.dimension, false, gamma).omegaSquared;
  const double scale = all.cwiseAbs().maxCoeff();
  const int n = int(q.size());
  Matrix M(n, n);
  va.massMatrix(q, M);
  for (int j = 0; j < d.omegaSquared.size(); ++j) {
    a.values = std::max(a.values, std::abs(s.omegaSquared[j] - d.omegaSquared[j]) / scale);
    a.negative += d.omegaSquared[j] < 0 ? 1 : 0;
    // simple, well separated ω² here: the shapes agree up to rounding
    const double shape = (s.shapes.col(j) - d.shapes.col(j)).norm() / d.shapes.col(j).norm();
    a.shapes = std::max(a.shapes, shape);
    double gap = scale;  // a single mode: its vector is fixed to rounding
    for (Eigen::Index k = 0; k < all.size(); ++k)
      if (k != j) gap = std::min(gap, std::abs(all[k] - d.omegaSquared[j]));
    a.shapesPerGap = std::max(a.shapesPerGap, shape / (std::numeric_limits<double>::epsilon() * scale / gap));
  }
  const Matrix G = s.shapes.transpose() * M * s.shapes;
  CHECK((G - Matrix::Identity(G.rows(), G.cols())).norm() <= 1e-9);
  // the mode equation on ker C: H v − ω² M v ⟂ ker C (H with the body loads' Γ, eq B3)
  Matrix H(n, n);
  totalPotentialHessian(va.chain(), q, F, H);
  addBodyLoadHessian(gamma, H);
  const Matrix C = va.constraintRows(q, held, locked);
  const Matrix R = H * s.shapes - M * s.shapes * s.omegaSquared.asDiagonal();
  const Matrix Z = Eigen::FullPivLU<Matrix>(C.rows() ? C : Matrix::Zero(1, n)).kernel();
  const Matrix Zo = Eigen::HouseholderQR<Matrix>(Z).householderQ() * Matrix::Identity(n, Z.cols());
  CHECK((Zo.transpose() * R).norm() <= 1e-11 * H.norm() * s.shapes.norm());
  CHECK((C * s.shapes).norm() <= 1e-12 * s.shapes.norm() * std::max(1.0, C.norm()));
  for (int j : locked) CHECK(s.shapes.row(j).norm() == 0.0);
  return a;
}

}  // namespace

TEST_CASE("vibration structured: the O(n) route equals the dense route (free, held, locked, weight, stable and unstable)",
          "[vibration][vibration_structured]") {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  double worstValues = 0.0, worstShapes = 0.0, worstShapesPerGap = 0.0;
  int unstableCases = 0;
  const int large = buckle::test::kSanitizedBuild ? 100 : 300;  // (sanitized_build.h)
  for (int n : {3, 10, 60, large}) {
    const Chain chain = stiffChain(n);
    VibrationAnalysis va(chain, periodicInertia(chain, 1.0));
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = U(rng) * 3.0 / n;
    // a mild load (stable at small n) and a strong compression (several negative ω²)
    for (const Wrench& F : {Wrench(-0.3, 0.2, 0.1), Wrench(-40.0 / n, 0.5 / n, 0.0)}) {
      Vector gamma = Vector::Zero(n);
      for (int i = 0; i < n; ++i) gamma[i] = 0.01 * (n - i) / n;  // a body-load generator (γ of eq B3)
      for (const std::vector<int>& held : {std::vector<int>{}, {1}, {0, 1}, {0, 1, 2}}) {
        if (n == large && held.size() == 1) continue;  // (the dense references at the largest n dominate the cost)
        for (const std::vector<int>& locked :
             {std::vector<int>{}, n > 3 ? std::vector<int>{0, n / 2, n / 2 + 1, n - 1} : std::vector<int>{1}}) {
          for (bool weight : {false, true}) {
            INFO("n = " << n << ", Fx = " << F.x() << ", held " << held.size() << ", locked " << locked.size()
                        << ", weight " << weight);
            const int k = std::min(5, n);
            const Agreement a = compareRoutes(va, q, F, held, locked, k, weight ? gamma : Vector());
            CHECK(a.values <= 1e-11);
            // the dense route's vectors are accurate to ~ε‖spectrum‖/gap times a modest constant (its backward
            // error grows with n: Davis–Kahan)
            CHECK(a.shapesPerGap <= 1e4);
            worstShapesPerGap = std::max(worstShapesPerGap, a.shapesPerGap);
            worstValues = std::max(worstValues, a.values);
            worstShapes = std::max(worstShapes, a.shapes);
            if (a.negative >= 2) ++unstableCases;
          }
        }
      }
    }
  }
  CHECK(unstableCases >= 20);  // the compressed cases do have several negative ω²
  WARN("structured vs dense: values " << worstValues << " of the spectrum, shapes " << worstShapes << " ("
                                       << worstShapesPerGap << " eps |spectrum| / gap)");
}

TEST_CASE("vibration structured: extreme units (lengths x1e4 with stiffness x1e-8, x1e-4 with x1e8) agree with the dense "
          "route and scale omega^2 by k / L (rods: inertia ~ L^3)",
          "[vibration][vibration_structured]") {
  const int n = 60;
  const Vector q = Vector::LinSpaced(n, 0.02, -0.03);
  const Chain ref = stiffChain(n);
  VibrationAnalysis base(ref, InertiaData::uniformRods(ref, 1.0));
  base.setRoute(VibrationRoute::Structured);
  const Wrench F0(-0.05, 0.01, 0.0);
  const VibrationModes m0 = base.modes(q, F0, {1}, {7}, 4);
  for (const auto& [L, k] : {std::pair<double, double>{1e4, 1e-8}, {1e-4, 1e8}}) {
    INFO("L = " << L << ", k = " << k);
    const Chain chain = stiffChain(n, L, k);
    VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
    const Wrench F(F0.x() * k * L, F0.y() * k * L, 0.0);  // the same angles, loads ×kL (eq 17)
    const Agreement a = compareRoutes(va, q, F, {1}, {7}, 4);
    CHECK(a.values <= 1e-11);
    CHECK(a.shapes <= 1e-6);
    va.setRoute(VibrationRoute::Structured);
    const VibrationModes m = va.modes(q, F, {1}, {7}, 4);
    for (int j = 0; j < 4; ++j)
      CHECK(std::abs(m.omegaSquared[j] - m0.omegaSquared[j] * k / L) <= 1e-9 * std::abs(m0.omegaSquared[j] * k / L));
  }
}

TEST_CASE("vibration structured: omega^2 crosses zero at the located branch points and fold of a 100-segment chain",
          "[vibration][vibration_structured]") {
  const int n = 100;
  cont::TracerOptions o;
  o.maxPoints = 20000;
  SECTION("branch points of the compressed clamped-pinned column") {
    const Chain chain = stiffChain(n);
    const std::vector<double> crit = testing::compressiveCriticalLoads(chain);
    REQUIRE(crit.size() >= 2);
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
    o.lambdaMin = 0.5 * (crit[1] + crit[2]);
    o.lambdaMax = 0.0;
    o.step.initialStep = 0.05 * std::abs(crit[0]);
    o.step.maxStep = 0.2 * std::abs(crit[0]);
    o.step.minStep = 1e-6 * std::abs(crit[0]);
    const cont::Branch br = cont::trace(problem, Vector::Zero(n + 1), 0.0, cont::InitialDirection::decreasingLambda(), o);
    VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
    REQUIRE(n >= VibrationAnalysis::kStructuredFrom);  // the automatic route is the structured one
    const std::vector<int> held = problem.endCondition().heldIndices();
    const auto bps = br.specialPointsOfType(cont::SpecialPointType::BranchPoint);
    REQUIRE(bps.size() == 2);
    const VibrationModes whole = va.modes(Vector::Zero(n), Wrench::Zero(), held, {}, 1, false);
    for (const cont::SpecialPoint* sp : bps) {
      INFO("lambda = " << sp->lambda);
      const int index = std::min(sp->inertiaBefore, sp->inertiaAfter);
      const VibrationModes m = va.modes(sp->u.head(n), problem.wrench(sp->u, sp->lambda), held, {}, index + 2, false);
      REQUIRE(m.route == VibrationRoute::Structured);
      // zero to the location's accuracy: against the neighbouring ω², which is not
      CHECK(std::abs(m.omegaSquared[index]) <= 1e-8 * std::abs(m.omegaSquared[index + 1]));
      CHECK(std::abs(m.omegaSquared[index + 1]) > 1e-3 * whole.omegaSquared[0]);
    }
  }
}

TEST_CASE("vibration structured: a heavy tip (M_theta nearly of rank one): every omega^2, far above the pencil's diagonal "
          "scale, as the dense route, also from the previous call's values",
          "[vibration][vibration_structured]") {
  const int n = 70;
  const Chain chain = stiffChain(n);
  InertiaData inertia;
  for (int i = 0; i < n; ++i) {  // light rods and a heavy last link with its mass at the tip
    const double l = chain.linkLengths()[i + 1], m = i + 1 == n ? 1.0 : 0.03;
    inertia.links.push_back({m, i + 1 == n ? 0.0 : m * l * l / 12.0, i + 1 == n ? l : 0.5 * l});
  }
  VibrationAnalysis va(chain, inertia);
  const Vector q = Vector::LinSpaced(n, 0.01, -0.02);
  const Wrench F(-0.02, 0.001, 0.0);
  va.setRoute(VibrationRoute::Dense);
  const VibrationModes d = va.modes(q, F, {1}, {}, n, false);
  va.setRoute(VibrationRoute::Structured);
  const double scale = d.omegaSquared.cwiseAbs().maxCoeff();
  for (int call = 0; call < 2; ++call) {  // cold, then warm
    const VibrationModes s = va.modes(q, F, {1}, {}, n, false);
    REQUIRE(s.omegaSquared.size() == d.omegaSquared.size());
    // (M is ill-conditioned here: both routes are good to ~ε cond(M) of the spectrum, 4e-10 seen)
    CHECK((s.omegaSquared - d.omegaSquared).cwiseAbs().maxCoeff() <= 3e-9 * scale);
  }
}

TEST_CASE("vibration structured: omega^2 crosses zero at the located fold of a 100-segment chain (free end, lateral force)",
          "[vibration][vibration_structured]") {
  const int n = 100;
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 0.5));
  EquilibriumProblem problem(chain, EndCondition::freeEnd(Eigen::Vector3d(0, 0.001, 0)), Eigen::Vector3d(1, 0, 0));
  cont::TracerOptions o;
  o.maxPoints = 20000;
  o.lambdaMin = -0.3;
  o.lambdaMax = 0.3;
  o.step.initialStep = 0.003;
  o.step.maxStep = 0.015;
  o.step.minStep = 3e-7;
  const cont::Branch br = cont::trace(problem, Vector::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
  const auto folds = br.specialPointsOfType(cont::SpecialPointType::Fold);
  REQUIRE(folds.size() == 1);
  const cont::SpecialPoint& sp = *folds[0];
  VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
  const int index = std::min(sp.inertiaBefore, sp.inertiaAfter);
  INFO("fold at lambda = " << sp.lambda << ", inertia " << sp.inertiaBefore << " -> " << sp.inertiaAfter);
  const VibrationModes m = va.modes(sp.u.head(n), problem.wrench(sp.u, sp.lambda), {}, {}, n, false);
  REQUIRE(m.route == VibrationRoute::Structured);
  REQUIRE(index < n);
  const double scale = m.omegaSquared.cwiseAbs().maxCoeff();
  CHECK(std::abs(m.omegaSquared[index]) <= 1e-10 * scale);
  // the neighbours are not zero: the crossing one is isolated
  if (index > 0) CHECK(std::abs(m.omegaSquared[index - 1]) > 1e3 * std::abs(m.omegaSquared[index]));
  if (index + 1 < n) CHECK(std::abs(m.omegaSquared[index + 1]) > 1e3 * std::abs(m.omegaSquared[index]));
}

TEST_CASE("vibration structured: the automatic route is dense below kStructuredFrom joints and structured from it",
          "[vibration][vibration_structured]") {
  for (int n : {VibrationAnalysis::kStructuredFrom - 1, VibrationAnalysis::kStructuredFrom}) {
    const Chain chain = stiffChain(n);
    VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
    const VibrationModes m = va.modes(Vector::Zero(n), Wrench(-0.01, 0, 0), {1}, {}, 2);
    CHECK(m.route == (n >= VibrationAnalysis::kStructuredFrom ? VibrationRoute::Structured : VibrationRoute::Dense));
  }
  // bad input on the structured route: the same errors as the dense one
  const int n = 70;
  const Chain chain = stiffChain(n);
  VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
  CHECK_THROWS_AS(va.modes(Vector::Zero(n + 1), Wrench::Zero(), {}, {}, 1), std::invalid_argument);
  CHECK_THROWS_AS(va.modes(Vector::Zero(n), Wrench::Zero(), {}, {n}, 1), std::invalid_argument);
  CHECK_THROWS_AS(va.modes(Vector::Zero(n), Wrench::Zero(), {4}, {}, 1), std::invalid_argument);
}

TEST_CASE("vibration structured: at points holding self contacts the coupling bordered on the pencil gives the dense "
          "route's modes",
          "[vibration][vibration_structured]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> U(-0.6, 0.6);
  const int n = 80;
  const Chain chain = stiffChain(n);
  VibrationAnalysis va(chain, periodicInertia(chain, 1.0));
  Vector q(n);
  for (int i = 0; i < n; ++i) q[i] = U(rng) * 3.0 / n;
  const SelfContact a{{70, 3}, {20, true, 1}}, b{{10, 1}, {60, false, 2}};
  for (const Wrench& F : {Wrench(-0.3, 0.2, 0.1), Wrench(-40.0 / n, 0.5 / n, 0.0)})
    for (int contacts : {1, 2})
      for (bool locked : {false, true})
        for (const std::vector<int>& held : {std::vector<int>{}, {1}}) {
          INFO("Fx = " << F.x() << ", self contacts " << contacts << ", locked " << locked << ", held " << held.size());
          ContactSet set;
          set.hold(a);
          if (contacts == 2) set.hold(b);
          if (locked) set.lock(40, LimitSide::Upper);
          Vector forces(contacts);
          forces[0] = 0.7;
          if (contacts == 2) forces[1] = -0.4;  // one pulling: E's signs both ways
          va.setRoute(VibrationRoute::Dense);
          const VibrationModes d = va.modes(q, F, held, set, forces, 5, true);
          va.setRoute(VibrationRoute::Structured);
          const VibrationModes s = va.modes(q, F, held, set, forces, 5, true);
          va.setRoute(VibrationRoute::Automatic);
          REQUIRE(s.route == VibrationRoute::Structured);
          CHECK(s.fallback.empty());
          REQUIRE(s.dimension == d.dimension);
          REQUIRE(s.omegaSquared.size() == d.omegaSquared.size());
          const double scale = va.modes(q, F, held, set, forces, d.dimension, false).omegaSquared.cwiseAbs().maxCoeff();
          for (int j = 0; j < d.omegaSquared.size(); ++j) {
            CHECK(std::abs(s.omegaSquared[j] - d.omegaSquared[j]) <= 1e-11 * scale);
            CHECK((s.shapes.col(j) - d.shapes.col(j)).norm() <= 1e-6 * d.shapes.col(j).norm());
          }
        }
}
