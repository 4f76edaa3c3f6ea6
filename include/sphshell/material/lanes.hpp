#pragma once
// Batched material updates: N integral points ("lanes") at once, in
// structure-of-arrays form, so that the compiler runs the arithmetic of
// several points in one vector instruction. A law that offers them provides
//   template <int N> struct Lanes;            its State for N points, one array per field,
//                                             with State state(int k) const and
//                                             void set_state(int k, const State&)
//   template <int N> int update_lanes(Lanes<N>&, const VoigtLanes<N>& d_eps) const;
// update_lanes(lanes, d_eps) gives every lane k the state that
// update(state k, d_eps k) gives (to round-off: the same operations, in vector
// registers), and returns how many lanes yielded; when it throws (a
// non-finite increment, a return map that fails), every lane is left as it
// was, so that a caller updating states in place can redo them one by one.
// The single-point update()
// stays the reference; tests/test_material_lanes.cpp holds the two together
// over the fuzz stream. has_update_lanes_v<Law, N> tells whether a law offers
// them; update_lanes(law, states, d_eps) below takes the batched path when it
// does and the single-point one lane by lane when it does not.

#include <sphshell/core/types.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

#if defined(__SSE2__) || defined(_M_X64)
#include <immintrin.h>
#endif

namespace sphshell::material {

// N Voigt vectors (xx, yy, xy; engineering shear for strains), one array per component.
template <int N>
struct VoigtLanes {
  static_assert(N >= 1, "sphshell::material::VoigtLanes<N>: N must be at least 1");
  static constexpr int lanes = N;
  alignas(64) std::array<double, std::size_t(N)> xx{};
  alignas(64) std::array<double, std::size_t(N)> yy{};
  alignas(64) std::array<double, std::size_t(N)> xy{};

  Vector3 at(int k) const { return Vector3(xx[std::size_t(k)], yy[std::size_t(k)], xy[std::size_t(k)]); }
  void set(int k, const Vector3& value) {
    xx[std::size_t(k)] = value.x();
    yy[std::size_t(k)] = value.y();
    xy[std::size_t(k)] = value.z();
  }
};

namespace detail {

// x[k] ← √x[k]. std::sqrt must set errno for negative arguments, which keeps
// compilers from vectorising it inside a loop; the SIMD square root of the
// target (correctly rounded, as std::sqrt) is used directly instead.
template <std::size_t N>
inline void sqrt_lanes(std::array<double, N>& x) {
  std::size_t k = 0;
#if defined(__AVX512F__)
  // The zero-masked form with every lane selected: GCC 12's _mm512_sqrt_pd
  // starts from an "undefined" vector that -Wmaybe-uninitialized reports.
  for (; k + 8 <= N; k += 8) _mm512_storeu_pd(&x[k], _mm512_maskz_sqrt_pd(__mmask8(0xff), _mm512_loadu_pd(&x[k])));
#endif
#if defined(__AVX__)
  for (; k + 4 <= N; k += 4) _mm256_storeu_pd(&x[k], _mm256_sqrt_pd(_mm256_loadu_pd(&x[k])));
#endif
#if defined(__SSE2__) || defined(_M_X64)
  for (; k + 2 <= N; k += 2) _mm_storeu_pd(&x[k], _mm_sqrt_pd(_mm_loadu_pd(&x[k])));
#endif
  for (; k < N; ++k) x[k] = std::sqrt(x[k]);
}

// Whether any lane's value has a bit set (+0.0 has none): how a lane loop
// reports "some lane needs more" without a branch per lane. The flags are
// doubles (1.0 / 0.0, or 0.0 / NaN) because compilers vectorise a comparison of
// doubles into a double mask but not into an integer count (SSE2); the
// bitwise OR of their patterns then vectorises as an integer reduction.
template <std::size_t N>
inline bool any_lane(const std::array<double, N>& flags) {
  alignas(64) std::array<std::uint64_t, N> bits;
  std::memcpy(bits.data(), flags.data(), sizeof bits);
  std::uint64_t any = 0;
  for (std::size_t k = 0; k < N; ++k) any |= bits[k];
  return any != 0;
}

// flag ? a : b for a flag of 1.0 or 0.0, by bit masks: a selection written
// with ?: may be turned into branches (and a loop holding it left scalar), a
// bitwise blend never is; no floating-point operation touches a or b, so
// infinities and NaN in the lane not taken do no harm.
inline double blend(double flag, double a, double b) {
  std::uint64_t flag_bits, a_bits, b_bits;
  std::memcpy(&flag_bits, &flag, sizeof flag);
  std::memcpy(&a_bits, &a, sizeof a);
  std::memcpy(&b_bits, &b, sizeof b);
  // 1.0 is 0x3ff0…: bit 61 set; 0.0 has no bit set.
  const std::uint64_t take_a = std::uint64_t{0} - ((flag_bits >> 61) & 1u);
  const std::uint64_t bits = (a_bits & take_a) | (b_bits & ~take_a);
  double result;
  std::memcpy(&result, &bits, sizeof result);
  return result;
}

template <class Law, int N, class = void>
struct has_update_lanes : std::false_type {};
template <class Law, int N>
struct has_update_lanes<Law, N,
                        std::void_t<typename Law::template Lanes<N>,
                                    decltype(std::declval<const Law&>().update_lanes(
                                        std::declval<typename Law::template Lanes<N>&>(),
                                        std::declval<const VoigtLanes<N>&>()))>> : std::true_type {};

}  // namespace detail

template <class Law, int N>
inline constexpr bool has_update_lanes_v = detail::has_update_lanes<Law, N>::value;

// The N states of `states` updated by the strain increments `d_eps`: through
// the law's update_lanes when it has one, else lane by lane. Returns how many
// lanes yielded.
template <class Law, int N>
int update_lanes(const Law& law, std::array<typename Law::State, std::size_t(N)>& states, const VoigtLanes<N>& d_eps) {
  if constexpr (has_update_lanes_v<Law, N>) {
    typename Law::template Lanes<N> lanes;
    for (int k = 0; k < N; ++k) lanes.set_state(k, states[std::size_t(k)]);
    const int plastic = law.update_lanes(lanes, d_eps);
    for (int k = 0; k < N; ++k) states[std::size_t(k)] = lanes.state(k);
    return plastic;
  } else {
    int plastic = 0;
    for (int k = 0; k < N; ++k) plastic += law.update(states[std::size_t(k)], d_eps.at(k)).plastic ? 1 : 0;
    return plastic;
  }
}

}  // namespace sphshell::material
