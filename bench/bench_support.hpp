#pragma once
// What several benchmarks share: the calling thread's CPU time, the median
// of repeated measurements, and pinning a thread to a processor (Linux).

#include <algorithm>
#include <cstddef>
#include <vector>

#include <time.h>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

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

// Pinning threads to processors, for the benchmarks that compare processors
// (Linux: elsewhere no processor is listed and those benchmarks leave the
// comparison out).
#ifdef __linux__
// The first two processors the calling thread may run on (fewer if it may use
// fewer, none if they cannot be read).
inline std::vector<int> first_two_processors() {
  std::vector<int> processors;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed) != 0) return processors;
  for (int cpu = 0; cpu < CPU_SETSIZE && processors.size() < 2; ++cpu)
    if (CPU_ISSET(cpu, &allowed)) processors.push_back(cpu);
  return processors;
}

// Pins the thread that constructs it to one processor while it lives; the
// destructor gives that thread back the processors it was allowed before.
class ProcessorPin {
 public:
  explicit ProcessorPin(int cpu) {
    CPU_ZERO(&allowed_);
    if (pthread_getaffinity_np(pthread_self(), sizeof allowed_, &allowed_) != 0) return;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    pinned_ = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
  }
  ~ProcessorPin() {
    if (pinned_) pthread_setaffinity_np(pthread_self(), sizeof allowed_, &allowed_);
  }
  ProcessorPin(const ProcessorPin&) = delete;
  ProcessorPin& operator=(const ProcessorPin&) = delete;
  bool pinned() const { return pinned_; }

 private:
  cpu_set_t allowed_;
  bool pinned_ = false;
};
#else
inline std::vector<int> first_two_processors() { return {}; }
class ProcessorPin {
 public:
  explicit ProcessorPin(int) {}
  bool pinned() const { return false; }
};
#endif

}  // namespace sphshell::bench
