#include <sphshell/crack/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace sphshell;
using sphshell::crack::LineSegments;
using sphshell::crack::Segment;

static_assert(crack::is_crack_policy<LineSegments>::value && LineSegments::enabled);
static_assert(crack::check_crack_policy<LineSegments>() && crack::check_crack_policy<crack::None>());

// The enabled-policy traits reject what the solver could not use.
namespace broken_policies {
struct NonStaticConstant : LineSegments {
  double on_precrack_in_spacings = 1e-6;
};
struct FloatPoints : LineSegments {
  const std::vector<Eigen::Vector3f>& points() const { return float_points; }
  std::vector<Eigen::Vector3f> float_points;
};
struct WideSegment {
  std::size_t start_point, end_point;
  int crack_id;
};
struct WideSegments : LineSegments {
  const std::vector<WideSegment>& segments() const { return wide_segments; }
  std::vector<WideSegment> wide_segments;
};
struct ConsumesSegments : LineSegments {
  std::vector<std::size_t> affected_points(const std::vector<Vector3>&, std::vector<Segment>&&) const { return {}; }
};
struct NeedsArguments : LineSegments {
  explicit NeedsArguments(int) {}
};
}  // namespace broken_policies
static_assert(crack::detail::has_precrack_distance<LineSegments>::value);
static_assert(!crack::detail::has_precrack_distance<broken_policies::NonStaticConstant>::value);
static_assert(crack::detail::has_output_members<LineSegments>::value);
static_assert(!crack::detail::has_output_members<broken_policies::FloatPoints>::value);
static_assert(!crack::detail::has_output_members<broken_policies::WideSegments>::value);
static_assert(crack::detail::has_affected_points<LineSegments>::value);
static_assert(!crack::detail::has_affected_points<broken_policies::ConsumesSegments>::value);
static_assert(!std::is_default_constructible_v<broken_policies::NeedsArguments>);

namespace {

constexpr double spacing = 0.01;
constexpr double support_radius = 2.0 * spacing;
constexpr double pi = 3.14159265358979323846;

// A flat plate in the xy-plane: particles on the grid nodes (i Δ, j Δ), stress
// points at the cell centres ((i + ½) Δ, (j + ½) Δ), as the solver lays them out.
struct Plate {
  int cells_x;
  int cells_y;
  std::vector<Vector3> stress_points;
  std::vector<Vector3> normals;
  std::vector<Vector3> particles;

  Plate(int nx, int ny) : cells_x(nx), cells_y(ny) {
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        stress_points.emplace_back((i + 0.5) * spacing, (j + 0.5) * spacing, 0.0);
        normals.push_back(Vector3::UnitZ());
      }
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) particles.emplace_back(i * spacing, j * spacing, 0.0);
  }
  int stress_point(int i, int j) const { return j * cells_x + i; }
  LineSegments crack() const {
    LineSegments crack;
    crack.initialize(stress_points, normals, spacing, support_radius);
    return crack;
  }
};

Vector3 node(double i, double j) { return {i * spacing, j * spacing, 0.0}; }

const TangentFrame plate_frame = tangent_frame(Vector3::UnitZ());

bool visible_on_plate(const LineSegments& crack, const Vector3& a, const Vector3& b) {
  return crack.visible(a, b, plate_frame);
}

// Reference answer: every segment, no spatial index.
bool visible_brute_force(const LineSegments& crack, const Vector3& a, const Vector3& b,
                         const TangentFrame& frame) {
  for (const Segment& segment : crack.segments())
    if (crack::pair_is_cut_in_tangent_plane(a, b, crack.points()[segment.start_point],
                                            crack.points()[segment.end_point], frame, a))
      return false;
  return true;
}

// Visibility of every particle pair closer than the support radius.
std::vector<bool> visibility_table(const LineSegments& crack,
                                   const std::vector<Vector3>& particles) {
  std::vector<bool> table;
  for (const Vector3& a : particles)
    for (const Vector3& b : particles)
      if ((a - b).norm() < support_radius) table.push_back(crack.visible(a, b, plate_frame));
  return table;
}

