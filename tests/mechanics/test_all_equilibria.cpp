#include <catch2/catch.hpp>

#include <Eigen/QR>
#include <cmath>
#include <random>

#include "buckle/mechanics/all_equilibria.h"
#include "buckle/mechanics/dynamics.h"
#include "buckle/mechanics/energy_landscape.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/mirror_symmetry.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

// The chain's own units (EquilibriumProblem::lengthUnit/stiffnessUnit), for relative tolerances.
struct Units {
  double length, torque;
};
Units unitsOf(const Chain& chain, const EndCondition& end) {
  const EquilibriumProblem p(chain, end, Eigen::Vector3d::Zero());
  return {p.lengthUnit(), p.stiffnessUnit() * p.lengthUnit() * p.lengthUnit()};
}

// Index of the equilibrium of `r` at q (max |Δq_i| <= tol), −1 when none.
int find(const AllEquilibria& r, const Vector& q, double tol) {
  for (size_t k = 0; k < r.equilibria.size(); ++k)
    if ((r.equilibria[k].q - q).lpNorm<Eigen::Infinity>() <= tol) return int(k);
  return -1;
}

// Independent check of an equilibrium: ∂Π/∂q = ∂E/∂q − JᵀF with the whole end wrench (chain.h),
// the held coordinates at their values, in the chain's units.
double independentResidual(const Chain& chain, const EndCondition& end, const FoundEquilibrium& e) {
  const Units u = unitsOf(chain, end);
  Vector g(chain.size());
  totalPotentialGradient(chain, e.q, e.wrench, g);
  double r = g.lpNorm<Eigen::Infinity>() / u.torque;
  const Pose p = endPose(chain, e.q);
  for (int c : end.heldIndices()) r = std::max(r, std::abs(p[c] - end.value[c]) / (c == 2 ? 1.0 : u.length));
  for (int c : end.loadedIndices()) r = std::max(r, std::abs(e.wrench[c] - end.value[c]) / (c == 2 ? u.torque : u.torque / u.length));
  return r;
}

// Plain damped Newton on the equilibrium equations from one shape, written here apart from the
// library's solver: the brute-force search. True with u at a root to 1e-12 of the chain's units.
bool plainNewton(EquilibriumProblem& problem, Vector& u) {
  const int N = problem.dimension();
  const Vector scale = problem.scales().residuals;
  Vector F(N), Ft(N), Fl(N);
  Matrix Fu(N, N);
  auto norm = [&](const Vector& v, Vector& out) {
    return buckle::continuation::BoundProblem(problem).residual(v, 0.0, out)
               ? (out.array() / scale.array()).abs().maxCoeff()
               : INFINITY;
  };
  double r = norm(u, F);
  for (int it = 0; it < 100 && std::isfinite(r); ++it) {
    if (r < 1e-12) return true;
    if (!buckle::continuation::BoundProblem(problem).jacobian(u, 0.0, Fu, Fl)) return false;
    Vector du = -Fu.colPivHouseholderQr().solve(F);
    if (du.head(problem.segments()).lpNorm<Eigen::Infinity>() > 0.5)
      du *= 0.5 / du.head(problem.segments()).lpNorm<Eigen::Infinity>();
    double alpha = 1.0, rt = INFINITY;
    for (; alpha > 1e-4; alpha *= 0.5)
      if ((rt = norm(u + alpha * du, Ft)) < r) break;
    if (!(rt < r)) return false;
    u += alpha * du;
    r = norm(u, F);
  }
  return r < 1e-12;
}

bool inLimits(const Chain& chain, const Vector& q) {
  return (q.array() >= chain.lowerLimits().array()).all() && (q.array() <= chain.upperLimits().array()).all();
}

// Brute force: plain Newton from every shape; every root found within the limits must be listed.
// Returns the number of distinct roots it found.
int bruteForce(const Chain& chain, const EndCondition& end, const AllEquilibria& listed,
               const std::vector<Vector>& shapes) {
  EquilibriumOptions eo;
  eo.jointLimitsAsBoundaries = false;
  EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero(), eo);
  std::vector<Vector> distinct;
  for (const Vector& q0 : shapes) {
    Vector u = problem.initialGuess(q0, 0.0);
    if (!plainNewton(problem, u) || !inLimits(chain, u.head(chain.size()))) continue;
    INFO("brute-force root q = " << u.head(chain.size()).transpose());
    CHECK(find(listed, u.head(chain.size()), 1e-7) >= 0);
    bool seen = false;
    for (const Vector& d : distinct) seen = seen || (d - u.head(chain.size())).lpNorm<Eigen::Infinity>() < 1e-7;
    if (!seen) distinct.push_back(u.head(chain.size()));
  }
  return int(distinct.size());
}

