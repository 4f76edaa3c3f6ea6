// Cost of one explicit step of the paper's plate (51 × 51 particles, 2500
// stress points):
//  - per thickness rule, elastic, the analogue of the paper's Table 4 (CPU
//    time of the integral model relative to the global model);
//  - with fracture: the step cost of Lemaitre damage at q = 5 MPa while the
//    cracks grow (1.55–1.85 ms), crack::LineSegments against crack::None.
// Run single-threaded (OMP_NUM_THREADS=1) for per-step figures.
#include <sphshell/sphshell.hpp>

#include <benchmark/benchmark.h>

#include <chrono>

using namespace sphshell;

namespace {


template <class Rule>
void elastic_plate_step(benchmark::State& state) {
  SolverOptions options;
  Solver<approx::MLS<kernel::CubicSpline>, Rule, material::Elastic> solver(
      ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01), {210e9, 0.3}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
  for (auto _ : state) solver.step();
  state.counters["particles"] = double(solver.particle_count());
}

// Runs to the onset of cracking untimed, then times the steps while cracks grow.
template <class Crack>
void fracture_plate_step(benchmark::State& state) {
  for (auto _ : state) {
    SolverOptions options;
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::LemaitreDamage, Crack> solver(
        ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01), {210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24},
        options);
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 5e6);
    solver.run_until(1.55e-3);
    const long first = solver.steps();
    const auto start = std::chrono::steady_clock::now();
    solver.run_until(1.85e-3);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(seconds / double(solver.steps() - first));
    if constexpr (Crack::enabled) {
      state.counters["crack_length_m"] = solver.crack().total_length();
      state.counters["damaged_stress_points"] = double(solver.damaged_stress_point_count());
    }
  }
}

}  // namespace

BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Global)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<2>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<3>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<4>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<5>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<6>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(elastic_plate_step, thickness::Gauss<7>)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(fracture_plate_step, crack::None)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(fracture_plate_step, crack::LineSegments)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
