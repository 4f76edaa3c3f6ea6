#pragma once
// Gauss–Legendre integration through the thickness, N = 1..7 points (the paper's
// default is N = 5, section 2.1 after eq. 2.9). Exact for polynomials in ζ of degree
// up to 2N − 1.
//
// Reference points ξ_k and weights w_k on [-1, 1] (roots of P_N, w_k = 2/((1 − ξ²) P_N'(ξ)²)):
//   N  ξ_k                                          w_k
//   1  0                                            2
//   2  ±1/√3                                        1
//   3  0, ±√(3/5)                                   8/9, 5/9
//   4  ±√(3/7 ∓ (2/7)√(6/5))                        (18 ± √30)/36
//   5  0, ±(1/3)√(5 ∓ 2√(10/7))                     128/225, (322 ± 13√70)/900
//   6  ±0.2386191861, ±0.6612093865, ±0.9324695142  0.4679139346, 0.3607615730, 0.1713244924
//   7  0, ±0.4058451514, ±0.7415311856, ±0.9491079123  512/1225, 0.3818300505, 0.2797053915, 0.1294849662
// The tables below hold them to 21 significant digits; tests check them against these
// closed forms and against the Legendre recurrence.

#include <sphshell/thickness/thickness.hpp>

#include <array>

namespace sphshell::thickness {

namespace detail {

// Left empty: Gauss<N> itself reports an unsupported N.
template <int N>
struct GaussLegendreTable {};

template <>
struct GaussLegendreTable<1> {
  static constexpr std::array<double, 1> points{0.0};
  static constexpr std::array<double, 1> weights{2.0};
};

template <>
struct GaussLegendreTable<2> {
  static constexpr std::array<double, 2> points{-0.577350269189625764509,
                                                0.577350269189625764509};
  static constexpr std::array<double, 2> weights{1.0, 1.0};
};

template <>
struct GaussLegendreTable<3> {
  static constexpr std::array<double, 3> points{-0.774596669241483377036, 0.0,
                                                0.774596669241483377036};
  static constexpr std::array<double, 3> weights{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
};

template <>
struct GaussLegendreTable<4> {
  static constexpr std::array<double, 4> points{
      -0.861136311594052575224, -0.339981043584856264803, 0.339981043584856264803,
      0.861136311594052575224};
  static constexpr std::array<double, 4> weights{
      0.347854845137453857373, 0.652145154862546142627, 0.652145154862546142627,
      0.347854845137453857373};
};

template <>
struct GaussLegendreTable<5> {
  static constexpr std::array<double, 5> points{
      -0.906179845938663992798, -0.538469310105683091036, 0.0, 0.538469310105683091036,
      0.906179845938663992798};
  static constexpr std::array<double, 5> weights{
      0.236926885056189087514, 0.478628670499366468041, 128.0 / 225.0,
      0.478628670499366468041, 0.236926885056189087514};
};

template <>
struct GaussLegendreTable<6> {
  static constexpr std::array<double, 6> points{
      -0.932469514203152027812, -0.661209386466264513661, -0.238619186083196908631,
      0.238619186083196908631,  0.661209386466264513661,  0.932469514203152027812};
  static constexpr std::array<double, 6> weights{
      0.171324492379170345040, 0.360761573048138607570, 0.467913934572691047390,
      0.467913934572691047390, 0.360761573048138607570, 0.171324492379170345040};
};

template <>
struct GaussLegendreTable<7> {
  static constexpr std::array<double, 7> points{
      -0.949107912342758524526, -0.741531185599394439864, -0.405845151377397166907, 0.0,
      0.405845151377397166907,  0.741531185599394439864,  0.949107912342758524526};
  static constexpr std::array<double, 7> weights{
      0.129484966168869693271, 0.279705391489276667901, 0.381830050505118944950,
      512.0 / 1225.0,          0.381830050505118944950, 0.279705391489276667901,
      0.129484966168869693271};
};

}  // namespace detail

template <int N>
struct Gauss : detail::ScaledPoints<Gauss<N>> {
  static_assert(N >= 1 && N <= 7,
                "sphshell::thickness::Gauss<N> is tabulated for N = 1..7 points only; use N <= 7, or Simpson<N> for "
                "more points");
  static constexpr int num_points = N;
  static constexpr std::array<double, std::size_t(N)> reference_points =
      detail::GaussLegendreTable<N>::points;
  static constexpr std::array<double, std::size_t(N)> reference_weights =
      detail::GaussLegendreTable<N>::weights;
  static constexpr const char* name = "Gauss";
};

}  // namespace sphshell::thickness
