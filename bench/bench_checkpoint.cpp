// Cost of a checkpoint of the paper's plate (51 × 51 particles, 2500 stress
// points, Gauss<5>, J2 plasticity, the square_plate example's 1 MPa step load
// after 100 steps): writing it (save_checkpoint: serialise, checksum, write,
// fdatasync, rename) and reading it back (load_checkpoint into a solver built
// for it), against one step. The counter `bytes` is the file's size. The file
// goes to the system's temporary directory and is removed at the end.
// Run single-threaded (OMP_NUM_THREADS=1) for per-step figures.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include <unistd.h>

using namespace sphshell;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::J2Plasticity>;
const material::J2Plasticity::Parameters steel{210e9, 0.3, 235e6, 0.0};

ShellModel paper_plate() { return ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01); }

PlateSolver loaded_plate() {
  SolverOptions options;
  options.density = 7850.0;
  PlateSolver solver(paper_plate(), steel, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
  for (int n = 0; n < 100; ++n) solver.step();
  return solver;
}

std::string checkpoint_path() {
  return (std::filesystem::temp_directory_path() / ("sphshell_bench_checkpoint_" + std::to_string(::getpid()) + ".ckpt"))
      .string();
}

void checkpoint_write(benchmark::State& state) {
  const PlateSolver solver = loaded_plate();
  const std::string path = checkpoint_path();
  for (auto _ : state) solver.save_checkpoint(path);
  state.counters["bytes"] = double(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

void checkpoint_read(benchmark::State& state) {
  const std::string path = checkpoint_path();
  loaded_plate().save_checkpoint(path);
  SolverOptions options;
  options.density = 7850.0;
  PlateSolver solver(paper_plate(), steel, options);
  for (auto _ : state) solver.load_checkpoint(path);
  state.counters["bytes"] = double(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

void plate_step(benchmark::State& state) {
  PlateSolver solver = loaded_plate();
  for (auto _ : state) solver.step();
}

}  // namespace

BENCHMARK(checkpoint_write)->Unit(benchmark::kMillisecond);
BENCHMARK(checkpoint_read)->Unit(benchmark::kMillisecond);
BENCHMARK(plate_step)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
