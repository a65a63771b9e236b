#pragma once
// The timing helpers the benchmarks and `drape run` share.

#include <algorithm>
#include <ctime>
#include <vector>

namespace drape::cli {

/// A clock_gettime clock, s.
inline double clockSeconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// This thread's CPU time, s. The benchmarks report it beside the wall clock: other
/// processes on a shared machine inflate it less (the timed work is single-threaded).
inline double threadCpuSeconds() { return clockSeconds(CLOCK_THREAD_CPUTIME_ID); }

/// The process's CPU time, s: every thread's, for work spread over several.
inline double processCpuSeconds() { return clockSeconds(CLOCK_PROCESS_CPUTIME_ID); }

/// The median of the values (the mean of the middle two of an even count); 0 for none.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace drape::cli
