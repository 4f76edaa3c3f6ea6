#pragma once
// domain::Serial: one process owns the whole shell (domain/domain.hpp). The
// layout is the trivial one: every particle and integration point owned, the
// local numbering the global one, no ghosts to exchange, a gather the field
// itself. A failure leaves as it was thrown (the original exception, of its
// own type), and a checkpoint is one file at its path.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/solver/integration_points.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::domain {

class Serial {
 public:
  static constexpr bool is_distributed = false;
  struct Weights {};  // a serial run has no partition to weigh
  using EnergySum = double;  // sums in the serial loops' order

  int rank() const { return 0; }
  int size() const { return 1; }
  bool is_root() const { return true; }
  void agree(const std::optional<Failure>& failure) const {
    if (!failure) return;
    if (failure->original) std::rethrow_exception(failure->original);
    throw Error(failure->message);
  }
  template <class Body>
  void collectively(Body&& body) const {
    std::forward<Body>(body)();
  }
  // Inside a catch block: the exception itself, rethrown by agree().
  Failure failure_of_current_exception(long key) const {
    Failure failure{key, std::string(), std::current_exception()};
    try {
      throw;
    } catch (const std::exception& error) {
      failure.message = error.what();
    } catch (...) {
    }
    return failure;
  }
  bool first_process_decides(bool value) const { return value; }
  std::string checkpoint_file(const std::string& path) const { return path; }
  static std::string checkpoint_file_of(const std::string& path, int) { return path; }
  // A frame's file ("particles_000003" → "particles_000003.vtu"): the whole frame.
  static std::string piece_file_of(const std::string& frame, int) { return frame + ".vtu"; }

  // The share: everything, numbered as in the model.
  template <class Model>
  void check_share(const Model&) const {}
  template <class Model, class Points>
  void decompose(const Model& model, const Points& all_points, const Weights&) {
    particles_ = model.particle_count();
    stress_points_ = model.stress_point_count();
    for (solver::PointGroup group : solver::point_groups) rows_[solver::index_of(group)] = all_points.count(group);
  }
  std::size_t owned_count() const { return particles_; }
  std::size_t local_count() const { return particles_; }
  int global_of(std::size_t local) const { return static_cast<int>(local); }
  long local_of(std::size_t global) const { return static_cast<long>(global); }
  bool owns(int) const { return true; }
  // Stress point q's row in the local stress-point rows (all of them here).
  long owned_stress_row(std::size_t q) const { return static_cast<long>(q); }
  std::vector<std::size_t> owned_stress_rows() const {
    std::vector<std::size_t> rows(stress_points_);
    for (std::size_t q = 0; q < rows.size(); ++q) rows[q] = q;
    return rows;
  }
  std::size_t global_stress_point(std::size_t row) const { return row; }
  // The rows of point group g computed here, and their global rows.
  std::size_t local_row_count(std::size_t g) const { return rows_[g]; }
  std::size_t global_row(std::size_t, std::size_t row) const { return row; }
  // Global ids found by the processes, all of them: this process's.
  std::vector<std::int64_t> gathered_ids(const std::vector<std::int64_t>& mine) const { return mine; }
  void exchange(const std::vector<std::vector<Vector3>*>&) {}
  // A field in global order: the field itself.
  template <class Field>
  const Field& gathered(const Field& field) const {
    return field;
  }
  // The owner's value: this process's.
  template <class T>
  T from_owner(const std::optional<T>& value) const {
    return *value;
  }
  // Entries (global index, value) of the owners, as the array of `count`.
  std::vector<Vector3> assembled(std::size_t count, const std::vector<std::pair<std::size_t, Vector3>>& entries) const {
    std::vector<Vector3> all(count, Vector3::Zero());
    for (const auto& [index, x] : entries) all[index] = x;
    return all;
  }
  // The largest (global id, value): this process's.
  std::pair<long long, double> largest(std::pair<long long, double> mine) const { return mine; }
  // What a checkpoint records of the share: nothing beyond the model's counts.
  template <class Counts>
  void add_identity(Counts&) const {}
  std::uint64_t save_stamp() const { return 0; }
  void check_same_save(const std::string&, std::uint64_t, long) const {}

 private:
  std::size_t particles_ = 0;
  std::size_t stress_points_ = 0;
  std::array<std::size_t, 2> rows_{};
};

static_assert(check_domain<Serial>());

}  // namespace sphshell::domain
