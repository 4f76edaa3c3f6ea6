// Visibility predicates, the Shepard fallback, row rebuilds and input errors.
#include "approx_test_support.hpp"

#include <sphshell/approx/all.hpp>
#include <sphshell/kernel/all.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <set>

using namespace sphshell;
using approx::MLS;
using approx::NSPH;
using approx::ShapeFunctions;
using approx_test::PointSets;

namespace {

const double spacing = 0.01;
const double h = spacing;  // cubic spline: support 2 spacings

// Row `target` sees only the particles in `kept`; every other row sees all.
struct KeepOnly {
  std::size_t target;
  std::set<std::size_t> kept;
  bool operator()(std::size_t eval_index, std::size_t particle) const {
    return eval_index != target || kept.count(particle) > 0;
  }
};

// A straight crack along x = 0.1 for y < 0.1: pairs whose segment crosses it are cut.
struct VerticalCrack {
  const PointSets* sets;
  bool operator()(std::size_t eval_index, std::size_t particle) const {
    const Vector3& a = sets->eval_positions[eval_index];
    const Vector3& b = sets->particles[particle];
    const double c = 0.1 + 1e-4;  // off the grid lines, so no point lies on the crack
    if ((a.x() - c) * (b.x() - c) >= 0.0) return true;
    const double t = (c - a.x()) / (b.x() - a.x());
    return a.y() + t * (b.y() - a.y()) >= 0.1;
  }
};

std::size_t centre_row(int n) { return std::size_t((n / 2) * (n - 1) + n / 2); }

template <class Approximation>
void check_rows_equal(const ShapeFunctions& a, const ShapeFunctions& b, std::size_t r) {
  INFO("row " << r);
  REQUIRE(a.row_begin[r] == b.row_begin[r]);
  REQUIRE(a.capacity(r) == b.capacity(r));
  CHECK(a.row_size[r] == b.row_size[r]);
  CHECK(a.shepard[r] == b.shepard[r]);
  for (std::size_t s = a.row_begin[r]; s < a.row_begin[r + 1]; ++s) {
    CHECK(a.neighbour[s] == b.neighbour[s]);
    CHECK(a.value[s].phi == b.value[s].phi);
    CHECK(a.value[s].dphi_d1 == b.value[s].dphi_d1);
    CHECK(a.value[s].dphi_d2 == b.value[s].dphi_d2);
  }
}

}  // namespace

TEMPLATE_TEST_CASE("Rows with fewer than three visible neighbours fall back to Shepard", "[approx][crack]",
                   MLS<kernel::CubicSpline>, NSPH<kernel::CubicSpline>) {
  const int n = 11;
  const PointSets sets = approx_test::plate(n, spacing, 0.3, false);
  const std::size_t target = centre_row(n);
  const ShapeFunctions full =
      TestType::build(sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, h);
  REQUIRE(full.row_size[target] >= 8);
  const std::size_t begin = full.row_begin[target];
  const auto first = std::size_t(full.neighbour[begin]);
  const auto second = std::size_t(full.neighbour[begin + 3]);

  const ShapeFunctions cut = TestType::build(sets.particles, sets.volumes, sets.eval_positions,
                                             sets.eval_frames, h, KeepOnly{target, {first, second}});
  CHECK(cut.shepard[target] == 1);
  CHECK(cut.row_size[target] == 2);
  CHECK(cut.capacity(target) == full.capacity(target));
  CHECK(cut.neighbour[begin] == int(first));
  CHECK(cut.neighbour[begin + 1] == int(second));
  const double w_first =
      kernel::CubicSpline::value((sets.particles[first] - sets.eval_positions[target]).norm(), h);
  const double w_second =
      kernel::CubicSpline::value((sets.particles[second] - sets.eval_positions[target]).norm(), h);
  CHECK(cut.value[begin].phi == Approx(w_first / (w_first + w_second)).epsilon(1e-14));
  CHECK(cut.value[begin].phi + cut.value[begin + 1].phi == Approx(1.0).epsilon(1e-15));
  std::size_t hidden_slots = 0;
  for (std::size_t s = begin; s < cut.row_begin[target + 1]; ++s) {
    CHECK(cut.value[s].dphi_d1 == 0.0);
    CHECK(cut.value[s].dphi_d2 == 0.0);
    if (s >= begin + 2) {
      CHECK(cut.value[s].phi == 0.0);
      ++hidden_slots;
    }
  }
  CHECK(hidden_slots == full.capacity(target) - 2);
  for (std::size_t r = 0; r < cut.rows(); ++r)
    if (r != target) CHECK(cut.shepard[r] == 0);

  SECTION("three collinear neighbours are singular too") {
    // Particles of one grid row are not collinear after jitter; use a regular plate.
    const PointSets regular = approx_test::plate(n, spacing, 0.0, true);
    const std::size_t row = std::size_t(5 * n + 5);
    const ShapeFunctions line = TestType::build(
        regular.particles, regular.volumes, regular.eval_positions, regular.eval_frames, h,
        KeepOnly{row, {row - 1, row, row + 1}});
    CHECK(line.shepard[row] == 1);
    CHECK(line.row_size[row] == 3);
  }

  SECTION("no visible neighbour is an error naming the evaluation point") {
    CHECK_THROWS_WITH(TestType::build(sets.particles, sets.volumes, sets.eval_positions,
                                      sets.eval_frames, h, KeepOnly{target, {}}),
                      Catch::Contains("evaluation point " + std::to_string(target)));
  }
}

