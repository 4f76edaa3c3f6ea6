// Static solutions against the hand-tuned damped explicit runs they replace,
// both measured in one run (figures: docs/performance.md, "Static solutions"):
//  - clamped_plate_*: the clamped square plate of tests/test_solver_plate.cpp
//    (L = 1 m, L/d = 50, 21 x 21 particles, Gauss<2>, q = 1 kPa, linear),
//    against Mindlin's w D/(q L^4) = 0.0012754;
//  - cantilever_*: the cantilever strip under a fixed end shear of
//    tests/test_solver_shells.cpp (L = 0.5 m, 0.1 m wide, d = 0.02 m, nu = 0,
//    21 x 5 particles, Gauss<3>, nonlinear), the argument PL^2/EI = 1 or 2,
//    against the elastica's tip deflection w/L = 0.30172 and 0.49346
//    (Bisshopp & Drucker 1945; Mattiasson 1981), the values the test uses;
//  - plate_101_static: the clamped plate at 101 x 101 particles, Newton
//    (StaticMass::tangent) against the relaxation (the default); plate_tangent:
//    what a Newton iteration is made of at 101 x 101 and 201 x 201: one tangent
//    assembly (the one solve_static and sphshell::statics run) in force
//    evaluations, counted and in CPU time, and the sparse factorisations of it
//    (time, entries of L, memory).
// *_damped is the test's explicit run exactly (mass-proportional damping,
// run_until the test's end time); *_static is Solver::solve_static with the
// parameters named below. The time is the wall time of run_until /
// solve_static alone (the set-up, the same for both and a few ms, is the
// counter setup_s).
// Counters: the deflection each reaches (wDqL4, tip_w_over_L), its error in %
// of the reference (error_pct), the explicit steps or the force evaluations
// it took, the damped run's relative change over its last period.
// After the run the program prints, per case, the median wall and CPU times
// of both over the repetitions, their ratio (damped / static), and the
// difference of the static deflection from the damped one.
// plate_101_static / plate_tangent (not in the summary below) report
// their counters alone. Each benchmark runs its solve once per repetition; with
//   OMP_NUM_THREADS=1 ./bench_static --benchmark_repetitions=3
//   --benchmark_enable_random_interleaving=true
// (one command line) the repetitions of all of them interleave, so a change
// of the machine's load hits both variants alike.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/statics/sparse_factorisation.hpp>
#include <sphshell/statics/tangent.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <time.h>

using namespace sphshell;
using sphshell::bench::median;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of the process (one thread: OMP_NUM_THREADS=1).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Wall times and answers measured so far, per case ("plate", "cantilever 1", ...).
struct Measured {
  std::vector<double> damped_seconds, static_seconds, damped_cpu, static_cpu;
  double damped_answer = std::numeric_limits<double>::quiet_NaN(), static_answer = damped_answer;
};
std::map<std::string, Measured>& measured() {
  static std::map<std::string, Measured> cases;
  return cases;
}

void report_damped(const std::string& name, double seconds, double cpu, double answer) {
  Measured& m = measured()[name];
  m.damped_seconds.push_back(seconds);
  m.damped_cpu.push_back(cpu);
  m.damped_answer = answer;
}

void report_static(const std::string& name, double seconds, double cpu, double answer) {
  Measured& m = measured()[name];
  m.static_seconds.push_back(seconds);
  m.static_cpu.push_back(cpu);
  m.static_answer = answer;
}

