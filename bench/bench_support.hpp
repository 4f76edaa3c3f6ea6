#pragma once
// What several benchmarks share: the calling thread's CPU time and the median
// of repeated measurements.

#include <algorithm>
#include <cstddef>
#include <vector>

#include <time.h>

namespace sphshell::bench {

// CPU seconds of the calling thread: on a loaded machine wall time mostly
// measures the other processes.
inline double thread_seconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

// The middle value; the mean of the two middle ones for an even count.
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace sphshell::bench
