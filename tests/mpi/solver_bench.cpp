// The distributed step's cost on the paper's plate (docs/distributed.md,
// "Measured"): per rank, the CPU time and wall time per step, the bytes the
// halo exchange sends per step, and the share of the wall time spent in the
// exchange and in the agreement points. Not a test: run it by hand, e.g.
//   mpirun -np 1 mpi_solver_bench --n 201 --steps 40
//   mpirun -np 2 mpi_solver_bench --n 201 --steps 40
// and state the machine's load (printed from /proc/loadavg).
#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/j2_plasticity.hpp>
#include <sphshell/mpi/distributed_solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>

using namespace sphshell;

int main(int argc, char** argv) {
  mpi::Environment environment(argc, argv);
  int n = 201;
  long steps = 40;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string option = argv[k];
    if (option == "--n") n = std::stoi(argv[k + 1]);
    else if (option == "--steps") steps = std::stol(argv[k + 1]);
    else {
      std::fprintf(stderr, "usage: mpi_solver_bench [--n N] [--steps S]\n");
      return 2;
    }
  }
  const mpi::Communicator comm;
  using Distributed =
      mpi::DistributedSolver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::J2Plasticity>;
  SolverOptions options;
  options.density = 7850.0;
  Distributed solver(comm, ShellModel::rectangular_plate(0.5, 0.5, n, n, 0.01), {210e9, 0.3, 250e6, 1e9}, options);
  solver.clamp("boundary");
  solver.add_uniform_pressure(solver.model().all_particles(), 5e6);
  solver.step();  // the start-up half step and first force evaluation, not timed
  const mpi::CommunicationCounters before = solver.counters();
  comm.barrier();
  const std::clock_t cpu_start = std::clock();
  const auto wall_start = std::chrono::steady_clock::now();
  for (long s = 0; s < steps; ++s) solver.step();
  const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const mpi::CommunicationCounters& after = solver.counters();
  struct Row {
    double cpu_ms, compute_cpu_ms, wall_ms, exchange_ms, agreement_ms, bytes;
    long owned, ghosts, redundant;
  } mine{1e3 * cpu / steps,
         1e3 * (cpu - (after.communication_cpu_seconds - before.communication_cpu_seconds)) / steps,
         1e3 * wall / steps,
         1e3 * (after.exchange_seconds - before.exchange_seconds) / steps,
         1e3 * (after.agreement_seconds - before.agreement_seconds) / steps,
         static_cast<double>(after.bytes_sent - before.bytes_sent) / steps,
         static_cast<long>(solver.layout().owned_count()),
         static_cast<long>(solver.layout().ghost_count()),
         static_cast<long>(solver.layout().redundant_point_count())};
  const auto rows = comm.all_gather(mine);
  if (comm.is_root()) {
    std::string load;
    std::getline(std::ifstream("/proc/loadavg"), load);
    std::printf("plate %dx%d, J2, %ld steps on %d rank(s); load (/proc/loadavg) %s\n", n, n, steps, comm.size(),
                load.c_str());
    std::printf("rank  owned  ghosts  redundant  cpu ms/step  cpu outside MPI  wall ms/step  exchange ms/step  "
                "agreement ms/step  comm share  bytes sent/step\n");
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const Row& row = rows[r];
      std::printf("%4zu %6ld %7ld %10ld %12.3f %16.3f %13.3f %17.4f %18.4f %10.1f%% %16.0f\n", r, row.owned,
                  row.ghosts, row.redundant, row.cpu_ms, row.compute_cpu_ms, row.wall_ms, row.exchange_ms,
                  row.agreement_ms,
                  100.0 * (row.exchange_ms + row.agreement_ms) / row.wall_ms, row.bytes);
    }
  }
  return 0;
}
