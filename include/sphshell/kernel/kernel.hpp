#pragma once
// The kernel family contract.
//
// A kernel is a stateless type with
//   static constexpr double support_radius_factor;      // W(r, h) = 0 for r >= factor * h
//   static double value(double r, double h);            // W, normalized in 2-D: ∫ W dA = 1
//   static double derivative(double r, double h);       // dW/dr
// Kernels are radial, non-negative and compactly supported; r >= 0 is the
// (3-D) distance between the evaluation point and the particle.

#include <type_traits>
#include <utility>

namespace sphshell::kernel {

namespace detail {

template <class K, class = void>
struct has_support_radius_factor : std::false_type {};
template <class K>
struct has_support_radius_factor<
    K, std::enable_if_t<std::is_same_v<std::remove_cv_t<decltype(K::support_radius_factor)>, double>>>
    : std::true_type {};

template <class K, class = void>
struct has_value : std::false_type {};
template <class K>
struct has_value<K, std::enable_if_t<std::is_convertible_v<
                        decltype(K::value(std::declval<double>(), std::declval<double>())), double>>>
    : std::true_type {};

template <class K, class = void>
struct has_derivative : std::false_type {};
template <class K>
struct has_derivative<K, std::enable_if_t<std::is_convertible_v<
                             decltype(K::derivative(std::declval<double>(), std::declval<double>())),
                             double>>> : std::true_type {};

}  // namespace detail

template <class K>
inline constexpr bool is_kernel_v = detail::has_support_radius_factor<K>::value &&
                                    detail::has_value<K>::value && detail::has_derivative<K>::value;

template <class K>
struct is_kernel : std::bool_constant<is_kernel_v<K>> {};

// Instantiated by code that takes a kernel parameter, so a wrong type fails with
// a message naming the missing member instead of a deep template error.
template <class K>
constexpr bool check_kernel() {
  static_assert(detail::has_support_radius_factor<K>::value,
                "sphshell kernel: missing its support; add `static constexpr double support_radius_factor` (W = 0 for r >= factor * h)");
  static_assert(detail::has_value<K>::value,
                "sphshell kernel: missing its value; add `static double value(double r, double h)` (normalized in 2-D)");
  static_assert(detail::has_derivative<K>::value,
                "sphshell kernel: missing its derivative; add `static double derivative(double r, double h)` (dW/dr)");
  return true;
}

}  // namespace sphshell::kernel
