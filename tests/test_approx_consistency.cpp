// Partition of unity, linear reproduction and curved surfaces.
#include "approx_test_support.hpp"

#include <sphshell/approx/all.hpp>
#include <sphshell/kernel/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace sphshell;
using approx::MLS;
using approx::NSPH;
using approx::ShapeFunctions;
using approx_test::PointSets;

static_assert(approx::is_approximation_v<MLS<kernel::CubicSpline>>);
static_assert(approx::is_approximation<NSPH<kernel::QuinticSpline>>::value);
static_assert(!approx::is_approximation_v<kernel::CubicSpline>);
static_assert(approx::check_approximation<MLS<kernel::WendlandC2>>());

namespace {
// Has kernel_type and build but no rebuild_row.
struct WithoutRebuild {
  using kernel_type = kernel::CubicSpline;
  template <class Visible = approx::AlwaysVisible>
  static ShapeFunctions build(const std::vector<Vector3>&, const std::vector<double>&,
                              const std::vector<Vector3>&, const std::vector<TangentFrame>&, double,
                              Visible = {}) {
    return {};
  }
};
struct WithoutKernel : WithoutRebuild {
  using kernel_type = double;
};
}  // namespace
static_assert(approx::detail::has_build<WithoutRebuild>::value);
static_assert(!approx::is_approximation_v<WithoutRebuild>);
static_assert(!approx::detail::has_kernel_type<WithoutKernel>::value);

namespace {

constexpr double pi = 3.14159265358979323846;

// Support radius 2 spacings for every kernel, as the solver uses.
template <class Approximation>
double smoothing_length(double spacing) {
  return 2.0 * spacing / Approximation::kernel_type::support_radius_factor;
}

// Σ over row r of f(slot).
template <class F>
Vector2 row_sum(const ShapeFunctions& sf, std::size_t r, F&& gradient_weight) {
  Vector2 sum = Vector2::Zero();
  for (std::size_t s = sf.row_begin[r]; s < sf.row_begin[r] + std::size_t(sf.row_size[r]); ++s)
    sum += gradient_weight(s) * Vector2(sf.value[s].dphi_d1, sf.value[s].dphi_d2);
  return sum;
}

double phi_sum(const ShapeFunctions& sf, std::size_t r, const std::function<double(std::size_t)>& u) {
  double sum = 0.0;
  for (std::size_t s = sf.row_begin[r]; s < sf.row_begin[r] + std::size_t(sf.row_size[r]); ++s)
    sum += sf.value[s].phi * u(s);
  return sum;
}

void check_layout(const ShapeFunctions& sf, std::size_t rows) {
  REQUIRE(sf.rows() == rows);
  REQUIRE(sf.row_begin.size() == rows + 1);
  REQUIRE(sf.shepard.size() == rows);
  REQUIRE(sf.row_begin.back() == sf.slots());
  REQUIRE(sf.value.size() == sf.slots());
  for (std::size_t r = 0; r < rows; ++r) REQUIRE(std::size_t(sf.row_size[r]) <= sf.capacity(r));
}

// The plane tests measure gradients in units of 1/h so "1e-12" is
// independent of the spacing.
template <class Approximation>
void check_partition_of_unity(const PointSets& sets, double h) {
  const ShapeFunctions sf = Approximation::build(sets.particles, sets.volumes, sets.eval_positions,
                                                 sets.eval_frames, h);
  check_layout(sf, sets.eval_positions.size());
  double worst_phi = 0.0, worst_gradient = 0.0;
  std::size_t shepard_rows = 0;
  for (std::size_t r = 0; r < sf.rows(); ++r) {
    worst_phi = std::max(worst_phi, std::abs(phi_sum(sf, r, [](std::size_t) { return 1.0; }) - 1.0));
    worst_gradient = std::max(worst_gradient, h * row_sum(sf, r, [](std::size_t) { return 1.0; }).norm());
    shepard_rows += sf.shepard[r];
  }
  INFO("max |ΣΦ − 1| = " << worst_phi << ", max h|Σ∇Φ| = " << worst_gradient);
  CHECK(worst_phi < 1e-12);
  CHECK(worst_gradient < 1e-12);
  CHECK(shepard_rows == 0);
}

}  // namespace

