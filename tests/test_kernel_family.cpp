#include <sphshell/kernel/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace sphshell;

namespace {

struct MissingDerivative {
  static constexpr double support_radius_factor = 2.0;
  static double value(double, double) { return 0.0; }
};

// Midpoint rule over a square covering the support; the kernels are C1 at
// least, so 800² cells give ~1e-7 accuracy.
template <class K>
double integral_over_plane(double h) {
  const double radius = K::support_radius_factor * h;
  const int cells = 800;
  const double step = 2.0 * radius / cells;
  double sum = 0.0;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const double x = -radius + (i + 0.5) * step;
      const double y = -radius + (j + 0.5) * step;
      sum += K::value(std::hypot(x, y), h);
    }
  return sum * step * step;
}

}  // namespace

static_assert(kernel::is_kernel_v<kernel::CubicSpline>);
static_assert(kernel::is_kernel<kernel::WendlandC2>::value);
static_assert(kernel::is_kernel_v<kernel::QuinticSpline>);
static_assert(!kernel::is_kernel_v<MissingDerivative>);
static_assert(!kernel::is_kernel_v<double>);
static_assert(kernel::CubicSpline::support_radius_factor == 2.0);
static_assert(kernel::WendlandC2::support_radius_factor == 2.0);
static_assert(kernel::QuinticSpline::support_radius_factor == 3.0);

TEMPLATE_TEST_CASE("Kernels are normalized in 2-D", "[kernel]", kernel::CubicSpline,
                   kernel::WendlandC2, kernel::QuinticSpline) {
  for (const double h : {1.0, 0.013}) {
    INFO("h = " << h);
    CHECK(integral_over_plane<TestType>(h) == Approx(1.0).epsilon(1e-6));
  }
}

TEMPLATE_TEST_CASE("Kernels are non-negative, decreasing and compactly supported", "[kernel]",
                   kernel::CubicSpline, kernel::WendlandC2, kernel::QuinticSpline) {
  const double h = 0.7;
  const double radius = TestType::support_radius_factor * h;
  double previous = TestType::value(0.0, h);
  CHECK(previous > 0.0);
  CHECK(TestType::derivative(0.0, h) == 0.0);
  for (int i = 1; i < 1000; ++i) {
    const double r = radius * i / 1000.0;
    const double w = TestType::value(r, h);
    CHECK(w >= 0.0);
    CHECK(w <= previous);
    CHECK(TestType::derivative(r, h) <= 0.0);
    previous = w;
  }
  for (const double r : {radius, radius * (1 + 1e-12), 2 * radius, 1e9}) {
    CHECK(TestType::value(r, h) == 0.0);
    CHECK(TestType::derivative(r, h) == 0.0);
  }
}

TEMPLATE_TEST_CASE("Kernel derivatives match central differences", "[kernel]",
                   kernel::CubicSpline, kernel::WendlandC2, kernel::QuinticSpline) {
  const double h = 0.3;
  const double step = 1e-6;
  for (double q = 0.05; q < TestType::support_radius_factor - 0.01; q += 0.1) {
    const double r = q * h;
    const double numeric =
        (TestType::value(r + step, h) - TestType::value(r - step, h)) / (2 * step);
    INFO("q = " << q);
    CHECK(TestType::derivative(r, h) == Approx(numeric).epsilon(1e-6).margin(1e-8));
  }
}
