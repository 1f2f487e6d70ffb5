// bench_cases: buckle on the AUTO-07p comparison cases, one line per located point and a
// timing line per case, machine-readable (key=value) for compare_auto.sh.
//   bench_cases [--reps R] [--second-order] [--no-certified] [--lean-newton] [CASE ...]
//   default: all cases, R = 5
//   (median time); --second-order: TracerOptions::secondOrderPredictor; --no-certified:
//   TracerOptions::certifiedCounting = false (the like-for-like A/B against AUTO, which computes no
//   eigenvalues with IPS = 0); --lean-newton: TracerOptions::leanNewton (the corrector's own
//   reproduction of KINSOL's full Newton where it converges plainly, KINSOL otherwise)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "cases.h"

using namespace buckle::bench;

int main(int argc, char** argv) {
  int reps = 5;
  std::vector<std::string> names;
  bool secondOrder = false;
  bool certified = true;
  bool leanNewton = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--second-order")) secondOrder = true;
    else if (!std::strcmp(argv[i], "--no-certified")) certified = false;
    else if (!std::strcmp(argv[i], "--lean-newton")) leanNewton = true;
    else names.emplace_back(argv[i]);
  }
  if (names.empty()) names = caseNames();
  // Per point: the inertia only (the branch-point test; the locator asks for the crossing
  // eigenvalue itself), like AUTO's IPS = 0 runs, which compute no eigenvalues at all.
  Settings settings;
  settings.lowestEigenvalues = 0;
  settings.secondOrderPredictor = secondOrder;
  settings.certifiedCounting = certified;
  settings.leanNewton = leanNewton;
  int failures = 0;
  for (const auto& name : names) {
    std::vector<double> times;
    CaseResult r;
    for (int k = 0; k < reps; ++k) {
      if (!runCase(name, settings, r)) {
        std::fprintf(stderr, "unknown case %s\n", name.c_str());
        return 2;
      }
      times.push_back(r.seconds);
    }
    std::sort(times.begin(), times.end());
    const double med = times[times.size() / 2];
    if (r.points <= 0) ++failures;
    std::printf("case=%s points=%d time_ms=%.4f per_point_us=%.3f stop=%s\n", name.c_str(), r.points, 1e3 * med,
                r.points > 0 ? 1e6 * med / r.points : 0.0, buckle::continuation::toString(r.branch.stopReason));
    for (const auto& l : r.located) {
      std::printf("  point case=%s type=%s Fx=%.13e", name.c_str(), l.label.c_str(), l.Fx);
      if (std::isfinite(l.reference)) std::printf(" ref=%.13e err=%.2e", l.reference, std::abs(l.Fx - l.reference));
      std::printf("\n");
    }
  }
  return failures ? 1 : 0;
}
