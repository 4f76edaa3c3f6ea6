#pragma once
// The solver's checks of what a user asks of a run, each an Error naming the
// parameter, its value and what is allowed: particle sets, damping against the
// time step, run_until's end time against the step budget, and the memory the
// model will take against what the machine offers.

#include <cstddef>
#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/shell/local_spacing.hpp>
#include <sphshell/solver/options.hpp>
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace sphshell::solver {

// Numbers and vectors in messages, to six significant digits.
inline std::string number_text(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}
inline std::string vector_text(const Vector3& v) {
  std::ostringstream out;
  out.precision(6);
  out << v.transpose();
  return out.str();
}

// A prescribed displacement added mid-run may differ from the particle's
// displacement by this fraction of it (or of the spacing), round-off.
inline constexpr double prescribed_jump_tolerance = 1e-9;
// Mass-proportional damping c with c Δt above this flips the velocity's
// sign every step (v ← v (1 − c Δt/2)/(1 + c Δt/2) at zero force).
inline constexpr double largest_damping_times_step = 2.0;

// A set's indices in range and each listed once (a duplicate would apply a
// load or a motion twice).
inline ParticleSet checked_set(const ParticleSet& set, std::size_t particle_count) {
  if (set.empty()) detail::invalid_parameter("particle set size", 0, "must not be empty");
  std::vector<char> listed(particle_count, 0);
  for (int i : set) {
    if (i < 0 || static_cast<std::size_t>(i) >= particle_count)
      detail::invalid_parameter("particle index", i, "out of range [0, " + std::to_string(particle_count) + ")");
    if (listed[i]) detail::invalid_parameter("particle index", i, "listed twice in the set: list each particle once");
    listed[i] = 1;
  }
  return set;
}

inline void check_damping(double damping, double time_step) {
  if (damping * time_step > largest_damping_times_step)
    detail::invalid_parameter("damping", damping,
                              "with the time step " + number_text(time_step) +
                                  " s, damping × time step = " + number_text(damping * time_step) +
                                  " must be <= 2 (above, the velocity flips sign every step); at most " +
                                  number_text(largest_damping_times_step / time_step) + " 1/s");
}

// Where a run stands: time, step size and the steps taken.
struct RunPosition {
  double time;
  double time_step;
  long steps;
};

// run_until's end time: finite, not in the past, and within the step budget.
inline void check_run_end(double t_end, const RunPosition& at, long max_steps_per_run) {
  detail::require_finite("t_end", t_end);
  if (t_end < at.time - 0.5 * at.time_step)
    detail::invalid_parameter(
        "t_end", t_end,
        "must not lie before the current time " + number_text(at.time) + " s (step " + std::to_string(at.steps) + ")");
  const double steps = (t_end - at.time) / at.time_step;
  if (steps > static_cast<double>(max_steps_per_run))
    detail::invalid_parameter(
        "t_end", t_end,
        "needs " + number_text(steps) + " steps of " + number_text(at.time_step) +
            " s from t = " + number_text(at.time) +
            " s, more than SolverOptions::max_steps_per_run = " + std::to_string(max_steps_per_run) +
            ": check the time step, the material and the end time, or raise the budget");
}

// The last memory estimate made on this thread, for the message when an
// allocation fails after the check passed (the solver's members are gone then).
inline std::string& memory_estimate_text() {
  static thread_local std::string text;
  return text;
}

// What the solver's large arrays will take, against what the machine
// offers; refused up front with both figures. Per particle: the state,
// forces, inertia and books (about 40 vectors of 3 doubles); per
// integration point: its section state and strains, resultants, frame and
// reference gradients; per slot (row × neighbour): approx::bytes_per_slot.
inline constexpr double bytes_per_particle = 40 * 3 * sizeof(double);
template <class SectionState>
inline constexpr double bytes_per_point = sizeof(SectionState) + 60 * sizeof(double);

template <class SectionState>
void check_memory(const ShellModel& model, const SolverOptions& options) {
  double covered = 0.0;
  for (double area : model.particle_area) covered += area;
  const bool particles_integrate = options.particle_integration_share > 0.0 || options.particle_shear_weight > 0.0;
  const double particles = static_cast<double>(model.particle_count());
  const double points = static_cast<double>(model.stress_point_count()) + (particles_integrate ? particles : 0.0);
  // Each row's own support radius: support_radius_factor × its local spacing.
  const LocalSpacing spacing = local_spacing(model);
  double slots = 0.0;
  const auto add_rows = [&](const std::vector<double>& local) {
    for (double s : local)
      slots += approx::expected_row_size(model.particle_count(), covered, options.support_radius_factor * s);
  };
  add_rows(spacing.stress_point);
  if (particles_integrate) add_rows(spacing.particle);
  const double needed =
      particles * bytes_per_particle + points * bytes_per_point<SectionState> + slots * approx::bytes_per_slot;
  const double available = approx::available_memory();
  std::ostringstream text;
  text.precision(4);
  text << "the model of " << model.particle_count() << " particles and " << model.stress_point_count()
       << " stress points needs about " << approx::format_bytes(needed) << " (" << slots << " neighbour slots); "
       << approx::format_bytes(available) << " available";
  memory_estimate_text() = text.str();
  if (needed > available)
    throw Error("sphshell: model too large for the memory available: " + text.str() +
                " (MemAvailable, the cgroup limit and ulimit -v); use fewer particles or a smaller "
                "support_radius_factor");
}

// A prescribed displacement u(X, t) at a particle, added at step `steps`
// (time `time`): at the start it must be zero (the run starts from the
// reference configuration); added mid-run it must continue from the
// particle's displacement now, else the jump would be imposed as one step's
// velocity (a shock). An Error naming the particle otherwise.
inline void check_prescribed_displacement_start(int particle, const Vector3& start, const Vector3& now, double time,
                                                long steps, double minimum_spacing) {
  if (steps == 0 && start.norm() > 0.0)
    detail::invalid_parameter("prescribed displacement at t = 0, particle " + std::to_string(particle),
                              start.transpose(), "must be zero: the run starts from the reference configuration");
  const double allowed = prescribed_jump_tolerance * std::max(now.norm(), minimum_spacing);
  if (steps > 0 && !((start - now).norm() <= allowed))
    detail::invalid_parameter("prescribed displacement at t = " + number_text(time) + " s, particle " +
                                  std::to_string(particle),
                              start.transpose(),
                              "must equal the particle's displacement now (" + vector_text(now) +
                                  "): a prescribed motion added mid-run continues from the current state");
}

}  // namespace sphshell::solver
