#pragma once
// External loads on particles: pressure (uniform or p(X, t), follower or fixed
// direction), point forces and moments, gravity, and ready-made time functions.
//
// Each load is type-erased once (a virtual call per load and range of
// particles); its loop over particles calls the user's callable inline. A
// load that calls no user code per particle (a uniform pressure, point forces
// and moments, gravity: their time function is evaluated once per step) is
// shared by the threads, each particle of the set being listed once
// (solver::checked_set); a pressure function p(X, t) is called serially, as
// it need not be thread-safe.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell {

namespace time_function {
// f(t) = 1 from t_start on (a step load). t_start must be finite.
struct Step {
  double t_start = 0.0;
  double operator()(double t) const { return t >= t_start ? 1.0 : 0.0; }
  // An Error naming the parameter unless t_start is finite (a NaN start would never switch the load on).
  void validate() const { detail::require_finite("time_function::Step::t_start", t_start); }
};
// f(t) rises linearly from 0 at t_start to 1 at t_start + rise_time, then stays 1.
// rise_time must be finite and >= 0, t_start finite.
struct Ramp {
  double rise_time = 0.0;  // s; 0 makes it a step at t_start
  double t_start = 0.0;
  double operator()(double t) const {
    if (t <= t_start) return 0.0;
    return t >= t_start + rise_time ? 1.0 : (t - t_start) / rise_time;
  }
  void validate() const {
    detail::require_nonnegative("time_function::Ramp::rise_time", rise_time);
    detail::require_finite("time_function::Ramp::t_start", t_start);
  }
};
}  // namespace time_function

namespace detail {
template <class F, class = void>
struct has_validate : std::false_type {};
template <class F>
struct has_validate<F, std::void_t<decltype(std::declval<const F&>().validate())>> : std::true_type {};

// A time function's own check (Step, Ramp, or a user type with validate()),
// called when a load is added; other callables are taken as they are.
template <class TimeFunction>
void check_time_function(const TimeFunction& time) {
  if constexpr (has_validate<TimeFunction>::value) time.validate();
}
}  // namespace detail

// Which way a pressure pushes.
enum class PressureDirection {
  follower,  // along the current director (follows the deforming shell)
  fixed      // along the reference normal
};

namespace detail {

// What a load sees and where it adds: per particle the reference position and
// normal, the current director, the reference area and the mass; it adds to
// the external force (N) and the external moment (N·m, about the particle;
// only its part normal to the director acts, the director has no drilling
// rotation).
// Sign convention: a positive pressure acts on the face the normal points out
// of and pushes the shell against its normal, f = −p A n (for a spherical cap
// with outward normals, positive pressure is inward). A is the reference area
// of the particle. A point force or moment applies its full value to every
// particle of its set.
struct LoadContext {
  double time;
  const std::vector<Vector3>& reference_position;
  const std::vector<Vector3>& reference_normal;
  const std::vector<Vector3>& director;
  const std::vector<double>& area;
  const std::vector<double>& mass;
  std::vector<Vector3>& force;
  std::vector<Vector3>& moment;
};

// A load adds its contribution in two parts: its time function, evaluated once
// per step on the calling thread (it is user code: it may throw and need not
// be thread-safe), and the additions to the particles of its set, made for one
// range of particle indices at a time and for disjoint ranges on several
// threads at once, unless the load calls user code per particle (serial()).
class Load {
 public:
  virtual ~Load() = default;
  // The load's time factor at `time` (1 for a load without a time function).
  virtual double factor(double time) const = 0;
  // Adds the load, scaled by `factor`, to the particles of its set whose
  // index is in [first, last), reading only those particles' entries of the
  // context (the solver steps other ranges meanwhile). Unless serial(), it
  // runs inside a parallel loop and must not throw (the library's loads are
  // declared noexcept).
  virtual void apply(LoadContext& context, double factor, std::size_t first, std::size_t last) const = 0;
  // True when apply() calls user code per particle: it is then called once,
  // on the whole range, by the calling thread.
  virtual bool serial() const { return false; }
};

// A load's particles in index order, so that those in a range of indices are
// found by two binary searches (a set lists each particle once, so the order
// does not change what a particle receives).
class SortedParticles {
 public:
  explicit SortedParticles(std::vector<int> particles) : particles_(std::move(particles)) {
    std::sort(particles_.begin(), particles_.end());
  }
  template <class Visit>
  void visit(std::size_t first, std::size_t last, Visit&& visit) const {
    const auto below = [](int particle, std::size_t index) { return static_cast<std::size_t>(particle) < index; };
    const auto from = std::lower_bound(particles_.begin(), particles_.end(), first, below);
    const auto to = std::lower_bound(from, particles_.end(), last, below);
    for (auto it = from; it != to; ++it) visit(static_cast<std::size_t>(*it));
  }

