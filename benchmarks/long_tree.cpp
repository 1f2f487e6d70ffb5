// long_tree: the bifurcation tree of a long straight chain (issue 13, "Done when"): the trivial
// branch of the clamped–pinned chain under Fx through its first K branch points, every one
// refined and switched on both sides, P points per branch (the trivial branch in steps of its
// λ range / (P − 1), the switched ones in steps of 0.2/√n), traced by the mechanics layer's one
// entry (traceEquilibria: the core's tree driver, contact and the branch reports). Each row: wall
// time of the tree, peak resident memory of the process so far, the branches and how many of
// the 2K switches left the trivial branch, and the largest relative difference of the K branch
// points from the O(n) linear buckling route (Sturm counts + Rayleigh quotient, an independent
// computation: linear_buckling.h), and, with --dense-max ≥ n, from the dense pencil.
//
//   long_tree [--quick] [--n N] [--bps K] [--points P] [--dense-max N] [--child-step H] [--verbose]
//     --quick        CI size: n = 100, K = 3, P = 20
//     --n N          only this chain length (default: n = 1000 with K = 10, then n = 10000 with K = 5)
//     --bps K        branch points switched (default 10 at n ≤ 2000, else 5)
//     --points P     points per branch (default 50)
//     --dense-max N  largest n also compared with the dense pencil (default 0: none; it is O(n³))
//     --child-step H the switched branches' step (default 0.2/√n); the trivial branch's own step,
//                    |λ_end|/(P − 1), reproduces the tiny-step children of issue 13 (fold test)
//     --verbose      one line per switched branch: points, special points, why it stopped
// Memory is the process's peak (getrusage), so run one n per process for a clean figure.
#include <sys/resource.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/linear_buckling.h"
#include "common.h"

namespace cont = buckle::continuation;
using namespace buckle::mechanics;

