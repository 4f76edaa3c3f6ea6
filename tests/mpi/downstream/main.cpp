// A consumer of sphshell::mpi: the exact sum of the ranks' numbers and the Error rule.
// It includes the headers it uses (the MPI layer's communicator, reductions and
// error agreement), not the distributed solver: what it checks is that the
// component brings MPI and the target; that the headers compile for a consumer
// is the umbrella header's check (tests/downstream/main.cpp).
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/core/exact_sum.hpp>
#include <sphshell/mpi/reductions.hpp>

#include <iostream>

int main(int argc, char** argv) {
  sphshell::mpi::Environment environment(argc, argv);
  const sphshell::mpi::Communicator comm;
  // 0.1 on every rank: the sum is the correctly rounded P × 0.1 of the doubles.
  sphshell::ExactSum mine;
  mine.add(0.1);
  const double total = sphshell::mpi::sum(comm, mine);
  sphshell::ExactSum expected;
  for (int r = 0; r < comm.size(); ++r) expected.add(0.1);
  if (total != expected.value()) return 1;
  try {
    sphshell::mpi::collectively(comm, [&] {
      if (comm.rank() == comm.size() - 1) throw sphshell::Error("stop");
    });
  } catch (const sphshell::Error& error) {
    if (comm.is_root()) std::cout << "downstream mpi OK on " << comm.size() << " ranks: " << error.what() << '\n';
    return 0;
  }
  return 1;
}
