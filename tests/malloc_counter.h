// Counts heap allocations, for the tests that hot loops allocate nothing. Interposes malloc,
// through which operator new, Eigen and SUNDIALS all allocate. Any test file may include it; exactly
// one file per test program includes malloc_counter_definition.h, the interposed malloc.
// Disabled under AddressSanitizer and ThreadSanitizer, which own malloc: BUCKLE_COUNT_MALLOC is
// then 0 and the tests say so.
#pragma once

#include <atomic>
#include <cstddef>

namespace buckle::testing {
inline std::atomic<long> mallocCalls{0};
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define BUCKLE_COUNT_MALLOC 0
#else
#define BUCKLE_COUNT_MALLOC 1
#endif
