#pragma once
// mpi::Domain: the domain part (domain/domain.hpp) of a run over the ranks of
// a communicator. It holds this rank's share (mpi/layout.hpp: owned
// particles, then ghosts, in the local numbering), the halo plan that keeps
// the ghosts current (mpi/halo.hpp) and the agreement on failures
// (mpi/error_agreement.hpp), and counts the time its collectives take.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/mpi/halo.hpp>
#include <sphshell/mpi/layout.hpp>

#include <chrono>
#include <cstddef>
#include <ctime>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::mpi {

// What a rank measured of its own steps (the bench, docs/distributed.md).
struct CommunicationCounters {
  long exchanges = 0;                // halo exchanges
  std::size_t bytes_sent = 0;        // by this rank, all exchanges
  double exchange_seconds = 0.0;     // wall time inside the halo exchange
  double agreement_seconds = 0.0;    // wall time inside agreement points and reductions
  double communication_cpu_seconds = 0.0;  // process CPU time inside both (MPI polls while it waits)
};

class Domain {
 public:
  static constexpr bool is_distributed = true;

  // comm must outlive the domain.
  explicit Domain(const Communicator& comm) : comm_(&comm) {}

  const Communicator& communicator() const { return *comm_; }
  int rank() const { return comm_->rank(); }
  int size() const { return comm_->size(); }
  bool is_root() const { return comm_->is_root(); }

  // This rank's share; the halo plan is made from it (collective).
  void set_layout(RankLayout layout) { layout_ = std::move(layout); }
  void plan_halo() { halo_ = HaloPlan(*comm_, layout_); }
  const RankLayout& layout() const { return layout_; }
  const HaloPlan& halo() const { return halo_; }
  const CommunicationCounters& counters() const { return counters_; }

  bool owns(int global) const {
    const int k = layout_.local_of[static_cast<std::size_t>(global)];
    return k >= 0 && static_cast<std::size_t>(k) < layout_.owned_count();
  }

  void agree(const std::optional<domain::Failure>& failure) const {
    const Timer timer(*this);
    agree_on_failure(*comm_, failure);
  }
  template <class Body>
  void collectively(Body&& body) const {
    mpi::collectively(*comm_, std::forward<Body>(body));
  }
  // The failure the exception being handled makes here (inside a catch block).
  domain::Failure failure_of_current_exception(long key) const {
    return mpi::failure_of_current_exception(*comm_, key);
  }
  bool first_process_decides(bool value) const {
    return comm_->all_gather(static_cast<char>(value ? 1 : 0)).front() != 0;
  }
  std::string checkpoint_file(const std::string& path) const { return path + ".rank" + std::to_string(rank()); }

  // The ghosts' copies of the given per-particle fields, from their owners.
  void exchange(const std::vector<std::vector<Vector3>*>& fields) {
    const auto started = std::chrono::steady_clock::now();
    const std::clock_t cpu = std::clock();
    exchange_.exchange(*comm_, halo_, fields);
    counters_.exchange_seconds += seconds_since(started);
    counters_.communication_cpu_seconds += static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
    ++counters_.exchanges;
    counters_.bytes_sent += halo_.bytes_sent(fields.size());
  }

  // Counts the wall and CPU time of a reduction done outside the domain
  // (the energy books) as agreement time.
  class Timer {
   public:
    explicit Timer(const Domain& domain)
        : domain_(domain), started_(std::chrono::steady_clock::now()), cpu_(std::clock()) {}
    ~Timer() {
      domain_.counters_.agreement_seconds += seconds_since(started_);
      domain_.counters_.communication_cpu_seconds += static_cast<double>(std::clock() - cpu_) / CLOCKS_PER_SEC;
    }
    Timer(const Timer&) = delete;
    Timer& operator=(const Timer&) = delete;

   private:
    const Domain& domain_;
    std::chrono::steady_clock::time_point started_;
    std::clock_t cpu_;
  };

 private:
  static double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  const Communicator* comm_;
  RankLayout layout_;
  HaloPlan halo_;
  HaloExchange exchange_;
  // Timing only: the counters change in const collectives.
  mutable CommunicationCounters counters_;
};

static_assert(domain::check_domain<Domain>());

}  // namespace sphshell::mpi