std::vector<Vector> randomShapes(const Chain& chain, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vector> shapes;
  for (int k = 0; k < count; ++k) {
    Vector q(chain.size());
    for (int i = 0; i < chain.size(); ++i)
      q[i] = chain.lowerLimits()[i] + (chain.upperLimits()[i] - chain.lowerLimits()[i]) * unit(rng);
    shapes.push_back(q);
  }
  return shapes;
}

void checkAllAccurate(const Chain& chain, const EndCondition& end, const AllEquilibria& r, double tolerance) {
  for (const FoundEquilibrium& e : r.equilibria) {
    INFO("q = " << e.q.transpose());
    CHECK(e.accuracy <= tolerance);
    CHECK(independentResidual(chain, end, e) <= 10.0 * tolerance);
    CHECK(inLimits(chain, e.q));
    CHECK(e.stable == (e.index == 0 && e.zeroEigenvalues == 0));
  }
  for (size_t k = 1; k < r.equilibria.size(); ++k) CHECK(r.equilibria[k - 1].potential <= r.equilibria[k].potential);
}

}  // namespace

TEST_CASE("n = 3, end held at (5.5b, 0): the sweep's equilibria one-to-one, deflation alone finds the same set",
          "[all_equilibria]") {
  // The paper's straight chain (Fig 4, data/scenes/fig4.json) with the end moved in by b/2.
  for (const auto& [a, L0] : std::vector<std::pair<double, double>>{{0.5, 2.25}, {0.5, 3.0}, {0.3, 1.5}}) {
    INFO("a = " << a << ", L0 = " << L0);
    const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(a, 1.0, 1.0, L0));
    const EndCondition end = EndCondition::heldPosition(5.5, 0.0);
    AllEquilibriaOptions options;
    options.landscapeStarts = false;  // deflation on its own: the sweep only compared
    const AllEquilibria r = allEquilibria(chain, end, options);
    LandscapeOptions lo;
    lo.samples = 4001;
    const EnergyLandscape land = energyLandscape(chain, 5.5, 0.0, lo);
    REQUIRE(r.equilibria.size() == land.equilibria.size());
    CHECK(r.sweepCount == int(land.equilibria.size()));
    int stable = 0;
    for (const LandscapeEquilibrium& e : land.equilibria) {
      const int k = find(r, e.q, 1e-10);
      REQUIRE(k >= 0);
      const FoundEquilibrium& f = r.equilibria[size_t(k)];
      CHECK(f.stable == e.stable);
      CHECK(f.byDeflation);
      CHECK(f.bySweep);
      CHECK(f.shape == e.shape);
      CHECK(std::abs(f.potential - e.energy) <= 1e-12 * std::abs(e.energy));
      CHECK((f.wrench.head(2) - e.F.head(2)).norm() <= 1e-8 * (1.0 + e.F.norm()));
      stable += e.stable;
    }
    CHECK(r.deflationOnly == 0);
    CHECK(r.sweepOnly == 0);
    checkAllAccurate(chain, end, r, 1e-10);
    REQUIRE(r.morse.applies);
    CHECK(r.morse.holds());
    if (a == 0.5) {
      // monotonic segments (κ > 0): two U minima and two Z maxima on one closed curve (Table I)
      CHECK(r.equilibria.size() == 4);
      CHECK(stable == 2);
      CHECK(r.morse.loops == 1);
      CHECK(r.morse.arcs == 0);
      CHECK(r.equilibria[0].shape == "U");
      CHECK(r.equilibria[3].shape == "Z");
    } else {
      // non-monotonic (κ < 0): eight, four stable, the reversed Table I of erratum 8 among them
      CHECK(r.equilibria.size() == 8);
      CHECK(stable == 4);
    }
  }
}

TEST_CASE("n = 3, end held, with the links' weight: the sweep of E + V and deflation find the same set, Morse holds",
          "[all_equilibria][body_loads]") {
  // the paper's chain as uniform rods under a tilted g (docs/mechanics.md, eq B1-B3): the sweep
  // along the configuration curve and deflated Newton on the full equations are two independent
  // searches of the same weighted equilibria
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  for (const double weight : {0.02, 0.08}) {
    INFO("mass per length " << weight);
    AllEquilibriaOptions options;
    options.landscapeStarts = false;  // deflation on its own: the sweep only compared
    options.body = BodyLoads::weight(chain, InertiaData::uniformRods(chain, weight), {0.5, -0.866}, {0.0, 0.0});
    const EndCondition end = EndCondition::heldPosition(5.5, 0.4);
    const AllEquilibria r = allEquilibria(chain, end, options);
    REQUIRE(r.sweepCount >= 2);
    CHECK(r.sweepCount == int(r.equilibria.size()));
    CHECK(r.deflationOnly == 0);
    CHECK(r.sweepOnly == 0);
    REQUIRE(r.morse.applies);
    CHECK(r.morse.holds());
    for (const FoundEquilibrium& f : r.equilibria) {
      CHECK(f.byDeflation);
      CHECK(f.bySweep);
    }
  }
}

