#pragma once
// ExactSum: a sum of doubles that does not depend on the order of its terms.
//
// Why: a distributed run splits a sum over particles or points between ranks,
// and floating-point addition is not associative, so ((a+b)+c) on one rank and
// (a+b)+(c) over two give different last bits. ExactSum holds the sum exactly,
// as one fixed-point integer in units of the smallest subnormal 2^-1074 (every
// finite double is an integer multiple of it), and rounds once, to the nearest
// double (ties to even), when the value is read. The result is therefore the
// correctly rounded exact sum, identical for any order, any split between
// ranks and any reduction tree; two accumulators combine by integer addition.
//
// Representation: limbs of 32 bits held in int64 (limb k carries bits
// [32k, 32k + 32) of the integer), so a limb takes about 2^30 additions before
// the carries must be propagated; normalize() does that (add() calls it in
// time). The finite range needs 2098 bits (2^-1074 … 2^1024), plus headroom for
// the carry of many terms: 68 limbs. Non-finite terms are counted apart:
// NaN, or +inf with −inf, reads as NaN; an infinity of one sign reads as it.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace sphshell {

class ExactSum {
 public:
  static constexpr int limb_bits = 32;
  static constexpr int limb_count = 68;
  // The limbs and the three counters of non-finite terms, as one array: what
  // a reduction between ranks adds element by element (mpi/reductions.hpp).
  static constexpr int raw_size = limb_count + 3;
  using Raw = std::array<std::int64_t, raw_size>;

  ExactSum() { raw_.fill(0); }

  void add(double x) {
    // The IEEE 754 fields, read directly (through frexp and ldexp the add took
    // 3.2 times as long, tests/mpi/halo_bench.cpp):
    // a normal x is ±(2^52 + fraction) 2^(e − 1075), that is the integer
    // 2^52 + fraction shifted by e − 1 in units of 2^-1074; a subnormal is
    // ±fraction unshifted.
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    const auto biased_exponent = static_cast<int>((bits >> fraction_bits) & exponent_mask);
    std::uint64_t mantissa = bits & fraction_mask;
    if (biased_exponent == exponent_mask) {  // infinity or NaN
      ++raw_[mantissa != 0 ? nan_slot : ((bits >> sign_bit) != 0 ? negative_infinity_slot : positive_infinity_slot)];
      return;
    }
    int shift = 0;
    if (biased_exponent != 0) {
      mantissa |= std::uint64_t{1} << fraction_bits;
      shift = biased_exponent - 1;
    }
    if (mantissa == 0) return;  // ±0
    const int limb = shift / limb_bits, offset = shift % limb_bits;
    const std::int64_t sign = (bits >> sign_bit) != 0 ? -1 : 1;
    // The mantissa in two halves, each placed by a shift that fits 64 bits.
    const std::uint64_t low = (mantissa & limb_mask) << offset;
    const std::uint64_t high = (mantissa >> limb_bits) << offset;
    raw_[limb] += sign * static_cast<std::int64_t>(low & limb_mask);
    raw_[limb + 1] += sign * static_cast<std::int64_t>((low >> limb_bits) + (high & limb_mask));
    raw_[limb + 2] += sign * static_cast<std::int64_t>(high >> limb_bits);
    if (++pending_ == additions_before_carry) normalize();
  }
  ExactSum& operator+=(double x) {
    add(x);
    return *this;
  }
  // Adds another accumulator exactly (both are normalised first, so no limb overflows).
  ExactSum& operator+=(const ExactSum& other) {
    normalize();
    ExactSum copy = other;
    copy.normalize();
    for (int k = 0; k < raw_size; ++k) raw_[k] += copy.raw_[k];
    normalize();
    return *this;
  }

  // Propagates the carries: limbs 0 … limb_count − 2 end in [0, 2^32), the
  // last one holds the sign. The value is unchanged.
  void normalize() {
    for (int k = 0; k + 1 < limb_count; ++k) {
      const std::int64_t carry = floor_divide(raw_[k]);
      raw_[k] -= carry * limb_base;
      raw_[k + 1] += carry;
    }
    pending_ = 0;
  }

