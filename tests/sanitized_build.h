// Whether the tests run under AddressSanitizer (.ci/run's second stage: -O1, Eigen's assertions
// on, every access checked). The few tests whose cost is a dense reference at a large n compare
// at a smaller n there: the sanitizers look for memory and undefined-behaviour errors, which the
// smaller chains reach through the same code paths, and the full sizes run in the Release build.
#pragma once

namespace buckle::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
#else
inline constexpr bool kSanitizedBuild = false;
#endif

}  // namespace buckle::test
