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
#include <sphshell/core/exact_sum.hpp>
#include <sphshell/mpi/halo.hpp>
#include <sphshell/mpi/layout.hpp>
#include <sphshell/mpi/partition.hpp>
#include <sphshell/mpi/reductions.hpp>
#include <sphshell/solver/integration_points.hpp>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <random>
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

  // The share (collective with the Solver's set-up): the recursive-coordinate-
  // bisection partition of the whole model in the reference configuration,
  // this rank's layout, then the halo plan.
  using Weights = PartitionWeights;
  using EnergySum = ExactSum;  // exact: the same for any rank count
  template <class Model>
  void check_share(const Model& model) const {
    detail::check_parts(size(), model.particle_count());  // before rows that a tiny model cannot build
  }
  template <class Model, class Points>
  void decompose(const Model& model, const Points& all_points, const Weights& weights) {
    const DecompositionInput input = decomposition_input(model, all_points);
    partition_ = partition(input, size(), weights);
    set_layout(rank_layout(input, partition_, rank()));
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    owned_row_of_stress_point_.assign(model.stress_point_count(), -1);
    for (std::size_t k = 0; k < layout_.computed[g].size(); ++k)
      if (layout_.computed_is_owned[g][k]) owned_row_of_stress_point_[layout_.computed[g][k]] = static_cast<long>(k);
  }
  // This rank's rows of the whole model's (the edge-tied shear's corners renumbered).
  template <class Points>
  Points local_rows(const Points& all) const {
    return all.subset(layout_.computed, layout_.local_of, layout_.local_count());
  }
  template <class States, class Points>
  States local_states(const States& all, const Points& all_points) const {
    std::vector<std::size_t> computed_points;
    for (solver::PointGroup group : solver::point_groups) {
      const std::size_t g = solver::index_of(group);
      for (std::size_t row : layout_.computed[g]) computed_points.push_back(all_points.point(group, row));
    }
    return all.subset(computed_points);
  }
  std::size_t owned_count() const { return layout_.owned_count(); }
  std::size_t local_count() const { return layout_.local_count(); }
  int global_of(std::size_t local) const { return layout_.global_of(local); }
  long local_of(std::size_t global) const { return layout_.local_of[global]; }
  // Stress point q's local row when this rank owns it, else -1.
  long owned_stress_row(std::size_t q) const { return owned_row_of_stress_point_[q]; }
  // Local stress-point rows owned here, in global order.
  std::vector<std::size_t> owned_stress_rows() const {
    const std::size_t g = solver::index_of(solver::PointGroup::stress_points);
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < layout_.computed[g].size(); ++k)
      if (layout_.computed_is_owned[g][k]) rows.push_back(k);
    return rows;
  }
  // The rows of point group g computed here, and their global rows.
  std::size_t local_row_count(std::size_t g) const { return layout_.computed[g].size(); }
  std::size_t global_row(std::size_t g, std::size_t row) const { return layout_.computed[g][row]; }
  // Global ids found by the ranks, all of them (collective).
  std::vector<std::int64_t> gathered_ids(const std::vector<std::int64_t>& mine) const {
    return comm_->all_gather_v(mine);
  }
  std::size_t global_stress_point(std::size_t row) const {
    return layout_.computed[solver::index_of(solver::PointGroup::stress_points)][row];
  }

  // The owned values of a per-particle field, in global order on every rank
  // (collective; O(N) bytes: for checks and small runs).
  std::vector<Vector3> gathered(const std::vector<Vector3>& local_field) const {
    // Checked on every rank together, so that a short field on one rank is
    // an Error on all of them, not a rank left waiting in the gather.
    collectively([&] {
      if (local_field.size() < layout_.owned_count())
        sphshell::detail::invalid_parameter("local field size", local_field.size(),
                                            "must cover this rank's " + std::to_string(layout_.owned_count()) +
                                                " owned particles (local numbering: owned, then ghosts)");
    });
    std::vector<std::pair<std::size_t, Vector3>> mine(layout_.owned_count());
    for (std::size_t i = 0; i < mine.size(); ++i)
      mine[i] = {static_cast<std::size_t>(layout_.owned[i]), local_field[i]};
    return assembled(layout_.local_of.size(), mine);
  }
  // The value of the one rank that has it (collective).
  template <class T>
  T from_owner(const std::optional<T>& value) const {
    std::vector<T> mine;
    if (value) mine.push_back(*value);
    return comm_->all_gather_v(mine).front();
  }
  // Entries (global index, value) of every rank, as the array of `count` (collective).
  std::vector<Vector3> assembled(std::size_t count, const std::vector<std::pair<std::size_t, Vector3>>& entries) const {
    struct Entry {  // trivially copyable, as a gather needs
      std::int64_t index;
      double value[3];
    };
    std::vector<Entry> mine;
    for (const auto& [index, x] : entries) mine.push_back({static_cast<std::int64_t>(index), {x.x(), x.y(), x.z()}});
    std::vector<Vector3> all(count, Vector3::Zero());
    for (const Entry& entry : comm_->all_gather_v(mine))
      all[static_cast<std::size_t>(entry.index)] = Vector3(entry.value[0], entry.value[1], entry.value[2]);
    return all;
  }
  // What a rank's checkpoint file records of the share: the rank count and rank.
  template <class Counts>
  void add_identity(Counts& counts) const {
    counts.push_back({"rank count", static_cast<std::uint64_t>(size())});
    counts.push_back({"rank", static_cast<std::uint64_t>(rank())});
  }
  // The correctly rounded totals of several exact accumulators over all
  // ranks, in one all-reduce (mpi::sums; collective).
  template <std::size_t N>
  std::array<double, N> totals(const std::array<const ExactSum*, N>& local) const {
    return sums(*comm_, local);
  }
  // The largest (global id, value) of the ranks' (id < 0: none), ties to the
  // lowest id, as a serial max_element finds it (collective).
  std::pair<long long, double> largest(std::pair<long long, double> mine) const {
    struct Candidate {
      long long id;
      double value;
    };
    Candidate best{-1, -1.0};
    for (const Candidate& candidate : comm_->all_gather(Candidate{mine.first, mine.second}))
      if (candidate.id >= 0 &&
          (candidate.value > best.value || (candidate.value == best.value && candidate.id < best.id)))
        best = candidate;
    return {best.id, best.value};
  }
  // After loading: every rank's file came from the same save.
  void check_same_save(const std::string& path, std::uint64_t stamp, long steps) const {
    const std::vector<std::uint64_t> stamps = comm_->all_gather(stamp);
    const std::vector<std::int64_t> all_steps = comm_->all_gather(static_cast<std::int64_t>(steps));
    for (std::size_t r = 1; r < stamps.size(); ++r)
      if (stamps[r] != stamps[0])
        throw Error("sphshell: checkpoint files '" + path + ".rank0' (step " + std::to_string(all_steps[0]) +
                    ") and '" + path + ".rank" + std::to_string(r) + "' (step " + std::to_string(all_steps[r]) +
                    ") were written by different saves");
  }
  // A stamp of one save shared by all ranks (collective): files of different
  // saves cannot be loaded together.
  std::uint64_t save_stamp() const {
    std::uint64_t stamp = 0;
    if (is_root())
      stamp = static_cast<std::uint64_t>(std::random_device{}()) << 32 ^
              static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    return comm_->all_gather(stamp).front();
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
  std::string checkpoint_file(const std::string& path) const { return checkpoint_file_of(path, rank()); }
  // The file of checkpoint `path` that process `process` writes and reads.
  static std::string checkpoint_file_of(const std::string& path, int process) {
    return path + ".rank" + std::to_string(process);
  }
  // Process `process`'s piece of a frame ("particles_000003" → "particles_000003_r2.vtu").
  static std::string piece_file_of(const std::string& frame, int process) {
    return frame + "_r" + std::to_string(process) + ".vtu";
  }

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
  Partition partition_;
  std::vector<long> owned_row_of_stress_point_;
  RankLayout layout_;
  HaloPlan halo_;
  HaloExchange exchange_;
  // Timing only: the counters change in const collectives.
  mutable CommunicationCounters counters_;
};

static_assert(domain::check_domain<Domain>());

}  // namespace sphshell::mpi
