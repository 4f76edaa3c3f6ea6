// The halo of an n × n plate (the paper's L = 0.5 m, d = 0.01 m) on the ranks
// of the run, for docs/scaling.md: per rank the owned and ghost particles,
// neighbour ranks, the points computed redundantly, the bytes one exchange of
// positions and directors sends, and its time; the cost of ExactSum against a
// plain loop; and, with --solver-steps K, the single-process step time of the
// same plate (J2 plasticity, Gauss<5>; rank 0 only) to set the exchange against.
//   mpirun -np P mpi_halo_bench [--n 201] [--exchanges 200] [--solver-steps 0]
#include <sphshell/mpi/all.hpp>
#include <sphshell/sphshell.hpp>

#include "mpi_test_support.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

int integer_option(int argc, char** argv, const char* name, int fallback) {
  for (int k = 1; k + 1 < argc; ++k)
    if (std::strcmp(argv[k], name) == 0) return std::atoi(argv[k + 1]);
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  mpi::Environment environment(argc, argv);
  const mpi::Communicator comm;
  const int n = integer_option(argc, argv, "--n", 201);
  const int exchanges = integer_option(argc, argv, "--exchanges", 200);
  const int solver_steps = integer_option(argc, argv, "--solver-steps", 0);

  const mpi_test::Case plate = mpi_test::paper_plate(n);
  const mpi::DecompositionInput input = plate.input();
  const mpi::Partition partition = mpi::partition(input, comm.size());
  const mpi::RankLayout layout = mpi::rank_layout(input, partition, comm.rank());
  const mpi::HaloPlan plan(comm, layout);

  std::vector<Vector3> x(layout.local_count(), Vector3::Zero()), d = x;
  for (std::size_t k = 0; k < layout.owned_count(); ++k) {
    x[k] = plate.model.particle_position[layout.owned[k]];
    d[k] = plate.model.particle_normal[layout.owned[k]];
  }
  mpi::HaloExchange exchange;
  std::vector<double> samples;
  for (int k = 0; k < exchanges; ++k) {
    comm.barrier();
    const double start = MPI_Wtime();
    exchange.exchange(comm, plan, {&x, &d});
    samples.push_back(MPI_Wtime() - start);
  }
  std::size_t computed = 0;
  for (std::size_t g = 0; g < mpi::group_count; ++g) computed += layout.computed[g].size();

  // The ledger's sums: three terms per owned particle per step.
  std::vector<double> terms(3 * layout.owned_count());
  for (std::size_t k = 0; k < terms.size(); ++k) terms[k] = 1.0 / static_cast<double>(k + 1);
  const int passes = 200;
  auto time_of = [&](auto&& body) {
    std::vector<double> times;
    for (int repeat = 0; repeat < 5; ++repeat) {
      const auto start = std::chrono::steady_clock::now();
      for (int pass = 0; pass < passes; ++pass) body();
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
                      (passes * static_cast<double>(terms.size())));
    }
    return median(times);
  };
  volatile double sink = 0.0;
  const double plain = time_of([&] {
    double s = 0.0;
    for (double t : terms) s += t;
    sink = sink + s;
  });
  const double exact = time_of([&] {
    sphshell::ExactSum s;
    for (double t : terms) s.add(t);
    sink = sink + s.value();
  });

  struct Row {
    long owned, ghosts, neighbours, computed, redundant, bytes_sent;
    double exchange_us;
  };
  const Row mine{static_cast<long>(layout.owned_count()), static_cast<long>(layout.ghost_count()),
                 static_cast<long>(plan.neighbours().size()), static_cast<long>(computed),
                 static_cast<long>(layout.redundant_point_count()), static_cast<long>(plan.bytes_sent(2)),
                 median(samples) * 1e6};
  const std::vector<Row> rows = comm.all_gather(mine);
  if (comm.is_root()) {
    std::printf("# plate %dx%d (%zu particles, %zu points) on %d ranks (RCB)\n", n, n, plate.model.particle_count(),
                plate.points->size(), comm.size());
    std::printf("# rank owned ghosts neighbours computed_points redundant_points bytes_sent_per_exchange exchange_us\n");
    for (std::size_t r = 0; r < rows.size(); ++r)
      std::printf("%4zu %7ld %6ld %3ld %8ld %6ld %9ld %9.1f\n", r, rows[r].owned, rows[r].ghosts, rows[r].neighbours,
                  rows[r].computed, rows[r].redundant, rows[r].bytes_sent, rows[r].exchange_us);
    std::printf("# sum of %zu terms on rank 0: plain loop %.2f ns/term, ExactSum %.2f ns/term\n", terms.size(),
                plain * 1e9, exact * 1e9);
  }
  if (solver_steps > 0 && comm.is_root()) {
    // The single-process step of the same plate, through the public API.
    SolverOptions options;
    options.density = 7850.0;
    Solver<mpi_test::Approximation, thickness::Gauss<5>, material::J2Plasticity> solver(
        ShellModel::rectangular_plate(0.5, 0.5, n, n, 0.01), {210e9, 0.3, 235e6, 0.0}, options);
    solver.clamp(solver.model().set("boundary"));
    solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
    solver.step();  // the first step includes the start-up
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < solver_steps; ++k) solver.step();
    const double step = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / solver_steps;
    std::printf("# stable time step %.4g s, step used %.4g s\n", solver.stable_time_step(), solver.time_step());
    std::printf("# single-process step (J2, Gauss<5>, %d threads): %.2f ms\n",
#ifdef _OPENMP
                omp_get_max_threads(),
#else
                1,
#endif
                step * 1e3);
  }
  return 0;
}
