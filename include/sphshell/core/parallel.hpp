#pragma once
// The library's one parallel seam. Every per-particle and per-point loop of a
// step runs through parallel::for_each (or for_each_range, for_each_task), so
// the threading rule lives here once:
//  - each index of the range is visited once, by one thread; a body writes
//    only what belongs to its own index, so what it writes is the same
//    whichever thread runs it and however many threads there are;
//  - sums over indices are never formed across tasks: a body writes its
//    term to an array, or the sum of a fixed chunk of indices in index
//    order, and the caller adds those up in an order that depends only on
//    the count (index order, chunk order, or detail::interleaved_sum), so
//    reductions are identical for any thread count too;
//  - an exception must not leave a worker thread (that would call
//    std::terminate): for_each keeps the error of the lowest failing index
//    and rethrows it after the loop, the same one whatever the thread count;
//    for_each_range and for_each_task bodies must not throw.
//
// Threads. The loops run on the library's own team of threads (the calling
// thread plus workers started on first use and kept for the process), not on
// OpenMP's: a waiting thread of the team spins for a short time (spin_time(),
// 50 µs by default) and then sleeps until there is work. OpenMP's default
// spin-waiting holds a core for far longer, so on a machine that runs any
// other CPU-bound process two threads were several times slower than one
// (docs/performance.md, "Threads"); OpenMP's spin time is fixed at program start by an
// environment variable, which a library must not impose on its users.
// Each thread has its own contiguous block of a loop's indices, the same block
// in every loop of the same size: a point's data then stays in the cache of
// the core that wrote it in the step before (handing the indices out in turn,
// task by task, made two threads slower than one, docs/performance.md, "Threads").
// A block is split into small tasks; a thread that has finished its own block
// takes the tasks left in the others', so a thread that the operating system
// holds back leaves most of its share to the others.
//
// How many threads: OpenMP's setting when the program is built with OpenMP
// (OMP_NUM_THREADS, omp_set_num_threads; one inside an OpenMP parallel
// region); without OpenMP the loops run serially on the calling thread. A loop
// started while the team is busy (a body that starts a loop itself, or a second
// user thread) runs serially on its calling thread.

#include <sphshell/core/error.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
#include <immintrin.h>
#define SPHSHELL_CPU_RELAX() _mm_pause()
#elif defined(__aarch64__) || defined(__arm__)
#define SPHSHELL_CPU_RELAX() __asm__ __volatile__("yield")
#else
#define SPHSHELL_CPU_RELAX() ((void)0)
#endif

#ifdef _OPENMP
#include <omp.h>
#define SPHSHELL_OMP(directive) _Pragma(directive)
#else
#define SPHSHELL_OMP(directive)
#endif

namespace sphshell::parallel {

// The number of threads a loop started here may use (see the header comment).
inline int thread_count() {
#ifdef _OPENMP
  return omp_in_parallel() ? 1 : std::max(1, omp_get_max_threads());
#else
  return 1;
#endif
}

namespace detail {

inline std::atomic<std::int64_t>& spin_nanoseconds() {
  static std::atomic<std::int64_t> nanoseconds{50'000};
  return nanoseconds;
}

// Spins until ready() or the spin time has passed; returns ready(). Between
// two readings of the clock the thread yields its core: with another process
// waiting for that core (a shared machine), the spinning thread would
// otherwise take time slices from it and from this program's own working
// thread (two threads took 1.20-1.31 of one thread's time with a busy
// process beside them, 1.05-1.07 with the yield; docs/performance.md, "Threads"); on
// an idle core the yield returns at once.
template <class Ready>
bool spin_until(Ready&& ready) {
  constexpr int polls_per_clock_reading = 64;
  const std::int64_t budget = spin_nanoseconds().load(std::memory_order_relaxed);
  if (budget <= 0) return ready();
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    for (int k = 0; k < polls_per_clock_reading; ++k) {
      if (ready()) return true;
      SPHSHELL_CPU_RELAX();
    }
    if (std::chrono::steady_clock::now() - start >= std::chrono::nanoseconds(budget)) return ready();
    std::this_thread::yield();
  }
}

// A task function: runs task number `task` of the job whose data is `context`.
using TaskFunction = void (*)(void* context, std::size_t task);

// The team. One per process, created on first use and never destroyed (its
// workers are detached and may still be parked when the program exits).
//
// A job is published as one 64-bit word: its sequence number, a closed flag,
// how many workers may join and how many have joined. A worker joins a job
// only while it is open, by raising the joined count; the caller claims tasks
// like the workers, closes the job when every task is claimed, and then waits
// only for the workers that joined. So a worker that wakes late (a loaded
// machine) never holds up a loop: it finds the job closed and goes back to
// waiting.
class Team {
 public:
  static Team& instance() {
    static Team* const team = new Team;  // never deleted: see above
    return *team;
  }

