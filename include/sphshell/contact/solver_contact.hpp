#pragma once
// The Solver's contact calls: a base part of the Solver (CRTP) for its rigid
// bodies and the shell's contact with itself. The bodies and the shell
// contact live in the solver's RigidBodySet (contact/body_set.hpp), which
// the step calls before and after its particle pass; this part adds them,
// queries them and writes their probes. The solver gives it its domain,
// model, options, time, time step, step latch and contact particles.

#include <sphshell/contact/body_set.hpp>
#include <sphshell/contact/shell_contact.hpp>
#include <sphshell/core/error.hpp>

#include <cstddef>
#include <string>
#include <utility>

namespace sphshell::contact {

template <class Solver>
class SolverContact {
 public:
  // A rigid body (contact/rigid_body.hpp) in penalty contact with the shell
  // (contact/penalty.hpp: k = s m / Δt², offsets of half the thickness,
  // Coulomb friction); a free body moves under the contact's reaction. The
  // run's time step is kept. Returns the body's id for rigid_body() and
  // add_rigid_body_probe(). One process only: a distributed run refuses.
  template <class Shape, class Motion>
  RigidBodyId add_rigid_body(RigidBody<Shape, Motion> body, const PenaltyOptions& contact_options = {}) {
    Solver& s = solver();
    one_process("add_rigid_body: a distributed run has no rigid bodies yet (the contact reactions are not summed "
                "over the processes); run the impact on one process");
    s.latch_.check();
    return s.bodies_.add(std::move(body), contact_options, s.contact_particles(), s.time_step_);
  }
  // The shell's penalty contact with itself (contact/shell_contact.hpp): far
  // parts of the shell, or two shells of the model, pushed apart when their
  // mid-surfaces come closer than the half thicknesses; material neighbours
  // are left out. Off unless enabled; once, before the first step. One
  // process only: a distributed run refuses.
  void enable_shell_contact(const ShellContactOptions& contact_options = {}) {
    Solver& s = solver();
    one_process("enable_shell_contact: a distributed run has no shell contact yet; run it on one process");
    s.latch_.check();
    if (s.steps_ != 0)
      sphshell::detail::invalid_parameter("enable_shell_contact at step", s.steps_, "must come before the first step");
    s.bodies_.enable_shell_contact(s.model_, contact_options, s.options_.rotary_inertia_scale);
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
  // CSV time history of a body (contact/body_set.hpp): now and after every step.
  void add_rigid_body_probe(const std::string& csv_path, RigidBodyId id) {
    solver().bodies_.add_probe(csv_path, id, solver().time_);
  }

 private:
  Solver& solver() { return static_cast<Solver&>(*this); }
  const Solver& solver() const { return static_cast<const Solver&>(*this); }
  // A distributed run refuses, with the same Error on every process.
  void one_process(const char* what) {
    if constexpr (Solver::distributed)
      solver().domain_.collectively([&] { throw Error(std::string("sphshell: ") + what); });
  }
};

}  // namespace sphshell::contact
