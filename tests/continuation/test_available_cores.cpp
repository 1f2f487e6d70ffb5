#include "buckle/continuation/available_cores.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <thread>

#if defined(__linux__)
#include <sched.h>
#endif

using buckle::continuation::availableCores;

TEST_CASE("The cores a process may use: its affinity mask, not the machine's count", "[available_cores]") {
  const int all = availableCores();
  CHECK(all >= 1);
  CHECK(all <= int(std::max(1u, std::thread::hardware_concurrency())));
#if defined(__linux__)
  // Pinned to one CPU (as `taskset -c` pins it), the process has one core; restored afterwards.
  cpu_set_t before;
  CPU_ZERO(&before);
  REQUIRE(sched_getaffinity(0, sizeof(before), &before) == 0);
  int first = 0;
  while (!CPU_ISSET(first, &before)) ++first;
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  REQUIRE(sched_setaffinity(0, sizeof(one), &one) == 0);
  const int pinned = availableCores();
  REQUIRE(sched_setaffinity(0, sizeof(before), &before) == 0);
  CHECK(pinned == 1);
  CHECK(availableCores() == all);
#endif
}
