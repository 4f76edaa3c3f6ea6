#pragma once
// The material family contract. A material law `Law` provides:
//   types      Law::Parameters, Law::State,
//              Law::UpdateResult { bool plastic; int iterations; }
//   construct  Law(const Law::Parameters&)   — validates, throws sphshell::Error
//   flags      static constexpr bool has_plasticity, has_damage;
//              static constexpr const char* name
//   members    State initial_state() const;
//              UpdateResult update(State&, const StrainVoigt& d_eps) const;
//              const Parameters& parameters() const;
//              double youngs_modulus() const; double poisson_ratio() const;
//              double shear_modulus() const;                  (G = E / (2(1 + ν)))
//              Matrix3 elasticity_matrix() const;             (plane-stress Γ, eq. 2.24)
//              double equivalent_stress(const State&) const;   (σ̄ = √(σᵀΞσ))
//              double equivalent_plastic_strain(const State&) const;
//              double damage(const State&) const;
//              bool failed(const State&) const;
//              double elastic_energy_density(const State&) const;
//   plastic    HardeningParameters hardening() const;     (when has_plasticity)
//   damage     DamageParameters damage_parameters() const; (when has_damage)
// What generic code needs of a law's constants goes through these members,
// never through the fields of Parameters (which each law names as it likes).
// is_material_law<Law> checks all of it; each has_* trait checks one member, and
// check_material_law<Law>() static_asserts them one by one so a compile error
// names the missing member.
//
// Rate-dependent laws. A law whose flow stress depends on the plastic strain
// rate declares
//   static constexpr bool rate_dependent = true;
// and provides, besides the update above,
//   UpdateResult update(State&, const StrainVoigt& d_eps, const UpdateContext&) const;
// UpdateContext carries the time step Δt that the strain increment spans (the
// rate is formed from it); Section::update passes it to such a law and calls
// every other law as before, so rate-independent laws and their call sites do
// not change (is_rate_dependent_v; a law without the flag is rate-independent).
// The two-argument update of a rate-dependent law is its quasi-static limit
// (Δt = +inf: the plastic strain rate is zero). Temperature, where a law uses
// it (JohnsonCook), is part of its State: adiabatic heating is local to the
// integral point, so it needs nothing from the solver.
//
// Checkpoints (solver/checkpoint.hpp) store each integral point's State field
// by field. A law whose solver is checkpointed gives its State
//   template <class S, class F> static void for_each_field(S& self, F&& field)
//   { field(self.stress, self.eps_p, ...); }
// listing every field (S is State or const State; fields are numbers, bools,
// enums, Eigen fixed-size matrices or structs that list theirs the same way).
// save_checkpoint names the State that lacks it at compile time; solvers that
// never checkpoint do not need it.
// A law with constants beyond E, ν, hardening() and damage_parameters() that
// change results (rate and temperature constants, failure constants) lists
// them all, so that a checkpoint loaded with other values is refused by name:
//   template <class F> void for_each_constant(F&& constant) const
//   { constant("C (strain-rate coefficient)", parameters_.C); ... }

#include <sphshell/core/types.hpp>

#include <type_traits>
#include <utility>

