// The machine's two roofs, for the roofline in docs/performance.md: memory
// bandwidth (STREAM-like triad a = b + s·c on three 32 MiB arrays, counted as
// 24 bytes per element: two reads and a write; write-allocate traffic not
// counted) and floating-point peak (16 independent multiply-add chains
// x = x·m + a, 2 flops each, in whatever vector width the build allows), each
// on one thread; run them beside the step benchmarks, under the same load.
// A third figure is for the threads paragraph: the time a cache line takes to
// go from one processor to another and back (two threads pinned to the first
// two processors the process may use pass a flag to and fro). What two
// threads of a step share moves at that price (docs/performance.md,
// "Threads"). It wants both processors free: with another process on one of
// them, each trip can wait for a time slice.
#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <atomic>
#include <chrono>
#include <cstddef>
#include <thread>
#include <vector>

namespace {

void triad_bandwidth(benchmark::State& state) {
  constexpr std::size_t n = std::size_t{32} << 20 >> 3;  // 32 MiB of doubles per array
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 0.5;
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<long long>(state.iterations()) * static_cast<long long>(3 * n * sizeof(double)));
}

void multiply_add_peak(benchmark::State& state) {
  double flops = 0.0;
  for (auto _ : state) flops = sphshell::bench::multiply_add_chains();
  state.counters["flops"] = benchmark::Counter(flops, benchmark::Counter::kIsIterationInvariantRate);
}

void core_to_core_round_trip(benchmark::State& state) {
  const std::vector<int> processors = sphshell::bench::first_two_processors();
  if (processors.size() < 2) {
    state.SkipWithError("needs two processors to pin threads to");
    return;
  }
  constexpr int trips = 100000;
  // The flag on a cache line of its own: `ready` from the other thread once it
  // is pinned, then `there` from this one and `back` from the other per trip.
  enum : int { back = 0, there = 1, ready = 2 };
  struct alignas(64) Flag {
    std::atomic<int> value{back};
  } flag;
  bool pinned = true;
  for (auto _ : state) {
    flag.value.store(back);
    bool other_pinned = false;  // read after join(), which orders it
    std::thread other([&] {
      const sphshell::bench::ProcessorPin pin(processors[1]);
      other_pinned = pin.pinned();
      flag.value.store(ready, std::memory_order_release);
      for (int k = 0; k < trips; ++k) {
        while (flag.value.load(std::memory_order_acquire) != there) {
        }
        flag.value.store(back, std::memory_order_release);
      }
    });
    const sphshell::bench::ProcessorPin pin(processors[0]);
    while (flag.value.load(std::memory_order_acquire) != ready) {
    }
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < trips; ++k) {
      flag.value.store(there, std::memory_order_release);
      while (flag.value.load(std::memory_order_acquire) != back) {
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    other.join();
    pinned = pinned && pin.pinned() && other_pinned;
    state.SetIterationTime(seconds / trips);
  }
  if (!pinned) state.SkipWithError("could not pin the two threads to processors");
}

}  // namespace

BENCHMARK(triad_bandwidth)->Unit(benchmark::kMillisecond);
BENCHMARK(multiply_add_peak)->Unit(benchmark::kMicrosecond);
BENCHMARK(core_to_core_round_trip)->UseManualTime()->Iterations(5)->Unit(benchmark::kNanosecond);

BENCHMARK_MAIN();
