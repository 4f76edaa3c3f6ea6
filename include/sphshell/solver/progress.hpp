#pragma once
// The progress line of a long run: every progress_interval steps, the step,
// the simulated time (of the end time and the share done, when the run has
// one), the wall-clock rate and the estimated time left, and the energy
// books. It goes to MonitoringOptions::progress_stream, std::clog by default,
// so a program's standard output stays its own.

#include <sphshell/core/error.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/options.hpp>

#include <chrono>
#include <cmath>
#include <iostream>
#include <ostream>
#include <sstream>

namespace sphshell::solver {

class ProgressReporter {
 public:
  explicit ProgressReporter(const MonitoringOptions& monitoring) : monitoring_(monitoring) {}

  // A run toward end_time starts now (run_until): the rate and the time left
  // are measured from here.
  void start_run(const StepTime& at, double end_time) {
    end_time_ = end_time;
    has_end_time_ = true;
    run_start_ = at;
    wall_start_ = Clock::now();
  }
  void end_run() { has_end_time_ = false; }

  bool is_due(long step) const {
    return monitoring_.progress_interval > 0 && step % monitoring_.progress_interval == 0;
  }

  void write(const StepTime& at, const EnergyReport& e) const {
    std::ostringstream line;
    line.precision(4);
    line << "step " << at.step << "  t = " << at.time << " s";
    if (has_end_time_) {
      const double span = end_time_ - run_start_.time;
      const double done = span > 0.0 ? (at.time - run_start_.time) / span : 1.0;
      line << " of " << end_time_ << " s (" << std::fixed;
      line.precision(1);
      line << 100.0 * done << " %)";
      line << std::defaultfloat;
      line.precision(4);
      const double seconds = std::chrono::duration<double>(Clock::now() - wall_start_).count();
      const long steps = at.step - run_start_.step;
      if (seconds > 0.0 && steps > 0) {
        const double rate = static_cast<double>(steps) / seconds;
        line << "  " << rate << " steps/s";
        if (done > 0.0) line << "  ETA " << format_duration(seconds * (1.0 - done) / done);
      }
    }
    line << "  kinetic " << e.kinetic << " J  internal " << e.internal << " J  external " << e.external_work
         << " J  balance " << e.balance() << " J\n";
    std::ostream& out = monitoring_.progress_stream ? *monitoring_.progress_stream : std::clog;
    out << line.str() << std::flush;
  }

 private:
  using Clock = std::chrono::steady_clock;

  // 42 s, 3 min 20 s, 2 h 05 min.
  static std::string format_duration(double seconds) {
    std::ostringstream out;
    if (!std::isfinite(seconds) || seconds < 0.0) return "?";
    const long total = std::lround(seconds);
    if (total < 60) {
      out << total << " s";
    } else if (total < 3600) {
      out << total / 60 << " min " << total % 60 << " s";
    } else {
      out << total / 3600 << " h ";
      out.width(2);
      out.fill('0');
      out << (total % 3600) / 60 << " min";
    }
    return out.str();
  }

  MonitoringOptions monitoring_;
  bool has_end_time_ = false;
  double end_time_ = 0.0;
  StepTime run_start_;
  Clock::time_point wall_start_ = Clock::now();
};

}  // namespace sphshell::solver
