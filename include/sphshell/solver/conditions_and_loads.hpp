#pragma once
// The conditions and loads of a run, on particle sets given by ids or by a
// model set's name (shell/particle_selection.hpp): one API for Solver and
// mpi::DistributedSolver, a base each derives from (CRTP). The solver
// provides, to this base only:
//   add_conditions(set, add): checks the set (range, each listed once; an
//     unknown name is an Error naming it) and calls
//     add(constraints, members, reference_position, reference_normal) for
//     each set of conditions it keeps (a distributed run: the whole set in
//     global ids, for the serial checks and messages, then its owned members
//     in local ids);
//   add_load(set, make): the same; keeps make(members), the load on the
//     members whose loads it applies;
//   check_displacement_start(set, u): an Error when u(X, t) does not continue
//     the particles' own displacement;
//   time(), time_step().
// The values are checked first, the set then: the same Error on every rank of
// a distributed run, whose ranks all make the same call.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/particle_selection.hpp>

#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::solver {

template <class Solver>
class ConditionsAndLoads {
  using Positions = std::vector<Vector3>;

 public:
  // Boundary conditions (shell/constraints.hpp).
  void clamp(const ParticleSelection& set) {
    conditions(set, [](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions&) {
      c.clamp(members);
    });
  }
  // Translations fixed, rotations free ("soft" simple support).
  void simply_support(const ParticleSelection& set) {
    conditions(set, [](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions&) {
      c.simply_support(members);
    });
  }
  // Translations fixed and the director kept from tilting along the edge
  // ("hard" simple support of Mindlin plates): fixes rotation about n × t.
  void simply_support_hard(const ParticleSelection& set, const Vector3& edge_tangent) {
    conditions(set, [&](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions& normal) {
      c.simply_support_hard(members, normal, edge_tangent);
    });
  }
  // Mirror symmetry about a plane (given by its normal) through the particles:
  // no translation across the plane and no rotation tilting the director out of it.
  void symmetry_plane(const ParticleSelection& set, const Vector3& plane_normal) {
    conditions(set, [&](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions& normal) {
      c.symmetry_plane(members, normal, plane_normal);
    });
  }
  void fix_translation(const ParticleSelection& set, const Vector3& direction) {
    conditions(set, [&](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions&) {
      c.fix_translation(members, direction);
    });
  }
  void fix_rotation(const ParticleSelection& set, const Vector3& axis) {
    conditions(set, [&](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions&, const Positions&) {
      c.fix_rotation(members, axis);
    });
  }
  // Prescribed displacement u(X, t) (a Vector3 from the reference position and
  // time) imposed on all three translations of the set; it must continue the
  // particles' displacement at the time it is given.
  template <class DisplacementFunction>
  void prescribe_displacement(const ParticleSelection& set, DisplacementFunction displacement) {
    static_assert(std::is_invocable_r_v<Vector3, DisplacementFunction, const Vector3&, double>,
                  "prescribe_displacement: the function must be callable as Vector3 u(const Vector3& X, double t)");
    self().check_displacement_start(set, displacement);
    motion<sphshell::detail::PrescribedDisplacement<DisplacementFunction>>(set, displacement);
  }
  // Prescribed velocity v(X, t) imposed on all three translations of the set.
  template <class VelocityFunction>
  void prescribe_velocity(const ParticleSelection& set, VelocityFunction velocity) {
    static_assert(std::is_invocable_r_v<Vector3, VelocityFunction, const Vector3&, double>,
                  "prescribe_velocity: the function must be callable as Vector3 v(const Vector3& X, double t)");
    motion<sphshell::detail::PrescribedVelocity<VelocityFunction>>(set, velocity);
  }

  // Loads (shell/loads.hpp). Pressure p(X, t) in Pa (see loads.hpp for the sign convention).
  template <class PressureFunction>
  void add_pressure(const ParticleSelection& set, PressureFunction pressure,
                    PressureDirection direction = PressureDirection::follower) {
    static_assert(std::is_invocable_r_v<double, PressureFunction, const Vector3&, double>,
                  "add_pressure: the pressure must be callable as double p(const Vector3& X, double t)");
    self().add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PressureLoad<PressureFunction>>(members, std::move(pressure), direction);
    });
  }
  template <class TimeFunction = time_function::Step>
  void add_uniform_pressure(const ParticleSelection& set, double pressure, TimeFunction time = {},
                            PressureDirection direction = PressureDirection::follower) {
    sphshell::detail::require_finite("pressure", pressure);
    self().add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::UniformPressureLoad<TimeFunction>>(members, pressure, std::move(time), direction);
    });
  }
  // A force (N) on every particle of the set.
  template <class TimeFunction = time_function::Step>
  void add_point_force(const ParticleSelection& set, const Vector3& force, TimeFunction time = {}) {
    if (!force.allFinite()) sphshell::detail::invalid_parameter("point force", force.transpose(), "must be finite");
    self().add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PointForceLoad<TimeFunction>>(members, force, std::move(time));
    });
  }
  // A moment (N·m) on every particle of the set; its part along the director
  // (drilling) does not act.
  template <class TimeFunction = time_function::Step>
  void add_point_moment(const ParticleSelection& set, const Vector3& moment, TimeFunction time = {}) {
    if (!moment.allFinite()) sphshell::detail::invalid_parameter("point moment", moment.transpose(), "must be finite");
    self().add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PointMomentLoad<TimeFunction>>(members, moment, std::move(time));
    });
  }
  // Gravity (or any uniform acceleration field, m/s²) on the set's mass.
  template <class TimeFunction = time_function::Step>
  void add_gravity(const ParticleSelection& set, const Vector3& acceleration, TimeFunction time = {}) {
    if (!acceleration.allFinite())
      sphshell::detail::invalid_parameter("gravity acceleration", acceleration.transpose(), "must be finite");
    self().add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::GravityLoad<TimeFunction>>(members, acceleration, std::move(time));
    });
  }

 private:
  Solver& self() { return static_cast<Solver&>(*this); }
  template <class Add>
  void conditions(const ParticleSelection& set, Add&& add) {
    self().add_conditions(set, std::forward<Add>(add));
  }
  // A motion object per set of conditions the solver keeps (each a copy of the function).
  template <class Motion, class Function>
  void motion(const ParticleSelection& set, const Function& function) {
    conditions(set, [&](sphshell::detail::Constraints& c, const ParticleSet& members, const Positions& position, const Positions&) {
      c.add_motion(members, std::make_unique<Motion>(function), position, self().time(), self().time_step());
    });
  }
};

}  // namespace sphshell::solver
