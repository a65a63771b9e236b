#pragma once
// A cheap clock for timing the stages of a substep.
//
// The solver and the colliders time every stage of every substep: about 430 readings of
// `std::chrono::steady_clock::now()` per frame of the walking skirt, at some 28 ns each on
// the machines we measure on (a call into libstdc++, then the vDSO's scaling of the
// time-stamp counter), 3 % of the skirt's step. The counter itself, read in order, costs
// about 18 ns, and the solver reads it once per stage boundary (`lap`).
// Ticks are summed as integers and turned into seconds only when read.

#include <chrono>
#include <cstdint>

#if defined(__x86_64__)
#include <x86intrin.h>
#define DRAPE_STAGE_CLOCK_TSC 1
#else
#define DRAPE_STAGE_CLOCK_TSC 0
#endif

namespace drape {

/// Monotonic ticks: the processor's time-stamp counter where it runs at a constant rate in
/// every power state (an "invariant" counter, which the processor reports), else the steady
/// clock's nanoseconds.
class StageClock {
 public:
  using Ticks = std::uint64_t;

  [[nodiscard]] static Ticks now() noexcept {
#if DRAPE_STAGE_CLOCK_TSC
    if (kCounter) {
      // Ordered as the kernel reads it: the stage before has finished (else its last
      // instructions could count towards the next).
      _mm_lfence();
      return __rdtsc();
    }
#endif
    return static_cast<Ticks>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
            .count());
  }

  /// Adds the ticks since `since` to `total` and returns now: one reading per stage
  /// boundary when stages follow each other.
  static Ticks lap(Ticks& total, Ticks since) noexcept {
    const Ticks t = now();
    total += t - since;
    return t;
  }

  /// Ticks as seconds. On the counter, its rate is measured against the steady clock from
  /// the program's start to this call (to about 1e-6 after the first hundredth of a second).
  [[nodiscard]] static double seconds(Ticks ticks);

  /// Whether the ticks are the time-stamp counter's (else nanoseconds).
  [[nodiscard]] static bool usesCounter() noexcept { return kCounter; }

 private:
  static const bool kCounter;
};

}  // namespace drape
