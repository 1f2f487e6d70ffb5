// jump_timing: wall time of a jump (gradient flow to rest, then polish) over the chain length
// (issue 13). The chain: n bistable segments (a = 0.5, b = 1, k = 1, L0 = 1.2: κ < 0), end held
// on the x-axis (clamped–pinned), released from the unstable straight state at Fx = 0. Each row:
// the stepper, wall time of simulateJump (best of `reps`), accepted steps, and for the structured
// Rosenbrock method the largest difference of its landing from dense Rosenbrock4's where that is run.
//
//   jump_timing [--quick] [--n N] [--reps R] [--dense-max N]
//     --quick        CI size: n = 20 and 80, one repetition
//     --n N          only this chain length
//     --reps R       repetitions per timing, best kept (default 3)
//     --dense-max N  largest n also run with dense Rosenbrock4 (default 200)
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "buckle/mechanics/jump.h"

using namespace buckle::mechanics;

namespace {

int usage(const char* why) {
  std::fprintf(stderr, "jump_timing: %s\nusage: jump_timing [--quick] [--n N] [--reps R] [--dense-max N]\n", why);
  return 2;
}

bool positiveInt(const char* s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (!end || *end != '\0' || v < 1 || v > 1000000) return false;
  out = int(v);
  return true;
}

struct Timed {
  JumpResult result;
  double seconds = 1e300;
};

Timed timeJump(EquilibriumProblem& problem, const Vector& u0, StepperKind stepper, int reps) {
  Timed t;
  JumpOptions options;
  options.integration = jumpIntegrationDefaults(problem.chain().size());
  options.integration.stepper = stepper;
  options.integration.recordTrajectory = false;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    t.result = simulateJump(problem, u0, 0.0, options);
    t.seconds = std::min(t.seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // one row at a time (long runs)
  bool quick = false;
  int reps = 3, denseMax = 200, only = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if ((a == "--reps" || a == "--dense-max" || a == "--n") && i + 1 < argc) {
      int& target = a == "--reps" ? reps : a == "--n" ? only : denseMax;
      if (!positiveInt(argv[++i], target)) return usage((a + " needs a positive integer").c_str());
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (quick) reps = 1;
  const std::vector<int> sizes = only > 0  ? std::vector<int>{only}
                                 : quick ? std::vector<int>{20, 80}
                                         : std::vector<int>{50, 200, 1000, 5000};
  std::printf("%-7s %-24s %12s %8s %10s %16s\n", "n", "stepper", "time [ms]", "steps", "success", "landing vs dense");
  bool ok = true;
  for (int n : sizes) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
    EquilibriumProblem problem(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0));
    const Vector u0 = problem.initialGuess(Vector::Zero(n), 0.0);
    const Timed structured = timeJump(problem, u0, StepperKind::StructuredRosenbrock4, reps);
    double landing = std::nan("");
    if (n <= denseMax) {
      const Timed dense = timeJump(problem, u0, StepperKind::Rosenbrock4, quick ? 1 : std::min(reps, 2));
      std::printf("%-7d %-24s %12.1f %8ld %10s %16s\n", n, "Rosenbrock4 (dense)", 1e3 * dense.seconds,
                  dense.result.steps, dense.result.success ? "yes" : "no", "");
      if (dense.result.success && structured.result.success)
        landing = (dense.result.to - structured.result.to).cwiseAbs().maxCoeff();
    }
    std::printf("%-7d %-24s %12.1f %8ld %10s %16.2e\n", n, "StructuredRosenbrock4", 1e3 * structured.seconds,
                structured.result.steps, structured.result.success ? "yes" : "no", landing);
    ok = ok && structured.result.success;
  }
  return ok ? 0 : 1;
}
