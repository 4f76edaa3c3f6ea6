#pragma once
// What several benchmarks share: the calling thread's CPU time, the median
// of repeated measurements, the machine's multiply-add peak, and pinning a
// thread to a processor (Linux).

#include <benchmark/benchmark.h>

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

// The floating-point roof of one thread: 16 independent multiply-add chains
// x = x·m + a over 8 doubles each, 2 flops per element and pass, in whatever
// vector width the build allows (the compiler vectorizes the inner loop and,
// with FMA, contracts each pair into one instruction). Returns the flops of
// one call; `passes` sets its length (4096: about 50 µs at 20 GFLOP/s).
inline double multiply_add_chains(int passes = 4096) {
  constexpr int chains = 16, lanes = 8;
  alignas(64) double x[chains][lanes];
  for (int c = 0; c < chains; ++c)
    for (int l = 0; l < lanes; ++l) x[c][l] = 1.0 + 1e-3 * (c + l);
  const double m = 0.999999, add = 1e-6;
  for (int r = 0; r < passes; ++r)
    for (int c = 0; c < chains; ++c)
      for (int l = 0; l < lanes; ++l) x[c][l] = x[c][l] * m + add;
  benchmark::DoNotOptimize(x);
  return 2.0 * chains * lanes * passes;
}

// The multiply-add peak in flop/s, CPU time of the calling thread, the best
// of `tries` calls of multiply_add_chains (the best, not the median: the
// roof is what the processor can do, and a call slowed by another process
// measures that process).
inline double multiply_add_peak(int tries = 50) {
  double best = 0.0;
  for (int k = 0; k < tries; ++k) {
    const double start = thread_seconds();
    const double flops = multiply_add_chains();
    const double seconds = thread_seconds() - start;
    if (seconds > 0.0) best = std::max(best, flops / seconds);
  }
  return best;
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
