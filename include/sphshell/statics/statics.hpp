#pragma once
// The static analysis family: equilibrium paths and stability of a Solver's
// model by Newton's method on a tangent stiffness assembled from the solver's
// own internal forces (docs/method.md, "Static solutions").
//
// Contract: a solver usable here moves its particles and directors to a given
// configuration at once (set_configuration) and exposes the internal forces
// and director forces of it, its model, options, material and approximation
// type, on one process (a distributed solver fails to compile here, its
// message naming the alternatives: Solver::solve_static's dynamic relaxation,
// StaticMass::particle_bound, runs over a domain's processes; or solve on one
// process and load its state). Solver::solve_static runs the same tangent
// assembly (statics/coupling.hpp) on the solver's own supports and loads
// (statics/static_solve.hpp).

#include <sphshell/core/types.hpp>

#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::statics {

namespace detail {

template <class S, class = void>
struct has_configuration_access : std::false_type {};
template <class S>
struct has_configuration_access<
    S, std::void_t<typename S::approximation_type, decltype(std::declval<S&>().set_configuration(
                                                       std::declval<std::vector<Vector3>>(),
                                                       std::declval<std::vector<Vector3>>())),
                   decltype(std::declval<const S&>().internal_forces()),
                   decltype(std::declval<const S&>().internal_director_forces()),
                   decltype(std::declval<const S&>().positions()), decltype(std::declval<const S&>().directors()),
                   decltype(std::declval<const S&>().model()), decltype(std::declval<const S&>().options()),
                   decltype(std::declval<const S&>().material()),
                   typename S::domain_type>> : std::bool_constant<!S::domain_type::is_distributed> {};

}  // namespace detail

// Whether `Solver` can be analysed statically here (see the contract above).
template <class Solver>
inline constexpr bool is_static_analysable_v = detail::has_configuration_access<Solver>::value;

}  // namespace sphshell::statics
