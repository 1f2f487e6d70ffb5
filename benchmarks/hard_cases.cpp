// hard_cases: the hard-case suite of benchmarks/RESULTS.md (issue 6). One row per case:
// pass/fail, accuracy against an independent answer, in-process time.
//
//   hard_cases [--quick] [--n N] [--only PREFIX]
//     --quick     CI size: clustered loads at n = 30 and 60, κ = 0 at n = 3 and 4, joint limit at n = 10
//     --n N       size of the large clustered case (default 1000; the other one is n = 200)
//     --only P    run only the cases whose id starts with P (units, cluster, cluster.top.n1000, …)
//
// Cases (independent answers in brackets):
//  units.<case>.<L>x<k>.<default|nondim>  the n = 3 chain with lengths ×L and spring stiffnesses ×k;
//      loads scale as F₀ = k·L (eq 17: Fx = λ k [b L0 − 2(b² − a²)] / b), angles are unit-free.
//      bp:    trivial branch, both branch points [eq 17 in the scaled constants]
//      fold:  free end, L0 = 0.5, Fy = 0.01 F₀ (AUTO's I_up) [ref.py's extended-system Newton ×F₀]
//      limit: switch at the U branch point, stop at the user joint limit |q| = 1.5 (AUTO's A_U)
//             [the unscaled run ×F₀; the end angle must be 1.5]
//      default: solver options as for the unscaled chain (AUTO's c-file values), λ range ×F₀, on
//               the EquilibriumProblem itself: the library's default path, which works in the
//               chain's own units (EquilibriumProblem::scales(), continuation/scaled_problem.h)
//      nondim:  the same options on the NondimensionalProblem view (nondimensional.h), an
//               independent, outside change of variables (its scales() are ones, so the core
//               does not scale again)
//  cluster.low.n<N>  the first 6 critical loads of the clamped–pinned chain [linear_buckling]
//  cluster.top.n<N>  the 6 most compressive critical loads, spaced ~1/n² apart [linear_buckling]
//  cluster.low.n<N>.reltol  cluster.low with locationTolerance 1e-12·|λ_1| (relative, not max(1, |λ|))
//  switch.n<N>      the first critical load's branch point switched on both sides at n = N (above
//                   the dense crossover at the default N = 1000) [linear_buckling; children off the
//                   straight chain, on opposite sides]
//  kappa0.n<N>      κ = 0 (L0 = 1.5): an (N−1)-fold zero at Fx = 0 [exact: Fx = 0, index 0 → N−1]
//  limit.n<N>       free end, lateral end force, user limit |q| ≤ 0.3: the stop on the limit
//                   [Newton on F(u, λ) = 0 with the limiting joint fixed, finite-difference Jacobian]
// Pass: every expected point found exactly once with the right multiplicity and inertia jump,
// relative error ≤ 1e-9 (limit angles: absolute 1e-12).
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "buckle/continuation/branch_switching.h"
#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/linear_buckling.h"
#include "cases.h"
#include "nondimensional.h"

using namespace buckle::bench;
using buckle::mechanics::AnalyticBuckling3;
using buckle::mechanics::BucklingMode;
using buckle::mechanics::LinearBucklingResult;