  // The exact sum rounded to the nearest double, ties to even.
  double value() const {
    const std::int64_t nans = raw_[nan_slot], positive = raw_[positive_infinity_slot],
                       negative = raw_[negative_infinity_slot];
    if (nans > 0 || (positive > 0 && negative > 0)) return std::numeric_limits<double>::quiet_NaN();
    if (positive > 0) return std::numeric_limits<double>::infinity();
    if (negative > 0) return -std::numeric_limits<double>::infinity();
    ExactSum magnitude = *this;
    magnitude.normalize();
    const bool negative_sum = magnitude.raw_[limb_count - 1] < 0;
    if (negative_sum) {
      for (int k = 0; k < limb_count; ++k) magnitude.raw_[k] = -magnitude.raw_[k];
      magnitude.normalize();
    }
    const double rounded = magnitude.round_nonnegative();
    return negative_sum ? -rounded : rounded;
  }

  // The state, for a reduction between ranks; normalise before sending (see
  // reductions.hpp), so that adding many of them overflows no limb.
  const Raw& raw() const { return raw_; }
  static ExactSum from_raw(const Raw& raw) {
    ExactSum sum;
    sum.raw_ = raw;
    sum.normalize();
    return sum;
  }

 private:
  static constexpr int mantissa_bits = 53;
  static constexpr int fraction_bits = 52;
  static constexpr int sign_bit = 63;
  static constexpr int exponent_mask = 0x7FF;
  static constexpr std::uint64_t fraction_mask = (std::uint64_t{1} << fraction_bits) - 1;
  static constexpr int subnormal_unit_exponent = 1074;  // 2^-1074 is the unit
  static constexpr std::int64_t limb_base = std::int64_t{1} << limb_bits;
  static constexpr std::uint64_t limb_mask = (std::uint64_t{1} << limb_bits) - 1;
  // Each add() puts less than 2^33 into a limb: 2^29 of them stay far below 2^63.
  static constexpr std::int64_t additions_before_carry = std::int64_t{1} << 29;
  static constexpr int nan_slot = limb_count, positive_infinity_slot = limb_count + 1,
                       negative_infinity_slot = limb_count + 2;

  static std::int64_t floor_divide(std::int64_t value) {
    std::int64_t quotient = value / limb_base;
    if (value % limb_base < 0) --quotient;
    return quotient;
  }

  // Bit b of the (normalised, non-negative) integer.
  bool bit(int b) const { return ((raw_[b / limb_bits] >> (b % limb_bits)) & 1) != 0; }
  // Whether any bit below b is set.
  bool any_below(int b) const {
    for (int k = 0; k < b / limb_bits; ++k)
      if (raw_[k] != 0) return true;
    const int offset = b % limb_bits;
    return offset > 0 && (raw_[b / limb_bits] & ((std::int64_t{1} << offset) - 1)) != 0;
  }

  double round_nonnegative() const {
    int top = limb_count - 1;
    while (top >= 0 && raw_[top] == 0) --top;
    if (top < 0) return 0.0;
    int highest = top * limb_bits + limb_bits - 1;
    while (!bit(highest)) --highest;
    // Keep the 53 bits from the highest down; below 2^53 units (subnormal
    // results) every bit is kept and the value is exact.
    const int lowest_kept = highest >= mantissa_bits ? highest - (mantissa_bits - 1) : 0;
    std::uint64_t mantissa = 0;
    for (int b = highest; b >= lowest_kept; --b) mantissa = (mantissa << 1) | (bit(b) ? 1u : 0u);
    if (lowest_kept > 0) {
      const bool half = bit(lowest_kept - 1);
      const bool beyond_half = any_below(lowest_kept - 1);
      if (half && (beyond_half || (mantissa & 1u))) ++mantissa;  // 2^53 after a carry is still exact
    }
    return std::ldexp(static_cast<double>(mantissa), lowest_kept - subnormal_unit_exponent);
  }

  Raw raw_;
  std::int64_t pending_ = 0;
};

}  // namespace sphshell