namespace sphshell::material {

// Initial yield stress σs0 and plastic modulus Ep = E Et / (E − Et) of a
// linearly hardening law (eq. 2.34–2.35).
struct HardeningParameters {
  double initial_yield_stress = 0.0;
  double plastic_modulus = 0.0;
};

// Damage threshold ε̄sp, critical equivalent plastic strain ε̄cp and critical
// damage Dc of a Lemaitre-type law (eq. 2.40–2.41).
struct DamageParameters {
  double threshold_strain = 0.0;
  double critical_strain = 0.0;
  double critical_damage = 0.0;
};

// What a rate-dependent law needs of the step besides its strain increment.
struct UpdateContext {
  // Δt, s, over which the strain increment is applied: the plastic strain
  // rate is Δε̄p/Δt. +inf is the quasi-static limit (rate zero); NaN, zero or
  // a negative value is refused by the law when it flows plastically.
  double time_step;
};

namespace detail {

using std::void_t;

template <class Default, class AlwaysVoid, template <class...> class Op, class... Args>
struct detector : std::false_type {};
template <template <class...> class Op, class... Args>
struct detector<void, void_t<Op<Args...>>, Op, Args...> : std::true_type {};

template <template <class...> class Op, class... Args>
using is_detected = detector<void, void, Op, Args...>;

template <class Law>
using parameters_type_t = typename Law::Parameters;
template <class Law>
using state_type_t = typename Law::State;
template <class Law>
using update_result_t = typename Law::UpdateResult;
template <class Law>
using update_result_fields_t = decltype(std::declval<typename Law::UpdateResult&>().plastic = true,
                                        std::declval<typename Law::UpdateResult&>().iterations = 1);
template <class Law>
using parameter_constructor_t = decltype(Law(std::declval<const typename Law::Parameters&>()));
template <class Law>
using initial_state_t = decltype(std::declval<const Law&>().initial_state());
template <class Law>
using update_t = decltype(std::declval<const Law&>().update(std::declval<typename Law::State&>(),
                                                            std::declval<const StrainVoigt&>()));
template <class Law>
using context_update_t = decltype(std::declval<const Law&>().update(std::declval<typename Law::State&>(),
                                                                    std::declval<const StrainVoigt&>(),
                                                                    std::declval<const UpdateContext&>()));
template <class Law>
using rate_dependent_t = decltype(std::bool_constant<Law::rate_dependent>{});
template <class Law>
using parameters_accessor_t = decltype(std::declval<const Law&>().parameters());
template <class Law>
using youngs_modulus_t = decltype(std::declval<const Law&>().youngs_modulus());
template <class Law>
using poisson_ratio_t = decltype(std::declval<const Law&>().poisson_ratio());
template <class Law>
using shear_modulus_t = decltype(std::declval<const Law&>().shear_modulus());
template <class Law>
using hardening_t = decltype(std::declval<const Law&>().hardening());
template <class Law>
using damage_parameters_t = decltype(std::declval<const Law&>().damage_parameters());
template <class Law>
using elasticity_matrix_t = decltype(std::declval<const Law&>().elasticity_matrix());
template <class Law>
using has_plasticity_t = decltype(std::bool_constant<Law::has_plasticity>{});
template <class Law>
using has_damage_t = decltype(std::bool_constant<Law::has_damage>{});
template <class Law>
using name_t = decltype(static_cast<const char*>(Law::name));
template <class Law>
using equivalent_stress_t = decltype(std::declval<const Law&>().equivalent_stress(
    std::declval<const typename Law::State&>()));
template <class Law>
using equivalent_plastic_strain_t = decltype(std::declval<const Law&>().equivalent_plastic_strain(
    std::declval<const typename Law::State&>()));
template <class Law>
using damage_t =
    decltype(std::declval<const Law&>().damage(std::declval<const typename Law::State&>()));
template <class Law>
using failed_t =
    decltype(std::declval<const Law&>().failed(std::declval<const typename Law::State&>()));
template <class Law>
using elastic_energy_density_t = decltype(std::declval<const Law&>().elastic_energy_density(
    std::declval<const typename Law::State&>()));

// Detected and convertible to Expected.
template <class Expected, template <class...> class Op, class Law, class = void>
struct yields : std::false_type {};
template <class Expected, template <class...> class Op, class Law>
struct yields<Expected, Op, Law, std::enable_if_t<is_detected<Op, Law>::value>>
    : std::is_convertible<Op<Law>, Expected> {};

template <class Law, class = void>
struct initial_state_returns_state : std::false_type {};
template <class Law>
struct initial_state_returns_state<Law, void_t<state_type_t<Law>, initial_state_t<Law>>>
    : std::is_convertible<initial_state_t<Law>, typename Law::State> {};

template <class Law, class = void>
struct update_returns_result : std::false_type {};
template <class Law>
struct update_returns_result<Law, void_t<update_result_t<Law>, update_t<Law>>>
    : std::is_convertible<update_t<Law>, typename Law::UpdateResult> {};

template <class Law, class = void>
struct context_update_returns_result : std::false_type {};
template <class Law>
struct context_update_returns_result<Law, void_t<update_result_t<Law>, context_update_t<Law>>>
    : std::is_convertible<context_update_t<Law>, typename Law::UpdateResult> {};

template <class Law, class = void>
struct rate_dependent_flag : std::false_type {};
template <class Law>
struct rate_dependent_flag<Law, void_t<rate_dependent_t<Law>>> : std::bool_constant<Law::rate_dependent> {};

}  // namespace detail

// Whether Law declares `static constexpr bool rate_dependent = true` (and so
// is updated with an UpdateContext).
template <class Law>
struct is_rate_dependent : detail::rate_dependent_flag<Law> {};
template <class Law>
inline constexpr bool is_rate_dependent_v = is_rate_dependent<Law>::value;

template <class Law>
struct has_context_update : detail::context_update_returns_result<Law> {};

template <class Law>
struct has_parameters_type : detail::is_detected<detail::parameters_type_t, Law> {};
template <class Law>
struct has_state_type : detail::is_detected<detail::state_type_t, Law> {};
template <class Law>
struct has_update_result_type : detail::is_detected<detail::update_result_fields_t, Law> {};
template <class Law>
struct has_parameter_constructor : detail::is_detected<detail::parameter_constructor_t, Law> {};
template <class Law>
struct has_initial_state : detail::initial_state_returns_state<Law> {};
template <class Law>
struct has_update : detail::update_returns_result<Law> {};
template <class Law>
struct has_parameters_accessor : detail::is_detected<detail::parameters_accessor_t, Law> {};
template <class Law>
struct has_youngs_modulus : detail::yields<double, detail::youngs_modulus_t, Law> {};
template <class Law>
struct has_poisson_ratio : detail::yields<double, detail::poisson_ratio_t, Law> {};
template <class Law>
struct has_shear_modulus : detail::yields<double, detail::shear_modulus_t, Law> {};
template <class Law>
struct has_hardening : detail::yields<HardeningParameters, detail::hardening_t, Law> {};
template <class Law>
struct has_damage_parameters : detail::yields<DamageParameters, detail::damage_parameters_t, Law> {};
template <class Law>
struct has_elasticity_matrix : detail::yields<Matrix3, detail::elasticity_matrix_t, Law> {};

namespace detail {
// A plastic law must give its hardening and a damage law its damage
// parameters; flags that are missing are reported by their own checks.
template <class Law, class = void>
struct has_parameters_its_flags_need : std::false_type {};
template <class Law>
struct has_parameters_its_flags_need<Law, void_t<has_plasticity_t<Law>, has_damage_t<Law>>>
    : std::bool_constant<(!Law::has_plasticity || has_hardening<Law>::value) &&
                         (!Law::has_damage || has_damage_parameters<Law>::value)> {};
// A rate-dependent law must take the step's context.
template <class Law>
struct has_update_its_flags_need
    : std::bool_constant<!is_rate_dependent<Law>::value || has_context_update<Law>::value> {};
}  // namespace detail
template <class Law>
struct has_plasticity_flag : detail::is_detected<detail::has_plasticity_t, Law> {};
template <class Law>
struct has_damage_flag : detail::is_detected<detail::has_damage_t, Law> {};
template <class Law>
struct has_name : detail::is_detected<detail::name_t, Law> {};
template <class Law>
struct has_equivalent_stress : detail::yields<double, detail::equivalent_stress_t, Law> {};
template <class Law>
struct has_equivalent_plastic_strain
    : detail::yields<double, detail::equivalent_plastic_strain_t, Law> {};
template <class Law>
struct has_damage_accessor : detail::yields<double, detail::damage_t, Law> {};
template <class Law>
struct has_failed : detail::yields<bool, detail::failed_t, Law> {};
template <class Law>
struct has_elastic_energy_density : detail::yields<double, detail::elastic_energy_density_t, Law> {
};

template <class Law>
struct is_material_law
    : std::conjunction<has_parameters_type<Law>, has_state_type<Law>, has_update_result_type<Law>,
                       has_parameter_constructor<Law>, has_initial_state<Law>, has_update<Law>,
                       has_parameters_accessor<Law>, has_youngs_modulus<Law>,
                       has_poisson_ratio<Law>, has_shear_modulus<Law>, has_elasticity_matrix<Law>,
                       has_plasticity_flag<Law>, detail::has_parameters_its_flags_need<Law>,
                       has_damage_flag<Law>, has_name<Law>, has_equivalent_stress<Law>,
                       has_equivalent_plastic_strain<Law>, has_damage_accessor<Law>,
                       has_failed<Law>, has_elastic_energy_density<Law>,
                       detail::has_update_its_flags_need<Law>> {};

template <class Law>
inline constexpr bool is_material_law_v = is_material_law<Law>::value;

// static_assert(check_material_law<Law>()) reports the first missing member by name.
template <class Law>
constexpr bool check_material_law() {
  static_assert(has_parameters_type<Law>::value, "material law: missing nested type Parameters; add `struct Parameters { ... };` holding the law's constants");
  static_assert(has_state_type<Law>::value, "material law: missing nested type State; add `struct State { StressVoigt stress; ... };` (one integral point)");
  static_assert(has_update_result_type<Law>::value,
                "material law: missing nested type UpdateResult; add `struct UpdateResult { bool plastic; int iterations; };`");
  static_assert(has_parameter_constructor<Law>::value,
                "material law: missing constructor; add `explicit Law(const Parameters&)` (validating, throwing sphshell::Error)");
  static_assert(has_initial_state<Law>::value, "material law: missing initial state; add `State initial_state() const`");
  static_assert(has_update<Law>::value,
                "material law: missing update; add `UpdateResult update(State&, const StrainVoigt& d_eps) const`");
  if constexpr (is_rate_dependent<Law>::value)
    static_assert(has_context_update<Law>::value,
                  "material law: a law with rate_dependent = true needs the step's time step; add `UpdateResult "
                  "update(State&, const StrainVoigt& d_eps, const UpdateContext&) const`");
  static_assert(has_parameters_accessor<Law>::value,
                "material law: missing parameters accessor; add `const Parameters& parameters() const`");
  static_assert(has_youngs_modulus<Law>::value,
                "material law: missing Young's modulus; add `double youngs_modulus() const`");
  static_assert(has_poisson_ratio<Law>::value,
                "material law: missing Poisson's ratio; add `double poisson_ratio() const`");
  static_assert(has_shear_modulus<Law>::value,
                "material law: missing shear modulus; add `double shear_modulus() const` (G = E / (2(1 + nu)))");
  static_assert(has_elasticity_matrix<Law>::value,
                "material law: missing plane-stress stiffness; add `Matrix3 elasticity_matrix() const` (eq. 2.24)");
  static_assert(has_plasticity_flag<Law>::value,
                "material law: missing plasticity flag; add `static constexpr bool has_plasticity`");
  static_assert(has_damage_flag<Law>::value,
                "material law: missing damage flag; add `static constexpr bool has_damage`");
  if constexpr (has_plasticity_flag<Law>::value)
    if constexpr (Law::has_plasticity)
      static_assert(has_hardening<Law>::value,
                    "material law: a law with has_plasticity needs its hardening; add `HardeningParameters "
                    "hardening() const`");
  if constexpr (has_damage_flag<Law>::value)
    if constexpr (Law::has_damage)
      static_assert(has_damage_parameters<Law>::value,
                    "material law: a law with has_damage needs its damage constants; add `DamageParameters "
                    "damage_parameters() const`");
  static_assert(has_name<Law>::value, "material law: missing name; add `static constexpr const char* name`");
  static_assert(has_equivalent_stress<Law>::value,
                "material law: missing equivalent stress; add `double equivalent_stress(const State&) const`");
  static_assert(has_equivalent_plastic_strain<Law>::value,
                "material law: missing equivalent plastic strain; add `double equivalent_plastic_strain(const State&) const`");
  static_assert(has_damage_accessor<Law>::value,
                "material law: missing damage accessor; add `double damage(const State&) const`");
  static_assert(has_failed<Law>::value, "material law: missing failure flag; add `bool failed(const State&) const`");
  static_assert(has_elastic_energy_density<Law>::value,
                "material law: missing stored energy; add `double elastic_energy_density(const State&) const`");
  return is_material_law<Law>::value;
}

}  // namespace sphshell::material