namespace {

constexpr double kRelTol = 1e-9;
constexpr double kFoldReference = 0.1777097421507;  // ref.py (shared/peers/auto07p), unscaled

struct Row {
  std::string id;
  bool pass = false;
  double error = std::numeric_limits<double>::quiet_NaN();  // relative unless noted
  double ms = 0.0;
  std::string note;
};

double relErr(double x, double ref) { return std::abs(x - ref) / std::max(std::abs(ref), 1e-300); }

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string scaleName(double s) {
  if (s == 1.0) return "1";
  return fmt("%.0e", s);
}

class Timer {
 public:
  double ms() const { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

SegmentParameters scaledSegment(double a, double b, double k, double L0, const UnitScale& s) {
  return SegmentParameters::symmetric(a * s.length, b * s.length, k * s.stiffness, L0 * s.length);
}

std::string stopNote(const cont::Branch& b) {
  std::string s = std::string("stop ") + cont::toString(b.stopReason);
  if (!b.stopMessage.empty() && b.stopReason != cont::StopReason::LambdaRange && b.stopReason != cont::StopReason::Boundary)
    s += " (" + b.stopMessage.substr(0, 60) + ")";
  return s;
}

// ---- extreme units --------------------------------------------------------------------------

Row unitsBranchPoints(const UnitScale& us, bool nondim) {
  Row row;
  row.id = "units.bp." + scaleName(us.length) + "x" + scaleName(us.stiffness) + (nondim ? ".nondim" : ".default");
  const double a = 0.5 * us.length, b = us.length, k = us.stiffness, L0 = 2.25 * us.length;
  const AnalyticBuckling3 ref = buckle::mechanics::analyticClampedPinned3(a, b, k, L0);
  EquilibriumProblem problem(Chain::uniform(3, SegmentParameters::symmetric(a, b, k, L0)), EndCondition::clampedPinned(0.0),
                             Eigen::Vector3d(1, 0, 0));
  NondimensionalProblem view(problem, typicalUnits(problem.chain()));
  const double F0 = nondim ? view.lambdaScale() : 1.0;  // λ unit seen by the tracer
  const Timer timer;
  cont::Tracer tracer(nondim ? static_cast<const cont::Problem&>(view) : problem,
                      tracerOptions(Settings(), -2.5 * us.force() / F0, 0.0));
  const cont::Branch br = tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda());
  row.ms = timer.ms();
  const auto bps = br.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  row.note = std::to_string(bps.size()) + " BP, " + std::to_string(br.points.size()) + " points, " + stopNote(br);
  if (bps.size() != 2) return row;
  row.error = std::max(relErr(F0 * bps[0]->lambda, ref.FxU), relErr(F0 * bps[1]->lambda, ref.FxZ));
  row.pass = row.error <= kRelTol && bps[0]->multiplicity == 1 && bps[1]->multiplicity == 1 && bps[0]->inertiaBefore == 0 &&
             bps[0]->inertiaAfter == 1 && bps[1]->inertiaAfter == 2;
  if (row.error <= kRelTol && !row.pass) row.note += ", wrong multiplicity/inertia";
  return row;
}

Row unitsFold(const UnitScale& us, bool nondim) {
  Row row;
  row.id = "units.fold." + scaleName(us.length) + "x" + scaleName(us.stiffness) + (nondim ? ".nondim" : ".default");
  EquilibriumProblem problem(Chain::uniform(3, scaledSegment(0.5, 1.0, 1.0, 0.5, us)),
                             EndCondition::freeEnd(Eigen::Vector3d(0, 0.01 * us.force(), 0)), Eigen::Vector3d(1, 0, 0));
  NondimensionalProblem view(problem, typicalUnits(problem.chain()));
  const double F0 = nondim ? view.lambdaScale() : 1.0;
  const Timer timer;
  cont::Tracer tracer(nondim ? static_cast<const cont::Problem&>(view) : problem,
                      tracerOptions(Settings(), -3.0 * us.force() / F0, 3.0 * us.force() / F0));
  const cont::Branch br = tracer.trace(Eigen::VectorXd::Zero(3), 0.0, cont::InitialDirection::increasingLambda());
  row.ms = timer.ms();
  const auto lps = br.specialPointsOfType(cont::SpecialPointType::Fold);
  row.note = std::to_string(lps.size()) + " LP, " + std::to_string(br.points.size()) + " points, " + stopNote(br);
  if (lps.size() != 1) return row;
  row.error = relErr(F0 * lps[0]->lambda, kFoldReference * us.force());
  row.pass = row.error <= kRelTol && lps[0]->inertiaBefore == 3 && lps[0]->inertiaAfter == 2;
  if (row.error <= kRelTol && !row.pass) row.note += ", wrong inertia";
  return row;
}

// End of the U branch at the user joint limit |q| = 1.5: Fx (physical units) and max |q|.
struct LimitEnd {
  bool ok = false;
  double Fx = 0.0, qmax = 0.0;
  std::string note;
};

LimitEnd unitsLimitEnd(const UnitScale& us, bool nondim, double& ms) {
  LimitEnd out;
  SegmentParameters p = scaledSegment(0.5, 1.0, 1.0, 2.25, us);
  p.qMinUser = -1.5;
  p.qMaxUser = 1.5;
  EquilibriumProblem problem(Chain::uniform(3, p), EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  NondimensionalProblem view(problem, typicalUnits(problem.chain()));
  const cont::Problem& traced = nondim ? static_cast<const cont::Problem&>(view) : problem;
  const double F0 = nondim ? view.lambdaScale() : 1.0;
  const Timer timer;
  cont::Tracer tracer(traced, tracerOptions(Settings(), -3.0 * us.force() / F0, 0.0));
  const cont::Branch trivial = tracer.trace(Eigen::VectorXd::Zero(4), 0.0, cont::InitialDirection::decreasingLambda());
  const auto bps = trivial.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  if (bps.empty()) {
    ms = timer.ms();
    out.note = "no BP on the trivial branch, " + stopNote(trivial);
    return out;
  }
  Eigen::VectorXd direction;
  std::string why;
  if (!cont::bifurcatingDirection(traced, *bps[0], direction, &why)) {
    ms = timer.ms();
    out.note = "no bifurcating direction: " + why;
    return out;
  }
  const cont::Branch br = cont::switchBranch(tracer, *bps[0], direction, 1);
  ms = timer.ms();
  out.note = std::to_string(br.points.size()) + " points, " + stopNote(br);
  const auto bds = br.specialPointsOfType(cont::SpecialPointType::Boundary);
  if (bds.size() != 1) return out;
  out.ok = true;
  out.Fx = F0 * bds[0]->lambda;
  out.qmax = bds[0]->u.head(3).cwiseAbs().maxCoeff();
  return out;
}

Row unitsLimit(const UnitScale& us, bool nondim, double referenceFx) {
  Row row;
  row.id = "units.limit." + scaleName(us.length) + "x" + scaleName(us.stiffness) + (nondim ? ".nondim" : ".default");
  const LimitEnd end = unitsLimitEnd(us, nondim, row.ms);
  row.note = end.note;
  if (!end.ok) return row;
  row.error = relErr(end.Fx, referenceFx * us.force());
  row.pass = row.error <= kRelTol && std::abs(end.qmax - 1.5) <= 1e-12;
  row.note += ", |q|max - 1.5 = " + fmt("%.1e", end.qmax - 1.5);
  return row;
}

// ---- clustered critical loads ----------------------------------------------------------------

std::vector<double> compressiveCriticalLoads(const Chain& chain) {
  const int n = chain.size();
  const LinearBucklingResult lb =
      buckle::mechanics::linearBuckling(chain, Eigen::VectorXd::Zero(n), EndCondition::clampedPinned(0.0));
  std::vector<double> crit;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0) crit.push_back(m.lambda);
  std::sort(crit.begin(), crit.end(), [](double x, double y) { return x > y; });  // closest to 0 first
  return crit;
}

// Traces the trivial branch from λ0 down to λEnd with a step of a third of the range (several
// BPs per step) and checks it against crit[first .. first + count). relativeLocation: the location
// target 1e-12 relative to the cluster's own load scale |crit[first]| instead of the default
// locationTolerance·max(1, |λ|) (absolute below |λ| = 1).
Row clustered(const std::string& id, int n, bool top, int count, bool relativeLocation = false) {
  Row row;
  row.id = id;
  const Chain chain = Chain::uniform(n, mainSegment());
  const Timer timer;
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  const double lbMs = timer.ms();
  if (int(crit.size()) < count + 2) {
    row.note = "too few critical loads";
    return row;
  }
  const size_t first = top ? crit.size() - size_t(count) : 0;
  const double lambda0 = top ? 0.5 * (crit[first - 1] + crit[first]) : 0.0;
  const double lambdaEnd =
      top ? crit.back() - 0.5 * (crit[crit.size() - 2] - crit.back()) : 0.5 * (crit[size_t(count) - 1] + crit[size_t(count)]);
  double minGap = std::numeric_limits<double>::infinity();
  for (size_t i = first; i + 1 < first + size_t(count); ++i) minGap = std::min(minGap, std::abs(crit[i + 1] - crit[i]));

  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  Settings s;
  s.maxStep = s.initialStep = std::abs(lambdaEnd - lambda0) / 3;
  s.minStep = 1e-6 * s.maxStep;
  cont::TracerOptions o = tracerOptions(s, lambdaEnd, lambda0);
  if (relativeLocation) o.location.tolerance = 1e-12 * std::min(1.0, std::abs(crit[first]));
  cont::Tracer tracer(problem, o);
  const cont::Branch br = tracer.trace(Eigen::VectorXd::Zero(n + 1), lambda0, cont::InitialDirection::decreasingLambda());
  row.ms = timer.ms();
  const auto bps = br.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  row.note = std::to_string(bps.size()) + "/" + std::to_string(count) + " BP in [" + fmt("%.6g", lambdaEnd) + ", " +
             fmt("%.6g", lambda0) + "], min gap " + fmt("%.2e", minGap) + ", " + std::to_string(br.points.size()) +
             " points, linear_buckling " + fmt("%.0f ms", lbMs) + ", " + stopNote(br);
  if (int(bps.size()) != count) return row;
  row.error = 0.0;
  bool structure = true;
  for (size_t i = 0; i < bps.size(); ++i) {
    row.error = std::max(row.error, relErr(bps[i]->lambda, crit[first + i]));
    structure = structure && bps[i]->multiplicity == 1 && bps[i]->inertiaBefore == int(first + i) &&
                bps[i]->inertiaAfter == int(first + i) + 1;
  }
  row.pass = structure && row.error <= kRelTol;
  if (!structure) row.note += ", wrong multiplicity/inertia";
  return row;
}

// Branch switching above the dense crossover: the trivial branch through the first critical
// load of the clamped–pinned chain, both sides of it switched (tree depth 1, 20 points each).
// Pass: the BP within 1e-12 relative of linear_buckling, two children off the straight chain
// (‖q‖ ≥ half the arclength from the BP, as a pitchfork leaving along its mode) on opposite sides.
Row switched(int n) {
  Row row;
  row.id = "switch.n" + std::to_string(n);
  const Chain chain = Chain::uniform(n, mainSegment());
  const Timer timer;
  const std::vector<double> crit = compressiveCriticalLoads(chain);
  const double lbMs = timer.ms();
  if (crit.size() < 2) {
    row.note = "too few critical loads";
    return row;
  }
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  Settings s;
  s.maxStep = s.initialStep = std::abs(crit[0]) / 2.7;  // no step ends on the point
  s.minStep = 1e-6 * s.maxStep;
  const cont::TracerOptions o = tracerOptions(s, 0.5 * (crit[0] + crit[1]), 0.0);
  cont::TreeOptions tree;
  tree.branchSwitching = 1;
  cont::TracerOptions children = o;
  children.maxPoints = 20;
  children.lambdaMin = 2.0 * crit[1];
  tree.childTracer = children;
  const Timer traceTimer;
  const cont::BranchTree t = cont::traceTree(problem, Eigen::VectorXd::Zero(n + 1), 0.0,
                                             {cont::InitialDirection::decreasingLambda()}, o, tree);
  row.ms = traceTimer.ms();
  const auto bps = t.branches.at(0).specialPointsOfType(cont::SpecialPointType::BranchPoint);
  row.note = std::to_string(bps.size()) + " BP, " + std::to_string(t.branches.size() - 1) + " children, linear_buckling " +
             fmt("%.0f ms", lbMs) + " (not in the time)";
  if (bps.size() != 1 || t.branches.size() != 3) return row;
  row.error = relErr(bps[0]->lambda, crit[0]);
  bool off = true;
  double side[2] = {0.0, 0.0};
  for (size_t b = 1; b < 3; ++b) {
    const cont::Branch& child = t.branches[b];
    if (child.points.size() < 3) {
      off = false;
      continue;
    }
    const cont::ContinuationPoint& p = child.points.back();
    off = off && p.u.head(n).norm() >= 0.5 * (p.arclength - child.points.front().arclength);
    side[b - 1] = p.u[n / 2];
    row.note += ", child " + std::to_string(b) + ": " + std::to_string(child.points.size()) + " points, |q| " +
                fmt("%.2e", p.u.head(n).norm());
  }
  row.pass = row.error <= 1e-12 && off && side[0] * side[1] < 0.0;
  return row;
}

// ---- degenerate pitchfork --------------------------------------------------------------------

Row kappaZero(int n) {
  Row row;
  row.id = "kappa0.n" + std::to_string(n);
  // L0 = 2b(1 − (a/b)²) = 1.5: K_q = 0 on the straight chain, the Hessian is −Fx·G.
  EquilibriumProblem problem(Chain::uniform(n, mainSegment(1.5)), EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  const Timer timer;
  cont::Tracer tracer(problem, tracerOptions(Settings(), -2.5, 0.5));
  const cont::Branch br = tracer.trace(Eigen::VectorXd::Zero(n + 1), 0.5, cont::InitialDirection::decreasingLambda());
  row.ms = timer.ms();
  const auto bps = br.specialPointsOfType(cont::SpecialPointType::BranchPoint);
  row.note = std::to_string(bps.size()) + " BP";
  if (!bps.empty())
    row.note += " (multiplicity " + std::to_string(bps[0]->multiplicity) + ", index " + std::to_string(bps[0]->inertiaBefore) +
                " -> " + std::to_string(bps[0]->inertiaAfter) + ")";
  row.note += ", expected multiplicity " + std::to_string(n - 1) + ", error absolute, " + stopNote(br);
  if (bps.size() != 1) return row;
  row.error = std::abs(bps[0]->lambda);  // exact answer 0: absolute error (loads of order κ-scale k b = 1)
  row.pass = row.error <= kRelTol && bps[0]->multiplicity == n - 1 && bps[0]->inertiaBefore == 0 &&
             bps[0]->inertiaAfter == n - 1;
  return row;
}

// ---- joint limits at larger n ----------------------------------------------------------------

Row jointLimit(int n) {
  Row row;
  row.id = "limit.n" + std::to_string(n);
  const double qLimit = 0.3;
  SegmentParameters p = mainSegment();
  p.qMinUser = -qLimit;
  p.qMaxUser = qLimit;
  EquilibriumProblem problem(Chain::uniform(n, p), EndCondition::freeEnd(), Eigen::Vector3d(0, 1, 0));
  const Timer timer;
  Settings s;
  s.maxStep = 0.1;
  cont::Tracer tracer(problem, tracerOptions(s, 0.0, 100.0));
  const cont::Branch br = tracer.trace(Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::increasingLambda());
  row.ms = timer.ms();
  const auto bds = br.specialPointsOfType(cont::SpecialPointType::Boundary);
  row.note = std::to_string(bds.size()) + " boundary, " + stopNote(br);
  if (bds.size() != 1) return row;
  const cont::SpecialPoint& bd = *bds[0];
  Eigen::Index j = 0;
  const double qmax = bd.u.head(n).cwiseAbs().maxCoeff(&j);
  // Independent answer: Newton on F(q, λ) = 0 with q_j = ±limit fixed (unknowns: the other
  // angles and λ), central-difference Jacobian of the residual, from a perturbed start.
  const double qj = std::copysign(qLimit, bd.u[j]);
  Eigen::VectorXd z(n);  // (q without j, λ)
  for (int i = 0, c = 0; i < n; ++i)
    if (i != j) z[c++] = bd.u[i] + 1e-4;
  z[n - 1] = bd.lambda * (1 + 1e-4);
  auto G = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd q(n), F(n);
    for (int i = 0, c = 0; i < n; ++i) q[i] = i == j ? qj : x[c++];
    cont::BoundProblem(problem).residual(q, x[n - 1], F);
    return F;
  };
  for (int it = 0; it < 12; ++it) {
    const Eigen::VectorXd g = G(z);
    Eigen::MatrixXd Jz(n, n);
    for (int c = 0; c < n; ++c) {
      const double h = 1e-6 * std::max(1.0, std::abs(z[c]));
      Eigen::VectorXd zp = z, zm = z;
      zp[c] += h;
      zm[c] -= h;
      Jz.col(c) = (G(zp) - G(zm)) / (2 * h);
    }
    z -= Jz.partialPivLu().solve(g);
  }
  row.error = relErr(bd.lambda, z[n - 1]);
  row.pass = row.error <= kRelTol && std::abs(qmax - qLimit) <= 1e-12 && G(z).norm() <= 1e-12;
  row.note += ", joint " + std::to_string(j + 1) + " |q| - limit = " + fmt("%.1e", qmax - qLimit) + ", Fy = " + fmt("%.10g", bd.lambda) +
              " (reference " + fmt("%.10g", z[n - 1]) + ")";
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int bigN = 1000;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--n") && i + 1 < argc) bigN = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else {
      std::fprintf(stderr, "usage: hard_cases [--quick] [--n N] [--only PREFIX]\n");
      return 2;
    }
  }
  std::vector<Row> rows;
  auto want = [&](const char* prefix) { return only.empty() || std::string(prefix).rfind(only, 0) == 0 || only.rfind(prefix, 0) == 0; };
  auto add = [&](Row r) {
    std::printf("%-4s %-30s err %-8s %9.1f ms  %s\n", r.pass ? "PASS" : "FAIL", r.id.c_str(),
                std::isfinite(r.error) ? fmt("%.1e", r.error).c_str() : "-", r.ms, r.note.c_str());
    std::fflush(stdout);
    rows.push_back(std::move(r));
  };

