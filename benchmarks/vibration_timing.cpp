// vibration_timing: cost per point of the natural frequencies (mechanics/vibration.h) over the
// chain length (issue 31), both routes side by side: the lowest `count` modes with their shapes of
// the clamped–pinned chain (y held) of the paper's segments (a = 0.5, b = 1, k = 1, L0 = 2.25) bent
// to q_i = (0.5/n) sin(3πi/n) under Fx = −0.1, slender rods of unit mass per length. Each row: n,
// count, route, wall and CPU seconds per point (best of `reps`; the structured route cold, i.e.
// without the previous point's values, and warm, the same point again: its Newton start along a
// branch), and ω₁² (a figure to compare across runs and routes). The dense route runs up to
// n = 1000 (O(n³)). Then the same with the middle segment's distal corner held on the base wall by
// a force of 0.05 (a wall stretch: one more bordered row and the force's Hessian term; the rows
// "…+wall").
//
//   vibration_timing [--quick] [--n N] [--reps R] [--count K]
//     --quick    CI size: n = 3 and 50, one repetition
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "buckle/mechanics/vibration.h"

using namespace buckle::mechanics;

namespace {

int usage(const char* why) {
  std::fprintf(stderr, "vibration_timing: %s\nusage: vibration_timing [--quick] [--n N] [--reps R] [--count K]\n", why);
  return 2;
}

bool positiveInt(const char* s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (!end || *end != '\0' || v < 1 || v > 100000) return false;
  out = int(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {3, 50, 300, 1000, 10000};
  int reps = 3, count = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    int v = 0;
    if (a == "--quick") {
      sizes = {3, 50};
      reps = 1;
    } else if ((a == "--n" || a == "--reps" || a == "--count") && i + 1 < argc && positiveInt(argv[i + 1], v)) {
      ++i;
      if (a == "--n") sizes = {v};
      if (a == "--reps") reps = v;
      if (a == "--count") count = v;
    } else {
      return usage(("bad argument " + a).c_str());
    }
  }
  std::printf("%6s %6s %-21s %12s %12s %22s\n", "n", "count", "route", "wall_s", "cpu_s", "omega1_sq");
  for (int n : sizes) {
    const Chain chain = Chain::uniform(n, SegmentParameters::symmetric(0.5, 1.0, 1.0, 2.25));
    Vector q(n);
    for (int i = 0; i < n; ++i) q[i] = 0.5 / n * std::sin(3.0 * 3.141592653589793 * (i + 1) / n);
    struct Run {
      const char* name;
      VibrationRoute route;
      bool warm;
    };
    ContactSet onWall;
    onWall.touch(WallVertex{n / 2, 3});
    const Vector wallForce = Vector::Constant(1, 0.05);
    const ContactSet none;
    for (const bool wallStretch : {false, true}) {
      const ContactSet& contacts = wallStretch ? onWall : none;
      const Vector forces = wallStretch ? wallForce : Vector();
      for (const Run& run : {Run{"dense", VibrationRoute::Dense, false}, Run{"structured-cold", VibrationRoute::Structured, false},
                             Run{"structured-warm", VibrationRoute::Structured, true}}) {
        if (run.route == VibrationRoute::Dense && n > 1000) continue;
        double wall = 1e300, cpu = 1e300, omega1 = 0.0;
        for (int r = 0; r < reps; ++r) {
          // a fresh analysis per cold repetition (no previous values); warm: one call before the timed one
          VibrationAnalysis va(chain, InertiaData::uniformRods(chain, 1.0));
          va.setRoute(run.route);
          if (run.warm) va.modes(q, Wrench(-0.1, 0.0, 0.0), {1}, contacts, forces, count, true);
          const auto t0 = std::chrono::steady_clock::now();
          const std::clock_t c0 = std::clock();
          const VibrationModes m = va.modes(q, Wrench(-0.1, 0.0, 0.0), {1}, contacts, forces, count, true);
          cpu = std::min(cpu, double(std::clock() - c0) / CLOCKS_PER_SEC);
          wall = std::min(wall, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
          omega1 = m.omegaSquared[0];
        }
        const std::string name = std::string(run.name) + (wallStretch ? "+wall" : "");
        std::printf("%6d %6d %-21s %12.4g %12.4g %22.15g\n", n, count, name.c_str(), wall, cpu, omega1);
      }
    }
  }
  return 0;
}
