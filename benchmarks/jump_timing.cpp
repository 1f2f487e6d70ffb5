// jump_timing: wall time of a jump (gradient flow, then polish) over the chain length (issue 13),
// in two cases:
//   fold        what a user meets: the first fold of a loaded, curled chain found by the tracer.
//               n bistable segments (a = 0.5, b = 1, k = 1) graded in L0 from 1.3 at the base to
//               1.2 at the end (the base joint's well is the shallowest), free end under a
//               constant Fy = 0.01/n (k̄b̄) and an end moment M = λ; every joint starts in its
//               negative well (q_i = −2 acos(L0_i / 1.5)) at M = 0, and the tracer follows M up
//               to the first fold (a simple zero eigenvalue: the base joint's barrier).
//   degenerate  the straight chain of identical bistable segments (L0 = 1.2), end held on the
//               x-axis (clamped–pinned), released at Fx = 0: an (n − 1)-fold lowest eigenvalue,
//               the direction from the rule of jump.h (step 1), a cascade of joints snapping.
//   inertial    the fold case with masses (slender rods, unit mass per length) and joint damping 1:
//               the inertial model (D2), dense Rosenbrock4 with its differenced Jacobian against
//               the structured method on its exact O(n) Jacobian.
// Each row: the case, n, the stepper, its local error tolerance (jumpIntegrationDefaults: 1e-10,
// above kStructuredJumpFrom segments kLongJumpTolerance), whether the flow hands over to Newton in
// the stable basin (jump.h, step 2) or integrates to rest, wall time of simulateJump (best of
// `reps`), accepted steps, basin tests, and ‖Δq‖∞ of the landing from the case's reference (dense
// Rosenbrock4 to rest where run, else the structured method to rest at 1e-10). Above
// kStructuredJumpFrom segments a last row runs the default stepper, StructuredSwitching
// (Dormand–Prince while the flow is not stiff, jump.h).
//
//   jump_timing [--quick] [--n N] [--reps R] [--dense-max N] [--case fold|degenerate]
//     --quick        CI size: n = 20 and 80 (the inertial case n = 8), one repetition
//     --n N          only this chain length
//     --reps R       repetitions per timing, best kept (default 3)
//     --dense-max N  largest n also run with dense Rosenbrock4 (default 200)
//     --case C       only this case (fold, degenerate, inertial)
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/jump.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

int usage(const char* why) {
  std::fprintf(stderr,
               "jump_timing: %s\nusage: jump_timing [--quick] [--n N] [--reps R] [--dense-max N] [--case fold|degenerate|inertial]\n",
               why);
  return 2;
}

bool positiveInt(const char* s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (!end || *end != '\0' || v < 1 || v > 1000000) return false;
  out = int(v);
  return true;
}

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Timed {
  JumpResult result;
  double seconds = 1e300;
};

Timed timeJump(EquilibriumProblem& problem, const Vector& u0, double lambda, StepperKind stepper, double tolerance,
               Handover handover, int reps, const DynamicsScene& scene) {
  Timed t;
  JumpOptions options;
  options.scene = scene;
  options.integration = jumpIntegrationDefaults(problem.chain().size());
  options.integration.stepper = stepper;
  options.integration.absoluteTolerance = options.integration.relativeTolerance = tolerance;
  options.integration.recordTrajectory = false;
  options.handover = handover;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    t.result = simulateJump(problem, u0, lambda, options);
    t.seconds = std::min(t.seconds, seconds(t0));
  }
  return t;
}

/// A jump's start: the problem, the unknowns and λ.
struct Start {
  std::unique_ptr<EquilibriumProblem> problem;
  Vector u;
  double lambda = 0.0;
  bool found = false;
  double traceSeconds = 0.0;
  int tracedPoints = 0;
};

Start degenerateStart(int n) {
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 1.2));
  Start s;
  s.problem = std::make_unique<EquilibriumProblem>(chain, EndCondition::clampedPinned(0.0, 0.0), Eigen::Vector3d(1, 0, 0));
  s.u = s.problem->initialGuess(Vector::Zero(n), 0.0);
  s.found = true;
  return s;
}

