// StageClock: its ticks, turned into seconds, measure the same intervals as the steady
// clock, and laps add up to the span they cover.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "drape/core/stage_clock.hpp"

namespace drape {
namespace {

using Steady = std::chrono::steady_clock;

double steadySeconds(Steady::time_point a, Steady::time_point b) { return std::chrono::duration<double>(b - a).count(); }

TEST(StageClock, SecondsAgreeWithTheSteadyClock) {
  for (const int ms : {5, 40, 120}) {
    const Steady::time_point s0 = Steady::now();
    const StageClock::Ticks t0 = StageClock::now();
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));
    const StageClock::Ticks t1 = StageClock::now();
    const Steady::time_point s1 = Steady::now();
    const double expected = steadySeconds(s0, s1);
    // Both clocks are read around the same interval: they differ by the readings' order
    // (microseconds) and the rate's measurement (a millionth).
    EXPECT_NEAR(StageClock::seconds(t1 - t0), expected, 1e-4 + 1e-3 * expected) << ms << " ms";
    EXPECT_GT(t1, t0);
  }
}

TEST(StageClock, LapsAddUpToTheirSpan) {
  StageClock::Ticks first = 0, second = 0;
  const StageClock::Ticks start = StageClock::now();
  StageClock::Ticks t = start;
  std::this_thread::sleep_for(std::chrono::milliseconds(3));
  t = StageClock::lap(first, t);
  std::this_thread::sleep_for(std::chrono::milliseconds(7));
  const StageClock::Ticks end = StageClock::lap(second, t);
  EXPECT_EQ(first + second, end - start);
  // A sleep lasts at least its duration (it may last longer on a busy machine).
  EXPECT_GE(StageClock::seconds(first), 0.003 - 1e-4);
  EXPECT_GE(StageClock::seconds(second), 0.007 - 1e-4);
}

TEST(StageClock, ZeroTicksAreZeroSeconds) { EXPECT_EQ(StageClock::seconds(0), 0.0); }

}  // namespace
}  // namespace drape