  if (want("units")) {
    double refMs = 0.0;
    const LimitEnd ref = unitsLimitEnd(UnitScale{}, false, refMs);
    const std::vector<double> lengths = {1e-3, 1.0, 1e3}, stiffnesses = {1e-6, 1.0, 1e6};
    for (bool nondim : {false, true})
      for (double L : lengths)
        for (double k : stiffnesses) {
          const UnitScale us{L, k};
          add(unitsBranchPoints(us, nondim));
          add(unitsFold(us, nondim));
          add(unitsLimit(us, nondim, ref.Fx));
        }
  }
  if (want("cluster")) {
    std::vector<int> sizes = quick ? std::vector<int>{30, 60} : std::vector<int>{200};
    if (!quick && bigN != 200) sizes.push_back(bigN);
    for (int n : sizes)
      for (const char* end : {"low", "top"}) {
        const std::string id = std::string("cluster.") + end + ".n" + std::to_string(n);
        if (want(id.c_str())) add(clustered(id, n, end[0] == 't', 6));
      }
    // The low end of the large chain again with a location target relative to the loads there.
    const std::string id = "cluster.low.n" + std::to_string(sizes.back()) + ".reltol";
    if (want(id.c_str())) add(clustered(id, sizes.back(), false, 6, true));
  }
  if (want("switch")) add(switched(quick ? 60 : bigN));
  if (want("kappa0"))
    for (int n : quick ? std::vector<int>{3, 4} : std::vector<int>{3, 4, 5, 10}) add(kappaZero(n));
  if (want("limit"))
    for (int n : quick ? std::vector<int>{10} : std::vector<int>{10, 100}) add(jointLimit(n));

  int failed = 0;
  double total = 0.0;
  for (const Row& r : rows) {
    failed += r.pass ? 0 : 1;
    total += r.ms;
  }
  std::printf("hard_cases: %zu cases, %d failed, %.0f ms\n", rows.size(), failed, total);
  return 0;  // failures are results here (the table reports them); run_quick checks the program runs
}