 private:
  std::vector<int> particles_;
};

// Adds a pressure p on particle i: f = −p A n, n the current director
// (follower) or the reference normal (fixed).
inline void add_pressure_force(LoadContext& c, std::size_t i, double p, PressureDirection direction) {
  const Vector3& n = direction == PressureDirection::follower ? c.director[i] : c.reference_normal[i];
  c.force[i] -= p * c.area[i] * n;
}

// p(X, t) on the particles of the set, in the set's order, on one thread.
template <class PressureFunction>
class PressureLoad final : public Load {
 public:
  PressureLoad(std::vector<int> particles, PressureFunction pressure, PressureDirection direction)
      : particles_(std::move(particles)), pressure_(std::move(pressure)), direction_(direction) {}
  double factor(double) const override { return 1.0; }
  void apply(LoadContext& c, double, std::size_t first, std::size_t last) const override {
    for (int particle : particles_) {
      const std::size_t i = static_cast<std::size_t>(particle);
      if (i >= first && i < last) add_pressure_force(c, i, pressure_(c.reference_position[i], c.time), direction_);
    }
  }
  bool serial() const override { return true; }

 private:
  std::vector<int> particles_;
  PressureFunction pressure_;
  PressureDirection direction_;
};

// p·f(t) on every particle of the set, the same as PressureLoad with
// p(X, t) = p·f(t).
template <class TimeFunction>
class UniformPressureLoad final : public Load {
 public:
  UniformPressureLoad(std::vector<int> particles, double pressure, TimeFunction time_function,
                      PressureDirection direction)
      : particles_(std::move(particles)),
        pressure_(pressure),
        time_function_(std::move(time_function)),
        direction_(direction) {
    check_time_function(time_function_);
  }
  double factor(double time) const override { return time_function_(time); }
  void apply(LoadContext& c, double factor, std::size_t first, std::size_t last) const noexcept override {
    const double p = pressure_ * factor;
    particles_.visit(first, last, [&](std::size_t i) { add_pressure_force(c, i, p, direction_); });
  }

 private:
  SortedParticles particles_;
  double pressure_;
  TimeFunction time_function_;
  PressureDirection direction_;
};

template <class TimeFunction>
class PointForceLoad final : public Load {
 public:
  PointForceLoad(std::vector<int> particles, Vector3 force, TimeFunction time_function)
      : particles_(std::move(particles)), force_(force), time_function_(std::move(time_function)) {
    check_time_function(time_function_);
  }
  double factor(double time) const override { return time_function_(time); }
  void apply(LoadContext& c, double factor, std::size_t first, std::size_t last) const noexcept override {
    const Vector3 f = factor * force_;
    particles_.visit(first, last, [&](std::size_t i) { c.force[i] += f; });
  }

 private:
  SortedParticles particles_;
  Vector3 force_;
  TimeFunction time_function_;
};

template <class TimeFunction>
class PointMomentLoad final : public Load {
 public:
  PointMomentLoad(std::vector<int> particles, Vector3 moment, TimeFunction time_function)
      : particles_(std::move(particles)), moment_(moment), time_function_(std::move(time_function)) {
    check_time_function(time_function_);
  }
  double factor(double time) const override { return time_function_(time); }
  void apply(LoadContext& c, double factor, std::size_t first, std::size_t last) const noexcept override {
    const Vector3 m = factor * moment_;
    particles_.visit(first, last, [&](std::size_t i) { c.moment[i] += m; });
  }

 private:
  SortedParticles particles_;
  Vector3 moment_;
  TimeFunction time_function_;
};

// Body force of an acceleration field g (m/s²) on each particle's mass.
template <class TimeFunction>
class GravityLoad final : public Load {
 public:
  GravityLoad(std::vector<int> particles, Vector3 acceleration, TimeFunction time_function)
      : particles_(std::move(particles)), acceleration_(acceleration), time_function_(std::move(time_function)) {
    check_time_function(time_function_);
  }
  double factor(double time) const override { return time_function_(time); }
  void apply(LoadContext& c, double factor, std::size_t first, std::size_t last) const noexcept override {
    const Vector3 g = factor * acceleration_;
    particles_.visit(first, last, [&](std::size_t i) { c.force[i] += c.mass[i] * g; });
  }

