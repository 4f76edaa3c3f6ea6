#pragma once
// Morris' quintic B-spline, support 3h, normalized in 2-D (σ = 7 / (478 π h²)).

#include <sphshell/kernel/kernel.hpp>

namespace sphshell::kernel {

struct QuinticSpline {
  static constexpr double support_radius_factor = 3.0;

  static double value(double r, double h) {
    const double q = r / h;
    // Tested on r rather than q so r = support_radius_factor * h is outside
    // whatever the rounding of r / h (the neighbour search uses the same test).
    if (r >= support_radius_factor * h) return 0.0;
    double sum = pow5(3.0 - q);
    if (q < 2.0) sum -= 6.0 * pow5(2.0 - q);
    if (q < 1.0) sum += 15.0 * pow5(1.0 - q);
    return 7.0 / (478.0 * pi * h * h) * sum;
  }

  static double derivative(double r, double h) {
    const double q = r / h;
    if (r >= support_radius_factor * h) return 0.0;
    double sum = -5.0 * pow4(3.0 - q);
    if (q < 2.0) sum += 30.0 * pow4(2.0 - q);
    if (q < 1.0) sum -= 75.0 * pow4(1.0 - q);
    return 7.0 / (478.0 * pi * h * h * h) * sum;
  }

 private:
  static constexpr double pi = 3.14159265358979323846;
  static double pow4(double t) {
    const double t2 = t * t;
    return t2 * t2;
  }
  static double pow5(double t) { return pow4(t) * t; }
};

}  // namespace sphshell::kernel
