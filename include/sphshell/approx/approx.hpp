#pragma once
// The approximation family contract.
//
// An approximation A (MLS<Kernel>, NSPH<Kernel>) is a stateless type with
//   using kernel_type = Kernel;
//   static ShapeFunctions build(particles, particle_volumes, eval_positions,
//                               eval_frames, h, visible = AlwaysVisible{});
//     with h one smoothing length for every row (double) or one per row
//     (std::vector<double>, the gather form W(x_j − x_i, h_i));
//   static void rebuild_row(ShapeFunctions&, row, particles, particle_volumes,
//                           eval_position, eval_frame, h, visible);
// build computes Φ_j and ∇Φ_j (in each evaluation point's tangent frame) of
// every evaluation point from the particles within
// kernel_type::support_radius_factor · h (its own h); rebuild_row recomputes one row in
// place from the neighbours stored in it (after a crack hides more pairs).
// `visible(eval_index, particle)` says whether a pair interacts; build calls it
// from several OpenMP threads at once, so it must be safe to call concurrently
// (a const operator() reading shared data is).

#include <sphshell/approx/shape_functions.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/kernel/kernel.hpp>

#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::approx {

namespace detail {

template <class A, class = void>
struct has_kernel_type : std::false_type {};
template <class A>
struct has_kernel_type<A, std::void_t<typename A::kernel_type>>
    : std::bool_constant<kernel::is_kernel_v<typename A::kernel_type>> {};

template <class A, class = void>
struct has_build : std::false_type {};
template <class A>
struct has_build<A, std::enable_if_t<std::is_same_v<
                        decltype(A::build(std::declval<const std::vector<Vector3>&>(),
                                          std::declval<const std::vector<double>&>(),
                                          std::declval<const std::vector<Vector3>&>(),
                                          std::declval<const std::vector<TangentFrame>&>(),
                                          1.0, AlwaysVisible{})),
                        ShapeFunctions>>> : std::true_type {};

template <class A, class = void>
struct has_build_per_row : std::false_type {};
template <class A>
struct has_build_per_row<A, std::enable_if_t<std::is_same_v<
                                decltype(A::build(std::declval<const std::vector<Vector3>&>(),
                                                  std::declval<const std::vector<double>&>(),
                                                  std::declval<const std::vector<Vector3>&>(),
                                                  std::declval<const std::vector<TangentFrame>&>(),
                                                  std::declval<const std::vector<double>&>(), AlwaysVisible{})),
                                ShapeFunctions>>> : std::true_type {};

template <class A, class = void>
struct has_rebuild_row : std::false_type {};
template <class A>
struct has_rebuild_row<
    A, std::void_t<decltype(A::rebuild_row(
           std::declval<ShapeFunctions&>(), std::size_t{}, std::declval<const std::vector<Vector3>&>(),
           std::declval<const std::vector<double>&>(), std::declval<const Vector3&>(),
           std::declval<const TangentFrame&>(), 1.0, AlwaysVisible{}))>> : std::true_type {};

}  // namespace detail

template <class A>
inline constexpr bool is_approximation_v = detail::has_kernel_type<A>::value &&
                                           detail::has_build<A>::value && detail::has_build_per_row<A>::value &&
                                           detail::has_rebuild_row<A>::value;

template <class A>
struct is_approximation : std::bool_constant<is_approximation_v<A>> {};

// For code taking an approximation parameter (the solver): a wrong type fails
// with a message naming the missing member.
template <class A>
constexpr bool check_approximation() {
  static_assert(detail::has_kernel_type<A>::value,
                "sphshell approximation: missing its kernel; add `using kernel_type = <a kernel>` (see kernel/kernel.hpp)");
  static_assert(detail::has_build<A>::value,
                "sphshell approximation: missing the build; add `static ShapeFunctions build(particles, "
                "particle_volumes, eval_positions, eval_frames, h, visible)`");
  static_assert(detail::has_build_per_row<A>::value,
                "sphshell approximation: missing the build with local smoothing lengths; add `static ShapeFunctions "
                "build(particles, particle_volumes, eval_positions, eval_frames, const std::vector<double>& h, "
                "visible)` (one h per evaluation point)");
  static_assert(detail::has_rebuild_row<A>::value,
                "sphshell approximation: missing the row rebuild; add `static void rebuild_row(ShapeFunctions&, "
                "row, particles, particle_volumes, eval_position, eval_frame, h, visible)`");
  return true;
}

}  // namespace sphshell::approx
