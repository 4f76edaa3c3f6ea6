// Cost of one explicit step of the paper's plate (51 × 51 particles, 2500
// stress points, 0.5 m, 10 mm, clamped, 1 MPa, nonlinear), one thread:
//  - paper_plate_step: per thickness rule and approximation, J2 plasticity
//    (and Gauss<5> elastic), timed from 1 ms on, when the plate has yielded.
//    Counters: ns_per_particle_step (CPU time of the stepping thread),
//    gflops (the step's counted flops, counted_flops_per_particle_step, over
//    that time), peak_gflops (the multiply-add roof of the same build,
//    bench_support.hpp, measured in the same run) and of_peak, their ratio;
//    vector_bits is the width of the instruction set the program was compiled
//    for, whose name and the configured SPHSHELL_SIMD are in the context
//    lines (instruction_set, sphshell_simd) at the top of the output;
//  - with fracture: the step cost of Lemaitre damage at q = 5 MPa while the
//    cracks grow (1.55–1.85 ms), crack::LineSegments against crack::None,
//    each alone and, in fracture_cost_ratio, both advanced in alternating
//    chunks of steps so that a change of machine load hits both alike (the
//    counter `ratio` is LineSegments' time over None's).
// Run single-threaded (OMP_NUM_THREADS=1) for per-step figures.
#include <sphshell/approx/all.hpp>
#include <sphshell/core/simd.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <chrono>
#include <cstring>
#include <memory>
#include <type_traits>

using namespace sphshell;
using sphshell::bench::thread_seconds;

namespace {

// The instruction set in the output's context lines: the one the compiler
// targeted here and the one the package was configured with.
const bool instruction_set_in_context = [] {
  benchmark::AddCustomContext("instruction_set", simd::instruction_set());
  benchmark::AddCustomContext("sphshell_simd", simd::configured_instruction_set());
  return true;
}();

// Width of a vector register of the set the compiler targeted here (64: scalar).
int vector_bits() {
  const char* set = simd::instruction_set();
  if (std::strcmp(set, "AVX_512") == 0) return 512;
  if (std::strcmp(set, "AVX2_256") == 0) return 256;
  if (std::strcmp(set, "SSE2") == 0) return 128;
  return 64;
}

// The flops of one step, counted from the code (no hardware counters on the
// machines measured; docs/performance-history.md, "The roofline, as first
// counted"): per shape-function slot 30 in the gather of the neighbours'
// positions and directors and 30 in the force sum; per integration point 60
// for the strains and 90 for the conjugate forces; per thickness point 38 in
// the section (elastic predictor, yield check, return map, resultants: 190
// for Gauss<5>), a resultant rule counted as one; per stress point 150 for the
// tied transverse shear. Gauss<5> on this plate: about 2.3 kflop per particle.
template <class Approx, class Rule>
double counted_flops_per_step(const ShellModel& model, const SolverOptions& options, double shear_modulus,
                              double poisson_ratio) {
  const solver::IntegrationPoints<Approx> points(model, options.physics(), options.particle_integration(),
                                                 shear_modulus, poisson_ratio);
  constexpr double per_slot = 30.0 + 30.0, per_point = 60.0 + 90.0, per_thickness_point = 38.0;
  constexpr double per_stress_point = 150.0;
  constexpr int thickness_points = Rule::num_points > 0 ? Rule::num_points : 1;
  return per_slot * double(points.slot_count()) +
         (per_point + per_thickness_point * thickness_points) * double(points.size()) +
         per_stress_point * double(points.count(solver::PointGroup::stress_points));
}

// The multiply-add roof of this build, measured once per run.
double peak_flops() {
  static const double peak = sphshell::bench::multiply_add_peak();
  return peak;
}

constexpr double paper_pressure = 1e6, yielded_from = 1e-3;

template <class Law>
typename Law::Parameters paper_material() {
  if constexpr (std::is_same_v<Law, material::Elastic>)
    return {210e9, 0.3};
  else
    return {210e9, 0.3, 235e6, 0.0};
}

// The paper's plate as examples/square_plate --case plastic runs it, stepped
// untimed to 1 ms (yielded), then timed step by step on this thread's clock.
template <class Approx, class Rule, class Law>
void paper_plate_step(benchmark::State& state) {
  SolverOptions options;
  options.density = 7850.0;
  options.nonlinear = true;
  const ShellModel model = ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01);
  Solver<Approx, Rule, Law> solver(model, paper_material<Law>(), options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), paper_pressure);
  solver.run_until(yielded_from);
  const double poisson_ratio = 0.3, shear_modulus = 210e9 / (2.0 * (1.0 + poisson_ratio));
  const double flops = counted_flops_per_step<Approx, Rule>(model, options, shear_modulus, poisson_ratio);
  double seconds = 0.0;
  long steps = 0;
  for (auto _ : state) {
    const double start = thread_seconds();
    solver.step();
    seconds += thread_seconds() - start;
    ++steps;
  }
  const double particles = double(solver.particle_count());
  const double peak = peak_flops();
  state.counters["ns_per_particle_step"] = 1e9 * seconds / (double(steps) * particles);
  state.counters["flops_per_particle_step"] = flops / particles;
  state.counters["gflops"] = 1e-9 * flops * double(steps) / seconds;
  state.counters["peak_gflops"] = 1e-9 * peak;
  state.counters["of_peak"] = flops * double(steps) / seconds / peak;
  state.counters["vector_bits"] = vector_bits();
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

using MLS = approx::MLS<kernel::CubicSpline>;
using NSPH = approx::NSPH<kernel::CubicSpline>;
using J2 = material::J2Plasticity;
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Gauss<5>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Global, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Gauss<2>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Gauss<3>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Gauss<7>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Simpson<5>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, NSPH, thickness::Gauss<5>, J2)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(paper_plate_step, MLS, thickness::Gauss<5>, material::Elastic)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(fracture_plate_step, crack::None)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(fracture_plate_step, crack::LineSegments)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(fracture_cost_ratio)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