TEST_CASE("n = 3, end held: over a grid of end positions the Morse count holds and deflation adds nothing",
          "[all_equilibria]") {
  // tall-gap triangles (a/b = 0.2), non-monotonic segments: up to eight equilibria
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.2, 1.0, 1.0, 1.5));
  int cases = 0, withArcs = 0, sixOrMore = 0;
  for (double x = 1.0; x <= 5.5; x += 0.9)
    for (double y = 0.0; y <= 2.0; y += 0.7) {
      INFO("x = " << x << ", y = " << y);
      AllEquilibriaOptions options;
      options.randomStarts = 32;
      const AllEquilibria r = allEquilibria(chain, EndCondition::heldPosition(x, y), options);
      CHECK(r.deflationOnly == 0);  // nothing the complete sweep missed
      CHECK(r.sweepUnresolved == 0);
      if (r.morse.applies) {
        CHECK(r.morse.holds());
        ++cases;
        withArcs += r.morse.arcs > 0;
      }
      sixOrMore += r.equilibria.size() >= 6;
    }
  CHECK(cases >= 15);
  CHECK(withArcs >= 1);
  CHECK(sixOrMore >= 1);
}

TEST_CASE("n = 4 and 5 under a load: every listed equilibrium is one, and brute force finds none outside the list",
          "[all_equilibria]") {
  SECTION("n = 4 cantilever, inclined end force: a dense grid of Newton starts") {
    const Chain chain = Chain::uniform(4, SegmentParameters::symmetric(0.4, 1.0, 1.0, 2.0));
    const EndCondition end = EndCondition::freeEnd(Wrench(-0.6, 0.15, 0.0));
    const AllEquilibria r = allEquilibria(chain, end);
    REQUIRE(!r.equilibria.empty());
    checkAllAccurate(chain, end, r, 1e-10);
    std::vector<Vector> grid;
    const int m = 7;
    for (int k = 0; k < m * m * m * m; ++k) {
      Vector q(4);
      for (int i = 0, rest = k; i < 4; ++i, rest /= m)
        q[i] = chain.lowerLimits()[i] + (chain.upperLimits()[i] - chain.lowerLimits()[i]) * (rest % m + 0.5) / m;
      grid.push_back(q);
    }
    CHECK(bruteForce(chain, end, r, grid) >= 1);
  }
  SECTION("n = 5 clamped-pinned past the second critical load: many random Newton starts") {
    const Chain chain = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    const EndCondition end = EndCondition::clampedPinned(-0.9);
    const AllEquilibria r = allEquilibria(chain, end);
    REQUIRE(r.equilibria.size() >= 3);  // the straight shape and a mirror pair at least
    checkAllAccurate(chain, end, r, 1e-10);
    CHECK(find(r, Vector::Zero(5), 1e-12) >= 0);
    CHECK(bruteForce(chain, end, r, randomShapes(chain, 3000, 11)) >= 3);
  }
}

