#pragma once
// The timing helpers the benchmarks and `drape run` share.

#include <algorithm>
#include <ctime>
#include <vector>

namespace drape::cli {

/// This thread's CPU time, s. The benchmarks report it beside the wall clock: other
/// processes on a shared machine inflate it less (the timed work is single-threaded).
inline double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The process's CPU time, s: every thread's, for work spread over several.
inline double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The median of the values (the mean of the middle two of an even count); 0 for none.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace drape::cli
