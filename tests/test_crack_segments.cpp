#include <sphshell/crack/segment_intersection.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

using namespace sphshell;
using sphshell::crack::orientation;
using sphshell::crack::pair_is_cut;
using sphshell::crack::side_of_line;

namespace {

// Paper's Fig. 4 notation: L1 is the crack through points 1 and 2, L2 the
// particle pair through points 3 and 4; L1(x3, y3) is the signed side of
// point 3 relative to L1.
struct Figure4Case {
  Vector2 point1;
  Vector2 point2;
  Vector2 point3;
  Vector2 point4;
};

int sign_of_l1_product(const Figure4Case& c) {
  return side_of_line(c.point1, c.point2, c.point3) * side_of_line(c.point1, c.point2, c.point4);
}

int sign_of_l2_product(const Figure4Case& c) {
  return side_of_line(c.point3, c.point4, c.point1) * side_of_line(c.point3, c.point4, c.point2);
}

// The verdict must not depend on how either segment is oriented, nor on which
// of the two is handed in first within each pair of points.
void check_verdict(const Figure4Case& c, bool expected_cut) {
  CHECK(pair_is_cut(c.point3, c.point4, c.point1, c.point2) == expected_cut);
  CHECK(pair_is_cut(c.point4, c.point3, c.point1, c.point2) == expected_cut);
  CHECK(pair_is_cut(c.point3, c.point4, c.point2, c.point1) == expected_cut);
  CHECK(pair_is_cut(c.point4, c.point3, c.point2, c.point1) == expected_cut);
  // Same configuration embedded in a plate at z = 2: projection is exact there.
  const TangentFrame plate = tangent_frame(Vector3::UnitZ());
  const Vector3 origin(0.0, 0.0, 2.0);
  auto lift = [](const Vector2& p) { return Vector3(p.x(), p.y(), 2.0); };
  CHECK(crack::pair_is_cut_in_tangent_plane(lift(c.point3), lift(c.point4), lift(c.point1),
                                            lift(c.point2), plate, origin) == expected_cut);
}

// The straightforward double evaluation, for showing where it fails.
double naive_orientation(const Vector2& a, const Vector2& b, const Vector2& p) {
  return (a.x() - p.x()) * (b.y() - p.y()) - (a.y() - p.y()) * (b.x() - p.x());
}

int sign(double value) { return (value > 0.0) - (value < 0.0); }

const double ulp_at_half = std::ldexp(1.0, -53);

}  // namespace

