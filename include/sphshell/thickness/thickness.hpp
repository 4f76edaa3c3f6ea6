#pragma once
// The thickness-rule family: how the stress through the shell thickness is turned
// into the resultants T (force per length) and M (moment per length), eq. (2.8)-(2.9).
//
// A rule is a stateless type providing
//   static constexpr int num_points;                         // integral points per stress point (0: resultant model)
//   static constexpr std::array<double, num_points> reference_points;   // ξ_k on [-1, 1]
//   static constexpr std::array<double, num_points> reference_weights;  // sum to 2
//   static constexpr const char* name;
// The scaled quantities are ζ_k = ξ_k d/2 and A_k = w_k d/2 on [-d/2, d/2].
//
// The stress integration itself lives in Section<Rule, Law> (section.hpp): one class
// template for every rule, specialized for Global, so the solver spells the same type
// whatever the rule is.
//
// Checkpoints store Section<Rule, Law>::State: for the integral rules an array
// of the law's states (each listing its fields, material.hpp); a Section of a
// rule of its own (as Global's) lists the fields of its State with a static
// for_each_field, as ResultantState does.

#include <sphshell/core/types.hpp>

#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>

namespace sphshell::thickness {

// Resultants of one stress point, Voigt (xx, yy, xy): membrane force T in N/m and
// bending moment M in N·m/m.
struct Resultants {
  StressVoigt membrane = StressVoigt::Zero();
  StressVoigt moment = StressVoigt::Zero();
};

namespace traits {

template <class Rule, class = void>
struct has_num_points : std::false_type {};
template <class Rule>
struct has_num_points<Rule, std::enable_if_t<std::is_same_v<
                                std::remove_cv_t<decltype(Rule::num_points)>, int>>>
    : std::true_type {};

// The arrays are only checked once num_points is known to be there, so a rule that
// lacks num_points reports exactly that and not a cascade of follow-up errors.
template <class Rule, bool = has_num_points<Rule>::value, class = void>
struct has_reference_points : std::false_type {};
template <class Rule>
struct has_reference_points<
    Rule, true,
    std::enable_if_t<std::is_same_v<std::remove_cv_t<decltype(Rule::reference_points)>,
                                    std::array<double, std::size_t(Rule::num_points)>>>>
    : std::true_type {};

template <class Rule, bool = has_num_points<Rule>::value, class = void>
struct has_reference_weights : std::false_type {};
template <class Rule>
struct has_reference_weights<
    Rule, true,
    std::enable_if_t<std::is_same_v<std::remove_cv_t<decltype(Rule::reference_weights)>,
                                    std::array<double, std::size_t(Rule::num_points)>>>>
    : std::true_type {};

template <class Rule, class = void>
struct has_name : std::false_type {};
template <class Rule>
struct has_name<Rule, std::void_t<decltype(static_cast<const char*>(Rule::name))>>
    : std::true_type {};

}  // namespace traits

template <class Rule>
inline constexpr bool is_thickness_rule_v =
    traits::has_num_points<Rule>::value && traits::has_reference_points<Rule>::value &&
    traits::has_reference_weights<Rule>::value && traits::has_name<Rule>::value;
// The earlier spelling of is_thickness_rule_v.
template <class Rule>
inline constexpr bool is_thickness_rule = is_thickness_rule_v<Rule>;

// Call inside a template that takes a rule: each missing member gets its own message.
template <class Rule>
constexpr bool check_thickness_rule() {
  static_assert(traits::has_num_points<Rule>::value,
                "sphshell::thickness rule is missing its point count; add `static constexpr int num_points` (0 for a "
                "resultant model with its own Section)");
  static_assert(traits::has_reference_points<Rule>::value,
                "sphshell::thickness rule is missing its points; add `static constexpr std::array<double, "
                "num_points> reference_points` (on [-1, 1])");
  static_assert(traits::has_reference_weights<Rule>::value,
                "sphshell::thickness rule is missing its weights; add `static constexpr std::array<double, "
                "num_points> reference_weights` (summing to 2)");
  static_assert(traits::has_name<Rule>::value,
                "sphshell::thickness rule is missing its name; add `static constexpr const char* name`");
  return is_thickness_rule_v<Rule>;
}

namespace detail {

// Scaling shared by the integral rules: [-1, 1] -> [-d/2, d/2].
template <class Rule>
struct ScaledPoints {
  static constexpr double zeta(int k, double thickness) {
    return 0.5 * thickness * Rule::reference_points[std::size_t(k)];
  }
  static constexpr double weight(int k, double thickness) {
    return 0.5 * thickness * Rule::reference_weights[std::size_t(k)];
  }
};

}  // namespace detail
}  // namespace sphshell::thickness
