// Counts heap allocations, for the tests that hot loops allocate nothing. Interposes malloc,
// through which operator new, Eigen and SUNDIALS all allocate. Include in exactly one
// translation unit per test program. Disabled under AddressSanitizer and ThreadSanitizer, which
// own malloc: BUCKLE_COUNT_MALLOC is then 0 and the tests say so.
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
extern "C" void *__libc_malloc(std::size_t size);
extern "C" void *malloc(std::size_t size) noexcept {
  buckle::testing::mallocCalls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
#endif