  // Takes the team for one job; false when another job holds it (the caller
  // then runs its loop serially).
  bool try_acquire() { return !busy_.exchange(true, std::memory_order_acquire); }
  void release() { busy_.store(false, std::memory_order_release); }

  // Runs tasks [0, task_count) of `function` on the caller and up to
  // threads − 1 workers. The team must be acquired.
  // Thread t's block is tasks [t·task_count/threads, (t+1)·task_count/threads);
  // the caller is thread 0 and worker k (in the order they were started) is
  // thread k + 1.
  void run(std::size_t task_count, int threads, TaskFunction function, void* context) {
    const int helpers = std::min(start_workers(threads - 1), max_joined);
    function_ = function;
    context_ = context;
    task_count_ = task_count;
    block_count_ = static_cast<std::size_t>(helpers) + 1;
    if (blocks_.size() < block_count_) blocks_ = std::vector<Block>(block_count_);
    for (std::size_t b = 0; b < block_count_; ++b)
      blocks_[b].range.store(pack(block_start(b), block_start(b + 1)), std::memory_order_relaxed);
    finished_.store(0, std::memory_order_relaxed);
    sequence_ = (sequence_ + 1) & sequence_mask;
    job_.store(sequence_ << sequence_shift | static_cast<std::uint64_t>(helpers) << limit_shift,
               std::memory_order_seq_cst);
    if (sleeping_workers_.load(std::memory_order_seq_cst) > 0) {
      std::lock_guard<std::mutex> lock(mutex_);
      work_ready_.notify_all();
    }
    work(0);
    const std::uint64_t closed = job_.fetch_or(closed_bit, std::memory_order_acq_rel);
    const int joined = static_cast<int>(closed & joined_mask);
    wait_for_workers(joined);
  }

 private:
  static constexpr int max_joined = 0x7fff;
  static constexpr std::uint64_t joined_mask = 0xffff;
  static constexpr int limit_shift = 16;
  static constexpr std::uint64_t limit_mask = 0x7fff;
  static constexpr std::uint64_t closed_bit = std::uint64_t{1} << 31;
  static constexpr int sequence_shift = 32;
  static constexpr std::uint64_t sequence_mask = 0xffffffff;

  Team() = default;

  static std::uint64_t sequence_of(std::uint64_t job) { return job >> sequence_shift; }

  std::size_t block_start(std::size_t block) const { return block * task_count_ / block_count_; }

  // A block's unclaimed tasks [front, back) in one word: its thread claims from
  // the front, the others from the back, so a thread that helps out takes the
  // tasks farthest from where the block's own thread is working.
  static std::uint64_t pack(std::size_t front, std::size_t back) {
    return static_cast<std::uint64_t>(front) << half_shift | static_cast<std::uint64_t>(back);
  }
  static std::size_t front_of(std::uint64_t range) { return static_cast<std::size_t>(range >> half_shift); }
  static std::size_t back_of(std::uint64_t range) { return static_cast<std::size_t>(range & half_mask); }

