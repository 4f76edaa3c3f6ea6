#pragma once
// The MPI seam of the distributed layer (docs/distributed.md): a communicator
// the library owns for itself, and checked wrappers of the few collectives the
// layer uses.
//
// Nothing here is global. The library never calls MPI_Init on its own and
// keeps no static state: a user (or a test) creates an Environment in main(),
// hands the layer a Communicator, and every call of the layer goes through it.
// The Communicator duplicates the communicator it is given, so the layer's
// messages can never match a user's receive, and it returns MPI errors to the
// caller (as an Error naming the call) instead of aborting.
//
// Threads: the layer calls MPI only outside OpenMP regions, from the thread
// that called MPI_Init (MPI_THREAD_FUNNELED is enough for hybrid runs).

#include <sphshell/core/error.hpp>

#include <mpi.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::mpi {

namespace detail {

// An MPI return code other than MPI_SUCCESS becomes an Error naming the call.
inline void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw Error(std::string("sphshell: MPI call ") + call + " failed: " + std::string(text, static_cast<std::size_t>(length)));
}

inline bool initialized() {
  int flag = 0;
  MPI_Initialized(&flag);
  return flag != 0;
}
inline bool finalized() {
  int flag = 0;
  MPI_Finalized(&flag);
  return flag != 0;
}

}  // namespace detail

// What MPI must allow of threads: the layer itself needs only funneled calls.
enum class ThreadSupport { single, funneled, serialized, multiple };

// MPI_Init_thread in the constructor, MPI_Finalize in the destructor, for a
// program's main(). An MPI already initialised by someone else is left alone
// (and not finalised here). A thread level below the one asked for is an Error.
class Environment {
 public:
  Environment(int& argc, char**& argv, ThreadSupport required = ThreadSupport::funneled) {
    if (detail::initialized()) return;
    int provided = 0;
    detail::check(MPI_Init_thread(&argc, &argv, level_of(required), &provided), "MPI_Init_thread");
    owns_ = true;
    if (provided < level_of(required)) {
      MPI_Finalize();
      owns_ = false;
      sphshell::detail::invalid_parameter("MPI thread support", provided,
                                          "the MPI library provides less than the level required (" +
                                              std::to_string(level_of(required)) + ")");
    }
  }
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;
  ~Environment() {
    if (owns_ && !detail::finalized()) MPI_Finalize();
  }

 private:
  static int level_of(ThreadSupport support) {
    switch (support) {
      case ThreadSupport::single: return MPI_THREAD_SINGLE;
      case ThreadSupport::funneled: return MPI_THREAD_FUNNELED;
      case ThreadSupport::serialized: return MPI_THREAD_SERIALIZED;
      case ThreadSupport::multiple: return MPI_THREAD_MULTIPLE;
    }
    return MPI_THREAD_MULTIPLE;
  }
  bool owns_ = false;
};

// The layer's own duplicate of a user communicator (MPI_COMM_WORLD by
// default). Move-only; the duplicate is freed with the object (which must
// therefore die before MPI_Finalize, e.g. before the Environment).
class Communicator {
 public:
  explicit Communicator(MPI_Comm parent = MPI_COMM_WORLD) {
    if (!detail::initialized() || detail::finalized())
      throw Error("sphshell: mpi::Communicator needs MPI to be initialised (create an mpi::Environment in main)");
    detail::check(MPI_Comm_dup(parent, &comm_), "MPI_Comm_dup");
    detail::check(MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
    detail::check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    detail::check(MPI_Comm_size(comm_, &size_), "MPI_Comm_size");
  }
  Communicator(const Communicator&) = delete;
  Communicator& operator=(const Communicator&) = delete;
  Communicator(Communicator&& other) noexcept
      : comm_(std::exchange(other.comm_, MPI_COMM_NULL)), rank_(other.rank_), size_(other.size_) {}
  Communicator& operator=(Communicator&& other) noexcept {
    if (this != &other) {
      release();
      comm_ = std::exchange(other.comm_, MPI_COMM_NULL);
      rank_ = other.rank_;
      size_ = other.size_;
    }
    return *this;
  }
  ~Communicator() { release(); }

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == root; }
  MPI_Comm get() const { return comm_; }
  static constexpr int root = 0;

