#pragma once
// The kinematic conditions and dead loads of a static problem, and the
// displacements a path can be controlled by.
//
// The conditions are kept here, not in the solver: held translation
// directions, held rotation axes, symmetry planes (no translation across the
// plane, the director kept in it), and dead forces and moments at load factor
// 1 (a moment M does the work M · δθ for a director rotation δθ).

#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>

#include <cstddef>
#include <utility>
#include <vector>

namespace sphshell::statics {

// Conditions and dead loads, per particle.
struct Conditions {
  std::vector<std::vector<Vector3>> held_translations;   // directions with zero displacement
  std::vector<std::vector<Vector3>> held_rotation_axes;  // global axes with zero rotation
  std::vector<std::vector<Vector3>> symmetry_normals;    // planes the particle lies on
  std::vector<char> rotations_held;                      // both director rotations held
  std::vector<Vector3> force;                            // N, at load factor 1
  std::vector<Vector3> moment;                           // N·m, at load factor 1

  Conditions() = default;
  explicit Conditions(std::size_t particles)
      : held_translations(particles),
        held_rotation_axes(particles),
        symmetry_normals(particles),
        rotations_held(particles, 0),
        force(particles, Vector3::Zero()),
        moment(particles, Vector3::Zero()) {}

  std::size_t particle_count() const { return force.size(); }

  void clamp(const ParticleSet& set) {
    for (int i : set) {
      held_translations[i] = {Vector3::UnitX(), Vector3::UnitY(), Vector3::UnitZ()};
      rotations_held[i] = 1;
    }
  }
  void hold_translation(const ParticleSet& set, const Vector3& direction) {
    for (int i : set) held_translations[i].push_back(direction.normalized());
  }
  void hold_rotation(const ParticleSet& set, const Vector3& axis) {
    for (int i : set) held_rotation_axes[i].push_back(axis.normalized());
  }
  void symmetry_plane(const ParticleSet& set, const Vector3& normal) {
    for (int i : set) {
      held_translations[i].push_back(normal.normalized());
      symmetry_normals[i].push_back(normal.normalized());
    }
  }
  void add_force(const ParticleSet& set, const Vector3& f) {
    for (int i : set) force[i] += f;
  }
  void add_moment(const ParticleSet& set, const Vector3& m) {
    for (int i : set) moment[i] += m;
  }
};

// A displacement of the model, Σ w_j u_j · direction over particles j with
// weights w_j (a particle's own, or the approximation's value at a point).
struct ControlDisplacement {
  std::vector<std::pair<int, double>> weights;
  Vector3 direction;
};

// An arc-length step's control: Σ_j a_j · u_j − start, with a_j the motion of
// particle j over the path's last step divided by √N times its length ‖Δx‖
// (N particles: the control grows by the root-mean-square motion of the
// particles along that direction), start its value where the step begins.
struct PathDirection {
  std::vector<std::pair<int, Vector3>> motion;
  double start = 0.0;
};

}  // namespace sphshell::statics
