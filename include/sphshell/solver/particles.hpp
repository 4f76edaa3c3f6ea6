#pragma once
// The particles' state, inertia and forces, each a plain structure of arrays
// indexed by particle.
//
// Owned and ghost particles: a process integrates the particles it owns,
// [0, owned_count), and only mirrors the ghosts, [owned_count, size()), whose
// state another process sends it (a distributed run). In a single process
// every particle is owned and the ghost range is empty.

#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>

#include <cstddef>
#include <vector>

#include <cmath>

namespace sphshell::solver {

// Index ranges of the owned and the ghost particles.
struct ParticleRanges {
  std::size_t owned_begin = 0, owned_end = 0;
  std::size_t ghost_begin = 0, ghost_end = 0;
  std::size_t owned_count() const { return owned_end - owned_begin; }
  std::size_t ghost_count() const { return ghost_end - ghost_begin; }
};

// Kinematic state: mid-surface position x, unit director d, velocity v and
// angular velocity ω (normal to d: the director has no drilling rotation).
struct ParticleState {
  std::vector<Vector3> position, director, velocity, angular_velocity;
  ParticleRanges ranges;

  // At rest in the reference configuration, every particle owned.
  static ParticleState at_rest(const std::vector<Vector3>& reference_position,
                               const std::vector<Vector3>& reference_normal) {
    ParticleState state;
    state.position = reference_position;
    state.director = reference_normal;
    state.velocity.assign(reference_position.size(), Vector3::Zero());
    state.angular_velocity.assign(reference_position.size(), Vector3::Zero());
    state.ranges = {0, reference_position.size(), reference_position.size(), reference_position.size()};
    return state;
  }
  std::size_t size() const { return position.size(); }
  std::size_t owned_count() const { return ranges.owned_count(); }

  // Checkpoints (solver/checkpoint.hpp); the ranges are the model's.
  template <class Writer>
  void save(Writer& out) const {
    out(position, director, velocity, angular_velocity);
  }
  template <class Reader>
  void load(Reader& in) {
    in.read_exact(position, "particle positions");
    in.read_exact(director, "particle directors");
    in.read_exact(velocity, "particle velocities");
    in.read_exact(angular_velocity, "particle angular velocities");
  }
};

// A particle's position and director side by side: the internal-force
// assembler packs them once per step, so gathering a point's neighbours reads
// one place per neighbour instead of two.
struct PackedKinematics {
  Vector3 position, director;
};
// The gather reads a particle's six numbers as one vector (IntegrationPoints::gather).
static_assert(sizeof(PackedKinematics) == 6 * sizeof(double),
              "PackedKinematics must hold position then director as six contiguous doubles");

// Lumped translational mass m (kg) and rotary inertia I (kg·m²) per particle.
struct Inertia {
  std::vector<double> mass, rotary_inertia;

  // m = ρ d A and I = s_I ρ d³/12 A with each particle's own thickness d and
  // the rotary-inertia scale s_I (docs/method.md §1, §7).
  static Inertia lumped(const ShellModel& model, double density, double rotary_inertia_scale) {
    Inertia inertia;
    const std::size_t n = model.particle_count();
    inertia.mass.resize(n);
    inertia.rotary_inertia.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double d = model.particle_thickness(i);
      inertia.mass[i] = density * d * model.particle_area[i];
      inertia.rotary_inertia[i] = rotary_inertia_scale * density * d * d * d / 12.0 * model.particle_area[i];
    }
    return inertia;
  }
};

// Σ d_i A_i over the particles: the shell's volume.
inline double shell_volume(const ShellModel& model) {
  double volume = 0.0;
  for (std::size_t i = 0; i < model.particle_count(); ++i) volume += model.particle_thickness(i) * model.particle_area[i];
  return volume;
}

// Forces on the particles. The internal ones are ∂Π/∂x_j and ∂Π/∂d_j (the
// generalized force on the director; its moment is −d × g). The external
// ones are what the loads apply: a force and a moment about the particle.
struct ParticleForces {
  std::vector<Vector3> internal, internal_director, external, external_moment;

  explicit ParticleForces(std::size_t particles = 0)
      : internal(particles, Vector3::Zero()),
        internal_director(particles, Vector3::Zero()),
        external(particles, Vector3::Zero()),
        external_moment(particles, Vector3::Zero()) {}

  // Checkpoints (solver/checkpoint.hpp): the forces of the last evaluation,
  // which the next step starts from.
  template <class Writer>
  void save(Writer& out) const {
    out(internal, internal_director, external, external_moment);
  }
  template <class Reader>
  void load(Reader& in) {
    in.read_exact(internal, "internal forces");
    in.read_exact(internal_director, "internal director forces");
    in.read_exact(external, "external forces");
    in.read_exact(external_moment, "external moments");
  }
};

// The rotation vector taking the unit vector `from` (a reference director)
// to the unit vector `to` (the current one): zero when they are parallel.
inline Vector3 rotation_vector(const Vector3& from, const Vector3& to) {
  // Below this sine the directors are parallel (no rotation).
  constexpr double negligible_rotation_sine = 1e-300;
  const Vector3 axis = from.cross(to);
  const double sine = axis.norm();
  if (sine < negligible_rotation_sine) return Vector3::Zero();
  return axis / sine * std::atan2(sine, from.dot(to));
}

}  // namespace sphshell::solver
