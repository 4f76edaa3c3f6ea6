// Building all shape functions of an n × n particle plate with stress points at
// the cell centres (support radius 2 spacings). Per-point time and storage are
// the figures to compare across sizes (linear scaling) and methods. Set
// OMP_NUM_THREADS=1 for the single-thread figure; on a machine shared with
// other jobs, OMP_WAIT_POLICY=passive keeps spinning threads from distorting
// the multi-thread figure.
#include <sphshell/approx/all.hpp>
#include <sphshell/kernel/all.hpp>

#include <benchmark/benchmark.h>

#include <ctime>
#include <vector>

using namespace sphshell;

namespace {

double process_cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

struct Plate {
  std::vector<Vector3> particles;
  std::vector<double> volumes;
  std::vector<Vector3> stress_points;
  std::vector<TangentFrame> frames;
};

Plate make_plate(int n, double spacing) {
  Plate plate;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      plate.particles.emplace_back(i * spacing, j * spacing, 0.0);
      plate.volumes.push_back(spacing * spacing);
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i)
      plate.stress_points.emplace_back((i + 0.5) * spacing, (j + 0.5) * spacing, 0.0);
  plate.frames.assign(plate.stress_points.size(), tangent_frame(Vector3::UnitZ()));
  return plate;
}

template <class Approximation>
void build_shape_functions(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double spacing = 1.0 / (n - 1);
  const double h = 2.0 * spacing / Approximation::kernel_type::support_radius_factor;
  const Plate plate = make_plate(n, spacing);
  std::size_t bytes = 0, slots = 0;
  double cpu_seconds = 0.0;
  for (auto _ : state) {
    const double cpu_start = process_cpu_seconds();
    approx::ShapeFunctions sf =
        Approximation::build(plate.particles, plate.volumes, plate.stress_points, plate.frames, h);
    benchmark::DoNotOptimize(sf.value.data());
    benchmark::ClobberMemory();
    cpu_seconds += process_cpu_seconds() - cpu_start;
    bytes = sf.bytes();
    slots = sf.slots();
  }
  const auto points = static_cast<double>(plate.stress_points.size());
  // Wall time per point (real time, as the solver sees it) ...
  state.counters["time_per_point"] = benchmark::Counter(
      points, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  // ... and CPU time of all threads per point, which other jobs on a busy
  // machine disturb much less.
  state.counters["cpu_us_per_point"] = benchmark::Counter(
      1e6 * cpu_seconds / points, benchmark::Counter::kAvgIterations);
  state.counters["bytes_per_point"] = static_cast<double>(bytes) / points;
  state.counters["neighbours_per_point"] = static_cast<double>(slots) / points;
  state.counters["points"] = points;
}

void sizes(benchmark::internal::Benchmark* b) {
  b->Arg(51)->Arg(201)->Arg(801)->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace

BENCHMARK_TEMPLATE(build_shape_functions, approx::MLS<kernel::CubicSpline>)->Apply(sizes);
BENCHMARK_TEMPLATE(build_shape_functions, approx::NSPH<kernel::CubicSpline>)->Apply(sizes);
BENCHMARK_TEMPLATE(build_shape_functions, approx::MLS<kernel::WendlandC2>)->Apply(sizes);
BENCHMARK_TEMPLATE(build_shape_functions, approx::MLS<kernel::QuinticSpline>)->Apply(sizes);

BENCHMARK_MAIN();
