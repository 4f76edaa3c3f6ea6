#pragma once
// External loads on particles: pressure (uniform or p(X, t), follower or fixed
// direction), point forces and moments, gravity, and ready-made time functions.
//
// Each load is type-erased once (one virtual call per load per step); its loop
// over particles calls the user's callable inline. A loop that calls no user
// code per particle (a uniform pressure, point forces and moments, gravity:
// their time function is evaluated once per step) is shared by the threads,
// each particle of the set being listed once (solver::checked_set); a
// pressure function p(X, t) is called serially, as it need not be thread-safe.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>

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

class Load {
 public:
  virtual ~Load() = default;
  virtual void apply(LoadContext& context) const = 0;
};

// Adds a pressure p on particle i: f = −p A n, n the current director
// (follower) or the reference normal (fixed).
inline void add_pressure_force(LoadContext& c, std::size_t i, double p, PressureDirection direction) {
  const Vector3& n = direction == PressureDirection::follower ? c.director[i] : c.reference_normal[i];
  c.force[i] -= p * c.area[i] * n;
}

template <class PressureFunction>
class PressureLoad final : public Load {
 public:
  PressureLoad(std::vector<int> particles, PressureFunction pressure, PressureDirection direction)
      : particles_(std::move(particles)), pressure_(std::move(pressure)), direction_(direction) {}
  void apply(LoadContext& c) const override {
    for (int i : particles_)
      add_pressure_force(c, std::size_t(i), pressure_(c.reference_position[i], c.time), direction_);
  }

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
  void apply(LoadContext& c) const override {
    const double p = pressure_ * time_function_(c.time);
    parallel::for_each(std::size_t{0}, particles_.size(), [&](std::size_t k) noexcept {
      add_pressure_force(c, std::size_t(particles_[k]), p, direction_);
    });
  }

 private:
  std::vector<int> particles_;
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
  void apply(LoadContext& c) const override {
    const Vector3 f = time_function_(c.time) * force_;
    parallel::for_each(std::size_t{0}, particles_.size(),
                       [&](std::size_t k) noexcept { c.force[std::size_t(particles_[k])] += f; });
  }

 private:
  std::vector<int> particles_;
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
  void apply(LoadContext& c) const override {
    const Vector3 m = time_function_(c.time) * moment_;
    parallel::for_each(std::size_t{0}, particles_.size(),
                       [&](std::size_t k) noexcept { c.moment[std::size_t(particles_[k])] += m; });
  }

 private:
  std::vector<int> particles_;
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
  void apply(LoadContext& c) const override {
    const Vector3 g = time_function_(c.time) * acceleration_;
    parallel::for_each(std::size_t{0}, particles_.size(), [&](std::size_t k) noexcept {
      const std::size_t i = std::size_t(particles_[k]);
      c.force[i] += c.mass[i] * g;
    });
  }

 private:
  std::vector<int> particles_;
  Vector3 acceleration_;
  TimeFunction time_function_;
};

}  // namespace detail

// The loads of a run: each applied in turn into zeroed force and moment
// arrays; a load that produces a non-finite value stops the run.
class ExternalLoads {
 public:
  void add(std::unique_ptr<detail::Load> load) { loads_.push_back(std::move(load)); }
  bool empty() const { return loads_.empty(); }

  void apply(const StepTime& at, detail::LoadContext& context) const {
    parallel::for_each(std::size_t{0}, context.force.size(), [&](std::size_t i) noexcept {
      context.force[i].setZero();
      context.moment[i].setZero();
    });
    for (const auto& load : loads_) load->apply(context);
    parallel::for_each(std::size_t{0}, context.force.size(), [&](std::size_t i) {
      if (!all_finite(context.force[i], context.moment[i]))
        detail::fail_unstable(at, "non-finite external load at particle " + std::to_string(i) +
                                      " (a pressure, force or moment function returned NaN or infinity)");
    });
  }

 private:
  std::vector<std::unique_ptr<detail::Load>> loads_;
};

}  // namespace sphshell
