#pragma once
// The conditions and loads of a run, on particle sets given by ids or by a
// model set's name (shell/particle_selection.hpp): a base part of the Solver
// (CRTP) that owns them. Every process checks a whole set as a serial run
// does (range, each listed once; an unknown name is an Error naming it: the
// same Error on every process, which all make the same call), then keeps the
// conditions and loads on the members it owns (local ids); a distributed run
// also keeps the whole sets' conditions in global ids (checker_), for the
// serial checks and messages. The values are checked first, the set then.
// The solver gives this base its domain, model, particles, reference data,
// time() and time_step().

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/domain/domain.hpp>
#include <sphshell/shell/constraints.hpp>
#include <sphshell/shell/loads.hpp>
#include <sphshell/shell/particle_selection.hpp>
#include <sphshell/solver/run_checks.hpp>

#include <cstddef>
#include <memory>
#include <optional>
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
    check_displacement_start(set, displacement);
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
    add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PressureLoad<PressureFunction>>(members, std::move(pressure), direction);
    });
  }
  template <class TimeFunction = time_function::Step>
  void add_uniform_pressure(const ParticleSelection& set, double pressure, TimeFunction time = {},
                            PressureDirection direction = PressureDirection::follower) {
    sphshell::detail::require_finite("pressure", pressure);
    add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::UniformPressureLoad<TimeFunction>>(members, pressure, std::move(time), direction);
    });
  }
  // A force (N) on every particle of the set.
  template <class TimeFunction = time_function::Step>
  void add_point_force(const ParticleSelection& set, const Vector3& force, TimeFunction time = {}) {
    if (!force.allFinite()) sphshell::detail::invalid_parameter("point force", force.transpose(), "must be finite");
    add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PointForceLoad<TimeFunction>>(members, force, std::move(time));
    });
  }
  // A moment (N·m) on every particle of the set; its part along the director
  // (drilling) does not act.
  template <class TimeFunction = time_function::Step>
  void add_point_moment(const ParticleSelection& set, const Vector3& moment, TimeFunction time = {}) {
    if (!moment.allFinite()) sphshell::detail::invalid_parameter("point moment", moment.transpose(), "must be finite");
    add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::PointMomentLoad<TimeFunction>>(members, moment, std::move(time));
    });
  }
  // Gravity (or any uniform acceleration field, m/s²) on the set's mass.
  template <class TimeFunction = time_function::Step>
  void add_gravity(const ParticleSelection& set, const Vector3& acceleration, TimeFunction time = {}) {
    if (!acceleration.allFinite())
      sphshell::detail::invalid_parameter("gravity acceleration", acceleration.transpose(), "must be finite");
    add_load(set, [&](const ParticleSet& members) {
      return std::make_unique<sphshell::detail::GravityLoad<TimeFunction>>(members, acceleration, std::move(time));
    });
  }

 protected:
  sphshell::detail::Constraints constraints_;  // owned particles, local indices
  sphshell::detail::Constraints checker_;      // distributed: the whole sets, global ids, for the serial checks and messages
  ExternalLoads loads_;

 private:
  Solver& self() { return static_cast<Solver&>(*this); }
  // A set checked by every process (range, each listed once; the same Error
  // everywhere), handed with its members in global ids and its owned members
  // in local ids to `apply`.
  template <class Apply>
  void on_set(const ParticleSelection& set, Apply&& apply) {
    const Solver& s = self();
    s.domain_.collectively([&] {
      const ParticleSet global = checked_set(set.members(s.model_), s.model_.particle_count());
      ParticleSet local;
      for (int i : global)
        if (s.domain_.owns(i)) local.push_back(static_cast<int>(s.domain_.local_of(static_cast<std::size_t>(i))));
      apply(global, local);
    });
  }
  template <class Add>
  void conditions(const ParticleSelection& set, Add&& add) {
    const Solver& s = self();
    on_set(set, [&](const ParticleSet& global, const ParticleSet& local) {
      if constexpr (Solver::domain_type::is_distributed)
        add(checker_, global, s.model_.particle_position, s.model_.particle_normal);
      add(constraints_, local, s.reference_position_, s.reference_normal_);
    });
  }
  template <class Make>
  void add_load(const ParticleSelection& set, Make&& make) {
    on_set(set, [&](const ParticleSet&, const ParticleSet& local) { loads_.add(make(local)); });
  }
  // An Error when displacement(X, t) does not continue the particles' own
  // displacement, from the owner of each particle; the failure first in the
  // set's order wins, as in the serial loop.
  template <class Displacement>
  void check_displacement_start(const ParticleSelection& set, const Displacement& displacement) {
    const Solver& s = self();
    on_set(set, [&](const ParticleSet& global, const ParticleSet&) {
      std::optional<domain::Failure> failure;
      for (std::size_t k = 0; k < global.size() && !failure; ++k) {
        const int i = global[k];
        if (!s.domain_.owns(i)) continue;
        const auto at = static_cast<std::size_t>(s.domain_.local_of(static_cast<std::size_t>(i)));
        try {
          check_prescribed_displacement_start(i, displacement(s.model_.particle_position[i], s.time_),
                                              s.particles_.position[at] - s.reference_position_[at], s.time_,
                                              s.steps_, s.model_.minimum_spacing());
        } catch (...) {
          failure = s.domain_.failure_of_current_exception(static_cast<long>(k));
        }
      }
      s.domain_.agree(failure);
    });
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
