// actuation_path: wall time of a control path (issue 29): the free end of n paper segments
// (a = 0.5 b, L0 = 2.25 b) under the payload Fx = Fy = −0.9/n k b (−0.3 at n = 3, the
// actuation_dL0 scene), driven by dL0 of every segment from 0 downwards, 100 continuation points
// with stability (inertia and smallest eigenvalue at every point) and fold location; the start
// (the straight chain loaded to the payload) is not timed. Units: nondimensional (b = 1, k = 1)
// and SI (b = 0.02 m, k = 2000 N/m: the same path in metres and newtons). Best of `reps` runs.
//
// Built with the benchmarks (-DBUCKLE_BUILD_BENCHMARKS=ON: build-bench/bin/actuation_path), or by
// hand against a build's libraries: g++ -O3 -DNDEBUG -std=c++17 -I libcontinuation/include
// -isystem /usr/include/eigen3 benchmarks/actuation_path.cpp build/libcontinuation/libbuckle_mechanics.a
// build/libcontinuation/libbuckle_continuation.a -lsundials_kinsol -lsundials_nvecserial
// -lsundials_sunlinsoldense -lsundials_sunmatrixdense -o /tmp/actuation_path
//
//   actuation_path [--reps R] [--quick]
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "payload_paths.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

struct Row {
  double seconds = std::numeric_limits<double>::infinity();
  double loadSeconds = std::numeric_limits<double>::infinity();  // the load path from the same start
  size_t points = 0, folds = 0;
  double lambdaEnd = 0.0;
  bool started = false;
};

Row run(int n, double b, double k, int reps) {
  const Chain chain = buckle::bench::payloadChain(n, b, k);
  const Eigen::Vector3d payload = buckle::bench::payloadOf(n, b, k);
  Row row;
  // the start: the straight chain loaded to the payload (not timed)
  Eigen::VectorXd start;
  if (!buckle::bench::loadedStart(chain, payload, start)) return row;
  row.started = true;
  for (int r = 0; r < reps; ++r) {
    EquilibriumProblem actuated(chain, EndCondition::freeEnd(payload), Eigen::Vector3d::Zero(), {},
                                ControlDirection::named(n, ControlInput::dL0));
    cont::TracerOptions o;
    o.maxPoints = 100;
    o.detection.stability = true;
    o.detection.lowestEigenvalues = 1;
    const auto t0 = std::chrono::steady_clock::now();
    const cont::Branch b = cont::trace(actuated, start, 0.0, cont::InitialDirection::decreasingLambda(), o);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.seconds = std::min(row.seconds, s);
    row.points = b.points.size();
    row.folds = b.specialPointsOfType(cont::SpecialPointType::Fold).size();
    row.lambdaEnd = b.points.back().lambda;
    // for comparison: 100 points of the load path (the payload's factor) from the same start
    EquilibriumProblem loadPath(chain, EndCondition::freeEnd(), payload);
    const auto t1 = std::chrono::steady_clock::now();
    cont::trace(loadPath, start, 1.0, cont::InitialDirection::increasingLambda(), o);
    row.loadSeconds = std::min(row.loadSeconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  bool quick = false;
  buckle::bench::parseRepsQuick(argc, argv, reps, quick);
  std::printf("%-16s %6s %8s %6s %14s %12s %12s %16s\n", "units", "n", "points", "folds", "dL0 at end (b)", "time (ms)",
              "us/point", "load path (ms)");
  for (const auto& u : buckle::bench::kBenchUnits)
    for (int n : {3, 50, 1000}) {
      if (quick && n > 50) continue;
      const Row r = run(n, u.b, u.k, reps);
      if (!r.started) {
        std::printf("%-16s %6d   the payload could not be applied to the straight chain\n", u.name, n);
        continue;
      }
      std::printf("%-16s %6d %8zu %6zu %14.6g %12.3f %12.1f %16.3f\n", u.name, n, r.points, r.folds, r.lambdaEnd / u.b,
                  1e3 * r.seconds, 1e6 * r.seconds / double(r.points), 1e3 * r.loadSeconds);
    }
  return 0;
}
