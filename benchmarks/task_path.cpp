// task_path: wall time of a task-space path (issue 29): the free end of n paper segments
// (a = 0.5 b, L0 = 2.25 b) under the payload Fx = Fy = −0.9/n k b (−0.3 at n = 3) is driven in
// (x, y) along a straight line from its loaded pose towards (−0.05, +0.1)·(chain length) further on,
// 100 continuation points with stability and stiffness at fixed inputs at every point (O(n)) and
// the special points (fold of the task map, loss of stability, joint limit, input bound) located.
// Rule (a) `chosen`: the inputs dL0 and L0 of every segment, O(n) bordered solves. Rule (b)
// `min_change`: those two and dL0 of segment 1, the optimality system (2n + 5 unknowns) by block
// elimination through H, O(n) with 3 inputs. Rule (c) `most_stable`: the same three inputs, its
// optimality system (3n + 6 unknowns, the start optimum by continuation in the objective's weight,
// timed) with a dense differenced Jacobian, n = 3 and 50 only. The start (the straight chain loaded to the payload)
// is not timed. Units:
// nondimensional (b = 1, k = 1) and SI (b = 0.02 m, k = 2000 N/m). Best of `reps` runs.
//
// Built with the benchmarks (-DBUCKLE_BUILD_BENCHMARKS=ON: build/bin/task_path), or by hand as
// benchmarks/actuation_path.cpp says.
//
//   task_path [--reps R] [--quick]
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/task_path_trace.h"
#include "payload_paths.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

struct Row {
  double seconds = std::numeric_limits<double>::infinity();
  size_t points = 0;
  double sEnd = 0.0;
  const char* end = "";
  bool started = false;
};

Row run(int n, double b, double k, TaskRule rule, int reps) {
  const Chain chain = buckle::bench::payloadChain(n, b, k);
  const Eigen::Vector3d payload = buckle::bench::payloadOf(n, b, k);
  Row row;
  Eigen::VectorXd q0;
  if (!buckle::bench::loadedStart(chain, payload, q0)) return row;
  row.started = true;
  TaskSetup setup;
  setup.payload = payload;
  setup.coordinates = {0, 1};
  setup.rule = rule;
  setup.inputs = {{ControlInput::dL0, -1}, {ControlInput::L0, -1}};
  if (rule != TaskRule::Chosen) setup.inputs.push_back({ControlInput::dL0, 0});
  const Pose pose = endPose(chain, q0);
  Eigen::VectorXd to(2);
  to << pose[0] - 0.05 * chain.length(), pose[1] + 0.1 * chain.length();
  for (int r = 0; r < reps; ++r) {
    TaskPathProblem problem(chain, setup);
    TaskPathOptions opt;
    opt.tracer.maxPoints = 100;
    const auto t0 = std::chrono::steady_clock::now();
    const TaskPathResult result = traceTaskPath(problem, q0, {to}, chain.length(), opt);
    row.seconds = std::min(row.seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    row.points = result.points.size();
    row.sEnd = result.points.empty() ? 0.0 : result.points.back().s;
    row.end = toString(result.end);
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  bool quick = false;
  buckle::bench::parseRepsQuick(argc, argv, reps, quick);
  std::printf("%-16s %-10s %6s %8s %12s %12s %12s  %s\n", "units", "rule", "n", "points", "s at end (b)", "time (ms)",
              "us/point", "end");
  for (const auto& u : buckle::bench::kBenchUnits)
    for (TaskRule rule : {TaskRule::Chosen, TaskRule::MinimumChange, TaskRule::MostStable})
      for (int n : {3, 50, 1000}) {
        if (quick && n > 50) continue;
        // most_stable's optimality system (3n + 6 unknowns) has a dense, differenced Jacobian
        // (task_path.h): O(n³) per Newton step, not meant for n = 1000
        if (rule == TaskRule::MostStable && n > 50) continue;
        const Row r = run(n, u.b, u.k, rule, quick ? 1 : reps);
        const char* ruleName = rule == TaskRule::Chosen          ? "chosen"
                               : rule == TaskRule::MinimumChange ? "min_change"
                                                                 : "most_stable";
        if (!r.started) {
          std::printf("%-16s %-10s %6d   the payload could not be applied to the straight chain\n", u.name, ruleName, n);
          continue;
        }
        std::printf("%-16s %-10s %6d %8zu %12.6g %12.3f %12.1f  %s\n", u.name, ruleName, n, r.points, r.sEnd / u.b,
                    1e3 * r.seconds, 1e6 * r.seconds / double(std::max<size_t>(1, r.points)), r.end);
      }
  return 0;
}