namespace {

int usage(const char* why) {
  std::fprintf(stderr,
               "long_tree: %s\nusage: long_tree [--quick] [--n N] [--bps K] [--points P] [--dense-max N] [--child-step H] [--verbose]\n", why);
  return 2;
}

bool positiveInt(const char* s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (!end || *end != '\0' || v < 1 || v > 10000000) return false;
  out = int(v);
  return true;
}

double peakMegabytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

/// The first `count` compressive critical loads (λ = Fx < 0), closest to zero first.
std::vector<double> compressive(const LinearBucklingResult& lb, int count) {
  std::vector<double> crit;
  for (const BucklingMode& m : lb.modes)
    if (m.lambda < 0.0) crit.push_back(m.lambda);
  std::sort(crit.begin(), crit.end(), [](double x, double y) { return x > y; });
  if (int(crit.size()) > count) crit.resize(size_t(count));
  return crit;
}

struct Row {
  int n = 0, bps = 0, points = 0;
  double seconds = 0.0, megabytes = 0.0;
  int branches = 0, switched = 0, located = 0, childPoints = 0;
  double vsLinear = std::nan(""), vsDense = std::nan("");
  std::string children;  ///< per switched branch: points, special points, stop reason (--verbose)
};

Row run(int n, int K, int P, int denseMax, double childStep) {
  Row row;
  row.n = n;
  row.bps = K;
  row.points = P;
  const Chain chain = Chain::uniform(n, buckle::bench::mainSegment());
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(n);
  LinearBucklingOptions lbo;
  lbo.count = K + 1;
  const std::vector<double> crit = compressive(linearBuckling(chain, q0, EndCondition::clampedPinned(0.0), lbo), K + 1);
  if (int(crit.size()) < K + 1) {
    std::fprintf(stderr, "long_tree: n = %d has fewer than %d compressive critical loads\n", n, K + 1);
    return row;
  }
  EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0), Eigen::Vector3d(1, 0, 0));
  // The trivial branch from 0 to halfway between the K-th and (K+1)-th load in P points (steps
  // of range/(P − 1) in the chain's force unit k̄b̄ = 1); the switched branches P points each.
  const double lambdaEnd = 0.5 * (crit[size_t(K) - 1] + crit[size_t(K)]);
  EquilibriumBranchOptions opt;
  opt.tracer.step.maxStep = opt.tracer.step.initialStep = std::abs(lambdaEnd) / (P - 1);
  opt.tracer.step.minStep = 1e-6 * opt.tracer.step.maxStep;
  opt.tracer.maxPoints = P + 2 * K + 1;  // the located branch points are points of the branch too
  opt.tracer.lambdaMin = lambdaEnd;
  opt.tracer.lambdaMax = 0.0;
  opt.tracer.detection.lowestEigenvalues = 1;  // the smallest eigenvalue, as the scenes report it
  // The children move along the buckling modes, in joint angles: steps of 0.2/√n (0.02, the
  // scenes' initial step, at n = 100), so that 50 points bend the chain visibly but do not coil
  // it (the link angles sum the joint angles: 0.02 per joint coils a 2000-segment chain into
  // base and self contact). With the trivial branch's steps (|λ| ~ 1e−8 at n = 10 000) they would
  // stay within 1e−7 of the straight chain, where λ(s) − λ_c ~ λ_c s² is below the rounding of
  // the tangent's λ component and its sign, the fold test, is noise (spurious LPs).
  cont::TracerOptions child = opt.tracer;
  child.step.initialStep = child.step.maxStep = childStep > 0.0 ? childStep : 0.2 / std::sqrt(double(n));
  child.step.minStep = 1e-6 * child.step.maxStep;
  child.maxPoints = P;
  child.lambdaMin = 2.0 * crit[size_t(K)];
  opt.tree.childTracer = child;
  opt.tree.branchSwitching = 1;
  const auto t0 = std::chrono::steady_clock::now();
  const EquilibriumBranches tree =
      traceEquilibria(problem, q0, 0.0, cont::InitialDirection::decreasingLambda(), opt);
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.megabytes = peakMegabytes();
  const auto& branches = tree.tree.branches;
  row.branches = int(branches.size());
  for (const cont::Branch& b : branches) {
    if (b.parentId < 0) continue;
    row.childPoints = std::max(row.childPoints, int(b.points.size()));
    row.children += "  branch " + std::to_string(b.id) + " (BP " + std::to_string(b.parentSpecialPoint) +
                    (b.direction > 0 ? " +" : " -") + "): " + std::to_string(b.points.size()) + " points,";
    for (const cont::SpecialPoint& sp : b.specialPoints) row.children += std::string(" ") + cont::label(sp.type);
    row.children += std::string(", ") + cont::toString(b.stopReason) + "\n";
    for (const SpecialPointReport& sp : tree.reports[size_t(b.id)].specialPoints)
      if (sp.type == EventType::BaseContact || sp.type == EventType::SelfContact)
        row.children += "    " + sp.note.substr(0, 110) + "\n";
    // off the trivial branch: the joint angles grow along the child
    if (b.stopReason != cont::StopReason::SwitchFailed && b.points.size() >= 2 &&
        b.points.back().u.head(n).norm() > 0.0)
      ++row.switched;
  }
  const auto bps = branches.front().specialPointsOfType(cont::SpecialPointType::BranchPoint);
  row.located = int(bps.size());
  if (row.located == K) {
    row.vsLinear = 0.0;
    for (int i = 0; i < K; ++i)
      row.vsLinear = std::max(row.vsLinear, std::abs(bps[size_t(i)]->lambda - crit[size_t(i)]) / std::abs(crit[size_t(i)]));
    if (n <= denseMax) {
      // the dense pencil (all modes, O(n³)): an independent reference
      const std::vector<double> dense =
          compressive(linearBuckling(chain, q0, EndCondition::clampedPinned(0.0), LinearBucklingOptions{}), K);
      row.vsDense = 0.0;
      for (int i = 0; i < K; ++i)
        row.vsDense = std::max(row.vsDense, std::abs(bps[size_t(i)]->lambda - dense[size_t(i)]) / std::abs(dense[size_t(i)]));
    }
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // one row at a time (long runs)
  bool quick = false, verbose = false;
  int only = 0, K = 0, P = 50, denseMax = 0;
  double childStep = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--verbose") {
      verbose = true;
    } else if (a == "--child-step" && i + 1 < argc) {
      char* end = nullptr;
      childStep = std::strtod(argv[++i], &end);
      if (!end || *end != '\0' || !(childStep > 0.0) || !std::isfinite(childStep))
        return usage("--child-step needs a positive number");
    } else if ((a == "--n" || a == "--bps" || a == "--points" || a == "--dense-max") && i + 1 < argc) {
      int& target = a == "--n" ? only : a == "--bps" ? K : a == "--points" ? P : denseMax;
      if (!positiveInt(argv[++i], target)) return usage((a + " needs a positive integer").c_str());
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (P < 3) return usage("--points must be at least 3");
  std::vector<std::pair<int, int>> runs;  // (n, K)
  if (quick)
    runs = {{100, 3}};
  else if (only > 0)
    runs = {{only, K > 0 ? K : only <= 2000 ? 10 : 5}};
  else
    runs = {{1000, K > 0 ? K : 10}, {10000, K > 0 ? K : 5}};
  if (quick) P = 20;
  std::printf("%-7s %4s %6s %10s %9s %9s %9s %9s %12s %12s\n", "n", "BPs", "points", "time [s]", "peak MB",
              "branches", "switched", "child pts", "vs linear", "vs dense");
  bool ok = true;
  for (const auto& [n, k] : runs) {
    const Row r = run(n, k, P, denseMax, childStep);
    std::printf("%-7d %4d %6d %10.3f %9.1f %9d %9d %9d %12.2e %12.2e\n", r.n, r.located, r.points, r.seconds,
                r.megabytes, r.branches, r.switched, r.childPoints, r.vsLinear, r.vsDense);
    if (verbose) std::printf("%s", r.children.c_str());
    ok = ok && r.located == k;
  }
  return ok ? 0 : 1;
}
