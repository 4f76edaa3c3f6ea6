#pragma once
// What several benchmarks share: the calling thread's CPU time, the median
// of repeated measurements, and pinning a thread to a processor (Linux).

#include <algorithm>
#include <cstddef>
#include <vector>

#include <pthread.h>
#include <sched.h>
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

// The first two processors the calling thread may run on (fewer if it may
// use fewer), and pinning the calling thread to one of them and back (the
// processors it was allowed before, also when the pin goes out of scope).
class ProcessorPin {
 public:
  ProcessorPin() {
    CPU_ZERO(&allowed_);
    if (pthread_getaffinity_np(pthread_self(), sizeof allowed_, &allowed_) != 0) return;
    for (int cpu = 0; cpu < CPU_SETSIZE && processors_.size() < 2; ++cpu)
      if (CPU_ISSET(cpu, &allowed_)) processors_.push_back(cpu);
  }
  ~ProcessorPin() { release(); }
  ProcessorPin(const ProcessorPin&) = delete;
  ProcessorPin& operator=(const ProcessorPin&) = delete;
  const std::vector<int>& processors() const { return processors_; }
  // Pins the calling thread (any thread) to processor `cpu`.
  static bool pin(int cpu) {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    return pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
  }
  void release() { pthread_setaffinity_np(pthread_self(), sizeof allowed_, &allowed_); }

 private:
  cpu_set_t allowed_;
  std::vector<int> processors_;
};

}  // namespace sphshell::bench