void damage_one_by_one(LineSegments& crack, const std::vector<int>& stress_points) {
  for (int stress_point : stress_points) crack.add_damaged_stress_points({stress_point});
}

}  // namespace

TEST_CASE("a row of stress points damaged one by one forms one straight crack",
          "[crack][line_segments]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  CHECK(crack.empty());
  CHECK(crack.crack_count() == 0);

  const auto first = crack.add_damaged_stress_points({plate.stress_point(2, 5)});
  CHECK(first.empty());
  CHECK(crack.damaged_count() == 1);
  CHECK(crack.is_damaged(plate.stress_point(2, 5)));
  CHECK_FALSE(crack.is_damaged(plate.stress_point(3, 5)));
  CHECK(crack.crack_count() == 0);  // an isolated point is no crack yet

  const int n = 7;
  for (int i = 3; i < 2 + n; ++i) {
    const auto created = crack.add_damaged_stress_points({plate.stress_point(i, 5)});
    REQUIRE(created.size() == 1);
    CHECK(crack.points()[created[0].start_point].isApprox(
        plate.stress_points[plate.stress_point(i - 1, 5)]));
    CHECK(crack.points()[created[0].end_point].isApprox(
        plate.stress_points[plate.stress_point(i, 5)]));
  }
  CHECK(crack.segments().size() == std::size_t(n - 1));
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx((n - 1) * spacing));
  REQUIRE(crack.crack_lengths().size() == 1);
  CHECK(crack.crack_lengths()[0] == Approx((n - 1) * spacing));
  CHECK(crack.damaged_count() == std::size_t(n));
  CHECK(crack.points().size() == std::size_t(n));

  // Passing a registered stress point again changes nothing.
  CHECK(crack.add_damaged_stress_points({plate.stress_point(4, 5)}).empty());
  CHECK(crack.damaged_count() == std::size_t(n));
}

TEST_CASE("diagonal neighbours link, points two spacings apart do not", "[crack][line_segments]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  CHECK(crack.linking_distance() > std::sqrt(2.0) * spacing);
  CHECK(crack.linking_distance() < 2.0 * spacing);
  damage_one_by_one(crack,
                    {plate.stress_point(2, 2), plate.stress_point(3, 3), plate.stress_point(4, 4)});
  CHECK(crack.segments().size() == 2);
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx(2.0 * std::sqrt(2.0) * spacing));
  // Through the crack point shared by both segments: one of them cuts the pair
  // whichever way the rounded coordinates put that point.
  CHECK_FALSE(visible_on_plate(crack, node(3, 4), node(4, 3)));
  // A diagonal segment runs through the grid node between its stress points;
  // a particle on a crack's line is never cut off by it (docs/method.md §6).
  CHECK(visible_on_plate(crack, node(3, 3), node(4, 2)));
  CHECK(visible_on_plate(crack, node(3, 3), node(2, 4)));

  LineSegments gapped = plate.crack();
  damage_one_by_one(gapped, {plate.stress_point(2, 2), plate.stress_point(4, 2)});
  CHECK(gapped.empty());
  CHECK(gapped.crack_count() == 0);
  // The stress point in between joins both into one crack.
  const auto created = gapped.add_damaged_stress_points({plate.stress_point(3, 2)});
  CHECK(created.size() == 2);
  CHECK(gapped.crack_count() == 1);
  CHECK(gapped.total_length() == Approx(2.0 * spacing));
}

TEST_CASE("far-apart damage forms two cracks, counted once each has a segment",
          "[crack][line_segments]") {
  const Plate plate(16, 16);
  LineSegments crack = plate.crack();
  crack.add_damaged_stress_points({plate.stress_point(2, 2)});
  crack.add_damaged_stress_points({plate.stress_point(12, 12)});
  CHECK(crack.crack_count() == 0);
  crack.add_damaged_stress_points({plate.stress_point(3, 2)});
  CHECK(crack.crack_count() == 1);
  crack.add_damaged_stress_points({plate.stress_point(12, 13)});
  CHECK(crack.crack_count() == 2);
  const auto lengths = crack.crack_lengths();
  REQUIRE(lengths.size() == 2);
  CHECK(lengths[0] == Approx(spacing));
  CHECK(lengths[1] == Approx(spacing));
  const auto ids = crack.crack_ids();
  REQUIRE(ids.size() == 2);
  CHECK(ids[0] != ids[1]);
  CHECK(crack.segments()[0].crack_id != crack.segments()[1].crack_id);
}