 private:
  SortedParticles particles_;
  Vector3 acceleration_;
  TimeFunction time_function_;
};

}  // namespace detail

// The loads of a run: each applied in turn into zeroed force and moment
// arrays; a load that produces a non-finite value stops the run.
// Without a serial load (a pressure function p(X, t)) the loads are part of
// the solver's pass over the particles (apply_range): each thread zeroes a
// range, adds every load to it and checks it while its particles are in
// cache; apply() does the same in a pass of its own. The sums
// are those of one load after the other (each particle receives its loads in
// the order they were added), so they are the same for any thread count.
class ExternalLoads {
 public:
  void add(std::unique_ptr<detail::Load> load) {
    const bool serial = load->serial();
    loads_.push_back(std::move(load));
    any_serial_ = any_serial_ || serial;
  }
  bool empty() const { return loads_.empty(); }

  void apply(const StepTime& at, detail::LoadContext& context) {
    start_step(context.time);
    const std::size_t count = context.force.size();
    std::atomic<std::size_t> first_non_finite{count};
    if (!any_serial_) {
      parallel::for_each_range(std::size_t{0}, count, [&](std::size_t first, std::size_t last) noexcept {
        const std::size_t i = apply_range(context, first, last);
        if (i < last) parallel::keep_lowest(first_non_finite, i);
      });
    } else {
      parallel::for_each_range(std::size_t{0}, count,
                               [&](std::size_t first, std::size_t last) noexcept { zero(context, first, last); });
      for (std::size_t l = 0; l < loads_.size(); ++l) {
        const detail::Load& load = *loads_[l];
        const double factor = factors_[l];
        if (load.serial())
          load.apply(context, factor, 0, count);
        else
          parallel::for_each_range(std::size_t{0}, count, [&](std::size_t first, std::size_t last) noexcept {
            load.apply(context, factor, first, last);
          });
      }
      parallel::for_each_range(std::size_t{0}, count, [&](std::size_t first, std::size_t last) noexcept {
        const std::size_t i = first_non_finite_in(context, first, last);
        if (i < last) parallel::keep_lowest(first_non_finite, i);
      });
    }
    const std::size_t i = first_non_finite.load();
    if (i < count) fail_non_finite(at, i);
  }

  // The same in a pass that steps the particles in chunks
  // (Solver::advance_particles), possible when no load is serial(): start_step()
  // once before the pass, then apply_range(context, first, last) for each chunk,
  // which zeroes the chunk's forces and moments, adds every load to them and
  // returns the first particle of the chunk whose load is not finite (last if
  // none): the run then stops with fail_non_finite() at the lowest of them.
  bool applies_in_chunks() const { return !any_serial_; }
  void start_step(double time) {
    factors_.resize(loads_.size());
    for (std::size_t l = 0; l < loads_.size(); ++l) factors_[l] = loads_[l]->factor(time);
  }
  std::size_t apply_range(detail::LoadContext& context, std::size_t first, std::size_t last) const noexcept {
    zero(context, first, last);
    for (std::size_t l = 0; l < loads_.size(); ++l) loads_[l]->apply(context, factors_[l], first, last);
    return first_non_finite_in(context, first, last);
  }
  [[noreturn]] static void fail_non_finite(const StepTime& at, std::size_t i) {
    detail::fail_unstable(at, "non-finite external load at particle " + std::to_string(i) +
                                  " (a pressure, force or moment function returned NaN or infinity)");
  }

 private:
  static std::size_t first_non_finite_in(const detail::LoadContext& context, std::size_t first,
                                         std::size_t last) noexcept {
    for (std::size_t i = first; i < last; ++i)
      if (!all_finite(context.force[i], context.moment[i])) return i;
    return last;
  }
  static void zero(detail::LoadContext& context, std::size_t first, std::size_t last) noexcept {
    for (std::size_t i = first; i < last; ++i) {
      context.force[i].setZero();
      context.moment[i].setZero();
    }
  }
  std::vector<std::unique_ptr<detail::Load>> loads_;
  std::vector<double> factors_;  // each load's time factor this step
  bool any_serial_ = false;
};

}  // namespace sphshell
