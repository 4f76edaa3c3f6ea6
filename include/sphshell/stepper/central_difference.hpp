#pragma once
// The central difference (leapfrog) scheme of explicit dynamics, the paper's
// Table 2 time integration:
//   v^{n+½} = v^{n−½} + Δt M⁻¹ (f_ext − f_int) − c Δt v^{n},  v^{n} ≈ ½(v^{n−½} + v^{n+½}),
//   x^{n+1} = x^n + Δt v^{n+½},
// the same for the angular velocity with the moment −d × g of the director
// force g (plus any applied moment) and the rotary inertia, and the director
// turned by Δt ω^{n+½} (Rodrigues' formula). The velocities live at half
// steps, so the first update spans half a step. Mass-proportional damping is
// taken at the mid-step velocity, which keeps the update explicit.

#include <sphshell/core/types.hpp>
#include <sphshell/stepper/stepper.hpp>

#include <cmath>
#include <cstddef>

namespace sphshell::stepper {

class CentralDifference {
 public:
  // The leapfrog start-up: v^{½} = v^0 + ½Δt a^0.
  double velocity_step(long step, double time_step) const { return step == 0 ? 0.5 * time_step : time_step; }

  void advance_velocities(const StepContext& context, solver::ParticleState& state, const solver::Inertia& inertia,
                          const solver::ParticleForces& forces, std::size_t first, std::size_t last) {
    const double dt = context.velocity_step;
    const double c = context.damping;
    const double keep = (1.0 - 0.5 * c * dt) / (1.0 + 0.5 * c * dt);
    const double gain = dt / (1.0 + 0.5 * c * dt);
    for (std::size_t i = first; i < last; ++i) {
      const Vector3 force = forces.external[i] - forces.internal[i];
      state.velocity[i] = keep * state.velocity[i] + gain * force / inertia.mass[i];
      // δΠ = g·δd with δd = δθ × d gives ∂Π/∂θ = d × g, so the moment is −d × g.
      const Vector3 moment = forces.external_moment[i] - state.director[i].cross(forces.internal_director[i]);
      const Vector3 omega = keep * state.angular_velocity[i] + gain * moment / inertia.rotary_inertia[i];
      state.angular_velocity[i] = omega - omega.dot(state.director[i]) * state.director[i];  // no drilling
    }
  }

  void advance_configuration(const StepContext& context, solver::ParticleState& state, std::size_t first,
                             std::size_t last) {
    const double dt = context.time_step;
    for (std::size_t i = first; i < last; ++i) {
      state.position[i] += dt * state.velocity[i];
      const Vector3 rotation = dt * state.angular_velocity[i];
      const double angle = rotation.norm();
      if (angle > 0.0) {
        const Vector3 axis = rotation / angle;
        const Vector3& d = state.director[i];
        state.director[i] =
            (d * std::cos(angle) + axis.cross(d) * std::sin(angle) + axis * axis.dot(d) * (1.0 - std::cos(angle)))
                .normalized();
      }
    }
  }
};

}  // namespace sphshell::stepper
