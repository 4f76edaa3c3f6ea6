#pragma once
// The crack family. A crack policy states at compile time whether it is
// enabled (`static constexpr bool enabled`) and gives a `name`; an enabled
// policy also decides which particle pairs stay visible to each other and which
// stress points are removed (docs/method.md §6). The solver calls, of an enabled
// policy (crack::LineSegments): initialize(positions, normals, spacing,
// support_radius); add_precrack(polyline), returning the stress points it takes
// over as crack points; add_damaged_stress_points(points), returning the new
// segments; visible(a, b, frame); affected_points(positions, segments);
// spacing(); points(), segments() (with start_point, end_point, crack_id) and
// crack_point_of_stress_point(p) for output; and, to check that no particle
// lies on a pre-crack, the constant on_precrack_in_spacings and the static
// distance_to_precrack_piece(point, start, end). It must also be
// default-constructible. check_crack_policy asserts each. LineSegments adds
// introspection for users (is_damaged, damaged_count, crack_count,
// total_length, crack_lengths, empty). crack::None has none of them.
//
// Checkpoints (solver/checkpoint.hpp): an enabled policy whose solver is
// checkpointed also provides
//   template <class Writer> void save(Writer&) const;
//   template <class Reader> void load(Reader&);
// storing everything its answers depend on (topology, counters) and
// rebuilding its search structures on load, so that a restored run asks and
// gets the same answers bit for bit. save_checkpoint names a policy without
// them at compile time.

#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>

#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

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
inline constexpr bool is_crack_policy_v = is_crack_policy<Policy>::value;

template <class Policy, class = void>
struct is_enabled : std::false_type {};
template <class Policy>
struct is_enabled<Policy, std::enable_if_t<has_enabled_flag<Policy>::value>>
    : std::bool_constant<Policy::enabled> {};

namespace detail {

template <class Policy>
Policy& policy();
template <class Policy>
const Policy& const_policy();
template <class T>
const T& argument();

template <class Policy, class = void>
struct has_initialize : std::false_type {};
template <class Policy>
struct has_initialize<Policy, std::void_t<decltype(policy<Policy>().initialize(
                                  argument<std::vector<Vector3>>(), argument<std::vector<Vector3>>(), 1.0, 1.0))>>
    : std::true_type {};

template <class Policy, class = void>
struct has_add_precrack : std::false_type {};
template <class Policy>
struct has_add_precrack<Policy, std::void_t<decltype(policy<Policy>().add_precrack(argument<std::vector<Vector3>>()))>>
    : std::is_convertible<decltype(policy<Policy>().add_precrack(argument<std::vector<Vector3>>())),
                          std::vector<int>> {};

template <class Policy, class = void>
struct has_add_damaged_stress_points : std::false_type {};
template <class Policy>
struct has_add_damaged_stress_points<
    Policy, std::void_t<decltype(policy<Policy>().add_damaged_stress_points(argument<std::vector<int>>()))>>
    : std::true_type {};

template <class Policy, class = void>
struct has_visible : std::false_type {};
template <class Policy>
struct has_visible<Policy, std::void_t<decltype(bool{const_policy<Policy>().visible(
                               argument<Vector3>(), argument<Vector3>(), argument<TangentFrame>())})>>
    : std::true_type {};

// The solver passes both the new segments and segments() itself, as const lvalues.
template <class Policy, class = void>
struct has_affected_points : std::false_type {};
template <class Policy>
struct has_affected_points<
    Policy,
    std::void_t<decltype(const_policy<Policy>().affected_points(
                    argument<std::vector<Vector3>>(),
                    argument<decltype(policy<Policy>().add_damaged_stress_points(argument<std::vector<int>>()))>())),
                decltype(const_policy<Policy>().affected_points(argument<std::vector<Vector3>>(),
                                                                const_policy<Policy>().segments()))>>
    : std::bool_constant<
          std::is_convertible_v<decltype(const_policy<Policy>().affected_points(
                                    argument<std::vector<Vector3>>(), const_policy<Policy>().segments())),
                                std::vector<std::size_t>>> {};

template <class Policy, class = void>
struct has_spacing : std::false_type {};
template <class Policy>
struct has_spacing<Policy, std::void_t<decltype(double{const_policy<Policy>().spacing()})>> : std::true_type {};

template <class Policy, class = void>
struct has_output_members : std::false_type {};
template <class Policy>
struct has_output_members<
    Policy, std::void_t<decltype(int{const_policy<Policy>().segments().begin()->start_point}),
                        decltype(int{const_policy<Policy>().segments().begin()->end_point}),
                        decltype(int{const_policy<Policy>().segments().begin()->crack_id}),
                        decltype(int{const_policy<Policy>().crack_point_of_stress_point(0)})>>
    : std::is_convertible<decltype(const_policy<Policy>().points()), const std::vector<Vector3>&> {};

// A static data member: decltype names it `const double`, a non-static one `double`.
template <class Policy, class = void>
struct has_precrack_distance : std::false_type {};
template <class Policy>
struct has_precrack_distance<
    Policy, std::void_t<decltype(double{Policy::distance_to_precrack_piece(argument<Vector3>(), argument<Vector3>(),
                                                                           argument<Vector3>())})>>
    : std::is_same<decltype(Policy::on_precrack_in_spacings), const double> {};

}  // namespace detail

template <class Policy>
constexpr bool check_crack_policy() {
  static_assert(has_enabled_flag<Policy>::value,
                "crack policy: missing its flag; add `static constexpr bool enabled`");
  static_assert(has_name<Policy>::value, "crack policy: missing its name; add `static constexpr const char* name`");
  if constexpr (is_enabled<Policy>::value) {
    static_assert(std::is_default_constructible_v<Policy>,
                  "an enabled crack policy must be default-constructible (the solver holds one and initializes "
                  "it); add a default constructor");
    static_assert(detail::has_initialize<Policy>::value,
                  "an enabled crack policy needs its set-up; add `void initialize(positions, normals, spacing, "
                  "support_radius)`");
    static_assert(detail::has_add_precrack<Policy>::value,
                  "an enabled crack policy needs pre-cracks; add `std::vector<int> add_precrack(polyline)` "
                  "returning the absorbed stress points");
    static_assert(detail::has_add_damaged_stress_points<Policy>::value,
                  "an enabled crack policy needs crack growth; add `add_damaged_stress_points(stress_points)` "
                  "returning the new segments");
    static_assert(detail::has_visible<Policy>::value,
                  "an enabled crack policy needs `bool visible(a, b, frame) const`; add it (a, b positions, frame at a)");
    static_assert(detail::has_affected_points<Policy>::value,
                  "an enabled crack policy needs the rows a crack touches; add `std::vector<std::size_t> "
                  "affected_points(positions, segments) const` taking the segments add_damaged_stress_points "
                  "returns and segments() holds");
    static_assert(detail::has_spacing<Policy>::value, "an enabled crack policy needs its spacing; add `double spacing() const`");
    static_assert(detail::has_output_members<Policy>::value,
                  "an enabled crack policy needs output members; add `const std::vector<Vector3>& points() const`, "
                  "segments() with int start_point, end_point and crack_id, and `int "
                  "crack_point_of_stress_point(p) const`");
    static_assert(detail::has_precrack_distance<Policy>::value,
                  "an enabled crack policy needs the pre-crack distance; add `static constexpr double "
                  "on_precrack_in_spacings` and `static double distance_to_precrack_piece(point, start, end)`");
  }
  return is_crack_policy<Policy>::value;
}

}  // namespace sphshell::crack
