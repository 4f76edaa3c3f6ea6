#pragma once
// Monaghan's M4 cubic B-spline, support 2h, normalized in 2-D.

#include <sphshell/kernel/kernel.hpp>

namespace sphshell::kernel {

struct CubicSpline {
  static constexpr double support_radius_factor = 2.0;

  static double value(double r, double h) {
    // Tested on r rather than q so r = support_radius_factor * h is outside
    // whatever the rounding of r / h (the neighbour search uses the same test).
    if (r >= support_radius_factor * h) return 0.0;
    const double q = r / h;
    const double sigma = 10.0 / (7.0 * pi * h * h);
    if (q < 1.0) return sigma * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
    const double t = 2.0 - q;
    return sigma * 0.25 * t * t * t;
  }

  static double derivative(double r, double h) {
    if (r >= support_radius_factor * h) return 0.0;
    const double q = r / h;
    const double sigma = 10.0 / (7.0 * pi * h * h * h);
    if (q < 1.0) return sigma * (-3.0 * q + 2.25 * q * q);
    const double t = 2.0 - q;
    return -sigma * 0.75 * t * t;
  }

 private:
  static constexpr double pi = 3.14159265358979323846;
};

}  // namespace sphshell::kernel
