#include "drape/core/stage_clock.hpp"

#if DRAPE_STAGE_CLOCK_TSC
#include <cpuid.h>
#endif

namespace drape {
namespace {

bool invariantCounter() {
#if DRAPE_STAGE_CLOCK_TSC
  // CPUID 0x80000007, EDX bit 8: the time-stamp counter's rate is invariant (Intel and AMD).
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(0x80000007u, &eax, &ebx, &ecx, &edx) == 0) return false;
  return (edx & (1u << 8)) != 0;
#else
  return false;
#endif
}

/// Both clocks read together at the program's start: the origin of the rate's measurement.
struct Origin {
  std::chrono::steady_clock::time_point steady;
  StageClock::Ticks ticks;
};

Origin readOrigin() { return {std::chrono::steady_clock::now(), StageClock::now()}; }

}  // namespace

const bool StageClock::kCounter = invariantCounter();

namespace {
// After kCounter: both are in this file, which initialises in order.
const Origin kOrigin = readOrigin();
}  // namespace

double StageClock::seconds(Ticks ticks) {
  if (!kCounter) return 1e-9 * static_cast<double>(ticks);
  const Ticks nowTicks = now();
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - kOrigin.steady).count();
  const Ticks span = nowTicks - kOrigin.ticks;
  if (span == 0 || !(elapsed_s > 0)) return 0.0;
  return static_cast<double>(ticks) * (elapsed_s / static_cast<double>(span));
}

}  // namespace drape
