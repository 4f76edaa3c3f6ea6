// Gradient convergence of MLS for a smooth non-polynomial field.
#include "approx_test_support.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/kernel/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <iostream>

using namespace sphshell;

namespace {

const char* name(kernel::CubicSpline) { return "cubic spline"; }
const char* name(kernel::WendlandC2) { return "Wendland C2"; }
const char* name(kernel::QuinticSpline) { return "quintic spline"; }

double field(const Vector3& x) { return std::sin(2.0 * x.x() + 0.5) * std::cos(3.0 * x.y() - 0.2); }
Vector2 field_gradient(const Vector3& x) {
  return {2.0 * std::cos(2.0 * x.x() + 0.5) * std::cos(3.0 * x.y() - 0.2),
          -3.0 * std::sin(2.0 * x.x() + 0.5) * std::sin(3.0 * x.y() - 0.2)};
}

// Max gradient error over the evaluation points whose support lies inside the
// unit square (near an edge the one-sided support gives first order only).
template <class Kernel>
double gradient_error(int n, bool at_particles) {
  const double spacing = 1.0 / (n - 1);
  const double support = 2.0 * spacing;
  const double h = support / Kernel::support_radius_factor;
  const approx_test::PointSets sets = approx_test::plate(n, spacing, 0.0, at_particles);
  const approx::ShapeFunctions sf = approx::MLS<Kernel>::build(
      sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, h);
  double worst = 0.0;
  for (std::size_t r = 0; r < sf.rows(); ++r) {
    const Vector3& x = sets.eval_positions[r];
    if (std::min({x.x(), x.y(), 1.0 - x.x(), 1.0 - x.y()}) < support - 1e-12) continue;
    Vector2 gradient = Vector2::Zero();
    for (std::size_t s = sf.row_begin[r]; s < sf.row_begin[r] + std::size_t(sf.row_size[r]); ++s)
      gradient += field(sets.particles[std::size_t(sf.neighbour[s])]) * Vector2(sf.value[s].dphi_d1, sf.value[s].dphi_d2);
    worst = std::max(worst, (gradient - field_gradient(x)).norm());
  }
  return worst;
}

}  // namespace

TEMPLATE_TEST_CASE("MLS gradients converge at second order on regular sheets", "[approx][convergence]",
                   kernel::CubicSpline, kernel::WendlandC2, kernel::QuinticSpline) {
  for (const bool at_particles : {true, false}) {
    double previous = gradient_error<TestType>(11, at_particles);
    for (const int n : {21, 41, 81}) {
      const double error = gradient_error<TestType>(n, at_particles);
      const double order = std::log2(previous / error);
      std::cout << "MLS gradient convergence, " << (at_particles ? "particles" : "stress points")
                << ", " << name(TestType{}) << ": n = " << n << ", max error " << error
                << ", order " << order << '\n';
      INFO("n = " << n << ", error " << error << ", order " << order);
      CHECK(order >= 1.8);
      previous = error;
    }
  }
}
