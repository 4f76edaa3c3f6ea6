#pragma once
// Composite Simpson integration through the thickness on N equally spaced points
// (N odd >= 3, i.e. (N − 1)/2 panels) including both faces. Exact for polynomials in ζ
// up to degree 3; its points on the faces make it report the surface stresses.

#include <sphshell/thickness/thickness.hpp>

#include <array>

namespace sphshell::thickness {

namespace detail {

template <int N>
constexpr std::array<double, std::size_t(N)> simpson_points() {
  std::array<double, std::size_t(N)> points{};
  for (int k = 0; k < N; ++k) points[std::size_t(k)] = -1.0 + 2.0 * k / (N - 1);
  return points;
}

// h/3 · (1, 4, 2, 4, ..., 2, 4, 1) with spacing h = 2/(N − 1).
template <int N>
constexpr std::array<double, std::size_t(N)> simpson_weights() {
  std::array<double, std::size_t(N)> weights{};
  const double third_of_spacing = 2.0 / (3.0 * (N - 1));
  for (int k = 0; k < N; ++k) {
    const bool face = k == 0 || k == N - 1;
    weights[std::size_t(k)] = third_of_spacing * (face ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0));
  }
  return weights;
}

}  // namespace detail

template <int N>
struct Simpson : detail::ScaledPoints<Simpson<N>> {
  static_assert(N >= 3 && N % 2 == 1,
                "sphshell::thickness::Simpson<N> needs an odd number of points N >= 3; use N = 3, 5, 7, ...");
  static constexpr int num_points = N;
  static constexpr std::array<double, std::size_t(N)> reference_points =
      detail::simpson_points<N>();
  static constexpr std::array<double, std::size_t(N)> reference_weights =
      detail::simpson_weights<N>();
  static constexpr const char* name = "Simpson";
};

}  // namespace sphshell::thickness