TEST_CASE("n = 5 clamped-pinned: every equilibrium continuation reaches at the load is in the list",
          "[all_equilibria]") {
  const Chain chain = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const double Fx = -0.9;
  EquilibriumProblem traced(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  EquilibriumBranchOptions opt;
  opt.tracer.lambdaMin = Fx - 0.2;
  opt.tracer.lambdaMax = 0.0;
  opt.tracer.step.maxStep = 0.05;
  opt.tree.branchSwitching = 2;
  const EquilibriumBranches tree =
      traceEquilibria(traced, Vector::Zero(5), 0.0, cont::InitialDirection::decreasingLambda(), opt);
  const EndCondition end = EndCondition::clampedPinned(Fx);
  const AllEquilibria r = allEquilibria(chain, end);
  EquilibriumOptions eo;
  eo.jointLimitsAsBoundaries = false;
  EquilibriumProblem atLoad(chain, end, Eigen::Vector3d::Zero(), eo);
  int crossings = 0;
  for (const cont::Branch& b : tree.tree.branches)
    for (size_t k = 1; k < b.points.size(); ++k) {
      const cont::ContinuationPoint &p = b.points[k - 1], &n = b.points[k];
      if ((p.lambda - Fx) * (n.lambda - Fx) > 0.0 || p.lambda == n.lambda) continue;
      const double t = (Fx - p.lambda) / (n.lambda - p.lambda);
      Vector u = p.u + t * (n.u - p.u);  // on the branch to second order in the step; then corrected
      if (!plainNewton(atLoad, u) || !inLimits(chain, u.head(5))) continue;
      INFO("branch " << b.id << " at Fx = " << Fx << ": q = " << u.head(5).transpose());
      CHECK(find(r, u.head(5), 1e-7) >= 0);
      ++crossings;
    }
  CHECK(crossings >= 3);  // the straight branch and the bifurcated ones
}

TEST_CASE("symmetric chain: the mirror image of every equilibrium is in the list", "[all_equilibria]") {
  const Chain chain = Chain::uniform(5, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  for (const EndCondition& end : {EndCondition::clampedPinned(-0.9), EndCondition::freeEnd(Wrench(-0.3, 0.0, 0.0))}) {
    const EquilibriumProblem problem(chain, end, Eigen::Vector3d::Zero());
    const cont::Reflection mirror = mirrorSymmetry(problem);
    REQUIRE(mirror.enabled());
    const AllEquilibria r = allEquilibria(chain, end);
    REQUIRE(!r.equilibria.empty());
    for (const FoundEquilibrium& e : r.equilibria) {
      Vector u(problem.dimension());
      u << e.q, e.reactions;
      mirror.apply(u);
      const int k = find(r, u.head(5), 1e-8);
      INFO("q = " << e.q.transpose());
      REQUIRE(k >= 0);
      const FoundEquilibrium& image = r.equilibria[size_t(k)];
      CHECK((image.reactions - u.tail(problem.heldCount())).norm() <= 1e-8 * (1.0 + e.reactions.norm()));
      CHECK(image.index == e.index);
      CHECK(std::abs(image.potential - e.potential) <= 1e-12 * (1.0 + std::abs(e.potential)));
    }
  }
}

TEST_CASE("scaled units (lengths x1e4, stiffness x1e-8): the same set, scaled", "[all_equilibria]") {
  const double Ls = 1e4, Ks = 1e-8;
  auto segment = [](double s, double k) { return SegmentParameters::symmetric(0.4 * s, s, k, 2.0 * s); };
  const Chain base = Chain::uniform(4, segment(1.0, 1.0)), scaled = Chain::uniform(4, segment(Ls, Ks));
  const Wrench F(-0.6, 0.15, 0.02);  // force k b, torque k b²
  const Wrench Fs(F[0] * Ks * Ls, F[1] * Ks * Ls, F[2] * Ks * Ls * Ls);
  for (bool held : {false, true}) {
    EndCondition e1 = EndCondition::freeEnd(F), e2 = EndCondition::freeEnd(Fs);
    if (held) {  // x, y held, Me given: reactions as unknowns, positions scaled
      e1 = EndCondition::heldPosition(5.0, 2.0);
      e2 = EndCondition::heldPosition(5.0 * Ls, 2.0 * Ls);
      e1.value[2] = F[2];
      e2.value[2] = Fs[2];
    }
    const AllEquilibria a = allEquilibria(base, e1), b = allEquilibria(scaled, e2);
    INFO("held " << held);
    REQUIRE(!a.equilibria.empty());
    REQUIRE(a.equilibria.size() == b.equilibria.size());
    for (size_t k = 0; k < a.equilibria.size(); ++k) {
      const FoundEquilibrium &x = a.equilibria[k], &y = b.equilibria[k];
      CHECK((x.q - y.q).lpNorm<Eigen::Infinity>() <= 1e-8);
      CHECK(x.index == y.index);
      CHECK(std::abs(y.potential / (Ks * Ls * Ls) - x.potential) <= 1e-9 * (1.0 + std::abs(x.potential)));
      CHECK((y.pose.head(2) / Ls - x.pose.head(2)).norm() <= 1e-9);
      CHECK(y.accuracy <= 1e-10);
    }
    CHECK(a.starts == b.starts);
  }
}

TEST_CASE("options: bad values are named, an interrupt keeps what was found", "[all_equilibria]") {
  const Chain chain = Chain::uniform(3, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
  const EndCondition end = EndCondition::freeEnd(Wrench(-0.2, 0.0, 0.0));
  AllEquilibriaOptions o;
  o.tolerance = 0.0;
  CHECK_THROWS_WITH(allEquilibria(chain, end, o), Catch::Contains("tolerance"));
  o = AllEquilibriaOptions{};
  o.starts.push_back(Vector::Zero(4));
  CHECK_THROWS_WITH(allEquilibria(chain, end, o), Catch::Contains("starts[0]") && Catch::Contains("3"));
  o = AllEquilibriaOptions{};
  o.randomStarts = -1;
  CHECK_THROWS_WITH(allEquilibria(chain, end, o), Catch::Contains("randomStarts"));
  std::atomic<bool> stop{true};
  o = AllEquilibriaOptions{};
  o.interrupt.watch(&stop, "stop asked");
  const AllEquilibria r = allEquilibria(chain, end, o);
  CHECK(r.interrupted);
  CHECK(r.stopReason == "stop asked");
  CHECK(r.starts == 0);
}