TEMPLATE_TEST_CASE("Shape functions are a partition of unity with gradients summing to zero",
                   "[approx]", MLS<kernel::CubicSpline>, NSPH<kernel::CubicSpline>,
                   MLS<kernel::WendlandC2>, MLS<kernel::QuinticSpline>, NSPH<kernel::WendlandC2>,
                   NSPH<kernel::QuinticSpline>) {
  const double spacing = 0.01;
  const double h = smoothing_length<TestType>(spacing);
  for (const double jitter : {0.0, 0.3})
    for (const bool at_particles : {true, false}) {
      INFO("jitter " << jitter << ", evaluation at " << (at_particles ? "particles" : "cell centres"));
      check_partition_of_unity<TestType>(approx_test::plate(21, spacing, jitter, at_particles), h);
    }
}

TEMPLATE_TEST_CASE("MLS reproduces linear fields and their gradient on jittered points", "[approx]",
                   kernel::CubicSpline, kernel::WendlandC2, kernel::QuinticSpline) {
  using Approximation = MLS<TestType>;
  const double spacing = 0.01;
  const double h = smoothing_length<Approximation>(spacing);
  const double a = 0.3;
  const Vector2 b(1.7, -0.6);
  const auto field = [&](const Vector3& x) { return a + b.dot(x.head<2>()); };
  for (const bool at_particles : {true, false}) {
    const PointSets sets = approx_test::plate(21, spacing, 0.3, at_particles);
    const ShapeFunctions sf = Approximation::build(sets.particles, sets.volumes, sets.eval_positions,
                                                   sets.eval_frames, h);
    double worst_value = 0.0, worst_gradient = 0.0;
    for (std::size_t r = 0; r < sf.rows(); ++r) {
      const auto u = [&](std::size_t s) { return field(sets.particles[std::size_t(sf.neighbour[s])]); };
      worst_value = std::max(worst_value, std::abs(phi_sum(sf, r, u) - field(sets.eval_positions[r])));
      worst_gradient = std::max(worst_gradient, (row_sum(sf, r, u) - b).norm() / b.norm());
    }
    INFO("evaluation at " << (at_particles ? "particles" : "cell centres") << ": max value error "
                          << worst_value << ", max relative gradient error " << worst_gradient);
    CHECK(worst_value < 1e-12 * (std::abs(a) + b.norm()));
    CHECK(worst_gradient < 1e-12);
  }
}

TEMPLATE_TEST_CASE("NSPH's corrected gradient reproduces linear fields on jittered points",
                   "[approx]", kernel::CubicSpline, kernel::WendlandC2, kernel::QuinticSpline) {
  using Approximation = NSPH<TestType>;
  const double spacing = 0.01;
  const double h = smoothing_length<Approximation>(spacing);
  const Vector2 b(-2.5, 0.8);
  const auto field = [&](const Vector3& x) { return 4.0 + b.dot(x.head<2>()); };
  for (const bool at_particles : {true, false}) {
    const PointSets sets = approx_test::plate(21, spacing, 0.3, at_particles);
    const ShapeFunctions sf = Approximation::build(sets.particles, sets.volumes, sets.eval_positions,
                                                   sets.eval_frames, h);
    double worst_gradient = 0.0;
    for (std::size_t r = 0; r < sf.rows(); ++r) {
      const auto u = [&](std::size_t s) { return field(sets.particles[std::size_t(sf.neighbour[s])]); };
      worst_gradient = std::max(worst_gradient, (row_sum(sf, r, u) - b).norm() / b.norm());
    }
    INFO("max relative gradient error " << worst_gradient);
    CHECK(worst_gradient < 1e-12);
  }
}

