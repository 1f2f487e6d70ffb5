// gravity_path: cost per point of continuation in the gravity magnitude (issue 31, body_loads.h):
// the horizontal free-end chain of n paper segments (a = 0.5 b, L0 = 2.25 b) as uniform rods of
// mass per length ρ = 0.5 k b / (g_ref n² b) with a payload of the same weight as one link at the
// end, g = λ·(0, −1) from 0 upwards, 100 points with stability (inertia and smallest eigenvalue at
// every point). For comparison, 100 points of the same weightless chain under an end load Fy = −λ
// (the end-load path the body loads add to). Units: nondimensional (b = 1, k = 1) and SI
// (b = 0.02 m, k = 2000 N/m, ρ in kg/m, g in m/s²). Best of `reps` runs.
//
// Built with the benchmarks (-DBUCKLE_BUILD_BENCHMARKS=ON: build-bench/bin/gravity_path), or by
// hand as actuation_path (its header).
//
//   gravity_path [--reps R] [--quick]
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

#include "buckle/continuation/tracer.h"
#include "buckle/mechanics/body_loads.h"
#include "buckle/mechanics/equilibrium_problem.h"
#include "common.h"

using namespace buckle::mechanics;
namespace cont = buckle::continuation;

namespace {

struct Row {
  double seconds = std::numeric_limits<double>::infinity();
  double endLoadSeconds = std::numeric_limits<double>::infinity();
  size_t points = 0, endLoadPoints = 0;
  double gEnd = 0.0, tipEnd = 0.0;
};

Row run(int n, double b, double k, int reps) {
  const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5 * b, b, k, 2.25 * b));
  const double gRef = 9.81, rho = 0.5 * k * b / (gRef * n * n * b);
  const InertiaData rods = InertiaData::uniformRods(chain, rho);
  BodyLoads body = BodyLoads::weight(chain, rods, Eigen::Vector2d::Zero(), Eigen::Vector2d(0.0, -1.0));
  const double payload = rods.links[0].mass;
  body.points.push_back({n + 1, Eigen::Vector2d::Zero(), Eigen::Vector2d(0.0, -payload)});
  cont::TracerOptions o;
  o.maxPoints = 100;
  o.detection.stability = true;
  o.detection.lowestEigenvalues = 1;
  Row row;
  for (int r = 0; r < reps; ++r) {
    EquilibriumProblem heavy(chain, EndCondition::freeEnd(), Eigen::Vector3d::Zero(), {}, {}, body);
    auto t0 = std::chrono::steady_clock::now();
    const cont::Branch br = cont::trace(heavy, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
    row.seconds = std::min(row.seconds, buckle::bench::secondsSince(t0));
    row.points = br.points.size();
    row.gEnd = br.points.back().lambda;
    row.tipEnd = endPose(chain, br.points.back().u.head(n))[1] / chain.length();
    EquilibriumProblem endLoad(chain, EndCondition::freeEnd(), Eigen::Vector3d(0.0, -1.0, 0.0));
    t0 = std::chrono::steady_clock::now();
    const cont::Branch be = cont::trace(endLoad, Eigen::VectorXd::Zero(n), 0.0, cont::InitialDirection::increasingLambda(), o);
    row.endLoadSeconds = std::min(row.endLoadSeconds, buckle::bench::secondsSince(t0));
    row.endLoadPoints = be.points.size();
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 3;
  bool quick = false;
  buckle::bench::parseRepsQuick(argc, argv, reps, quick);
  std::printf("%-16s %6s %8s %12s %12s %12s %12s %18s\n", "units", "n", "points", "g at end", "tip y/L", "time (ms)",
              "us/point", "end load us/point");
  for (const buckle::bench::BenchUnits& u : buckle::bench::kBenchUnits)
    for (int n : {3, 50, 1000}) {
      if (quick && n > 50) continue;
      const Row r = run(n, u.b, u.k, reps);
      std::printf("%-16s %6d %8zu %12.6g %12.6g %12.3f %12.1f %18.1f\n", u.name, n, r.points, r.gEnd, r.tipEnd,
                  1e3 * r.seconds, 1e6 * r.seconds / double(r.points), 1e6 * r.endLoadSeconds / double(r.endLoadPoints));
    }
  return 0;
}
