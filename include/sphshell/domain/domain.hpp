#pragma once
// Domain parts: which share of the shell one process steps, and the few
// things a step needs from the other processes (docs/distributed.md). A
// serial run is the one-process case (domain::Serial, domain/serial.hpp); a
// distributed run over MPI uses mpi::Domain (mpi/domain.hpp, with the MPI
// target only: no header of this family includes mpi.h). Calls are per step,
// never per particle, so a template parameter costs nothing.
//
// A domain D provides:
//   static constexpr bool is_distributed;
//   int rank() const; int size() const; bool is_root() const;
//   void agree(const std::optional<domain::Failure>&) const
//       collective: when any process passes a failure, every process throws
//       Error with the agreed one's message (the lowest key; ties: lowest rank);
//   template <class Body> void collectively(Body&&) const
//       runs body(); an exception of any type on one process ends it on
//       every process as an Error with that message;
//   bool first_process_decides(bool) const
//       process 0's value on every process (a decision one clock takes);
//   std::string checkpoint_file(const std::string& path) const
//       the file of checkpoint `path` this process writes and reads;
//   static std::string checkpoint_file_of(path, int process),
//   static std::string piece_file_of(const std::string& frame, int process)
//       process `process`'s checkpoint file, and its file of a frame (the
//       output part: solver/output.hpp).

#include <exception>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

namespace sphshell::domain {

// A failure on one process: its ordering key (the serial loops stop at the
// lowest failing index, so an index makes the message the serial run's) and
// the message the run stops with.
struct Failure {
  long key = 0;
  std::string message;
  std::exception_ptr original;  // one process: the exception itself, rethrown as it was
};

namespace detail {
struct NoBody {
  void operator()() const {}
};
template <class D, class = void>
struct has_domain_members : std::false_type {};
template <class D>
struct has_domain_members<
    D, std::void_t<decltype(D::is_distributed), decltype(std::declval<const D&>().rank()),
                   decltype(std::declval<const D&>().size()), decltype(std::declval<const D&>().is_root()),
                   decltype(std::declval<const D&>().agree(std::optional<Failure>())),
                   decltype(std::declval<const D&>().collectively(NoBody{})),
                   decltype(std::declval<const D&>().first_process_decides(true)),
                   decltype(std::declval<const D&>().checkpoint_file(std::string())),
                   decltype(D::checkpoint_file_of(std::string(), 0)), decltype(D::piece_file_of(std::string(), 0))>>
    : std::true_type {};
}  // namespace detail

template <class D>
inline constexpr bool is_domain_v = detail::has_domain_members<D>::value;

template <class D>
constexpr bool check_domain() {
  static_assert(is_domain_v<D>,
                "not a domain part: it needs is_distributed, rank(), size(), is_root(), "
                "agree(std::optional<domain::Failure>), collectively(body), first_process_decides(bool) and "
                "checkpoint_file(path), checkpoint_file_of(path, process), piece_file_of(frame, process) (domain/domain.hpp); use domain::Serial or mpi::Domain");
  return is_domain_v<D>;
}

}  // namespace sphshell::domain