// The damped explicit run for `periods` periods of ω (the tests' hand-tuned
// runs): times it, reports `answer` (named `answer_name`), its error against
// `reference` and its change over the last period.
template <class S, class Answer>
void measure_damped(benchmark::State& state, const std::string& name, S& solver, double omega, int periods,
                    Answer answer, const char* answer_name, double reference) {
  const double period = 2 * M_PI / omega;
  const auto start = Clock::now();
  const double cpu_start = cpu_seconds();
  solver.run_until((periods - 1) * period);
  const double before = answer(solver);
  solver.run_until(periods * period);
  const double seconds = seconds_since(start);
  const double cpu = cpu_seconds() - cpu_start;
  const double value = answer(solver);
  state.SetIterationTime(seconds);
  report_damped(name, seconds, cpu, value);
  state.counters["steps"] = double(solver.steps());
  state.counters[answer_name] = value;
  state.counters["error_pct"] = 100.0 * (value / reference - 1.0);
  state.counters["last_period_change"] = std::abs(value - before) / value;
}

// solve_static with `parameters`: times it and reports as measure_damped does,
// with the solve's force evaluations, iterations and final residual.
template <class S, class Answer>
void measure_static(benchmark::State& state, const std::string& name, S& solver,
                    const solver::StaticParameters& parameters, Answer answer, const char* answer_name,
                    double reference) {
  const auto start = Clock::now();
  const double cpu_start = cpu_seconds();
  const solver::StaticResult result = solver.solve_static(parameters);
  const double seconds = seconds_since(start);
  const double cpu = cpu_seconds() - cpu_start;
  const double value = answer(solver);
  state.SetIterationTime(seconds);
  report_static(name, seconds, cpu, value);
  state.counters["force_evaluations"] = double(result.force_evaluations);
  state.counters["iterations"] = double(result.iterations);
  state.counters["residual"] = result.residual;
  state.counters[answer_name] = value;
  state.counters["error_pct"] = 100.0 * (value / reference - 1.0);
}

// ---------------------------------------------------------------- clamped plate

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;

constexpr double plate_L = 1.0, plate_slenderness = 50.0, plate_d = plate_L / plate_slenderness, plate_E = 210e9,
                 plate_nu = 0.3, plate_rho = 7850.0, plate_q = 1e3;
constexpr double plate_D = plate_E * plate_d * plate_d * plate_d / (12 * (1 - plate_nu * plate_nu));
constexpr double mindlin_50 = 0.0012754;  // w D / (q L^4), the value test_solver_plate checks against
// The damped run's fundamental frequency and its number of periods (test_solver_plate, clamped).
const double plate_omega = 35.99 / (plate_L * plate_L) * std::sqrt(plate_D / (plate_rho * plate_d));
constexpr int plate_periods = 6;

// The test's set-up: damped options for the explicit run, plain ones for the static solve
// (the static answer depends on neither density nor damping).
PlateSolver clamped_plate(bool damped, int particles_per_side = 21) {
  SolverOptions options;
  options.nonlinear = false;
  options.density = plate_rho;
  if (damped) {
    options.damping = 2 * plate_omega;
    options.rotary_inertia_scale = std::max(3.0, 3.0 * (plate_slenderness / 50.0) * (plate_slenderness / 50.0));
  }
  PlateSolver solver(ShellModel::rectangular_plate(plate_L, plate_L, particles_per_side, particles_per_side, plate_d),
                     {plate_E, plate_nu}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), plate_q, time_function::Step{},
                              PressureDirection::fixed);
  return solver;
}

double plate_coefficient(const PlateSolver& solver) {
  return -solver.displacement(solver.model().set("centre")[0]).z() * plate_D / (plate_q * std::pow(plate_L, 4));
}

void clamped_plate_damped(benchmark::State& state) {
  for (auto _ : state) {
    const auto setup_start = Clock::now();
    PlateSolver solver = clamped_plate(true);
    state.counters["setup_s"] = seconds_since(setup_start);
    measure_damped(state, "plate", solver, plate_omega, plate_periods, plate_coefficient, "wDqL4", mindlin_50);
  }
}

// Newton (StaticMass::tangent), one load step, ||r|| <= 1e-6 ||f||.
void clamped_plate_static(benchmark::State& state) {
  for (auto _ : state) {
    const auto setup_start = Clock::now();
    PlateSolver solver = clamped_plate(false);
    state.counters["setup_s"] = seconds_since(setup_start);
    solver::StaticParameters parameters;
    parameters.mass = solver::StaticMass::tangent;
    measure_static(state, "plate", solver, parameters, plate_coefficient, "wDqL4", mindlin_50);
  }
}

