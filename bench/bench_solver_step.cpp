// Cost of one explicit step of the paper's plate (51 × 51 particles, 2500
// stress points):
//  - per thickness rule, elastic, the analogue of the paper's Table 4 (CPU
//    time of the integral model relative to the global model);
//  - with fracture: the step cost of Lemaitre damage at q = 5 MPa while the
//    cracks grow (1.55–1.85 ms), crack::LineSegments against crack::None,
//    each alone and, in fracture_cost_ratio, both advanced in alternating
//    chunks of steps so that a change of machine load hits both alike (the
//    counter `ratio`, to stay ≤ 1.3).
// Run single-threaded (OMP_NUM_THREADS=1) for per-step figures.
#include <sphshell/sphshell.hpp>

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>

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

template <class Crack>
using FracturePlateSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::LemaitreDamage, Crack>;

// The paper's plate at q = 5 MPa (Table 3 damage parameters), run untimed to
// the onset of cracking.
template <class Crack>
std::unique_ptr<FracturePlateSolver<Crack>> plate_at_crack_onset() {
  auto solver = std::make_unique<FracturePlateSolver<Crack>>(
      ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01), material::LemaitreDamage::Parameters{210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24},
      SolverOptions{});
  solver->clamp(solver->model().set("boundary"));
  solver->add_uniform_pressure(solver->model().all_particles(), 5e6);
  solver->run_until(1.55e-3);
  return solver;
}

template <class S>
double seconds_for_steps(S& solver, int steps) {
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) solver.step();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Times the steps while cracks grow.
template <class Crack>
void fracture_plate_step(benchmark::State& state) {
  for (auto _ : state) {
    const auto owner = plate_at_crack_onset<Crack>();
    FracturePlateSolver<Crack>& solver = *owner;
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

// Both solvers from the onset of cracking to 1.85 ms, alternating chunks of
// 10 steps; the reported time is LineSegments' per step, `ratio` the cost
// ratio LineSegments / None over the same steps.
void fracture_cost_ratio(benchmark::State& state) {
  for (auto _ : state) {
    const auto intact_solver = plate_at_crack_onset<crack::None>();
    const auto cracked_solver = plate_at_crack_onset<crack::LineSegments>();
    FracturePlateSolver<crack::None>& intact = *intact_solver;
    FracturePlateSolver<crack::LineSegments>& cracked = *cracked_solver;
    if (intact.time_step() != cracked.time_step()) {
      state.SkipWithError("the two solvers step with different time steps");
      break;
    }
    const int chunk = 10;
    double intact_seconds = 0.0, cracked_seconds = 0.0;
    long steps = 0;
    while (cracked.time() < 1.85e-3) {
      intact_seconds += seconds_for_steps(intact, chunk);
      cracked_seconds += seconds_for_steps(cracked, chunk);
      steps += chunk;
    }
    state.SetIterationTime(cracked_seconds / double(steps));
    state.counters["ratio"] = cracked_seconds / intact_seconds;
    state.counters["none_us_per_step"] = 1e6 * intact_seconds / double(steps);
    state.counters["crack_length_m"] = cracked.crack().total_length();
    state.counters["damaged_stress_points"] = double(cracked.damaged_stress_point_count());
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
BENCHMARK(fracture_cost_ratio)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