TEST_CASE("a stress point bridging two cracks merges them", "[crack][line_segments]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  damage_one_by_one(crack, {plate.stress_point(2, 5), plate.stress_point(3, 5),
                            plate.stress_point(5, 5), plate.stress_point(6, 5)});
  CHECK(crack.crack_count() == 2);
  const auto created = crack.add_damaged_stress_points({plate.stress_point(4, 5)});
  // One segment to the nearest point of each crack.
  REQUIRE(created.size() == 2);
  CHECK(created[0].crack_id == created[1].crack_id);
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx(4.0 * spacing));
  REQUIRE(crack.crack_lengths().size() == 1);
  CHECK(crack.crack_lengths()[0] == Approx(4.0 * spacing));
  for (const Segment& segment : crack.segments()) CHECK(segment.crack_id == created[0].crack_id);
  for (int id : crack.crack_of_point()) CHECK(id == created[0].crack_id);
}

TEST_CASE("a crack branches at a T-junction", "[crack][line_segments]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  for (int i = 2; i <= 6; ++i) crack.add_damaged_stress_points({plate.stress_point(i, 5)});
  const auto stem = crack.add_damaged_stress_points({plate.stress_point(4, 6)});
  REQUIRE(stem.size() == 1);
  // The nearest crack point is straight below (Δ), not the diagonal ones (√2 Δ).
  const int junction = crack.crack_point_of_stress_point(plate.stress_point(4, 5));
  CHECK(stem[0].start_point == junction);
  crack.add_damaged_stress_points({plate.stress_point(4, 7)});
  int segments_at_junction = 0;
  for (const Segment& segment : crack.segments())
    segments_at_junction += (segment.start_point == junction) + (segment.end_point == junction);
  CHECK(segments_at_junction == 3);
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx(6.0 * spacing));

  // The stem cuts pairs across it; the main crack still cuts pairs across it.
  CHECK_FALSE(visible_on_plate(crack, node(4, 7), node(5, 7)));
  CHECK_FALSE(visible_on_plate(crack, node(3, 5), node(3, 6)));
  CHECK(visible_on_plate(crack, node(5, 7), node(6, 7)));
}

TEST_CASE("a batch is processed in ascending index order", "[crack][line_segments]") {
  const Plate plate(12, 12);
  std::vector<int> row;
  for (int i = 2; i <= 8; ++i) row.push_back(plate.stress_point(i, 5));
  LineSegments one_by_one = plate.crack();
  damage_one_by_one(one_by_one, row);
  LineSegments batch = plate.crack();
  std::vector<int> shuffled = row;
  std::reverse(shuffled.begin(), shuffled.end());
  shuffled.push_back(row[3]);  // duplicates are ignored
  const auto created = batch.add_damaged_stress_points(shuffled);
  CHECK(created.size() == row.size() - 1);
  CHECK(batch.segments() == one_by_one.segments());
  CHECK(batch.points() == one_by_one.points());
  CHECK(batch.damaged_count() == row.size());
}

