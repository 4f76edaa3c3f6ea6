#pragma once
// The Solver's contact calls: a base part of the Solver (CRTP) for its rigid
// bodies and the shell's contact with itself. The bodies and the shell
// contact live in the solver's RigidBodySet (contact/body_set.hpp), which
// the step calls before and after its particle pass; this part adds them,
// queries them, adds their probes (to the solver's CSV probes,
// solver/output_probes.hpp) and ends their step. The solver gives it its
// domain, model, options, time, time step, step latch and contact particles.
//
// Distributed (mpi::Domain): every process holds every body, each evaluates
// the contact of the particles it owns, and the step's sums (the reaction on
// each body, the energy terms) are formed from every process's per-particle
// terms in the order of a serial run's particle pass (RigidBodySet::
// finish_step), so the bodies move alike on every process and by the bits of
// the serial run. A body's probe is written by process 0. The shell's
// contact with itself needs every particle that can touch an owned one, and
// the far side of a fold is no ghost (the ghosts are material neighbours):
// every process gathers all positions and directors each step and computes
// the whole shell's contact, as one process would, keeping its own
// particles' loads (O(N) per process and step: correct at any rank count,
// not yet a distributed search).

#include <sphshell/contact/body_set.hpp>
#include <sphshell/contact/shell_contact.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/solver/energy_ledger.hpp>
#include <sphshell/solver/output_probes.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::contact {

template <class Solver>
class SolverContact {
 public:
  // A rigid body (contact/rigid_body.hpp) in penalty contact with the shell
  // (contact/penalty.hpp: k = s m / Δt², offsets of half the thickness,
  // Coulomb friction); a free body moves under the contact's reaction. The
  // run's time step is kept. Returns the body's id for rigid_body() and
  // add_rigid_body_probe(). A body that starts inside the shell beyond a
  // particle's half thickness is refused, naming the particle of lowest
  // global id (the same Error on every process). Distributed: collective,
  // every process adds the same body.
  template <class Shape, class Motion>
  RigidBodyId add_rigid_body(RigidBody<Shape, Motion> body, const PenaltyOptions& contact_options = {}) {
    Solver& s = solver();
    s.latch_.check();
    s.domain_.collectively([&] { validate(contact_options); });
    const ContactParticles particles = s.contact_particles();
    std::optional<domain::Failure> failure;
    if (const auto inside = RigidBodySet::start_inside(body, particles, s.domain_.owned_count(),
                                                       [&](std::size_t i) { return s.domain_.global_of(i); })) {
      try {
        s.bodies_.refuse_start_inside(*inside);
      } catch (...) {
        failure = s.domain_.failure_of_current_exception(inside->particle);
      }
    }
    s.domain_.agree(failure);
    RigidBodyId id = 0;
    s.domain_.collectively([&] { id = s.bodies_.add(std::move(body), contact_options, particles, s.time_step_); });
    return id;
  }
  // The shell's penalty contact with itself (contact/shell_contact.hpp): far
  // parts of the shell, or two shells of the model, pushed apart when their
  // mid-surfaces come closer than the half thicknesses; material neighbours
  // are left out. Off unless enabled; once, before the first step.
  // Distributed: collective (see above).
  void enable_shell_contact(const ShellContactOptions& contact_options = {}) {
    Solver& s = solver();
    s.latch_.check();
    s.domain_.collectively([&] {
      if (s.steps_ != 0)
        sphshell::detail::invalid_parameter("enable_shell_contact at step", s.steps_,
                                            "must come before the first step");
      s.bodies_.enable_shell_contact(s.model_, contact_options, s.options_.rotary_inertia_scale);
    });
    if constexpr (Solver::distributed) {
      // Every particle's mass (fixed from the set-up on), from its owner.
      std::vector<Vector3> mass(s.domain_.owned_count());
      for (std::size_t i = 0; i < mass.size(); ++i) mass[i] = Vector3(s.inertia_.mass[i], 0.0, 0.0);
      const std::vector<Vector3> whole = s.domain_.gathered(mass);
      whole_mass_.resize(whole.size());
      for (std::size_t g = 0; g < whole.size(); ++g) whole_mass_[g] = whole[g].x();
    }
  }
  // What the shell contact found in the last step, and its loads per particle.
  ShellContactStatistics shell_contact_statistics() const {
    const RigidBodySet& bodies = solver().bodies_;
    return bodies.shell_contact() ? bodies.shell_contact()->statistics() : ShellContactStatistics{};
  }
  const ParticleContactLoads& shell_contact_loads() const { return solver().bodies_.shell_contact_loads(); }
  std::size_t rigid_body_count() const { return solver().bodies_.size(); }
  // A body's position, velocities and the contact load of the last step.
  RigidBodyState rigid_body(RigidBodyId id) const { return solver().bodies_.state(id); }
  // CSV time history of a body (solver/output_probes.hpp, RigidBodyProbe: t,
  // centre, velocity, contact force and impulse, contacts): a CSV probe like
  // the particle probes, a row now and every probe_interval (0: every step),
  // its file refused when another use has it, and continued after a
  // checkpoint that recorded it. Distributed: collective, written by process
  // 0 (an Error there, such as a path that cannot be written, is the Error of
  // every process).
  void add_rigid_body_probe(const std::string& csv_path, RigidBodyId id) {
    Solver& s = solver();
    s.domain_.collectively([&] {
      s.bodies_.check(id);
      s.output_->add_probe(csv_path, sphshell::solver::RigidBodyProbe{id}, s);
    });
  }

