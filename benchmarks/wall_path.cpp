// wall_path: cost per point of continuation with vertices held on the base wall (issue 31,
// contact.h, wall_contact.h) against the same chain's free points: n paper segments
// (a = 0.5 b, L0 = 2.25 b) whose unloaded shape is an arc of 2.8 rad (q0_i = 2.8/n, the
// preloads recomputed: unloaded_shape.h), free end, pushed back by Fx = −λ from 0 with the wall
// as a constraint. The end's distal corner reaches the wall (WC), the link then lies flat on it
// (a second WC) and the chain is pushed on with both held. Timed: the free trace up to the
// first contact, then continueUnderContact for the rest of 150 points (the wall stretches);
// beside them, 150 points of the same path without the wall (the chain passes through it).
// Stability (inertia and smallest eigenvalue) at every point. Units: nondimensional (b = 1,
// k = 1) and SI (b = 0.02 m, k = 2000 N/m). Best of `reps` runs.
//
// Built with the benchmarks (-DBUCKLE_BUILD_BENCHMARKS=ON), or by hand as actuation_path (its
// header).
//
//   wall_path [--reps R] [--quick] [--n N ...]   (default n = 3, 50, 1000)
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <vector>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/equilibrium_branches.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "common.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

struct Row {
  double freeSeconds = std::numeric_limits<double>::infinity();
  double wallSeconds = std::numeric_limits<double>::infinity();
  double ghostSeconds = std::numeric_limits<double>::infinity();
  size_t freePoints = 0, wallPoints = 0, ghostPoints = 0;
  int held = 0;          // vertices on the wall at the end
  double lambdaEnd = 0;  // Fx = −λ at the end, in k b
};

Row run(int n, double b, double k, int reps) {
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(n, 2.8 / n);
  const std::vector<SegmentParameters> segments(size_t(n), SegmentParameters::symmetric(0.5 * b, b, k, 2.25 * b));
  const Chain chain(preloadsForShape(segments, q0));
  EquilibriumOptions wall;
  wall.wallAsBoundary = true;
  cont::TracerOptions o;
  o.maxPoints = 150;
  o.lambdaMax = 100.0 * k * b;
  o.detection.stability = true;
  o.detection.lowestEigenvalues = 1;
  Row row;
  for (int r = 0; r < reps; ++r) {
    EquilibriumProblem problem(chain, EndCondition::freeEnd(), Eigen::Vector3d(-1.0, 0.0, 0.0), wall);
    auto t0 = std::chrono::steady_clock::now();
    cont::Branch branch = cont::trace(problem, q0, 0.0, cont::InitialDirection::increasingLambda(), o);
    row.freeSeconds = std::min(row.freeSeconds, buckle::bench::secondsSince(t0));
    row.freePoints = branch.points.size();
    t0 = std::chrono::steady_clock::now();
    const std::vector<ContactStretch> stretches = continueUnderContact(problem, branch, o);
    row.wallSeconds = std::min(row.wallSeconds, buckle::bench::secondsSince(t0));
    row.wallPoints = branch.points.size() - row.freePoints;
    row.held = stretches.back().locked.wallCount();
    row.lambdaEnd = branch.points.back().lambda / (k * b);
    EquilibriumProblem ghost(chain, EndCondition::freeEnd(), Eigen::Vector3d(-1.0, 0.0, 0.0));
    t0 = std::chrono::steady_clock::now();
    const cont::Branch through = cont::trace(ghost, q0, 0.0, cont::InitialDirection::increasingLambda(), o);
    row.ghostSeconds = std::min(row.ghostSeconds, buckle::bench::secondsSince(t0));
    row.ghostPoints = through.points.size();
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const buckle::bench::PathArgs args = buckle::bench::pathArgs(argc, argv, {3, 50, 1000});
  std::printf("%-16s %6s %12s %14s %12s %14s %6s %14s %18s\n", "units", "n", "free points", "free us/point",
              "wall points", "wall us/point", "held", "-Fx end (k b)", "no wall us/point");
  for (const buckle::bench::BenchUnits& u : buckle::bench::kBenchUnits)
    for (int n : args.sizes) {
      if (args.quick && n > 50) continue;
      const Row r = run(n, u.b, u.k, args.reps);
      std::printf("%-16s %6d %12zu %14.1f %12zu %14.1f %6d %14.6g %18.1f\n", u.name, n, r.freePoints,
                  1e6 * r.freeSeconds / double(std::max<size_t>(1, r.freePoints)), r.wallPoints,
                  1e6 * r.wallSeconds / double(std::max<size_t>(1, r.wallPoints)), r.held, r.lambdaEnd,
                  1e6 * r.ghostSeconds / double(std::max<size_t>(1, r.ghostPoints)));
    }
  return 0;
}
