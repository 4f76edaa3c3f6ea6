// How the step's cost grows with the model, and what the thickness rules cost
// against each other; one thread (the benchmark sets it), timed in that
// thread's CPU time.
//  - size_sweep: the paper's square plate (0.5 m, 10 mm, clamped, J2, Gauss<5>)
//    at 51², 101², 201² and 401² particles under 0.1 MPa, which keeps it
//    elastic (counter plastic_points: stress points that yielded). The
//    four solvers step in turns, each for about the same number of
//    particle-steps per turn, so a change of machine load hits all sizes
//    alike. Counters: ns_per_particle_step_<n> (median over the turns), the
//    ratio of 401² to 51², and bytes_per_particle_<n>: the growth of the
//    resident set while the solver was built, over its particles.
//  - rule_cost_ratio: Global against Gauss<5> on the same plate (51², J2,
//    1 MPa) once it is plastic (from 1 ms on), alternating chunks of 10 steps;
//    `ratio` is Global's time over Gauss<5>'s.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

using namespace sphshell;
using sphshell::bench::median;
using sphshell::bench::thread_seconds;

namespace {

template <class Rule>
using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, Rule, material::J2Plasticity>;

template <class Rule>
std::unique_ptr<PlateSolver<Rule>> paper_plate(int n, double pressure) {
  SolverOptions options;
  options.density = 7850.0;
  auto solver = std::make_unique<PlateSolver<Rule>>(ShellModel::rectangular_plate(0.5, 0.5, n, n, 0.01),
                                                    material::J2Plasticity::Parameters{210e9, 0.3, 235e6, 0.0},
                                                    options);
  solver->clamp(solver->model().set("boundary"));
  solver->add_uniform_pressure(solver->model().all_particles(), pressure);
  return solver;
}

// Resident set size in bytes (Linux /proc/self/statm).
double resident_bytes() {
  std::FILE* file = std::fopen("/proc/self/statm", "r");
  if (!file) return 0.0;
  long pages = 0, resident = 0;
  const int read = std::fscanf(file, "%ld %ld", &pages, &resident);
  std::fclose(file);
  return read == 2 ? double(resident) * double(sysconf(_SC_PAGESIZE)) : 0.0;
}

template <class S>
double seconds_for_steps(S& solver, int steps) {
  const double start = thread_seconds();
  for (int k = 0; k < steps; ++k) solver.step();
  return thread_seconds() - start;
}

void use_one_thread() {
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

void size_sweep(benchmark::State& state) {
  use_one_thread();
  constexpr std::array<int, 4> sizes{51, 101, 201, 401};
  constexpr double particle_steps_per_turn = 2.0e6;
  constexpr int turns = 7;
  constexpr double elastic_pressure = 1e5;
  std::vector<std::unique_ptr<PlateSolver<thickness::Gauss<5>>>> solvers;
  std::vector<double> bytes_per_particle;
  for (int n : sizes) {
    const double before = resident_bytes();
    solvers.push_back(paper_plate<thickness::Gauss<5>>(n, elastic_pressure));
    solvers.back()->step();  // the first step sizes the step's own arrays
    bytes_per_particle.push_back((resident_bytes() - before) / double(solvers.back()->particle_count()));
  }
  for (auto _ : state) {
    std::vector<std::vector<double>> ns(sizes.size());
    for (int turn = 0; turn < turns; ++turn)
      for (std::size_t k = 0; k < sizes.size(); ++k) {
        auto& solver = *solvers[k];
        const double particles = double(solver.particle_count());
        const int steps = std::max(2, int(particle_steps_per_turn / particles));
        ns[k].push_back(1e9 * seconds_for_steps(solver, steps) / (particles * steps));
      }
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      const std::string n = std::to_string(sizes[k]);
      state.counters["ns_per_particle_step_" + n] = median(ns[k]);
      state.counters["bytes_per_particle_" + n] = bytes_per_particle[k];
    }
    state.counters["ratio_401_51"] = median(ns.back()) / median(ns.front());
    state.SetIterationTime(1e-9 * median(ns.front()));
    // Still elastic: the sweep measures the elastic phase.
    double plastic = 0.0;
    for (const auto& solver : solvers)
      for (std::size_t p = 0; p < solver->stress_point_count(); ++p)
        for (int k = 0; k < 5; ++k) plastic += solver->equivalent_plastic_strain(int(p), k) > 0.0 ? 1.0 : 0.0;
    state.counters["plastic_integral_points"] = plastic;
  }
}

void rule_cost_ratio(benchmark::State& state) {
  use_one_thread();
  auto global = paper_plate<thickness::Global>(51, 1e6);
  auto gauss = paper_plate<thickness::Gauss<5>>(51, 1e6);
  global->run_until(1e-3);
  gauss->run_until(1e-3);
  if (global->time_step() != gauss->time_step()) {
    state.SkipWithError("the two solvers step with different time steps");
    return;
  }
  for (auto _ : state) {
    constexpr int chunk = 10, chunks = 30;
    std::vector<double> ratios;
    double global_seconds = 0.0, gauss_seconds = 0.0;
    for (int k = 0; k < chunks; ++k) {
      const double a = seconds_for_steps(*global, chunk), b = seconds_for_steps(*gauss, chunk);
      ratios.push_back(a / b);
      global_seconds += a;
      gauss_seconds += b;
    }
    state.SetIterationTime(global_seconds / (chunk * chunks));
    state.counters["ratio"] = median(ratios);
    state.counters["global_us_per_step"] = 1e6 * global_seconds / (chunk * chunks);
    state.counters["gauss5_us_per_step"] = 1e6 * gauss_seconds / (chunk * chunks);
  }
}

}  // namespace

BENCHMARK(size_sweep)->UseManualTime()->Iterations(1)->Unit(benchmark::kNanosecond);
BENCHMARK(rule_cost_ratio)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