// ---------------------------------------------------------------- the plate at 101 x 101

// solve_static at 101 x 101, ||r|| <= 1e-6 ||f||: Newton (argument 0) or the
// relaxation (argument 1, its automatic budget). The counters are the solve's
// own (force evaluations, iterations, factorisations), its CPU time, the
// deflection and its error against Mindlin's value for the continuum.
void plate_101_static(benchmark::State& state) {
  const bool newton = state.range(0) == 0;
  for (auto _ : state) {
    PlateSolver solver = clamped_plate(false, 101);
    solver::StaticParameters parameters;
    if (newton) parameters.mass = solver::StaticMass::tangent;
    const auto start = Clock::now();
    const double cpu_start = cpu_seconds();
    const solver::StaticResult result = solver.solve_static(parameters);
    state.SetIterationTime(seconds_since(start));
    state.counters["cpu_s"] = cpu_seconds() - cpu_start;
    state.counters["force_evaluations"] = double(result.force_evaluations);
    state.counters["iterations"] = double(result.iterations);
    state.counters["factorisations"] = double(result.factorisations);
    state.counters["residual"] = result.residual;
    state.counters["wDqL4"] = plate_coefficient(solver);
    state.counters["error_pct"] = 100.0 * (plate_coefficient(solver) / mindlin_50 - 1.0);
  }
}