namespace {

// u = a + b·ξ in each evaluation point's own tangent frame.
template <class Approximation>
void check_tangent_linear_field(const PointSets& sets, double h, bool values_too) {
  const ShapeFunctions sf = Approximation::build(sets.particles, sets.volumes, sets.eval_positions,
                                                 sets.eval_frames, h);
  const double a = -0.7;
  const Vector2 b(3.0, 1.25);
  double worst_value = 0.0, worst_gradient = 0.0, worst_unity = 0.0;
  std::size_t shepard_rows = 0;
  for (std::size_t r = 0; r < sf.rows(); ++r) {
    const TangentFrame& frame = sets.eval_frames[r];
    const auto u = [&](std::size_t s) {
      const Vector3 d = sets.particles[std::size_t(sf.neighbour[s])] - sets.eval_positions[r];
      return a + b.x() * d.dot(frame.e1) + b.y() * d.dot(frame.e2);
    };
    worst_value = std::max(worst_value, std::abs(phi_sum(sf, r, u) - a));
    worst_gradient = std::max(worst_gradient, (row_sum(sf, r, u) - b).norm() / b.norm());
    worst_unity = std::max(worst_unity, std::abs(phi_sum(sf, r, [](std::size_t) { return 1.0; }) - 1.0));
    shepard_rows += sf.shepard[r];
  }
  INFO("value error " << worst_value << ", relative gradient error " << worst_gradient);
  CHECK(shepard_rows == 0);
  CHECK(worst_unity < 1e-12);
  CHECK(worst_gradient < 1e-12);
  if (values_too) CHECK(worst_value < 1e-12 * (std::abs(a) + b.norm()));
}

// Particles on a cylinder of radius 0.1 (axis z), evaluation points at the
// particles or at the centres of the (θ, z) cells, pulled onto the surface.
PointSets cylinder(bool at_particles) {
  const double radius = 0.1, length = 0.1;
  const int around = 64, along = 21;
  const double dtheta = 2 * pi / around, dz = length / (along - 1);
  PointSets sets;
  const auto on_surface = [&](double theta, double z) {
    return Vector3(radius * std::cos(theta), radius * std::sin(theta), z);
  };
  for (int k = 0; k < along; ++k)
    for (int i = 0; i < around; ++i) {
      sets.particles.push_back(on_surface(i * dtheta, k * dz));
      sets.volumes.push_back(radius * dtheta * dz);
    }
  for (int k = 0; k < along - (at_particles ? 0 : 1); ++k)
    for (int i = 0; i < around; ++i) {
      const double theta = (i + (at_particles ? 0.0 : 0.5)) * dtheta;
      sets.eval_positions.push_back(on_surface(theta, (k + (at_particles ? 0.0 : 0.5)) * dz));
      sets.eval_frames.push_back(tangent_frame(Vector3(std::cos(theta), std::sin(theta), 0.0)));
    }
  return sets;
}

// A spherical cap of radius 0.1: a jittered plane grid lifted onto the sphere.
PointSets spherical_cap(bool at_particles) {
  const double radius = 0.1;
  PointSets sets = approx_test::plate(21, 0.004, 0.3, at_particles, 99);
  const auto lift = [&](Vector3& p) {
    p += Vector3(-0.04, -0.04, 0.0);
    p.z() = std::sqrt(radius * radius - p.x() * p.x() - p.y() * p.y());
  };
  for (Vector3& p : sets.particles) lift(p);
  for (double& v : sets.volumes) v = 0.004 * 0.004;
  for (std::size_t r = 0; r < sets.eval_positions.size(); ++r) {
    lift(sets.eval_positions[r]);
    sets.eval_frames[r] = tangent_frame(sets.eval_positions[r]);
  }
  return sets;
}

}  // namespace

TEMPLATE_TEST_CASE("Fields linear in the tangent coordinates are reproduced on curved shells",
                   "[approx][curved]", kernel::CubicSpline, kernel::WendlandC2,
                   kernel::QuinticSpline) {
  for (const bool at_particles : {true, false}) {
    INFO("evaluation at " << (at_particles ? "particles" : "cell centres"));
    {
      INFO("cylinder");
      const PointSets sets = cylinder(at_particles);
      const double spacing = 0.1 * 2 * pi / 64;
      const double h = 2.0 * spacing / TestType::support_radius_factor;
      check_tangent_linear_field<MLS<TestType>>(sets, h, true);
      check_tangent_linear_field<NSPH<TestType>>(sets, h, false);
    }
    {
      INFO("spherical cap");
      const PointSets sets = spherical_cap(at_particles);
      const double h = 2.0 * 0.004 / TestType::support_radius_factor;
      check_tangent_linear_field<MLS<TestType>>(sets, h, true);
      check_tangent_linear_field<NSPH<TestType>>(sets, h, false);
    }
  }
}

TEST_CASE("Builds are identical for any number of OpenMP threads", "[approx]") {
#ifdef _OPENMP
  const PointSets sets = approx_test::plate(41, 0.01, 0.3, false);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const ShapeFunctions serial = MLS<kernel::CubicSpline>::build(
      sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, 0.01);
  omp_set_num_threads(3);
  const ShapeFunctions parallel = MLS<kernel::CubicSpline>::build(
      sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, 0.01);
  omp_set_num_threads(threads);
  CHECK(serial.row_begin == parallel.row_begin);
  CHECK(serial.neighbour == parallel.neighbour);
  CHECK(serial.value == parallel.value);
#else
  // Not a pass: tests/CMakeLists.txt has ctest report this case as skipped.
  WARN("SKIPPED: built without OpenMP, there is no thread count to compare");
#endif
}