TEST_CASE("a straight crack cuts the pairs across it and nothing else",
          "[crack][line_segments][visibility]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  // Stress points (2..8, 5): the crack runs along y = 5.5 Δ from x = 2.5 Δ to 8.5 Δ.
  for (int i = 2; i <= 8; ++i) crack.add_damaged_stress_points({plate.stress_point(i, 5)});

  SECTION("pairs across the crack are cut") {
    CHECK_FALSE(visible_on_plate(crack, node(5, 5), node(5, 6)));
    CHECK_FALSE(visible_on_plate(crack, node(5, 6), node(5, 5)));
    CHECK_FALSE(visible_on_plate(crack, node(5, 5), node(6, 6)));
    CHECK_FALSE(visible_on_plate(crack, node(3, 4), node(3, 7)));
    CHECK_FALSE(visible_on_plate(crack, node(8, 5), node(9, 6)));  // through the tip segment
  }
  SECTION("pairs on one side are visible") {
    CHECK(visible_on_plate(crack, node(5, 5), node(6, 5)));
    CHECK(visible_on_plate(crack, node(5, 4), node(5, 5)));
    CHECK(visible_on_plate(crack, node(5, 6), node(6, 7)));
  }
  SECTION("pairs crossing only the extension beyond the tips are visible") {
    CHECK(visible_on_plate(crack, node(9, 5), node(9, 6)));
    CHECK(visible_on_plate(crack, node(10, 5), node(10, 6)));
    CHECK(visible_on_plate(crack, node(2, 5), node(2, 6)));
    CHECK(visible_on_plate(crack, node(1, 5), node(2, 6)));
  }
  SECTION("pairs longer than the support radius are judged too") {
    CHECK_FALSE(visible_on_plate(crack, node(5, 2), node(5, 9)));
    CHECK(visible_on_plate(crack, node(5, 0), node(5, 5)));
  }
  SECTION("a pair through the tip point is cut (the crack end touches it)") {
    CHECK_FALSE(visible_on_plate(crack, node(8.5, 5), node(8.5, 6)));
  }
  SECTION("the spatial index agrees with a scan of every segment") {
    int cut_pairs = 0;
    for (const Vector3& a : plate.particles)
      for (const Vector3& b : plate.particles) {
        if ((a - b).norm() >= support_radius) continue;
        const bool visible = crack.visible(a, b, plate_frame);
        CHECK(visible == visible_brute_force(crack, a, b, plate_frame));
        cut_pairs += !visible;
      }
    CHECK(cut_pairs > 0);
  }
}

TEST_CASE("visibility does not depend on the order of damage insertion",
          "[crack][line_segments][visibility]") {
  const Plate plate(12, 12);
  std::vector<int> band;
  for (int i = 2; i <= 8; ++i) band.push_back(plate.stress_point(i, 5 + (i > 5)));
  LineSegments forward = plate.crack();
  damage_one_by_one(forward, band);
  LineSegments backward = plate.crack();
  damage_one_by_one(backward, std::vector<int>(band.rbegin(), band.rend()));
  CHECK(forward.total_length() == Approx(backward.total_length()));
  CHECK(visibility_table(forward, plate.particles) == visibility_table(backward, plate.particles));
}

TEST_CASE("a pre-crack along a row of stress points takes them over as its crack points",
          "[crack][line_segments]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  // From inside cell (1, 5) along the stress-point row y = 5.5 to the stress
  // point (6, 5) itself, which then stands for the end vertex.
  const std::vector<int> absorbed = crack.add_precrack({node(1.2, 5.5), node(6.5, 5.5)});
  std::vector<int> expected;
  for (int i = 1; i <= 6; ++i) expected.push_back(plate.stress_point(i, 5));
  std::sort(expected.begin(), expected.end());
  CHECK(absorbed == expected);
  CHECK(crack.points().size() == 7);  // the start vertex and six stress points
  CHECK(crack.segments().size() == 6);
  CHECK(crack.total_length() == Approx(5.3 * spacing));
  CHECK(crack.damaged_count() == 0);  // taken over by the pre-crack, not damaged
  for (int i = 1; i <= 6; ++i) {
    INFO("stress point (" << i << ", 5)");
    CHECK(crack.is_damaged(plate.stress_point(i, 5)));
    CHECK(crack.points()[static_cast<std::size_t>(crack.crack_point_of_stress_point(plate.stress_point(i, 5)))]
              .isApprox(plate.stress_points[static_cast<std::size_t>(plate.stress_point(i, 5))]));
  }
  CHECK_FALSE(crack.is_damaged(plate.stress_point(0, 5)));
  CHECK_FALSE(crack.is_damaged(plate.stress_point(7, 5)));
  CHECK_FALSE(crack.is_damaged(plate.stress_point(3, 4)));
  CHECK_FALSE(visible_on_plate(crack, node(3, 5), node(3, 6)));
  CHECK(visible_on_plate(crack, node(8, 5), node(8, 6)));
  // Damage next along the row extends the same crack.
  crack.add_damaged_stress_points({plate.stress_point(7, 5)});
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx(6.3 * spacing));
  // A second pre-crack crossing the first does not take its stress points again.
  const std::vector<int> crossing = crack.add_precrack({node(3.5, 2.2), node(3.5, 8.8)});
  CHECK(std::find(crossing.begin(), crossing.end(), plate.stress_point(3, 5)) == crossing.end());
  CHECK(crossing.size() == 6);  // rows 2, 3, 4, 6, 7, 8 of column x = 3.5
}