 protected:
  // The particles' thicknesses in the local numbering (the model's serially).
  const std::vector<double>& contact_thicknesses() const {
    const Solver& s = solver();
    if constexpr (!Solver::distributed) {
      return s.model_.particle_thicknesses();
    } else {
      if (local_thickness_.size() != s.domain_.local_count()) {
        local_thickness_.resize(s.domain_.local_count());
        for (std::size_t i = 0; i < local_thickness_.size(); ++i)
          local_thickness_[i] = s.model_.particle_thicknesses()[static_cast<std::size_t>(s.domain_.global_of(i))];
      }
      return local_thickness_;
    }
  }
  // Before the particle pass: the bodies' and shell contact's step prepared,
  // the shell contact computed (over the whole shell: see above).
  void prepare_contact_step(std::size_t chunk_count) {
    Solver& s = solver();
    const ContactParticles particles = s.contact_particles();
    s.bodies_.prepare(particles, s.forces_.external, s.forces_.external_moment, s.time_step_, chunk_count);
    if (!s.bodies_.shell_contact()) return;
    const auto global_of = [&](std::size_t i) { return s.domain_.global_of(i); };
    if constexpr (Solver::distributed) {
      const typename Solver::domain_type::Timer timer(s.domain_);
      whole_position_ = s.domain_.gathered(s.particles_.position);
      whole_director_ = s.domain_.gathered(s.particles_.director);
      // The shell contact reads no velocities: none are gathered.
      const ContactParticles whole{whole_position_, whole_director_, no_velocities_, no_velocities_,
                                   whole_mass_,     s.model_.particle_thicknesses()};
      s.bodies_.compute_shell_contact(whole, s.time_step_, s.domain_.local_count(), global_of);
    } else {
      s.bodies_.compute_shell_contact(particles, s.time_step_, s.domain_.local_count(), global_of);
    }
  }
  // After the particle pass: the bodies move by the sums of every process's
  // terms (RigidBodySet::finish_step; one all-gather of the terms of the
  // particles near a body when distributed), and the books add the step.
  void finish_contact_step(const StepTime& at, double velocity_step) {
    Solver& s = solver();
    const auto global_of = [&](std::size_t i) { return s.domain_.global_of(i); };
    constexpr std::size_t chunk = solver::ParticleEnergyTerms::sum_chunk;
    if constexpr (Solver::distributed) {
      const typename Solver::domain_type::Timer timer(s.domain_);
      s.bodies_.finish_step(at, s.time_step_, velocity_step, chunk, global_of,
                            [&](std::vector<ContactTerm>&& mine) { return s.domain_.communicator().all_gather_v(mine); });
    } else {
      s.bodies_.finish_step(at, s.time_step_, velocity_step, chunk, global_of,
                            [](std::vector<ContactTerm>&& mine) { return std::move(mine); });
    }
  }

 private:
  Solver& solver() { return static_cast<Solver&>(*this); }
  const Solver& solver() const { return static_cast<const Solver&>(*this); }
  mutable std::vector<double> local_thickness_;  // distributed: contact_thicknesses()
  // Distributed shell contact: every particle's state, gathered.
  std::vector<Vector3> whole_position_, whole_director_;
  std::vector<double> whole_mass_;
  const std::vector<Vector3> no_velocities_;
};

}  // namespace sphshell::contact