  // Claims a task of `block` from its front (own) or back; false when none is left.
  bool claim(std::size_t block, bool own, std::size_t& task) {
    std::atomic<std::uint64_t>& range = blocks_[block].range;
    std::uint64_t current = range.load(std::memory_order_relaxed);
    for (;;) {
      const std::size_t front = front_of(current), back = back_of(current);
      if (front >= back) return false;
      const std::uint64_t claimed = own ? pack(front + 1, back) : pack(front, back - 1);
      if (range.compare_exchange_weak(current, claimed, std::memory_order_relaxed)) {
        task = own ? front : back - 1;
        return true;
      }
    }
  }

  // Thread `own` runs the tasks of its own block, then those still unclaimed
  // in the other blocks.
  void work(std::size_t own) {
    std::size_t task = 0;
    for (std::size_t k = 0; k < block_count_; ++k) {
      const std::size_t block = (own + k) % block_count_;
      while (claim(block, k == 0, task)) function_(context_, task);
    }
  }

  // Starts workers until there are `wanted` (or as many as the system gives);
  // returns how many there are.
  int start_workers(int wanted) {
    while (static_cast<int>(workers_started_) < wanted && !start_failed_) {
      try {
        std::thread(&Team::worker_loop, this, static_cast<std::size_t>(workers_started_) + 1).detach();
        ++workers_started_;
      } catch (const std::system_error&) {
        start_failed_ = true;  // run with the threads there are
      }
    }
    return std::min(wanted, static_cast<int>(workers_started_));
  }

  void wait_for_workers(int joined) {
    auto done = [&] { return finished_.load(std::memory_order_acquire) == joined; };
    if (joined == 0 || spin_until(done)) return;
    std::unique_lock<std::mutex> lock(mutex_);
    caller_sleeping_.store(true, std::memory_order_seq_cst);
    while (!done()) work_done_.wait(lock);
    caller_sleeping_.store(false, std::memory_order_relaxed);
  }

  // `thread` is this worker's place in the team (its block, see run()).
  void worker_loop(std::size_t thread) {
    std::uint64_t seen = sequence_of(job_.load(std::memory_order_acquire));
    for (;;) {
      auto published = [&] { return sequence_of(job_.load(std::memory_order_acquire)) != seen; };
      if (!spin_until(published)) {
        std::unique_lock<std::mutex> lock(mutex_);
        sleeping_workers_.fetch_add(1, std::memory_order_seq_cst);
        while (!published()) work_ready_.wait(lock);
        sleeping_workers_.fetch_sub(1, std::memory_order_relaxed);
      }
      std::uint64_t job = job_.load(std::memory_order_acquire);
      seen = sequence_of(job);
      if (!join(job, thread)) continue;
      work(thread);
      finished_.fetch_add(1, std::memory_order_seq_cst);
      if (caller_sleeping_.load(std::memory_order_seq_cst)) {
        std::lock_guard<std::mutex> lock(mutex_);
        work_done_.notify_one();
      }
    }
  }

  // Joins the job if it is still open and this worker is one of the threads
  // it may use; the caller then waits for this worker, so the job's data stays
  // valid until it reports back.
  bool join(std::uint64_t job, std::size_t thread) {
    const std::uint64_t sequence = sequence_of(job);
    for (;;) {
      if (sequence_of(job) != sequence || (job & closed_bit) || thread > ((job >> limit_shift) & limit_mask))
        return false;
      if (job_.compare_exchange_weak(job, job + 1, std::memory_order_acq_rel, std::memory_order_acquire))
        return true;
    }
  }

