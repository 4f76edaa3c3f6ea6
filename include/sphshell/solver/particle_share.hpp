#pragma once
// The particles of one process's share (solver.hpp), a base part of the
// Solver that owns them: the domain part (domain/domain.hpp), the particles'
// state, forces and masses in the local numbering (owned first, then
// ghosts; serially the model's), their reference data, and the queries on
// them by global id: a field in global order is the solver's own array on one
// process and gathered from the owners on several (collective).
//
// The failures of a step's particle part are keyed by phase, then by global
// id, so that the failure every process agrees on is the one the serial step
// stops at (a load failure before a prescribed motion's, before a non-finite
// state), with the serial message.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/run_checks.hpp>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace sphshell::solver {

template <class Domain>
class ParticleShare {
 public:
  std::size_t particle_count() const { return particle_count_; }
  // This process's share (rank, size; distributed: the communicator, the
  // layout, the halo plan and the communication counters).
  const Domain& domain() const { return domain_; }
  decltype(auto) communicator() const { return domain_.communicator(); }
  decltype(auto) layout() const { return domain_.layout(); }
  decltype(auto) halo() const { return domain_.halo(); }
  decltype(auto) counters() const { return domain_.counters(); }

  // The particles' fields in global order: serially the solver's own arrays;
  // distributed, gathered from their owners on every process (collective;
  // O(N) bytes: for checks and small runs).
  decltype(auto) gathered(const std::vector<Vector3>& local_field) const { return domain_.gathered(local_field); }
  decltype(auto) positions() const { return gathered(particles_.position); }
  decltype(auto) directors() const { return gathered(particles_.director); }
  decltype(auto) velocities() const { return gathered(particles_.velocity); }
  decltype(auto) angular_velocities() const { return gathered(particles_.angular_velocity); }
  decltype(auto) internal_forces() const { return gathered(forces_.internal); }
  // ∂Π/∂d_j: the internal generalized force on each director.
  decltype(auto) internal_director_forces() const { return gathered(forces_.internal_director); }
  // Collective.
  Vector3 displacement(int particle) const {
    check_particle(particle);
    return owner_vector(particle, [&](std::size_t i) { return particles_.position[i] - reference_position_[i]; });
  }
  // Rotation vector taking the reference director to the current one (collective).
  Vector3 rotation(int particle) const {
    check_particle(particle);
    return owner_vector(particle, [&](std::size_t i) {
      return rotation_vector(reference_normal_[i], particles_.director[i]);
    });
  }
  // This process's particles (the local numbering).
  const std::vector<double>& masses() const { return inertia_.mass; }
  const std::vector<double>& rotary_inertias() const { return inertia_.rotary_inertia; }
  const ParticleState& local_particles() const { return particles_; }
  const ParticleForces& local_forces() const { return forces_; }
  int global_id(std::size_t local) const {
    if (local >= domain_.local_count())
      detail::invalid_parameter("local particle index", local,
                                "must be below this process's local count " + std::to_string(domain_.local_count()));
    return domain_.global_of(local);
  }

 protected:
  ParticleShare() = default;
  template <class Where>
  explicit ParticleShare(const Where& where) : domain_(where) {}

  // The share's particles at rest, after the domain's decomposition.
  void share_particles(const ShellModel& model, const SolverOptions& options) {
    particle_count_ = model.particle_count();
    const Inertia all = Inertia::lumped(model, options.density, options.rotary_inertia_scale);
    const std::size_t local = domain_.local_count(), owned = domain_.owned_count();
    for (std::size_t k = 0; k < local; ++k) {
      const auto i = static_cast<std::size_t>(domain_.global_of(k));
      reference_position_.push_back(model.particle_position[i]);
      reference_normal_.push_back(model.particle_normal[i]);
      reference_area_.push_back(model.particle_area[i]);
      inertia_.mass.push_back(all.mass[i]);
      inertia_.rotary_inertia.push_back(all.rotary_inertia[i]);
    }
    particles_ = ParticleState::at_rest(reference_position_, reference_normal_);
    particles_.ranges = {0, owned, owned, local};
    forces_ = ParticleForces(local);
  }

  void check_particle(int particle) const {
    if (particle < 0 || static_cast<std::size_t>(particle) >= particle_count_)
      detail::invalid_parameter("particle index", particle, "out of range");
  }
  // value(local particle) of the process that owns the particle, on every process.
  template <class Value>
  Vector3 owner_vector(int particle, Value&& value) const {
    std::optional<std::array<double, 3>> mine;
    if (domain_.owns(particle)) {
      const Vector3 x = value(static_cast<std::size_t>(domain_.local_of(static_cast<std::size_t>(particle))));
      mine = std::array<double, 3>{x.x(), x.y(), x.z()};
    }
    const std::array<double, 3> x = domain_.from_owner(mine);
    return Vector3(x[0], x[1], x[2]);
  }

  detail::LoadContext load_context_at(double time) {
    return {time,           reference_position_, reference_normal_, particles_.director,
            reference_area_, inertia_.mass,       forces_.external,  forces_.external_moment};
  }

  enum class Phase : long { loads = 0, motions = 1, configuration = 2 };
  long key(Phase phase, std::size_t global) const {
    return static_cast<long>(phase) * static_cast<long>(particle_count_ + 1) + static_cast<long>(global);
  }
  // The first failure of a step is the one the serial step would stop at.
  static void keep_first(std::optional<domain::Failure>& kept, domain::Failure candidate) {
    if (!kept || candidate.key < kept->key) kept = std::move(candidate);
  }
  // One process stops at once where the serial loop does; several agree later.
  void stop_if_alone(const std::optional<domain::Failure>& failure) const {
    if constexpr (!Domain::is_distributed) domain_.agree(failure);
  }
  domain::Failure non_finite_load(const StepTime& at, std::size_t i) const {
    const int id = domain_.global_of(i);
    return {key(Phase::loads, static_cast<std::size_t>(id)),
            unstable_text(at, "non-finite external load at particle " + std::to_string(id) +
                                  " (a pressure, force or moment function returned NaN or infinity)"),
            nullptr};
  }
  // The message at the step's end time, with the global id.
  domain::Failure non_finite_state(const StepTime& at, std::size_t i) const {
    const int id = domain_.global_of(i);
    return {key(Phase::configuration, static_cast<std::size_t>(id)),
            unstable_text(at, "non-finite state at particle " + std::to_string(id) + " (external force " +
                                  number_text(forces_.external[i].norm()) + " N, internal force " +
                                  number_text(forces_.internal[i].norm()) + " N)"),
            nullptr};
  }
  static std::string unstable_text(const StepTime& at, const std::string& what) {
    try {
      detail::fail_unstable(at, what);
    } catch (const Error& error) {
      return error.what();
    }
    return what;
  }

  Domain domain_;  // this process's share, the halo and the agreement on failures
  std::size_t particle_count_ = 0;  // the whole model's
  std::vector<Vector3> reference_position_, reference_normal_;
  std::vector<double> reference_area_;
  ParticleState particles_;
  Inertia inertia_;
  ParticleForces forces_;
};

}  // namespace sphshell::solver
