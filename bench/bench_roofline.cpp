// The machine's two roofs, for the README's roofline paragraph: memory
// bandwidth (STREAM-like triad a = b + s·c on three 32 MiB arrays, counted as
// 24 bytes per element: two reads and a write; write-allocate traffic not
// counted) and floating-point peak (16 independent multiply-add chains
// x = x·m + a, 2 flops each, in whatever vector width the build allows). One
// thread; run it beside the step benchmarks, under the same load.
#include <benchmark/benchmark.h>

#include <cstddef>
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
  constexpr int chains = 16, lanes = 8, repeats = 4096;
  alignas(64) double x[chains][lanes];
  for (int c = 0; c < chains; ++c)
    for (int l = 0; l < lanes; ++l) x[c][l] = 1.0 + 1e-3 * (c + l);
  const double m = 0.999999, add = 1e-6;
  for (auto _ : state) {
    for (int r = 0; r < repeats; ++r)
      for (int c = 0; c < chains; ++c)
        for (int l = 0; l < lanes; ++l) x[c][l] = x[c][l] * m + add;
    benchmark::DoNotOptimize(x);
  }
  state.counters["flops"] = benchmark::Counter(2.0 * chains * lanes * repeats, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK(triad_bandwidth)->Unit(benchmark::kMillisecond);
BENCHMARK(multiply_add_peak)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