TEST_CASE("a pre-crack polyline cuts like a damage crack", "[crack][line_segments][visibility]") {
  const Plate plate(12, 12);
  LineSegments crack = plate.crack();
  crack.add_precrack({node(1.2, 5.3), node(4.0, 5.3), node(6.0, 6.3)});
  CHECK(crack.points().size() == 3);
  CHECK(crack.segments().size() == 2);
  CHECK(crack.crack_count() == 1);
  CHECK(crack.damaged_count() == 0);
  CHECK(crack.total_length() == Approx(2.8 * spacing + std::sqrt(5.0) * spacing));

  CHECK_FALSE(visible_on_plate(crack, node(2, 5), node(2, 6)));
  CHECK_FALSE(visible_on_plate(crack, node(5, 5), node(5, 6)));
  CHECK(visible_on_plate(crack, node(2, 5), node(3, 5)));
  CHECK(visible_on_plate(crack, node(2, 6), node(3, 6)));
  CHECK(visible_on_plate(crack, node(7, 6), node(7, 7)));  // beyond the tip
  CHECK(visible_on_plate(crack, node(1, 5), node(1, 6)));  // before the start

  // A stress point damaged at the tip links to the tip's crack point and joins its crack.
  const auto created = crack.add_damaged_stress_points({plate.stress_point(6, 6)});
  REQUIRE(created.size() == 1);
  CHECK(created[0].start_point == 2);
  CHECK(crack.crack_count() == 1);
  CHECK(created[0].crack_id == crack.segments()[0].crack_id);

  // Segments of mixed lengths: the index still finds every one in reach.
  for (const Vector3& a : plate.particles)
    for (const Vector3& b : plate.particles)
      if ((a - b).norm() < support_radius)
        CHECK(crack.visible(a, b, plate_frame) == visible_brute_force(crack, a, b, plate_frame));
}

TEST_CASE("affected points are exactly those within the support radius of the new segments",
          "[crack][line_segments]") {
  const Plate plate(16, 16);
  LineSegments crack = plate.crack();
  for (int i = 2; i <= 5; ++i) crack.add_damaged_stress_points({plate.stress_point(i, 7)});
  const auto created =
      crack.add_damaged_stress_points({plate.stress_point(6, 8), plate.stress_point(7, 8)});
  REQUIRE(created.size() == 2);

  std::vector<Vector3> eval_positions = plate.particles;
  eval_positions.insert(eval_positions.end(), plate.stress_points.begin(),
                        plate.stress_points.end());
  const auto affected = crack.affected_points(eval_positions, created);

  std::vector<std::size_t> expected;
  for (std::size_t i = 0; i < eval_positions.size(); ++i)
    for (const Segment& segment : created)
      if (crack::distance_to_segment(eval_positions[i], crack.points()[segment.start_point],
                                     crack.points()[segment.end_point]) < support_radius) {
        expected.push_back(i);
        break;
      }
  CHECK_FALSE(expected.empty());
  CHECK(affected == expected);
  CHECK(std::is_sorted(affected.begin(), affected.end()));
  CHECK(crack.affected_points(eval_positions, {}).empty());

  // Every pair whose visibility the new segments changed has its evaluation point listed.
  LineSegments before = plate.crack();
  for (int i = 2; i <= 5; ++i) before.add_damaged_stress_points({plate.stress_point(i, 7)});
  for (std::size_t i = 0; i < eval_positions.size(); ++i)
    for (const Vector3& b : plate.particles) {
      if ((eval_positions[i] - b).norm() >= support_radius) continue;
      if (crack.visible(eval_positions[i], b, plate_frame) !=
          before.visible(eval_positions[i], b, plate_frame))
        CHECK(std::binary_search(affected.begin(), affected.end(), i));
    }
}

