#pragma once
// Shared by the test modules: the long scenarios that `make test` runs in its optimised half
// only. Under AddressSanitizer and UBSan the walking dress's full runs take ten times their
// seconds, and the two halves of `make test` together must fit CI's time on two cores. The
// code they run is the code shorter tests run under the sanitizers (the dress's settle and
// first frames, the skirt's scenarios, the benchmarks' other cases); what the long ones add
// is length, and length is what the optimised half checks.

#include <gtest/gtest.h>

namespace drape::testing {

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

}  // namespace drape::testing

/// First statement of a long scenario's test: skipped, and said so, in the sanitizer build.
#define DRAPE_LONG_SCENARIO()                                                                  \
  do {                                                                                         \
    if constexpr (::drape::testing::kSanitizedBuild) {                                         \
      GTEST_SKIP() << "a long scenario: make test runs it in its optimised half (build/native)"; \
    }                                                                                          \
  } while (false)
