#pragma once
// Wendland's C2 function with support 2h, normalized in 2-D:
// W = 7 / (4 π h²) (1 − q/2)⁴ (1 + 2q), q = r/h. Free of the pairing
// instability of the B-splines.

#include <sphshell/kernel/kernel.hpp>

namespace sphshell::kernel {

struct WendlandC2 {
  static constexpr double support_radius_factor = 2.0;

  static double value(double r, double h) {
    const double q = r / h;
    // Tested on r rather than q so r = support_radius_factor * h is outside
    // whatever the rounding of r / h (the neighbour search uses the same test).
    if (r >= support_radius_factor * h) return 0.0;
    const double t = 1.0 - 0.5 * q;
    const double t2 = t * t;
    return 7.0 / (4.0 * pi * h * h) * t2 * t2 * (1.0 + 2.0 * q);
  }

  // d/dq [(1 − q/2)⁴ (1 + 2q)] = −5 q (1 − q/2)³.
  static double derivative(double r, double h) {
    const double q = r / h;
    if (r >= support_radius_factor * h) return 0.0;
    const double t = 1.0 - 0.5 * q;
    return -7.0 / (4.0 * pi * h * h * h) * 5.0 * q * t * t * t;
  }

 private:
  static constexpr double pi = 3.14159265358979323846;
};

}  // namespace sphshell::kernel
