// Two threads against one on the paper's plate (51 × 51 particles, 2500
// stress points, Gauss<5>, J2 plasticity, the square_plate example's 1 MPa
// step load), wall time:
//  - threads_under_load: while a busy process that this benchmark starts (and
//    stops) holds a core, the situation of a user's laptop or a shared node;
//  - threads_idle: without it (the machine's other load stays: report it).
// Two solvers of the same plate step in alternating chunks of 20 steps, one on
// 1 thread and one on 2 (the order swapped every round), so a change of the
// machine's load hits both alike. The counter `ratio` is the median over the
// rounds of (2-thread chunk time) / (1-thread chunk time): below 1 the second
// thread helps. `load1` is the 1-minute
// load average when the benchmark started. `steal` is the share of the
// machine's CPU time that its hypervisor gave to other guests while the
// rounds ran (Linux /proc/stat; −1 where it cannot be read): a virtual
// machine can show no load of its own and still lose its cores for a while,
// and then "idle" is not idle. The argument is the team's spin time in µs
// (parallel::set_spin_time; 50 is the library's default).
// threads_idle also steps, in the same rounds, a one-thread solver pinned to
// each of the first two processors the process may use (the four chunks of a
// round in the orders of a Williams square), because a virtual machine's two
// processors need not be equally fast, and then no program's two threads are
// twice as fast as one thread on the faster (docs/performance.md,
// "Threads"). From the pinned chunk times t_a, t_b, ideal = 1 / (1/t_a + 1/t_b) is
// the time of two threads that share the work perfectly between the two
// processors. Counters, medians over the rounds: `ideal_ratio` (ideal over the
// one-thread time: what `ratio` would be with perfect sharing; the unpinned
// one-thread chunk runs wherever the scheduler leaves it), `efficiency` (ideal
// over the two-thread time: 1 is perfect, 0.9 is what "1.8 times faster" asks
// of equal processors), `core_speed_ratio` (the slower pinned time over the
// faster) and `cpuN_us_per_step` for each pinned processor N. They are left
// out where the process may use fewer than two processors or pinning fails.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include <benchmark/benchmark.h>

#include "bench_support.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <csignal>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace sphshell;
using sphshell::bench::median;
using sphshell::bench::ProcessorPin;
using sphshell::bench::first_two_processors;

namespace {

using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::J2Plasticity>;

PlateSolver loaded_plate() {
  SolverOptions options;
  options.density = 7850.0;
  PlateSolver solver(ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01), {210e9, 0.3, 235e6, 0.0}, options);
  solver.clamp(solver.model().set("boundary"));
  solver.add_uniform_pressure(solver.model().all_particles(), 1e6);
  return solver;
}