// One tangent assembly of the plate of 101 x 101 or 201 x 201 particles (the
// argument; statics::TangentAssembly, the
// clamped edge held) against one force evaluation (the configuration set
// again, which recomputes the internal forces), and the LDLT factorisation of
// the symmetrised tangent that Newton's step solves with (Eigen's
// SimplicialLDLT, AMD ordering, as solve_static's): of the tangent as
// assembled (every entry the differences give, as the path following keeps
// them) and without the entries at most 1e-12 of their column's largest (the
// differences' round-off, which solve_static leaves out). The counters:
// assembly_force_evaluations (the count: two per colour and degree of
// freedom, and one to restore the configuration), assembly_in_force_evaluations
// (its CPU time over one evaluation's), and for both factorisations the CPU
// time, the entries of the factor L and their memory (12 bytes an entry,
// value and row index); then newton_factorisation_s, the CPU time of the
// factorisation solve_static's Newton steps use (statics::SparseFactorisation,
// of the pruned tangent: CHOLMOD's supernodal Cholesky where the build has it,
// newton_factorisation_is_cholmod = 1, with its factor's entries and memory in
// use, cholmod_factor_entries and cholmod_memory_MB).
void plate_tangent(benchmark::State& state) {
  for (auto _ : state) {
    PlateSolver solver = clamped_plate(false, static_cast<int>(state.range(0)));
    statics::Conditions conditions(solver.model().particle_count());
    conditions.clamp(solver.model().set("boundary"));
    const std::vector<Vector3> x = solver.positions(), d = solver.directors();
    constexpr int evaluations = 20;
    double cpu = cpu_seconds();
    for (int k = 0; k < evaluations; ++k) solver.set_configuration(x, d);
    const double evaluation_cpu = (cpu_seconds() - cpu) / evaluations;
    statics::TangentAssembly<PlateSolver> assembly(solver, conditions);
    const statics::DegreesOfFreedom dofs = assembly.degrees_of_freedom();
    const auto start = Clock::now();
    cpu = cpu_seconds();
    const statics::SparseMatrix k = assembly.tangent(dofs);
    const double assembly_cpu = cpu_seconds() - cpu;
    // Column by column, the entries above 1e-12 of the column's largest.
    statics::SparseMatrix pruned = k;
    for (Eigen::Index column = 0; column < pruned.outerSize(); ++column) {
      double largest = 0.0;
      for (statics::SparseMatrix::InnerIterator it(pruned, column); it; ++it)
        largest = std::max(largest, std::abs(it.value()));
      for (statics::SparseMatrix::InnerIterator it(pruned, column); it; ++it)
        if (!(std::abs(it.value()) > statics::detail::negligible_tangent_entry * largest)) it.valueRef() = 0.0;
    }
    pruned.prune(0.0, 0.0);
    for (const auto& [name, matrix] : {std::pair<const char*, const statics::SparseMatrix*>{"", &k},
                                       std::pair<const char*, const statics::SparseMatrix*>{"pruned_", &pruned}}) {
      // At 201 x 201 the tangent as assembled would take gigabytes of L: the pruned one only.
      if (matrix == &k && state.range(0) > 101) continue;
      cpu = cpu_seconds();
      const Eigen::SimplicialLDLT<statics::SparseMatrix> ldlt(statics::symmetrised(*matrix));
      const double factorisation_cpu = cpu_seconds() - cpu;
      if (ldlt.info() != Eigen::Success) state.SkipWithError("the LDLT factorisation failed");
      const double factor_entries = double(ldlt.matrixL().nestedExpression().nonZeros());
      state.counters[std::string(name) + "tangent_entries"] = double(matrix->nonZeros());
      state.counters[std::string(name) + "factorisation_s"] = factorisation_cpu;
      state.counters[std::string(name) + "factor_entries"] = factor_entries;
      state.counters[std::string(name) + "factor_MB"] = 12.0 * factor_entries / 1e6;
    }
    // The factorisation Newton's steps use (statics::SparseFactorisation: CHOLMOD's
    // supernodal Cholesky where the build has it, else the LDLT above), of the
    // pruned tangent; with CHOLMOD also its factor's entries and its memory in use.
    statics::SparseFactorisation<statics::SparseMatrix> newton;
    cpu = cpu_seconds();
    if (!newton.factorise_symmetric(statics::symmetrised(pruned))) state.SkipWithError("the factorisation failed");
    state.counters["newton_factorisation_s"] = cpu_seconds() - cpu;
    state.counters["newton_factorisation_is_cholmod"] =
        newton.method() == statics::FactorisationMethod::cholmod_cholesky ? 1.0 : 0.0;
#if defined(SPHSHELL_HAVE_CHOLMOD)
    {
      Eigen::CholmodSupernodalLLT<statics::SparseMatrix> cholesky;
      cholesky.cholmod().print = 0;
      cholesky.compute(statics::symmetrised(pruned));
      state.counters["cholmod_factor_entries"] = cholesky.cholmod().lnz;
      state.counters["cholmod_memory_MB"] = double(cholesky.cholmod().memory_inuse) / 1e6;
    }
#endif
    state.SetIterationTime(seconds_since(start));
    state.counters["dofs"] = double(dofs.count());
    state.counters["colours"] = double(assembly.colour_count());
    state.counters["force_evaluation_ms"] = 1e3 * evaluation_cpu;
    state.counters["assembly_force_evaluations"] = double(assembly.report().force_evaluations);
    state.counters["assembly_s"] = assembly_cpu;
    state.counters["assembly_in_force_evaluations"] = assembly_cpu / evaluation_cpu;
  }
}

// ---------------------------------------------------------------- cantilever under end shear

using StripSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;

constexpr double strip_L = 0.5, strip_width = 0.1, strip_d = 0.02, strip_E = 210e9, strip_rho = 7850.0;
constexpr double strip_EI = strip_E * strip_width * strip_d * strip_d * strip_d / 12.0;
const double strip_omega = 3.516 * std::sqrt(strip_EI / (strip_rho * strip_width * strip_d)) / (strip_L * strip_L);
constexpr int strip_periods = 12;

