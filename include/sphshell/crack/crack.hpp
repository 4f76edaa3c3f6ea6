#pragma once
// The crack family. A crack policy states at compile time whether it is
// enabled (`static constexpr bool enabled`) and gives a `name`; an enabled
// policy also decides which particle pairs stay visible to each other and which
// stress points are removed (design.md §2.6). An enabled policy
// (crack::LineSegments) provides initialize, add_precrack (returning the
// stress points it takes over as crack points), add_damaged_stress_points,
// visible, affected_points, spacing, the constant on_precrack_in_spacings and
// distance_to_precrack_piece (the solver's check that no particle lies on a
// pre-crack), and the introspection members points, segments, is_damaged,
// crack_point_of_stress_point, damaged_count, crack_count, total_length,
// crack_lengths and empty; crack::None has none of them.

#include <type_traits>

namespace sphshell::crack {

template <class Policy, class = void>
struct has_enabled_flag : std::false_type {};
template <class Policy>
struct has_enabled_flag<Policy, std::void_t<decltype(bool{Policy::enabled})>> : std::true_type {};

template <class Policy, class = void>
struct has_name : std::false_type {};
template <class Policy>
struct has_name<Policy, std::void_t<decltype(Policy::name)>> : std::true_type {};

template <class Policy>
struct is_crack_policy
    : std::bool_constant<has_enabled_flag<Policy>::value && has_name<Policy>::value> {};

template <class Policy>
constexpr bool check_crack_policy() {
  static_assert(has_enabled_flag<Policy>::value,
                "a crack policy needs `static constexpr bool enabled`");
  static_assert(has_name<Policy>::value, "a crack policy needs `static constexpr const char* name`");
  return is_crack_policy<Policy>::value;
}

}  // namespace sphshell::crack
