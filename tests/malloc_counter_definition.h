// The interposed malloc of malloc_counter.h: included by exactly one file of each test program
// (no include guard, so that a second inclusion into one unity batch fails to compile rather than
// a second definition being dropped).
#include "malloc_counter.h"

#if BUCKLE_COUNT_MALLOC
extern "C" void *__libc_malloc(std::size_t size);
extern "C" void *malloc(std::size_t size) noexcept {
  buckle::testing::mallocCalls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
#endif