TEST_CASE("an axial crack on a cylinder cuts circumferential pairs",
          "[crack][line_segments][visibility]") {
  const double radius = 0.1;
  const int around = 126;
  const double angle_step = 2.0 * pi / around;
  const double arc_spacing = radius * angle_step;
  const int along = 20;
  auto on_cylinder = [&](double angle_index, double axial_index) {
    const double angle = angle_index * angle_step;
    return Vector3(radius * std::cos(angle), radius * std::sin(angle), axial_index * arc_spacing);
  };
  auto frame_at = [&](double angle_index) {
    const double angle = angle_index * angle_step;
    return tangent_frame(Vector3(std::cos(angle), std::sin(angle), 0.0));
  };
  // Stress points at integer indices, particles half a step off.
  std::vector<Vector3> stress_points;
  std::vector<Vector3> normals;
  for (int k = 0; k < along; ++k)
    for (int m = 0; m < around; ++m) {
      stress_points.push_back(on_cylinder(m, k));
      normals.push_back(frame_at(m).normal);
    }
  LineSegments crack;
  crack.initialize(stress_points, normals, arc_spacing, 2.0 * arc_spacing);
  std::vector<int> axial_line;
  for (int k = 5; k <= 14; ++k) axial_line.push_back(k * around);  // angle index 0
  crack.add_damaged_stress_points(axial_line);
  CHECK(crack.crack_count() == 1);
  CHECK(crack.total_length() == Approx(9.0 * arc_spacing));

  auto visible = [&](double angle_a, double axial_a, double angle_b, double axial_b) {
    return crack.visible(on_cylinder(angle_a, axial_a), on_cylinder(angle_b, axial_b),
                         frame_at(angle_a));
  };
  CHECK_FALSE(visible(-0.5, 9.5, 0.5, 9.5));
  CHECK_FALSE(visible(0.5, 9.5, -0.5, 9.5));
  CHECK_FALSE(visible(-0.5, 6.5, 0.5, 7.5));
  CHECK(visible(0.5, 9.5, 1.5, 9.5));     // one side
  CHECK(visible(0.5, 8.5, 0.5, 9.5));     // axial pair beside the crack
  CHECK(visible(-0.5, 16.5, 0.5, 16.5));  // beyond the tip
  // On the far side of the cylinder the crack projects straight onto the pair
  // in the tangent plane there, yet is out of reach.
  const double opposite = around / 2.0;
  CHECK(visible(opposite - 0.5, 9.5, opposite - 1.5, 9.5));
  CHECK_FALSE(visible_brute_force(crack, on_cylinder(opposite - 0.5, 9.5),
                                  on_cylinder(opposite - 1.5, 9.5), frame_at(opposite - 0.5)));
}

