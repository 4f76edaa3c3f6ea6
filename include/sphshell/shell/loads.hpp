#pragma once
// External loads on particles: pressure (uniform or p(X, t), follower or fixed
// direction), point forces and moments, gravity, and ready-made time functions.
//
// Each load is type-erased once (one virtual call per load per step); its loop
// over particles calls the user's callable inline.

#include <sphshell/core/error.hpp>
#include <sphshell/core/parallel.hpp>
#include <sphshell/core/types.hpp>

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace sphshell {

namespace time_function {
// f(t) = 1 from t_start on (a step load).
struct Step {
  double t_start = 0.0;
  double operator()(double t) const { return t >= t_start ? 1.0 : 0.0; }
};
// f(t) rises linearly from 0 at t_start to 1 at t_start + rise_time, then stays 1.
struct Ramp {
  double rise_time = 0.0;  // s; 0 makes it a step at t_start
  double t_start = 0.0;
  double operator()(double t) const {
    if (t <= t_start) return 0.0;
    return t >= t_start + rise_time ? 1.0 : (t - t_start) / rise_time;
  }
};
}  // namespace time_function

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

template <class PressureFunction>
class PressureLoad final : public Load {
 public:
  PressureLoad(std::vector<int> particles, PressureFunction pressure, PressureDirection direction)
      : particles_(std::move(particles)), pressure_(std::move(pressure)), direction_(direction) {}
  void apply(LoadContext& c) const override {
    for (int i : particles_) {
      const double p = pressure_(c.reference_position[i], c.time);
      const Vector3& n =
          direction_ == PressureDirection::follower ? c.director[i] : c.reference_normal[i];
      c.force[i] -= p * c.area[i] * n;
    }
  }

 private:
  std::vector<int> particles_;
  PressureFunction pressure_;
  PressureDirection direction_;
};

template <class TimeFunction>
class PointForceLoad final : public Load {
 public:
  PointForceLoad(std::vector<int> particles, Vector3 force, TimeFunction time_function)
      : particles_(std::move(particles)), force_(force), time_function_(std::move(time_function)) {}
  void apply(LoadContext& c) const override {
    const Vector3 f = time_function_(c.time) * force_;
    for (int i : particles_) c.force[i] += f;
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
      : particles_(std::move(particles)), moment_(moment), time_function_(std::move(time_function)) {}
  void apply(LoadContext& c) const override {
    const Vector3 m = time_function_(c.time) * moment_;
    for (int i : particles_) c.moment[i] += m;
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
      : particles_(std::move(particles)), acceleration_(acceleration), time_function_(std::move(time_function)) {}
  void apply(LoadContext& c) const override {
    const Vector3 g = time_function_(c.time) * acceleration_;
    for (int i : particles_) c.force[i] += c.mass[i] * g;
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
      if (!context.force[i].allFinite() || !context.moment[i].allFinite())
        detail::fail_unstable(at, "non-finite external load at particle " + std::to_string(i) +
                                      " (a pressure, force or moment function returned NaN or infinity)");
    });
  }

 private:
  std::vector<std::unique_ptr<detail::Load>> loads_;
};

}  // namespace sphshell