  void barrier() const { detail::check(MPI_Barrier(comm_), "MPI_Barrier"); }

  // Reductions of one value, the same result on every rank. max and min are
  // exact (order-free); sums of integers are exact. Floating-point sums go
  // through mpi/reductions.hpp, never through MPI_SUM on doubles, whose order
  // depends on the reduction tree.
  double max(double value) const { return all_reduce(value, MPI_DOUBLE, MPI_MAX); }
  double min(double value) const { return all_reduce(value, MPI_DOUBLE, MPI_MIN); }
  std::int64_t sum(std::int64_t value) const { return all_reduce(value, MPI_INT64_T, MPI_SUM); }
  std::int64_t max(std::int64_t value) const { return all_reduce(value, MPI_INT64_T, MPI_MAX); }
  void sum_in_place(std::vector<std::int64_t>& values) const {
    detail::check(MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T,
                                MPI_SUM, comm_),
                  "MPI_Allreduce");
  }

  // Every rank's value, in rank order, on every rank (trivially copyable types).
  template <class T>
  std::vector<T> all_gather(const T& value) const {
    static_assert(std::is_trivially_copyable_v<T>, "all_gather: the type must be trivially copyable");
    std::vector<T> values(static_cast<std::size_t>(size_));
    detail::check(MPI_Allgather(&value, static_cast<int>(sizeof(T)), MPI_BYTE, values.data(),
                                static_cast<int>(sizeof(T)), MPI_BYTE, comm_),
                  "MPI_Allgather");
    return values;
  }
  // Every rank's vector concatenated in rank order, on every rank.
  template <class T>
  std::vector<T> all_gather_v(const std::vector<T>& mine) const {
    static_assert(std::is_trivially_copyable_v<T>, "all_gather_v: the type must be trivially copyable");
    const std::vector<int> counts = all_gather(static_cast<int>(mine.size() * sizeof(T)));
    std::vector<int> displacements(counts.size(), 0);
    std::int64_t total = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      displacements[r] = static_cast<int>(total);
      total += counts[r];
    }
    if (total > static_cast<std::int64_t>(max_message_bytes))
      sphshell::detail::invalid_parameter("all_gather_v bytes", total, "must fit one MPI count (2^31 - 1)");
    std::vector<T> all(static_cast<std::size_t>(total) / sizeof(T));
    detail::check(MPI_Allgatherv(mine.data(), static_cast<int>(mine.size() * sizeof(T)), MPI_BYTE, all.data(),
                                 counts.data(), displacements.data(), MPI_BYTE, comm_),
                  "MPI_Allgatherv");
    return all;
  }
  // The root's string on every rank.
  void broadcast(std::string& text, int from) const {
    std::int64_t length = static_cast<std::int64_t>(text.size());
    detail::check(MPI_Bcast(&length, 1, MPI_INT64_T, from, comm_), "MPI_Bcast");
    text.resize(static_cast<std::size_t>(length));
    detail::check(MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, from, comm_), "MPI_Bcast");
  }

  // Largest byte count one message carries (MPI counts are int).
  static constexpr std::int64_t max_message_bytes = 2147483647;

 private:
  template <class T>
  T all_reduce(T value, MPI_Datatype type, MPI_Op op) const {
    T result{};
    detail::check(MPI_Allreduce(&value, &result, 1, type, op, comm_), "MPI_Allreduce");
    return result;
  }
  void release() noexcept {
    if (comm_ != MPI_COMM_NULL && !detail::finalized()) MPI_Comm_free(&comm_);
    comm_ = MPI_COMM_NULL;
  }

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
};

}  // namespace sphshell::mpi