// A child process that spins on one core until it is killed.
class BusyProcess {
 public:
  BusyProcess() : pid_(fork()) {
    if (pid_ == 0) {
      volatile unsigned long counter = 0;
      for (;;) counter = counter + 1;
    }
    // Let the scheduler see it before the timing starts.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  ~BusyProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  BusyProcess(const BusyProcess&) = delete;
  BusyProcess& operator=(const BusyProcess&) = delete;
  bool running() const { return pid_ > 0; }

 private:
  pid_t pid_;
};

void use_threads(int threads) {
#ifdef _OPENMP
  omp_set_num_threads(threads);
#else
  (void)threads;
#endif
}

double seconds_for_steps(PlateSolver& solver, int steps) {
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) solver.step();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The machine's CPU time so far, in clock ticks: all of it and the part
// stolen by the hypervisor (the first line of /proc/stat: user nice system
// idle iowait irq softirq steal ...). {-1, -1} where it cannot be read.
struct CpuTicks {
  double total = -1.0, steal = -1.0;
};
CpuTicks cpu_ticks() {
  std::ifstream stat("/proc/stat");
  std::string line, label;
  if (!std::getline(stat, line)) return {};
  std::istringstream fields(line);
  fields >> label;
  if (label != "cpu") return {};
  CpuTicks ticks{0.0, 0.0};
  double value = 0.0;
  constexpr int steal_field = 7;  // zero-based among the numbers
  for (int k = 0; k < 8 && fields >> value; ++k) {
    ticks.total += value;
    if (k == steal_field) ticks.steal = value;
  }
  return ticks;
}
double steal_share(const CpuTicks& before, const CpuTicks& after) {
  if (before.total < 0.0 || after.total <= before.total) return -1.0;
  return (after.steal - before.steal) / (after.total - before.total);
}

void two_against_one_thread(benchmark::State& state, bool with_busy_process) {
#ifndef _OPENMP
  state.SkipWithError("built without OpenMP: the loops run on one thread");
  return;
#endif
  const std::chrono::nanoseconds previous_spin = parallel::spin_time();
  parallel::set_spin_time(std::chrono::microseconds(state.range(0)));
  double load1 = 0.0;
  getloadavg(&load1, 1);
  PlateSolver one = loaded_plate(), two = loaded_plate();
  // One-thread solvers pinned to each processor (threads_idle only), stepped
  // in the same rounds so that every solver is at the same step.
  const std::vector<int> processors = first_two_processors();
  const bool per_processor = !with_busy_process && processors.size() == 2;
  std::vector<PlateSolver> pinned;
  if (per_processor) {
    pinned.push_back(loaded_plate());
    pinned.push_back(loaded_plate());
  }
  constexpr int chunk = 20, rounds = 16;
  // A round's chunks: 0 one thread, 1 two threads, 2 and 3 pinned. Four of
  // them in the rows of a Williams square (each chunk in each place once, and
  // after each other chunk once, every four rounds); two alternate.
  constexpr int four_orders[4][4] = {{0, 1, 3, 2}, {1, 2, 0, 3}, {2, 3, 1, 0}, {3, 0, 2, 1}};
  for (auto _ : state) {
    BusyProcess* busy = with_busy_process ? new BusyProcess : nullptr;
    if (busy && !busy->running()) state.SkipWithError("could not start the busy process");
    std::vector<double> ratios, ideal_ratios, efficiencies, speed_ratios;
    double one_seconds = 0.0, two_seconds = 0.0, pinned_seconds[2] = {0.0, 0.0};
    bool pinned_ok = per_processor;
    const CpuTicks ticks_before = cpu_ticks();
    for (int round = 0; round < rounds; ++round) {
      const int turns = per_processor ? 4 : 2;
      double t1 = 0.0, t2 = 0.0, t_pinned[2] = {0.0, 0.0};
      for (int turn = 0; turn < turns; ++turn) {
        const int which = per_processor ? four_orders[round % 4][turn] : (turn + round) % 2;
        if (which == 0) {
          use_threads(1);
          t1 = seconds_for_steps(one, chunk);
        } else if (which == 1) {
          use_threads(2);
          t2 = seconds_for_steps(two, chunk);
        } else {
          const int k = which - 2;
          use_threads(1);
          ProcessorPin pin(processors[std::size_t(k)]);  // for this chunk
          pinned_ok = pin.pinned() && pinned_ok;
          t_pinned[k] = seconds_for_steps(pinned[std::size_t(k)], chunk);
        }
      }
      ratios.push_back(t2 / t1);
      one_seconds += t1;
      two_seconds += t2;
      if (per_processor) {
        const double ideal = 1.0 / (1.0 / t_pinned[0] + 1.0 / t_pinned[1]);
        ideal_ratios.push_back(ideal / t1);
        efficiencies.push_back(ideal / t2);
        speed_ratios.push_back(std::max(t_pinned[0], t_pinned[1]) / std::min(t_pinned[0], t_pinned[1]));
        pinned_seconds[0] += t_pinned[0];
        pinned_seconds[1] += t_pinned[1];
      }
    }
    const CpuTicks ticks_after = cpu_ticks();
    delete busy;
    use_threads(1);
    state.SetIterationTime(two_seconds / (rounds * chunk));
    state.counters["ratio"] = median(ratios);
    state.counters["one_thread_us_per_step"] = 1e6 * one_seconds / (rounds * chunk);
    state.counters["two_threads_us_per_step"] = 1e6 * two_seconds / (rounds * chunk);
    state.counters["load1"] = load1;
    state.counters["steal"] = steal_share(ticks_before, ticks_after);
    if (per_processor && pinned_ok) {
      for (int k = 0; k < 2; ++k)
        state.counters["cpu" + std::to_string(processors[std::size_t(k)]) + "_us_per_step"] =
            1e6 * pinned_seconds[k] / (rounds * chunk);
      state.counters["core_speed_ratio"] = median(speed_ratios);
      state.counters["ideal_ratio"] = median(ideal_ratios);
      state.counters["efficiency"] = median(efficiencies);
    }
  }
  parallel::set_spin_time(previous_spin);
}

void threads_under_load(benchmark::State& state) { two_against_one_thread(state, true); }
void threads_idle(benchmark::State& state) { two_against_one_thread(state, false); }

}  // namespace

BENCHMARK(threads_under_load)->Arg(50)->Arg(20)->Arg(5)->Arg(0)->Arg(1000)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(threads_idle)->Arg(50)->Arg(20)->Arg(5)->Arg(0)->UseManualTime()->Iterations(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
