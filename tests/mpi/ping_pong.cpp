// Ping-pong between ranks 0 and 1 and the all-reduces of the distributed step,
// for the scaling model of docs/scaling.md: per-message latency (half a round
// trip) and bandwidth of this machine's transport (shared memory when both
// ranks are on one node), and the time of the collectives a step uses.
//   mpirun -np 2 mpi_ping_pong [--quick]
// Prints one line per message size: bytes, then the half round trip (µs) and
// bandwidth (MB/s) of the fastest of many short timing loops (the transport
// itself, while both ranks are on a core) and of their median (what a loaded
// machine gives).
#include <sphshell/mpi/all.hpp>

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  sphshell::mpi::Environment environment(argc, argv);
  const sphshell::mpi::Communicator comm;
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const int repeats = quick ? 1 : 41;  // short timing loops per size: their fastest and median are reported
  if (comm.size() < 2) {
    std::printf("mpi_ping_pong needs at least 2 ranks\n");
    return 1;
  }
  const int rank = comm.rank();
  const int tag = 1;
  if (comm.is_root())
    std::printf("# ping-pong rank 0 <-> 1 (%d ranks)\n"
                "# bytes  fastest: half_round_trip_us bandwidth_MB_per_s  median: half_round_trip_us bandwidth_MB_per_s\n",
                comm.size());
  for (std::size_t bytes = 8; bytes <= (std::size_t{8} << 20); bytes *= 4) {
    std::vector<char> buffer(bytes, 1);
    // About 1 ms of traffic per loop at 1 GB/s, at least 5 round trips.
    const int round_trips = quick ? 10 : static_cast<int>(std::max<std::size_t>(5, std::min<std::size_t>(500, (std::size_t{1} << 20) / bytes)));
    std::vector<double> samples;
    for (int repeat = 0; repeat < repeats; ++repeat) {
      comm.barrier();
      const double start = MPI_Wtime();
      for (int k = 0; k < round_trips; ++k) {
        if (rank == 0) {
          MPI_Send(buffer.data(), static_cast<int>(bytes), MPI_BYTE, 1, tag, comm.get());
          MPI_Recv(buffer.data(), static_cast<int>(bytes), MPI_BYTE, 1, tag, comm.get(), MPI_STATUS_IGNORE);
        } else if (rank == 1) {
          MPI_Recv(buffer.data(), static_cast<int>(bytes), MPI_BYTE, 0, tag, comm.get(), MPI_STATUS_IGNORE);
          MPI_Send(buffer.data(), static_cast<int>(bytes), MPI_BYTE, 0, tag, comm.get());
        }
      }
      samples.push_back((MPI_Wtime() - start) / round_trips / 2.0);
    }
    const double fastest = *std::min_element(samples.begin(), samples.end()), typical = median(samples);
    if (comm.is_root())
      std::printf("%9zu  %10.3f %10.1f  %10.3f %10.1f\n", bytes, fastest * 1e6, static_cast<double>(bytes) / fastest / 1e6,
                  typical * 1e6, static_cast<double>(bytes) / typical / 1e6);
  }
  // The collectives of a step: the Error agreement (MINLOC of a long/int pair),
  // an ExactSum reduction (71 int64), and a max of one double (the stable step).
  const int calls = quick ? 10 : 200;
  auto time_collective = [&](const char* name, auto&& call) {
    std::vector<double> samples;
    for (int repeat = 0; repeat < repeats; ++repeat) {
      comm.barrier();
      const double start = MPI_Wtime();
      for (int k = 0; k < calls; ++k) call();
      samples.push_back((MPI_Wtime() - start) / calls);
    }
    if (comm.is_root())
      std::printf("# %-44s fastest %8.3f us, median %8.3f us per call\n", name,
                  *std::min_element(samples.begin(), samples.end()) * 1e6, median(samples) * 1e6);
  };
  time_collective("agree_on_failure (no failure)", [&] { sphshell::mpi::agree_on_failure(comm, std::nullopt); });
  sphshell::ExactSum accumulator;
  accumulator.add(1.0);
  time_collective("mpi::sum(ExactSum) (568-byte all-reduce)", [&] { (void)sphshell::mpi::sum(comm, accumulator); });
  time_collective("Communicator::max(double)", [&] { (void)comm.max(1.0); });
  if (comm.is_root()) std::printf("# latency and bandwidth: the 8-byte and the 8 MiB lines above\n");
  return 0;
}
