#pragma once
// The Error rule of a distributed run (docs/distributed.md, "Errors"): an
// Error on one rank stops every rank, with the same message.
//
// A rank that threw on its own would leave the others waiting in their next
// collective for ever. So every part of a step that can fail runs up to an
// agreement point, which every rank reaches whether it failed or not: there
// the ranks find the failure of lowest key (ties: the lowest rank), its
// message is broadcast, and every rank throws Error with it. The key is what
// makes the message the serial run's: the serial loops stop at the lowest
// failing index, so a failing point or particle uses its global index as key
// (stress points before particle points, as solver::IntegrationPoints numbers
// them); a failure without an index uses 0, which the lowest rank then wins.
//
// Cost when nothing failed: one MPI_Allreduce of a (long, int) pair.

#include <sphshell/core/error.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/mpi/communicator.hpp>

#include <mpi.h>

#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace sphshell::mpi {

// A failure on one rank: its ordering key and the message the run stops with.
using Failure = domain::Failure;

// Collective. Throws Error(message of the agreed failure) on every rank when
// any rank passed a failure; returns on every rank otherwise.
inline void agree_on_failure(const Communicator& comm, const std::optional<Failure>& local) {
  // MPI_MINLOC on (key, rank): the smallest key, and the lowest rank holding it.
  struct {
    long key;
    int rank;
  } mine{local ? local->key : std::numeric_limits<long>::max(), comm.rank()}, agreed{0, 0};
  if (local && local->key == std::numeric_limits<long>::max())
    sphshell::detail::invalid_parameter("failure key", local->key, "the largest long is reserved for 'no failure'");
  detail::check(MPI_Allreduce(&mine, &agreed, 1, MPI_LONG_INT, MPI_MINLOC, comm.get()), "MPI_Allreduce");
  if (agreed.key == std::numeric_limits<long>::max()) return;
  std::string message = comm.rank() == agreed.rank ? local->message : std::string();
  comm.broadcast(message, agreed.rank);
  throw Error(message);
}

// The failure an exception being handled makes on this rank (call inside a
// catch block): an Error keeps its message; any other exception is named as
// such with its rank, so that every rank stops with a message that says
// where it came from.
inline Failure failure_of_current_exception(const Communicator& comm, long key) {
  const std::string where = "sphshell: exception on rank " + std::to_string(comm.rank()) + ": ";
  try {
    throw;
  } catch (const Error& error) {
    return Failure{key, error.what(), nullptr};
  } catch (const std::exception& error) {
    return Failure{key, where + error.what(), nullptr};
  } catch (...) {
    return Failure{key, where + "an exception that is not a std::exception", nullptr};
  }
}

// Runs body() on every rank and agrees on its outcome: an exception it throws
// (of any type) becomes this rank's failure with key key_of_unkeyed.
// Collective.
template <class Body>
void collectively(const Communicator& comm, Body&& body, long key_of_unkeyed = 0) {
  std::optional<Failure> failure;
  try {
    std::forward<Body>(body)();
  } catch (...) {
    failure = failure_of_current_exception(comm, key_of_unkeyed);
  }
  agree_on_failure(comm, failure);
}

}  // namespace sphshell::mpi