TEMPLATE_TEST_CASE("rebuild_row with a predicate gives the row of a full build with it",
                   "[approx][crack]", MLS<kernel::CubicSpline>, NSPH<kernel::CubicSpline>,
                   MLS<kernel::WendlandC2>) {
  const double support_h = 2.0 * spacing / TestType::kernel_type::support_radius_factor;
  const PointSets sets = approx_test::plate(21, spacing, 0.3, false);
  const VerticalCrack crack{&sets};
  const ShapeFunctions expected = TestType::build(sets.particles, sets.volumes, sets.eval_positions,
                                                  sets.eval_frames, support_h, crack);
  ShapeFunctions rebuilt =
      TestType::build(sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, support_h);
  std::size_t changed_rows = 0;
  for (std::size_t r = 0; r < rebuilt.rows(); ++r)
    if (expected.row_size[r] != rebuilt.row_size[r]) {
      ++changed_rows;
      TestType::rebuild_row(rebuilt, r, sets.particles, sets.volumes, sets.eval_positions[r],
                            sets.eval_frames[r], support_h, crack);
    }
  CHECK(changed_rows > 10);
  for (std::size_t r = 0; r < rebuilt.rows(); ++r) check_rows_equal<TestType>(rebuilt, expected, r);

  SECTION("healing: rebuilding with everything visible restores the original row") {
    const ShapeFunctions original =
        TestType::build(sets.particles, sets.volumes, sets.eval_positions, sets.eval_frames, support_h);
    for (std::size_t r = 0; r < rebuilt.rows(); ++r)
      TestType::rebuild_row(rebuilt, r, sets.particles, sets.volumes, sets.eval_positions[r],
                            sets.eval_frames[r], support_h, approx::AlwaysVisible{});
    for (std::size_t r = 0; r < rebuilt.rows(); ++r) check_rows_equal<TestType>(rebuilt, original, r);
  }

  SECTION("a rebuild that leaves nothing visible throws and keeps the row") {
    const std::size_t r = 7;
    const ShapeFunctions before = rebuilt;
    CHECK_THROWS_WITH(TestType::rebuild_row(rebuilt, r, sets.particles, sets.volumes,
                                            sets.eval_positions[r], sets.eval_frames[r], support_h,
                                            KeepOnly{r, {}}),
                      Catch::Contains("evaluation point 7"));
    check_rows_equal<TestType>(rebuilt, before, r);
  }
}

TEMPLATE_TEST_CASE("Invalid input throws sphshell::Error", "[approx][errors]", MLS<kernel::CubicSpline>,
                   NSPH<kernel::QuinticSpline>) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const PointSets good = approx_test::plate(6, spacing, 0.0, false);
  const auto build = [](const PointSets& s, double smoothing) {
    return TestType::build(s.particles, s.volumes, s.eval_positions, s.eval_frames, smoothing);
  };
  REQUIRE_NOTHROW(build(good, h));

  for (const double bad_h : {0.0, -h, nan, std::numeric_limits<double>::infinity()})
    CHECK_THROWS_WITH(build(good, bad_h), Catch::Contains("h"));

  PointSets s = good;
  s.particles[4].y() = nan;
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("point 4"));
  s = good;
  s.eval_positions[3].z() = nan;
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("evaluation point 3"));
  s = good;
  s.particles[9] = s.particles[2];
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("particles 2 and 9"));
  s = good;
  s.eval_positions[5] = s.eval_positions[1];
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("evaluation points 1 and 5"));
  s = good;
  s.eval_frames[6].normal = Vector3::Zero();
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("evaluation point 6"));
  for (const double bad_volume : {0.0, -1e-4, nan}) {
    s = good;
    s.volumes[8] = bad_volume;
    CHECK_THROWS_WITH(build(s, h), Catch::Contains("particle 8"));
  }
  s = good;
  s.volumes.pop_back();
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("volumes"));
  s = good;
  s.eval_frames.pop_back();
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("frames"));
  s = good;
  s.eval_positions[2] = Vector3(5.0, 5.0, 0.0);  // far from every particle
  CHECK_THROWS_WITH(build(s, h), Catch::Contains("evaluation point 2"));
  // An evaluation point may coincide with a particle (the other set).
  s = good;
  s.eval_positions[0] = s.particles[0];
  CHECK_NOTHROW(build(s, h));

  ShapeFunctions sf = build(good, h);
  const auto rebuild = [&](std::size_t row, double smoothing, const TangentFrame& frame) {
    TestType::rebuild_row(sf, row, good.particles, good.volumes, good.eval_positions[0], frame,
                          smoothing, approx::AlwaysVisible{});
  };
  CHECK_THROWS_AS(rebuild(0, 0.0, good.eval_frames[0]), Error);
  CHECK_THROWS_AS(rebuild(sf.rows(), h, good.eval_frames[0]), Error);
  CHECK_THROWS_AS(rebuild(0, h, TangentFrame{Vector3::UnitX(), Vector3::UnitY(), Vector3::Zero()}), Error);
  CHECK_NOTHROW(rebuild(0, h, good.eval_frames[0]));
}