Start foldStart(int n) {
  std::vector<SegmentParameters> segments;
  Vector q0(n);
  for (int i = 0; i < n; ++i) {
    const double L0 = 1.3 - 0.1 * i / std::max(1, n - 1);
    segments.push_back(SegmentParameters::symmetric(0.5, 1.0, 1.0, L0));
    q0[i] = -2.0 * std::acos(L0 / 1.5);  // the well c* = b L0 / (2(b² − a²))
  }
  Start s;
  s.problem = std::make_unique<EquilibriumProblem>(Chain(segments), EndCondition::freeEnd(Eigen::Vector3d(0.0, 0.01 / n, 0.0)),
                                                   Eigen::Vector3d(0, 0, 1));
  const auto t0 = std::chrono::steady_clock::now();
  const PolishResult p = polishEquilibrium(*s.problem, q0, 0.0);
  if (!p.converged) return s;
  cont::TracerOptions o;
  o.maxPoints = 2000;
  o.lambdaMax = 2.0;
  o.detection.branchPoints = false;
  o.detection.lowestEigenvalues = 0;
  cont::Tracer tracer(*s.problem, o);
  const cont::Branch branch = tracer.trace(p.u, 0.0, cont::InitialDirection::increasingLambda());
  s.traceSeconds = seconds(t0);
  s.tracedPoints = int(branch.points.size());
  const auto folds = branch.specialPointsOfType(cont::SpecialPointType::Fold);
  if (folds.empty()) return s;
  s.u = folds.front()->u;
  s.lambda = folds.front()->lambda;
  s.found = true;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // one row at a time (long runs)
  bool quick = false;
  int reps = 3, denseMax = 200, only = 0;
  std::string onlyCase;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if ((a == "--reps" || a == "--dense-max" || a == "--n") && i + 1 < argc) {
      int& target = a == "--reps" ? reps : a == "--n" ? only : denseMax;
      if (!positiveInt(argv[++i], target)) return usage((a + " needs a positive integer").c_str());
    } else if (a == "--case" && i + 1 < argc) {
      onlyCase = argv[++i];
      if (onlyCase != "fold" && onlyCase != "degenerate" && onlyCase != "inertial")
        return usage("--case must be fold, degenerate or inertial");
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (quick) reps = 1;
  const std::vector<int> sizes = only > 0  ? std::vector<int>{only}
                                 : quick ? std::vector<int>{20, 80}
                                         : std::vector<int>{50, 200, 1000, 5000};
  std::printf("%-11s %-6s %-22s %-6s %-9s %11s %7s %6s %8s %12s\n", "case", "n", "stepper", "tol", "handover", "time [ms]",
              "steps", "tests", "success", "landing diff");
  bool ok = true;
  for (const char* name : {"fold", "degenerate", "inertial"}) {
    const std::string c = name;
    if (!onlyCase.empty() && c != onlyCase) continue;
    // the inertial model integrates to rest (tens of thousands of steps): CI runs it at n = 8
    const std::vector<int> caseSizes = quick && c == "inertial" ? std::vector<int>{8} : sizes;
    for (int n : caseSizes) {
      Start s = c == "degenerate" ? degenerateStart(n) : foldStart(n);
      DynamicsScene scene;
      if (c == "inertial") {
        // slender rods of unit mass per length, joint damping of the order of the critical one
        scene.inertia = InertiaData::uniformRods(s.problem->chain(), 1.0);
        scene.jointDamping.assign(size_t(n), 1.0);
      }
      if (!s.found) {
        std::printf("%-11s %-6d no fold found by the tracer\n", c.c_str(), n);
        ok = false;
        continue;
      }
      if (c != "degenerate")
        std::printf("%-11s %-6d (traced to the fold M = %.6g in %d points, %.1f ms)\n", c.c_str(), n, s.lambda,
                    s.tracedPoints, 1e3 * s.traceSeconds);
      Vector reference;
      const double tight = IntegrationOptions().absoluteTolerance, tolerance = jumpIntegrationDefaults(n).absoluteTolerance;
      auto row = [&](StepperKind stepper, double tol, Handover handover, int r) {
        const Timed t = timeJump(*s.problem, s.u, s.lambda, stepper, tol, handover, r, scene);
        double diff = std::nan("");
        if (t.result.success) {
          if (reference.size() == 0) reference = t.result.to;
          else diff = (t.result.to - reference).cwiseAbs().maxCoeff();
        }
        std::printf("%-11s %-6d %-22s %-6.0e %-9s %11.1f %7ld %6d %8s %12.2e\n", c.c_str(), n,
                    stepper == StepperKind::Rosenbrock4             ? "Rosenbrock4 (dense)"
                    : stepper == StepperKind::StructuredSwitching ? "StructuredSwitching"
                                                                  : "StructuredRosenbrock4",
                    tol,
                    handover == Handover::Never ? "no" : "yes", 1e3 * t.seconds, t.result.steps, t.result.basinTests,
                    t.result.success ? "yes" : "no", diff);
        ok = ok && t.result.success && !(diff > 1e-9);
      };
      if (n <= denseMax) row(StepperKind::Rosenbrock4, tight, Handover::Never, quick ? 1 : std::min(reps, 2));
      row(StepperKind::StructuredRosenbrock4, tight, Handover::Never, reps);
      if (tolerance != tight) row(StepperKind::StructuredRosenbrock4, tolerance, Handover::Never, reps);
      // (the inertial model always integrates to rest: jump.h)
      if (c != "inertial") row(StepperKind::StructuredRosenbrock4, tolerance, Handover::Always, reps);
      // the default above kStructuredJumpFrom: Dormand–Prince while not stiff (jump.h)
      const StepperKind chosen = jumpIntegrationDefaults(n).stepper;
      if (chosen == StepperKind::StructuredSwitching)
        row(chosen, tolerance, c == "inertial" ? Handover::Never : Handover::Always, reps);
    }
  }
  return ok ? 0 : 1;
}
