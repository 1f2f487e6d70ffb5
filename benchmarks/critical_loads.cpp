// critical_loads: time and accuracy of the O(n) linear-buckling path (issue 13) over n.
// One row per n and end condition: wall time of linearBuckling for the first `count` critical
// loads with their modes (best of `reps`), and, where the dense pencil is feasible, the largest
// relative difference of the loads from it and the largest mode difference (both unit, up to
// sign). The free end also has the exact discrete loads
// λ_k = −(2κ/b) sin²((2k − 1)π/(4n)) of the uniform straight chain: their largest relative error.
//
//   critical_loads [--quick] [--count K] [--reps R] [--dense-max N] [--n N]
//     --quick        CI size: n = 100 and 1000, dense up to 100, one repetition
//     --count K      critical loads per run (default 5)
//     --reps R       repetitions per timing, best kept (default 3)
//     --dense-max N  largest n compared with the dense pencil (default 2000)
//     --n N          only this chain length (repeatable; default 1000, 2000, 10 000, 100 000)
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "buckle/mechanics/linear_buckling.h"

using buckle::mechanics::Chain;
using buckle::mechanics::EndCondition;
using buckle::mechanics::LinearBucklingOptions;
using buckle::mechanics::LinearBucklingResult;
using buckle::mechanics::SegmentParameters;

namespace {

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

int usage(const char* why) {
  std::fprintf(stderr, "critical_loads: %s\nusage: critical_loads [--quick] [--count K] [--reps R] [--dense-max N] [--n N]\n",
               why);
  return 2;
}

bool positiveInt(const char* s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (!end || *end != '\0' || v < 1 || v > 100000000) return false;
  out = int(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int count = 5, reps = 3, denseMax = 2000;
  std::vector<int> only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if ((a == "--count" || a == "--reps" || a == "--dense-max") && i + 1 < argc) {
      int& target = a == "--count" ? count : a == "--reps" ? reps : denseMax;
      if (!positiveInt(argv[++i], target)) return usage((a + " needs a positive integer").c_str());
    } else if (a == "--n" && i + 1 < argc) {
      int n = 0;
      if (!positiveInt(argv[++i], n) || n < 2) return usage("--n needs an integer >= 2");
      only.push_back(n);
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (quick) {
    reps = 1;
    denseMax = 100;
  }
  const std::vector<int> sizes = !only.empty() ? only
                                 : quick      ? std::vector<int>{100, 1000}
                                              : std::vector<int>{1000, 2000, 10000, 100000};
  const double a = 0.5, b = 1.0, k = 1.0, L0 = 2.25;  // the paper's main segment
  std::printf("%-8s %-15s %12s %14s %14s %14s\n", "n", "end", "time [ms]", "vs dense", "mode vs dense",
              "vs exact");
  bool ok = true;
  for (int n : sizes) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(a, b, k, L0));
    const double kappa = chain.segment(0).straightStiffness();
    const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(n);
    for (const bool pinned : {true, false}) {
      const EndCondition end = pinned ? EndCondition::clampedPinned(0.0) : EndCondition::freeEnd();
      LinearBucklingOptions opt;
      opt.count = count;
      LinearBucklingResult fast;
      double best = 1e300;
      for (int r = 0; r < reps; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        fast = buckle::mechanics::linearBuckling(chain, q0, end, opt);
        best = std::min(best, seconds(std::chrono::steady_clock::now() - t0));
      }
      if (int(fast.modes.size()) != std::min(count, n)) ok = false;
      double vsDense = std::nan(""), modeDense = std::nan(""), vsExact = std::nan("");
      if (n <= denseMax) {
        const LinearBucklingResult dense = buckle::mechanics::linearBuckling(chain, q0, end, LinearBucklingOptions{});
        vsDense = modeDense = 0.0;
        for (size_t j = 0; j < fast.modes.size() && j < dense.modes.size(); ++j) {
          vsDense = std::max(vsDense, std::abs(fast.modes[j].lambda - dense.modes[j].lambda) /
                                          std::abs(dense.modes[j].lambda));
          modeDense = std::max(modeDense, std::min((fast.modes[j].mode - dense.modes[j].mode).norm(),
                                                   (fast.modes[j].mode + dense.modes[j].mode).norm()));
        }
      }
      if (!pinned) {
        vsExact = 0.0;
        for (size_t j = 0; j < fast.modes.size(); ++j) {
          const double s = std::sin((2.0 * double(j + 1) - 1.0) * M_PI / (4.0 * n));
          const double exact = -2.0 * kappa / b * s * s;
          vsExact = std::max(vsExact, std::abs(fast.modes[j].lambda - exact) / std::abs(exact));
        }
      }
      std::printf("%-8d %-15s %12.2f %14.2e %14.2e %14.2e\n", n, pinned ? "clamped-pinned" : "free", 1e3 * best,
                  vsDense, modeDense, vsExact);
    }
  }
  return ok ? 0 : 1;
}