// The elastica's tip deflection w/L under P L^2/EI = alpha (the tabulated values test_solver_shells uses).
double elastica_tip(long alpha) { return alpha == 1 ? 0.30172 : 0.49346; }

StripSolver cantilever(bool damped, double alpha) {
  SolverOptions options;
  options.nonlinear = true;
  options.density = strip_rho;
  if (damped) {
    options.damping = 1.5 * strip_omega;
    options.rotary_inertia_scale = 4.0;
  }
  StripSolver solver(ShellModel::rectangular_plate(strip_L, strip_width, 21, 5, strip_d), {strip_E, 0.0}, options);
  solver.clamp(solver.model().set("x_min"));
  const ParticleSet& tip = solver.model().set("x_max");
  const double load = alpha * strip_EI / (strip_L * strip_L);
  solver.add_point_force(tip, Vector3(0, 0, -load / static_cast<double>(tip.size())));
  return solver;
}

double tip_deflection(const StripSolver& solver) {
  const ParticleSet& tip = solver.model().set("x_max");
  double w = 0.0;
  for (int i : tip) w += -solver.displacement(i).z() / static_cast<double>(tip.size());
  return w / strip_L;
}

std::string cantilever_case(long alpha) { return "cantilever PL^2/EI=" + std::to_string(alpha); }

void cantilever_damped(benchmark::State& state) {
  const long alpha = state.range(0);
  for (auto _ : state) {
    const auto setup_start = Clock::now();
    StripSolver solver = cantilever(true, double(alpha));
    state.counters["setup_s"] = seconds_since(setup_start);
    measure_damped(state, cantilever_case(alpha), solver, strip_omega, strip_periods, tip_deflection, "tip_w_over_L",
                   elastica_tip(alpha));
  }
}

// Adaptive dynamic relaxation (the default StaticMass::particle_bound, viscous
// damping) in one load step, ||r|| <= 1e-6 ||f|| (the default tolerance).
// test_static_solution takes two load steps {0.5, 1}: 2.2-2.8 times the
// evaluations of one, with the same answer. Newton (StaticMass::tangent)
// stalls on this strip (statics/static_solve.hpp, "Known limit"): its line search
// on ||r|| rejects the full steps.
void cantilever_static(benchmark::State& state) {
  const long alpha = state.range(0);
  for (auto _ : state) {
    const auto setup_start = Clock::now();
    StripSolver solver = cantilever(false, double(alpha));
    state.counters["setup_s"] = seconds_since(setup_start);
    solver::StaticParameters parameters;
    parameters.load_factors = {1.0};
    measure_static(state, cantilever_case(alpha), solver, parameters, tip_deflection, "tip_w_over_L",
                   elastica_tip(alpha));
  }
}

}  // namespace

BENCHMARK(clamped_plate_damped)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(clamped_plate_static)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(cantilever_damped)->Arg(1)->Arg(2)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(cantilever_static)->Arg(1)->Arg(2)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(plate_101_static)->Arg(0)->Arg(1)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(plate_tangent)->Arg(101)->Arg(201)->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  double load1 = 0.0;
  if (getloadavg(&load1, 1) != 1) load1 = -1.0;
  std::printf("\nmedians over the repetitions, damped / static (1-minute load average at the end %.2f):\n", load1);
  for (const auto& [name, m] : measured()) {
    if (m.damped_seconds.empty() || m.static_seconds.empty()) continue;
    const double damped = median(m.damped_seconds), fast = median(m.static_seconds);
    const double damped_cpu = median(m.damped_cpu), fast_cpu = median(m.static_cpu);
    std::printf("  %-22s wall %7.3f s / %7.3f s = %5.1f   cpu %7.3f s / %7.3f s = %5.1f   static - damped %+.2e %%\n",
                name.c_str(), damped, fast, damped / fast, damped_cpu, fast_cpu, damped_cpu / fast_cpu,
                100.0 * (m.static_answer / m.damped_answer - 1.0));
  }
  return 0;
}
