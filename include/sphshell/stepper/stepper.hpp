#pragma once
// The stepper family: the time integrator, the Solver's optional fifth
// template parameter (default stepper::CentralDifference).
//
// A stepper S is default-constructible and provides
//   double velocity_step(long step, double time_step) const;
//       the span of step n's velocity update (the central difference starts
//       its staggered velocities with half a step);
//   void advance_velocities(const StepContext&, solver::ParticleState&,
//                           const solver::Inertia&, const solver::ParticleForces&,
//                           std::size_t first, std::size_t last);
//       v and ω of particles [first, last) over context.velocity_step from
//       the forces, with the mass-proportional damping context.damping (ω
//       stays normal to d);
//   void advance_configuration(const StepContext&, solver::ParticleState&,
//                              std::size_t first, std::size_t last);
//       x and d of particles [first, last) over context.time_step from v and ω.
// The solver steps the particles in one pass over chunks of them, each chunk
// on one thread and several chunks at once: for each chunk it calls
// advance_velocities, then imposes the kinematic conditions on the new
// velocities and books the energies, then calls advance_configuration. So a
// particle's update reads and writes that particle's entries only, the two
// members write nothing else (a stepper's own members are for its settings,
// set before the run) and they must not throw: the solver calls them inside
// a noexcept task, so an exception would end the program (a non-finite result
// needs no exception: the solver's check after the update finds it). Only the owned particles
// (state.ranges.owned_begin … owned_end) are given to the stepper.
// check_stepper<S>() names a missing member.
//
// Checkpoints: a stepper is part of the solver's state. An empty one (as
// CentralDifference: its start-up half step follows from the step count) has
// nothing to store; one with members provides
//   template <class Writer> void save(Writer&) const;
//   template <class Reader> void load(Reader&);
// and save_checkpoint says so at compile time when they are missing.

#include <sphshell/core/error.hpp>
#include <sphshell/solver/particles.hpp>

#include <cstddef>
#include <type_traits>
#include <utility>

namespace sphshell::stepper {

// What a stepper is told about the step it takes.
struct StepContext {
  StepTime at;                 // the step count and time at the step's start
  double time_step = 0.0;      // Δt of the configuration update
  double velocity_step = 0.0;  // span of the velocity update (velocity_step(n, Δt))
  double damping = 0.0;        // c (1/s): M a = f − c M v
};

namespace detail {

template <class S, class = void>
struct has_velocity_step : std::false_type {};
template <class S>
struct has_velocity_step<S, std::void_t<decltype(double{std::declval<const S&>().velocity_step(1L, 1.0)})>>
    : std::true_type {};

template <class S, class = void>
struct has_advance_velocities : std::false_type {};
template <class S>
struct has_advance_velocities<
    S, std::void_t<decltype(std::declval<S&>().advance_velocities(
           std::declval<const StepContext&>(), std::declval<solver::ParticleState&>(),
           std::declval<const solver::Inertia&>(), std::declval<const solver::ParticleForces&>(),
           std::size_t{}, std::size_t{}))>>
    : std::true_type {};

template <class S, class = void>
struct has_advance_configuration : std::false_type {};
template <class S>
struct has_advance_configuration<
    S, std::void_t<decltype(std::declval<S&>().advance_configuration(
           std::declval<const StepContext&>(), std::declval<solver::ParticleState&>(), std::size_t{}, std::size_t{}))>>
    : std::true_type {};

}  // namespace detail

template <class S>
inline constexpr bool is_stepper_v = std::is_default_constructible_v<S> && detail::has_velocity_step<S>::value &&
                                     detail::has_advance_velocities<S>::value &&
                                     detail::has_advance_configuration<S>::value;

template <class S>
struct is_stepper : std::bool_constant<is_stepper_v<S>> {};

// For code taking a stepper parameter (the solver): each missing member gets
// its own message, ending with what to add.
template <class S>
constexpr bool check_stepper() {
  static_assert(std::is_default_constructible_v<S>,
                "sphshell stepper: the solver holds one and default-constructs it; add a default constructor");
  static_assert(detail::has_velocity_step<S>::value,
                "sphshell stepper: missing velocity step; add `double velocity_step(long step, double time_step) const`");
  static_assert(detail::has_advance_velocities<S>::value,
                "sphshell stepper: missing velocity update; add `void advance_velocities(const StepContext&, "
                "solver::ParticleState&, const solver::Inertia&, const solver::ParticleForces&, std::size_t first, "
                "std::size_t last)` (particles [first, last) only)");
  static_assert(detail::has_advance_configuration<S>::value,
                "sphshell stepper: missing configuration update; add `void advance_configuration(const "
                "StepContext&, solver::ParticleState&, std::size_t first, std::size_t last)` (particles [first, last) only)");
  return is_stepper_v<S>;
}

}  // namespace sphshell::stepper