TEST_CASE("Fig. 4 (a): L1 product > 0, L2 product > 0 -> effective", "[crack][fig4]") {
  // Pair entirely above the crack, crack entirely below the pair's line.
  const Figure4Case c{{0, 0}, {2, 0}, {0, 1}, {2, 2}};
  REQUIRE(sign_of_l1_product(c) > 0);
  REQUIRE(sign_of_l2_product(c) > 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (b): L1 product > 0, L2 product = 0 -> effective", "[crack][fig4]") {
  // Crack start lies on the pair's line, beyond the pair; the pair is on one
  // side of the crack.
  const Figure4Case c{{2, 0}, {3, 1}, {0, 0}, {1, 0}};
  REQUIRE(sign_of_l1_product(c) > 0);
  REQUIRE(sign_of_l2_product(c) == 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (c): L1 product = 0, L2 product > 0 -> effective", "[crack][fig4]") {
  // Pair point 3 on the crack's extension beyond the crack end, pair
  // perpendicular to the crack.
  const Figure4Case c{{0, 0}, {1, 0}, {2, 0}, {2, 1}};
  REQUIRE(sign_of_l1_product(c) == 0);
  REQUIRE(sign_of_l2_product(c) > 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (d): L1 product < 0, L2 product > 0 -> effective", "[crack][fig4]") {
  // The pair straddles the crack's line but the crack stops short of the pair.
  const Figure4Case c{{1, 1}, {1, 2}, {0, 0}, {2, 0}};
  REQUIRE(sign_of_l1_product(c) < 0);
  REQUIRE(sign_of_l2_product(c) > 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (e): L1 product < 0, L2 product = 0 -> invalid", "[crack][fig4]") {
  // The crack tip ends exactly on the pair's connection.
  const Figure4Case c{{1, 0}, {1, 1}, {0, 0}, {2, 0}};
  REQUIRE(sign_of_l1_product(c) < 0);
  REQUIRE(sign_of_l2_product(c) == 0);
  check_verdict(c, true);
}

TEST_CASE("Fig. 4 (f): L1 product < 0, L2 product < 0 -> invalid", "[crack][fig4]") {
  // Proper crossing.
  const Figure4Case c{{1, -1}, {1, 1}, {0, 0}, {2, 0}};
  REQUIRE(sign_of_l1_product(c) < 0);
  REQUIRE(sign_of_l2_product(c) < 0);
  check_verdict(c, true);
}

TEST_CASE("Fig. 4 (g): L1 product = 0, L2 product > 0 -> effective", "[crack][fig4]") {
  // Pair point 3 on the crack's extension before the crack start, pair leaving
  // obliquely away from the crack.
  const Figure4Case c{{1, 0}, {2, 0}, {0, 0}, {-1, 1}};
  REQUIRE(sign_of_l1_product(c) == 0);
  REQUIRE(sign_of_l2_product(c) > 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (h): L1 product = 0, L2 product = 0 -> effective", "[crack][fig4]") {
  // Pair point 3 coincides with crack end 2 (segments meet at a shared end).
  const Figure4Case c{{0, 0}, {1, 0}, {1, 0}, {2, 1}};
  REQUIRE(sign_of_l1_product(c) == 0);
  REQUIRE(sign_of_l2_product(c) == 0);
  check_verdict(c, false);
}

TEST_CASE("Fig. 4 (i): L1 product = 0, L2 product > 0 -> effective", "[crack][fig4]") {
  // Pair point 3 on the crack's extension, the pair leaning back over the
  // crack without reaching it.
  const Figure4Case c{{0, 0}, {1, 0}, {3, 0}, {0, 1}};
  REQUIRE(sign_of_l1_product(c) == 0);
  REQUIRE(sign_of_l2_product(c) > 0);
  check_verdict(c, false);
}

TEST_CASE("A pair starting on the crack's interior is not cut (touching from one side)",
          "[crack]") {
  // L1 product = 0, L2 product < 0: not one of Fig. 4's panels; the design's
  // rule keeps such a pair effective.
  const Figure4Case c{{0, 0}, {2, 0}, {1, 0}, {1, 1}};
  REQUIRE(sign_of_l1_product(c) == 0);
  REQUIRE(sign_of_l2_product(c) < 0);
  check_verdict(c, false);
}

TEST_CASE("Collinear pair and crack never cut", "[crack]") {
  SECTION("overlapping") { check_verdict({{0, 0}, {2, 0}, {1, 0}, {3, 0}}, false); }
  SECTION("pair inside the crack") { check_verdict({{0, 0}, {3, 0}, {1, 0}, {2, 0}}, false); }
  SECTION("disjoint") { check_verdict({{0, 0}, {1, 0}, {2, 0}, {3, 0}}, false); }
  SECTION("oblique line") { check_verdict({{0, 0}, {2, 2}, {1, 1}, {3, 3}}, false); }
}

TEST_CASE("A zero-length crack segment never cuts", "[crack]") {
  // Every point is 'on' the line of a point-crack, so the pair never straddles
  // it: callers may pass such segments (a crack made of one damaged stress
  // point) without filtering them.
  check_verdict({{1, 0}, {1, 0}, {0, 0}, {2, 0}}, false);
  check_verdict({{1, 1}, {1, 1}, {0, 0}, {2, 2}}, false);
  check_verdict({{1, 0.5}, {1, 0.5}, {0, 0}, {2, 0}}, false);
}

TEST_CASE("A zero-length pair is never cut", "[crack]") {
  check_verdict({{1, -1}, {1, 1}, {0, 0}, {0, 0}}, false);
  check_verdict({{1, -1}, {1, 1}, {1, 0}, {1, 0}}, false);
}

TEST_CASE("Pair endpoints coinciding with crack endpoints do not cut", "[crack]") {
  SECTION("identical segments") { check_verdict({{0, 0}, {1, 1}, {0, 0}, {1, 1}}, false); }
  SECTION("reversed identical segments") {
    check_verdict({{0, 0}, {1, 1}, {1, 1}, {0, 0}}, false);
  }
  SECTION("one shared end, crack crossing the pair's line elsewhere") {
    // Crack from (0, 0) to (2, 2); pair from (0, 0) to (2, 0): crack end 2 is
    // above the pair's line, crack end 1 is pair point 3.
    check_verdict({{0, 0}, {2, 2}, {0, 0}, {2, 0}}, false);
  }
  SECTION("crack end on pair point 4, pair straddling nothing") {
    check_verdict({{2, 0}, {2, 1}, {0, 0}, {2, 0}}, false);
  }
}

TEST_CASE("Orientation sign convention and symmetries", "[crack][orientation]") {
  const Vector2 a(0, 0), b(1, 0);
  CHECK(orientation(a, b, Vector2(0.5, 1)) > 0);
  CHECK(orientation(a, b, Vector2(0.5, -1)) < 0);
  CHECK(orientation(a, b, Vector2(7, 0)) == 0.0);
  CHECK(orientation(a, b, Vector2(0.5, 1)) == Approx(1.0));
}

TEST_CASE("Orientation is exact where naive double arithmetic gets the sign wrong",
          "[crack][orientation]") {
  // Points p = (0.5 + i·u, 0.5 + j·u), u = 2^-53 (one ulp at 0.5), against the
  // line y = x through (12, 12) and (24, 24): the exact orientation is
  // 12·(p_y − p_x), whose sign is sign(j − i).
  const Vector2 a(12, 12), b(24, 24);
  int naive_wrong = 0;
  int naive_flipped = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      const Vector2 p(0.5 + i * ulp_at_half, 0.5 + j * ulp_at_half);
      const int exact = sign(j - i);
      INFO("i = " << i << ", j = " << j);
      REQUIRE(side_of_line(a, b, p) == exact);
      // Cyclic permutations keep the sign, swaps flip it.
      REQUIRE(side_of_line(b, p, a) == exact);
      REQUIRE(side_of_line(p, a, b) == exact);
      REQUIRE(side_of_line(b, a, p) == -exact);
      const int naive = sign(naive_orientation(a, b, p));
      naive_wrong += naive != exact;
      naive_flipped += naive == -exact && exact != 0;
    }
  }
  // The test is only meaningful if the naive formula actually fails here.
  CHECK(naive_wrong > 0);
  CHECK(naive_flipped > 0);
}

TEST_CASE("Near-degenerate pairs get the exact verdict", "[crack]") {
  // Crack along y = x from (-12, -12) to (24, 24); pair point 3 within ulps of
  // the crack's line near (0.5, 0.5), pair point 4 well below it. The crack
  // clearly reaches the pair's line, so the pair is cut exactly when point 3 is
  // strictly above y = x, i.e. j > i.
  const Vector2 crack_start(-12, -12), crack_end(24, 24);
  const Vector2 below(10, -10);
  int naive_wrong = 0;
  for (int i = 0; i < 64; ++i) {
    for (int j = 0; j < 64; ++j) {
      const Vector2 near_line(0.5 + i * ulp_at_half, 0.5 + j * ulp_at_half);
      INFO("i = " << i << ", j = " << j);
      REQUIRE(pair_is_cut(near_line, below, crack_start, crack_end) == (j > i));
      REQUIRE(pair_is_cut(below, near_line, crack_end, crack_start) == (j > i));
      const bool naive_cut =
          sign(naive_orientation(crack_start, crack_end, near_line)) *
                  sign(naive_orientation(crack_start, crack_end, below)) <
              0 &&
          sign(naive_orientation(near_line, below, crack_start)) *
                  sign(naive_orientation(near_line, below, crack_end)) <=
              0;
      naive_wrong += naive_cut != (j > i);
    }
  }
  CHECK(naive_wrong > 0);
}

TEST_CASE("Orientation matches exact integer arithmetic on random and collinear inputs",
          "[crack][orientation]") {
  // Coordinates k·2^-20 with |k| < 2^26: the scaled determinant fits in 64-bit
  // integers, an independent exact reference. Large collinear triples make the
  // double products round, so the filter fails and the expansion path decides.
  std::mt19937_64 generator(20150601);
  std::uniform_int_distribution<std::int64_t> coordinate(-(std::int64_t{1} << 26) + 1,
                                                         (std::int64_t{1} << 26) - 1);
  std::uniform_int_distribution<std::int64_t> step(-64, 64);
  const double scale = std::ldexp(1.0, -20);
  auto reference_sign = [](std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by,
                           std::int64_t px, std::int64_t py) {
    const std::int64_t determinant = (bx - ax) * (py - ay) - (by - ay) * (px - ax);
    return (determinant > 0) - (determinant < 0);
  };
  int collinear_checked = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const std::int64_t ax = coordinate(generator), ay = coordinate(generator);
    std::int64_t bx = coordinate(generator), by = coordinate(generator);
    std::int64_t px = coordinate(generator), py = coordinate(generator);
    if (trial % 2 == 1) {
      // p = a + t·d and b = a + s·d (d a small direction), nudged by at most
      // one unit half of the time: exactly or nearly collinear, big coordinates.
      const std::int64_t dx = step(generator), dy = step(generator);
      const std::int64_t t = (std::int64_t{1} << 18) + step(generator);
      const std::int64_t s = -(std::int64_t{1} << 18) + step(generator);
      bx = ax + s * dx;
      by = ay + s * dy;
      px = ax + t * dx + (trial % 4 == 1 ? step(generator) % 2 : 0);
      py = ay + t * dy;
      if (std::llabs(bx) >= (std::int64_t{1} << 27) || std::llabs(by) >= (std::int64_t{1} << 27) ||
          std::llabs(px) >= (std::int64_t{1} << 27) || std::llabs(py) >= (std::int64_t{1} << 27))
        continue;
      ++collinear_checked;
    }
    const Vector2 a(ax * scale, ay * scale), b(bx * scale, by * scale),
        p(px * scale, py * scale);
    const int expected = reference_sign(ax, ay, bx, by, px, py);
    INFO("trial " << trial);
    REQUIRE(side_of_line(a, b, p) == expected);
    const double exact_path = crack::detail::orientation_exact(a, b, p);
    REQUIRE(sign(exact_path) == expected);
  }
  CHECK(collinear_checked > 5000);
}

TEST_CASE("Non-finite coordinates are rejected", "[crack][orientation]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double infinity = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(orientation(Vector2(0, 0), Vector2(1, 0), Vector2(nan, 1)), Error);
  CHECK_THROWS_AS(orientation(Vector2(infinity, 0), Vector2(1, 0), Vector2(0, 1)), Error);
  CHECK_THROWS_WITH(
      pair_is_cut(Vector2(0, 0), Vector2(2, 0), Vector2(1, nan), Vector2(1, 1)),
      Catch::Contains("finite") && Catch::Contains("nan"));
}

TEST_CASE("On a curved shell the test runs in the tangent plane", "[crack]") {
  // Points on the unit sphere near the north pole, parameterized by (u, v).
  auto on_sphere = [](double u, double v) { return Vector3(u, v, 1.0).normalized(); };
  const Vector3 pole(0, 0, 1);
  const TangentFrame frame = tangent_frame(pole);
  const Vector3 crack_start = on_sphere(0.0, -0.1), crack_end = on_sphere(0.0, 0.1);
  CHECK(crack::pair_is_cut_in_tangent_plane(on_sphere(-0.05, 0.0), on_sphere(0.05, 0.0),
                                            crack_start, crack_end, frame, pole));
  CHECK_FALSE(crack::pair_is_cut_in_tangent_plane(on_sphere(-0.05, 0.2), on_sphere(0.05, 0.2),
                                                  crack_start, crack_end, frame, pole));
  CHECK_FALSE(crack::pair_is_cut_in_tangent_plane(on_sphere(0.02, -0.05), on_sphere(0.05, 0.05),
                                                  crack_start, crack_end, frame, pole));
  // A tilted frame about an off-pole origin: same verdicts.
  const Vector3 origin = on_sphere(0.01, 0.02);
  const TangentFrame tilted = tangent_frame(origin);
  CHECK(crack::pair_is_cut_in_tangent_plane(on_sphere(-0.05, 0.0), on_sphere(0.05, 0.0),
                                            crack_start, crack_end, tilted, origin));
  CHECK_FALSE(crack::pair_is_cut_in_tangent_plane(on_sphere(-0.05, 0.2), on_sphere(0.05, 0.2),
                                                  crack_start, crack_end, tilted, origin));
  const Vector2 projected = crack::project_onto_tangent_plane(Vector3(1, 2, 3), Vector3(1, 1, 1),
                                                              tangent_frame(Vector3::UnitZ()));
  CHECK(projected == Vector2(0, 1));
}
