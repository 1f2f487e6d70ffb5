#include "buckle/continuation/available_cores.h"

#include <algorithm>
#include <thread>

#if defined(__linux__)
#include <sched.h>
#endif

namespace buckle::continuation {

int availableCores() {
#if defined(__linux__)
  // std::thread::hardware_concurrency() counts the machine's online CPUs, not those the process
  // may use: workers beyond them would only take turns.
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) == 0) return std::max(1, CPU_COUNT(&mask));
#endif
  return int(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace buckle::continuation