TEST_CASE("invalid crack input is rejected with a clear message",
          "[crack][line_segments][errors]") {
  const Plate plate(8, 8);

  SECTION("use before initialize") {
    LineSegments crack;
    CHECK_THROWS_WITH(crack.add_damaged_stress_points({0}), Catch::Contains("before initialize"));
    CHECK_THROWS_WITH(crack.add_precrack({node(1, 1), node(2, 1)}),
                      Catch::Contains("before initialize"));
    CHECK_THROWS_WITH(crack.visible(node(1, 1), node(2, 1), plate_frame),
                      Catch::Contains("before initialize"));
    CHECK_THROWS_WITH(crack.affected_points(plate.particles, {}),
                      Catch::Contains("before initialize"));
    CHECK_THROWS_AS(crack.is_damaged(0), Error);
  }
  SECTION("bad reference geometry") {
    LineSegments crack;
    CHECK_THROWS_WITH(crack.initialize(plate.stress_points, {}, spacing, support_radius),
                      Catch::Contains("normals"));
    CHECK_THROWS_WITH(crack.initialize(plate.stress_points, plate.normals, 0.0, support_radius),
                      Catch::Contains("spacing"));
    CHECK_THROWS_WITH(crack.initialize(plate.stress_points, plate.normals, spacing, -1.0),
                      Catch::Contains("support_radius"));
  }
  LineSegments crack = plate.crack();
  SECTION("stress point index out of range") {
    CHECK_THROWS_WITH(crack.add_damaged_stress_points({3, 64}),
                      Catch::Contains("stress point index = 64"));
    CHECK_THROWS_WITH(crack.add_damaged_stress_points({-1}),
                      Catch::Contains("stress point index = -1"));
    CHECK(crack.damaged_count() == 0);  // nothing of a rejected batch is applied
    CHECK_THROWS_AS(crack.is_damaged(64), Error);
  }
  SECTION("pre-crack point off the shell") {
    CHECK_THROWS_WITH(
        crack.add_precrack({node(1, 1), node(2, 1), node(2, 1) + Vector3(0, 0, 0.02)}),
        Catch::Contains("pre-crack point 2"));
    CHECK_THROWS_WITH(crack.add_precrack({node(1, 1), node(20, 1)}),
                      Catch::Contains("pre-crack point 1"));
    CHECK(crack.points().empty());
  }
  SECTION("zero-length pre-crack piece") {
    CHECK_THROWS_WITH(crack.add_precrack({node(1, 1), node(2, 1), node(2, 1)}),
                      Catch::Contains("pre-crack piece 1-2"));
    CHECK_THROWS_WITH(crack.add_precrack({node(1, 1)}), Catch::Contains("at least 2"));
  }
  SECTION("segment of another crack object") {
    const Segment foreign{0, 1, 0};
    CHECK_THROWS_WITH(crack.affected_points(plate.particles, {foreign}),
                      Catch::Contains("crack segment point index"));
  }
}

TEST_CASE("the same batch always gives the same topology", "[crack][line_segments][determinism]") {
  const Plate plate(20, 20);
  std::mt19937 generator(20150032);
  std::uniform_int_distribution<int> pick(0, 20 * 20 - 1);
  std::vector<int> batch;
  for (int k = 0; k < 120; ++k) batch.push_back(pick(generator));

  LineSegments first = plate.crack();
  const auto created_first = first.add_damaged_stress_points(batch);
  std::shuffle(batch.begin(), batch.end(), generator);
  LineSegments second = plate.crack();
  const auto created_second = second.add_damaged_stress_points(batch);
  CHECK(created_first == created_second);
  CHECK(first.segments() == second.segments());
  CHECK(first.points() == second.points());
  CHECK(first.crack_of_point() == second.crack_of_point());
  CHECK(first.crack_count() > 1);

  // Every segment links points within the linking distance, and every crack is
  // a tree: segments = points − 1 per crack id (isolated points aside).
  for (const Segment& segment : first.segments())
    CHECK((first.points()[segment.start_point] - first.points()[segment.end_point]).norm() <=
          first.linking_distance());
  std::vector<int> points_per_crack(first.crack_of_point().size() + 1, 0);
  std::vector<int> segments_per_crack(points_per_crack.size(), 0);
  for (int id : first.crack_of_point()) ++points_per_crack[id];
  for (const Segment& segment : first.segments()) ++segments_per_crack[segment.crack_id];
  for (std::size_t id = 0; id < points_per_crack.size(); ++id)
    if (points_per_crack[id] > 0) CHECK(segments_per_crack[id] == points_per_crack[id] - 1);
}
