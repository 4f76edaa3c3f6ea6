#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/statistics.hpp>
#include <sphshell/core/types.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

using namespace sphshell;

TEST_CASE("Error messages name the parameter and its value", "[core]") {
  CHECK_THROWS_WITH(detail::require_positive("thickness", -0.5),
                    Catch::Contains("thickness") && Catch::Contains("-0.5"));
  CHECK_THROWS_AS(detail::require_finite("E", std::numeric_limits<double>::quiet_NaN()), Error);
  CHECK_THROWS_WITH(detail::require_open_interval("nu", 0.5, -1.0, 0.5),
                    Catch::Contains("nu") && Catch::Contains("0.5"));
  CHECK_NOTHROW(detail::require_half_open_interval("Dc", 1.0, 0.0, 1.0));
  CHECK_THROWS_AS(detail::require_half_open_interval("Dc", 0.0, 0.0, 1.0), Error);
}

TEST_CASE("all_finite is false for any NaN or infinite component, true for the largest finite ones", "[core]") {
  const double largest = std::numeric_limits<double>::max(), tiny = std::numeric_limits<double>::denorm_min();
  const Vector3 finite(largest, -largest, tiny), signed_zero(-0.0, 0.0, -tiny);
  CHECK(all_finite(finite));
  CHECK(all_finite(finite, signed_zero, finite, signed_zero));
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()})
    for (int vector = 0; vector < 4; ++vector)
      for (int component = 0; component < 3; ++component) {
        std::array<Vector3, 4> v{finite, signed_zero, finite, signed_zero};
        v[std::size_t(vector)][component] = bad;
        CHECK_FALSE(all_finite(v[0], v[1], v[2], v[3]));
        CHECK_FALSE(all_finite(v[std::size_t(vector)]));
      }
}

TEST_CASE("interleaved_sum adds every value, whatever the count", "[core]") {
  // Integers are exact in any order: 1 + 2 + ... + n = n(n + 1)/2, for counts
  // below, at and above multiples of the eight partial sums.
  for (std::size_t n = 0; n <= 41; ++n) {
    std::vector<double> values(n);
    for (std::size_t i = 0; i < n; ++i) values[i] = static_cast<double>(i + 1);
    INFO("count " << n);
    CHECK(sphshell::detail::interleaved_sum(values) == static_cast<double>(n * (n + 1) / 2));
  }
  // Fractions: within a few ulps of the sum in long double.
  std::vector<double> values;
  long double reference = 0.0L;
  for (int i = 1; i <= 5101; ++i) {
    values.push_back(1.0 / (i + 0.37));
    reference += 1.0L / (i + 0.37L);
  }
  CHECK(std::abs(sphshell::detail::interleaved_sum(values) - static_cast<double>(reference)) <
        8 * std::numeric_limits<double>::epsilon() * static_cast<double>(reference));
}

TEST_CASE("Tangent frames are right-handed and orthonormal", "[core]") {
  const TangentFrame plate = tangent_frame(Vector3(0, 0, 2));
  CHECK(plate.e1.isApprox(Vector3::UnitX()));
  CHECK(plate.e2.isApprox(Vector3::UnitY()));
  for (const Vector3& normal : {Vector3(1, 0, 0), Vector3(0.3, -0.4, 0.5), Vector3(-1, 1e-3, 0)}) {
    const TangentFrame frame = tangent_frame(normal);
    CHECK(std::abs(frame.e1.dot(frame.e2)) < 1e-15);
    CHECK(std::abs(frame.e1.dot(frame.normal)) < 1e-15);
    CHECK(std::abs(frame.e1.norm() - 1.0) < 1e-15);
    CHECK(frame.e1.cross(frame.e2).isApprox(frame.normal, 1e-14));
    CHECK(frame.normal.isApprox(normal.normalized(), 1e-14));
  }
  CHECK_THROWS_WITH(tangent_frame(Vector3::Zero()), Catch::Contains("normal"));
}