  // The words every thread touches, each on its own cache line.
  static constexpr std::size_t cache_line = 64;
  alignas(cache_line) std::atomic<bool> busy_{false};
  alignas(cache_line) std::atomic<std::uint64_t> job_{0};
  // The unclaimed tasks of each thread's block (see claim()).
  struct alignas(cache_line) Block {
    std::atomic<std::uint64_t> range{0};
  };
  static constexpr int half_shift = 32;
  static constexpr std::uint64_t half_mask = 0xffffffff;
  std::vector<Block> blocks_;
  alignas(cache_line) std::atomic<int> finished_{0};
  alignas(cache_line) std::atomic<int> sleeping_workers_{0};
  std::atomic<bool> caller_sleeping_{false};
  std::mutex mutex_;
  std::condition_variable work_ready_, work_done_;
  // Written by the caller before it publishes a job, read by workers that joined it.
  TaskFunction function_ = nullptr;
  void* context_ = nullptr;
  std::size_t task_count_ = 0, block_count_ = 1;
  // The caller's own bookkeeping (only the thread holding the team touches these).
  std::uint64_t sequence_ = 0;
  unsigned workers_started_ = 0;
  bool start_failed_ = false;
};

// Tasks per thread (per block): enough that a thread held back by the system
// leaves most of its share to the others, few enough that claiming them costs
// nothing.
constexpr std::size_t tasks_per_thread = 16;
// Below this many indices per task a loop is not worth waking threads for.
constexpr std::size_t min_task_size = 8;

// The team for a loop of `count` indices on `threads` threads, or nullptr when
// the loop runs serially (one thread, too few indices, or the team is busy).
inline Team* team_for(std::size_t count, int threads) {
  if (threads <= 1 || count < 2 * min_task_size) return nullptr;
  Team* team = &Team::instance();
  return team->try_acquire() ? team : nullptr;
}
// The indices per task of a loop of `count` indices on `threads` threads.
inline std::size_t task_size_for(std::size_t count, int threads) {
  const std::size_t wanted = static_cast<std::size_t>(threads) * tasks_per_thread;
  return std::max(min_task_size, (count + wanted - 1) / wanted);
}

}  // namespace detail

// How long a waiting thread of the team spins before it sleeps (50 µs unless
// changed): long enough to catch the next loop of a step without a wake-up,
// short enough that a core is given back quickly to other processes.
inline std::chrono::nanoseconds spin_time() {
  return std::chrono::nanoseconds(detail::spin_nanoseconds().load(std::memory_order_relaxed));
}
// Sets it for the whole process; 0 sleeps at once. A negative time is an Error.
inline void set_spin_time(std::chrono::nanoseconds time) {
  if (time.count() < 0)
    sphshell::detail::invalid_parameter("parallel spin time (ns)", time.count(), "must be >= 0");
  detail::spin_nanoseconds().store(static_cast<std::int64_t>(time.count()), std::memory_order_relaxed);
}

// Calls body(first, last) on ranges that cover [begin, end) once: each
// thread's block of the range, cut into tasks of task_size_for() indices (a
// thread that finishes its block early takes tasks left in the others'), or
// one call for the whole range when the loop runs serially. for_each runs its
// indices through the same ranges, so a thread gets the same block of indices
// in both. For loops that make several passes over each index (a pass per
// load, then a check) while its data is in cache. body must not throw (note a
// failure and report it after the loop).
template <class Index, class Body>
void for_each_range(Index begin, Index end, Body&& body) {
  static_assert(std::is_integral_v<Index>, "parallel::for_each_range: the index must be an integer type");
  static_assert(std::is_nothrow_invocable_v<Body&, Index, Index>,
                "parallel::for_each_range: declare the body noexcept (note a failure and report it after the loop)");
  if (!(begin < end)) return;
  const std::size_t count = static_cast<std::size_t>(end - begin);
  struct Job {
    Body& body;
    Index begin;
    std::size_t count, task_size;
    static void run_task(void* context, std::size_t task) {
      const Job& job = *static_cast<const Job*>(context);
      const std::size_t from = task * job.task_size;
      const std::size_t to = std::min(job.count, from + job.task_size);
      job.body(static_cast<Index>(job.begin + static_cast<Index>(from)),
               static_cast<Index>(job.begin + static_cast<Index>(to)));
    }
  };
  const int threads = thread_count();
  if (detail::Team* team = detail::team_for(count, threads)) {
    Job job{body, begin, count, detail::task_size_for(count, threads)};
    team->run((count + job.task_size - 1) / job.task_size, threads, &Job::run_task, &job);
    team->release();
  } else {
    body(begin, end);
  }
}

// Calls body(i) for i in [begin, end) on the team, in the ranges of
// for_each_range (a body declared noexcept runs without the exception
// bookkeeping); on failure, on_failure(i, error) is called once, after the
// loop, with the lowest failing index and its exception (it is expected to
// throw; if it returns, the error is rethrown).
template <class Index, class Body, class OnFailure>
void for_each(Index begin, Index end, Body&& body, OnFailure&& on_failure) {
  static_assert(std::is_integral_v<Index>, "parallel::for_each: the index must be an integer type");
  // body gets each index as a value (static_cast<Index>(i), not the loop's
  // variable), as the trait below checks: a body taking Index& must not move
  // the loop.
  if constexpr (std::is_nothrow_invocable_v<Body&, Index>) {
    for_each_range(begin, end, [&body](Index first, Index last) noexcept {
      for (Index i = first; i < last; ++i) body(static_cast<Index>(i));
    });
  } else {
    // The failure of the lowest index, kept across the threads' ranges.
    std::mutex failure_mutex;
    Index failed = end;
    std::exception_ptr failure;
    for_each_range(begin, end, [&](Index first, Index last) noexcept {
      for (Index i = first; i < last; ++i) {
        try {
          body(static_cast<Index>(i));
        } catch (...) {
          std::lock_guard<std::mutex> lock(failure_mutex);
          if (i < failed) {
            failed = i;
            failure = std::current_exception();
          }
        }
      }
    });
    if (failure) {
      on_failure(failed, failure);
      std::rethrow_exception(failure);
    }
  }
}

// for_each without on_failure: the lowest failing index's exception is rethrown as it is.
template <class Index, class Body>
void for_each(Index begin, Index end, Body&& body) {
  for_each(begin, end, std::forward<Body>(body), [](Index, const std::exception_ptr&) {});
}

// Calls body(k) for k in [0, count), each k its own task: for a few large
// pieces of work (a handful per thread) that for_each would not share out.
// The rule of for_each holds (each thread takes its own block of tasks first,
// then the tasks left at the back of the others'); body must not throw.
template <class Body>
void for_each_task(std::size_t count, Body&& body) {
  static_assert(std::is_nothrow_invocable_v<Body&, std::size_t>,
                "parallel::for_each_task: declare the body noexcept (catch inside and report after the loop)");
  struct Job {
    Body& body;
    static void run_task(void* context, std::size_t task) { static_cast<Job*>(context)->body(task); }
  };
  Job job{body};
  const int threads = thread_count();
  detail::Team* team = nullptr;
  if (threads > 1 && count > 1) {
    team = &detail::Team::instance();
    if (!team->try_acquire()) team = nullptr;
  }
  if (team) {
    team->run(count, threads, &Job::run_task, &job);
    team->release();
  } else {
    for (std::size_t k = 0; k < count; ++k) body(k);
  }
}

// Lowers `lowest` to i if i is below it, whichever thread gets there first:
// for for_each_range and for_each_task bodies, which must not throw, to note
// the lowest failing index and report it after the loop (the loop's end
// orders the threads' writes before that read).
inline void keep_lowest(std::atomic<std::size_t>& lowest, std::size_t i) noexcept {
  std::size_t current = lowest.load(std::memory_order_relaxed);
  while (i < current && !lowest.compare_exchange_weak(current, i, std::memory_order_relaxed)) {
  }
}

// The message of a caught exception (for errors that add where they happened).
inline std::string what(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& caught) {
    return caught.what();
  } catch (...) {
    return "unknown exception";
  }
}

}  // namespace sphshell::parallel
