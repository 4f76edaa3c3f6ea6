// Bad geometry: each kind of inconsistent model ends in a
// sphshell::Error naming the quad, particle or option at fault and its value,
// at construction, instead of a misleading error later or a silent result.
#include "bad_input_support.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

using namespace bad_input;

TEST_CASE("A particle index past the end of the thickness arrays is an Error", "[bad_input][geometry]") {
  const ShellModel model = ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01);
  require_error([&] { model.particle_thickness(999); }, {"particle index = 999", "below the count (25)"});
  require_error([&] { model.stress_point_thickness(16); }, {"stress point index = 16"});
}

TEST_CASE("Normals in the plane of a flat sheet are named, not the support radius", "[bad_input][geometry]") {
  GeneralPlate plate;
  for (Vector3& n : plate.normals) n = Vector3::UnitX();
  for (Vector3& n : plate.stress_normals) n = Vector3::UnitX();
  require_error([&] { plate.build(); }, {"particle 0 normal", "plane of the flat sheet"});
  QuadPlate quads;
  for (Vector3& n : quads.normals) n = Vector3::UnitY();
  require_error([&] { quads.build(); }, {"particle 0 normal", "plane of quad 0"});
}

TEST_CASE("A single particle and collinear particles are refused as such", "[bad_input][geometry]") {
  require_error(
      [] {
        ShellModel({Vector3::Zero()}, {Vector3::UnitZ()}, {1e-4}, {Vector3(0.005, 0.005, 0)}, {Vector3::UnitZ()},
                   {1e-4}, 0.001);
      },
      {"particle count = 1", "at least 3 particles"});
  std::vector<Vector3> line, up;
  for (int i = 0; i < 6; ++i) line.emplace_back(0.01 * i, 0.0, 0.0), up.push_back(Vector3::UnitZ());
  require_error(
      [&] {
        ShellModel(line, up, std::vector<double>(6, 1e-4), {Vector3(0.025, 0.0, 0.0)}, {Vector3::UnitZ()}, {6e-4},
                   0.001);
      },
      {"one line"});
}

TEST_CASE("A support too small for the spacing names support_radius_factor", "[bad_input][geometry]") {
  SolverOptions options;
  options.support_radius_factor = 0.5;
  require_error([&] { ElasticSolver(ShellModel::rectangular_plate(0.1, 0.1, 6, 6, 0.01), steel, options); },
                {"support_radius_factor", "support radius"});
  // A plate 10⁴ times longer than wide (cells 0.1 m × 10 µm): √(cell area) is
  // far below the cells' length, but the local spacing takes each stress
  // point's distance to its farthest corner and each particle's long side
  // (shell/local_spacing.hpp), so every row reaches particles off its line
  // and fits linear fields: the strip is legal (with one support radius from
  // √A it was refused naming support_radius_factor).
  const ShellModel strip = ShellModel::rectangular_plate(1.0, 1e-4, 11, 11, 1e-5);
  const SolverOptions defaults;
  const solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>> points(strip, defaults.physics(),
                                                                            defaults.particle_integration(), 80e9);
  for (solver::PointGroup group : solver::point_groups)
    for (std::size_t row = 0; row < points.count(group); ++row) {
      CHECK(points.shape(group).shepard[row] == 0);
      CHECK(points.shape(group).row_size[row] >= 4);
    }
  CHECK_NOTHROW(ElasticSolver(strip, steel));
  // 1 m × 1 nm: the particles lie on one line to round-off.
  require_error([] { ShellModel::rectangular_plate(1.0, 1e-9, 11, 11, 1e-10); }, {"one line"});
}

TEST_CASE("Degenerate, bow-tie and missing quads are named by quad or particle", "[bad_input][geometry]") {
  QuadPlate degenerate;
  degenerate.positions[6] = degenerate.positions[0] + 0.5 * (degenerate.positions[1] - degenerate.positions[0]);
  degenerate.positions[5] = degenerate.positions[0] + 0.25 * (degenerate.positions[1] - degenerate.positions[0]);
  degenerate.quads[0] = {0, 1, 6, 5};  // four points on one line
  require_error([&] { degenerate.build(); }, {"quad 0 area", "degenerate quad"});

  QuadPlate bow_tie;
  bow_tie.quads[5] = {bow_tie.quads[5][0], bow_tie.quads[5][1], bow_tie.quads[5][3], bow_tie.quads[5][2]};
  require_error([&] { bow_tie.build(); }, {"quad 5 corners", "bow-tie"});

  QuadPlate lonely;
  lonely.positions.emplace_back(0.2, 0.2, 0.0);
  lonely.normals.emplace_back(0.0, 0.0, 1.0);
  require_error([&] { lonely.build(); }, {"particle 25", "belongs to no quad"});
}

TEST_CASE("A NaN coordinate of a from_quads model names its particle", "[bad_input][geometry]") {
  QuadPlate plate;
  plate.positions[4].y() = std::numeric_limits<double>::quiet_NaN();
  require_error([&] { plate.build(); }, {"particle 4 position", "must be finite"});
}

TEST_CASE("Normals alternating in orientation are refused", "[bad_input][geometry]") {
  QuadPlate quads(6, 6);
  for (std::size_t i = 0; i < quads.normals.size(); i += 2) quads.normals[i] = -Vector3::UnitZ();
  require_error([&] { quads.build(); }, {"normal", "points against quad"});
  GeneralPlate plate;
  for (std::size_t i = 1; i < plate.normals.size(); i += 2) plate.normals[i] = -Vector3::UnitZ();
  require_error([&] { plate.build(); }, {"particle 1 normal", "points against", "nearest stress point"});
}

TEST_CASE("Area sets that do not cover the surface once are refused", "[bad_input][geometry]") {
  GeneralPlate doubled_stress;
  for (double& a : doubled_stress.stress_areas) a *= 2.0;
  require_error([&] { doubled_stress.build(); }, {"sum of the particle areas", "covers the mid-surface once"});
  GeneralPlate doubled_particles;
  for (double& a : doubled_particles.areas) a *= 2.0;
  require_error([&] { doubled_particles.build(); }, {"sum of the particle areas", "covers the mid-surface once"});
  // The exact tributary areas pass, and reproduce the surface.
  const ShellModel good = GeneralPlate().build();
  double covered = 0.0;
  for (double a : good.particle_area) covered += a;
  CHECK(covered == Approx(0.01).epsilon(1e-12));
}

TEST_CASE("One stress-point area far above the others without the surface to match is refused",
          "[bad_input][geometry]") {
  // The areas no longer cover the surface once: refused by the area sums,
  // naming the largest area.
  GeneralPlate plate;
  plate.stress_areas[7] *= 1e4;
  require_error([&] { plate.build(); },
                {"sum of the particle areas", "covers the mid-surface once", "stress point 7 area = 4.000000",
                 "10000.000000 times the median"});
}

// A legal model with one stress point of 10⁴ times the others' area: a
// 120 × 120 cell plate whose central 100 × 100 cells are one stress point.
// The support radius is each point's own: that row covers the plate, every
// other row keeps its size on the uniform plate (with one global spacing,
// from the largest area, every row held all 14641 particles).
TEST_CASE("One stress point with a 1e4 times larger area widens its own row only", "[bad_input][geometry]") {
  constexpr int cells = 120, block = 100, n = cells + 1;
  const GeneralPlate uniform(n, 1.2);
  GeneralPlate graded(n, 1.2);
  const double s = 1.2 / cells;
  graded.stress_positions.clear();
  graded.stress_normals.clear();
  graded.stress_areas.clear();
  const int first = (cells - block) / 2;
  const auto in_block = [&](int k) { return k >= first && k < first + block; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i)
      if (!(in_block(i) && in_block(j))) {
        graded.stress_positions.emplace_back((i + 0.5) * s, (j + 0.5) * s, 0.0);
        graded.stress_normals.emplace_back(0.0, 0.0, 1.0);
        graded.stress_areas.push_back(s * s);
      }
  const std::size_t large = graded.stress_positions.size();
  graded.stress_positions.emplace_back(0.6, 0.6, 0.0);
  graded.stress_normals.emplace_back(0.0, 0.0, 1.0);
  graded.stress_areas.push_back(block * block * s * s);

  using Points = solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>>;
  const SolverOptions options;
  const Points before(uniform.build(), options.physics(), options.particle_integration(), 80e9);
  const Points after(graded.build(), options.physics(), options.particle_integration(), 80e9);
  const auto largest_row = [](const Points& points, solver::PointGroup group, std::size_t skip) {
    int largest = 0;
    for (std::size_t row = 0; row < points.count(group); ++row)
      if (row != skip) largest = std::max(largest, points.shape(group).row_size[row]);
    return largest;
  };
  using solver::PointGroup;
  const int uniform_stress = largest_row(before, PointGroup::stress_points, before.count(PointGroup::stress_points));
  const int uniform_particle = largest_row(before, PointGroup::particles, before.count(PointGroup::particles));
  INFO("rows on the uniform plate: at most " << uniform_stress << " (stress points), " << uniform_particle
                                             << " (particles); the large point's row "
                                             << after.shape(PointGroup::stress_points).row_size[large]);
  CHECK(uniform_stress <= 16);
  CHECK(uniform_particle <= 16);
  // Its own row: every particle within 2 × 100 spacings, here all of them.
  CHECK(after.shape(PointGroup::stress_points).row_size[large] == n * n);
  CHECK(after.support_radius(PointGroup::stress_points, large) == Approx(2.0 * block * s).epsilon(1e-12));
  CHECK(largest_row(after, PointGroup::stress_points, large) == uniform_stress);
  CHECK(largest_row(after, PointGroup::particles, after.count(PointGroup::particles)) == uniform_particle);
  // So the slots grow by that one row (about 1.0x), not by 1e3x.
  const double ratio = double(after.slot_count()) / double(before.slot_count());
  CHECK(ratio < 1.1);
  // And the solver runs on it.
  ShellModel model = graded.build();
  const ParticleSet& edge = model.define_set("edge", [](const Vector3& x) {
    return x.x() < 1e-9 || x.y() < 1e-9 || x.x() > 1.2 - 1e-9 || x.y() > 1.2 - 1e-9;
  });
  ElasticSolver solver(model, steel);
  solver.clamp(edge);
  solver.add_uniform_pressure(model.all_particles(), 1e3);
  CHECK_NOTHROW([&] {
    for (int k = 0; k < 3; ++k) solver.step();
  }());
}

TEST_CASE("Near-coincident particles are refused", "[bad_input][geometry]") {
  GeneralPlate plate;
  plate.positions[8] = plate.positions[7] + Vector3(1e-7, 0.0, 0.0);
  require_error([&] { plate.build(); }, {"particles 7 and 8", "near-coincident"});
}

TEST_CASE("Repeated corners and clockwise quads are named by quad", "[bad_input][geometry]") {
  QuadPlate repeated;
  repeated.quads[0] = {0, 0, 1, 6};
  require_error([&] { repeated.build(); }, {"quad 0 corners", "{0, 0, 1, 6}", "listed twice"});
  QuadPlate clockwise;
  for (Quad& q : clockwise.quads) std::swap(q[1], q[3]);
  require_error([&] { clockwise.build(); }, {"quad 0 corners", "clockwise"});
}

TEST_CASE("A thickness beyond the shell's extent is refused", "[bad_input][geometry]") {
  require_error([] { ShellModel::rectangular_plate(0.1, 0.1, 11, 11, 10.0); }, {"thickness = 10", "extent"});
  ShellModel model = ShellModel::rectangular_plate(0.1, 0.1, 11, 11, 0.01);
  require_error([&] { model.set_particle_thickness(3, 5.0); }, {"particle 3 thickness = 5", "extent"});
}

TEST_CASE("The builders' models pass the new checks", "[bad_input][geometry]") {
  CHECK_NOTHROW(ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01));
  CHECK_NOTHROW(ShellModel::spherical_cap(1.0, 0.5, 21, 0.01));
  CHECK_NOTHROW(ShellModel::cylindrical_panel(0.1, 0.3, 2 * M_PI, 3, 3, 0.001));
  CHECK_NOTHROW(ShellModel::cylindrical_panel(0.1, 0.3, 0.5, 4, 30, 0.001));
}

TEST_CASE("The director hourglass without the edge-tied shear or without cells is refused", "[bad_input][geometry]") {
  SolverOptions options;
  options.director_hourglass = true;
  options.transverse_shear = TransverseShear::shape_functions;
  options.particle_shear_weight = 0.01;
  require_error([&] { ElasticSolver(ShellModel::rectangular_plate(0.1, 0.1, 6, 6, 0.01), steel, options); },
                {"director_hourglass", "TransverseShear::cell_edges"});
  options.transverse_shear = TransverseShear::cell_edges;
  GeneralPlate plate;  // the general constructor: no cells
  require_error([&] { ElasticSolver(plate.build(), steel, options); }, {"director_hourglass", "cells"});
  CHECK_NOTHROW(ElasticSolver(ShellModel::rectangular_plate(0.1, 0.1, 6, 6, 0.01), steel, options));
}

TEST_CASE("A structured grid past int indices is refused before it is allocated", "[bad_input][geometry]") {
  // 50000² = 2.5e9 particles: refused at once, naming the counts (without the
  // check the builder would first try to allocate about 100 GB).
  require_error([&] { ShellModel::rectangular_plate(1.0, 1.0, 50000, 50000, 0.01); },
                {"nx × ny = 2500000000", "at most 2^31 - 1"});
  require_error([&] { ShellModel::cylindrical_panel(1.0, 1.0, 1.0, 50000, 50000, 0.01); },
                {"n_circumferential × n_axial = 2500000000"});
  require_error([&] { ShellModel::spherical_cap(1.0, 0.5, 50000, 0.01); }, {"n × n = 2500000000"});
  require_error([&] { spherical_cap_ogrid(1.0, 0.5, 50000, 0.01); }, {"m = 50000", "at most 46339"});
}

TEST_CASE("The O-grid's options and radius are checked against the rim", "[bad_input][geometry]") {
  OGridOptions bulging;
  bulging.block_fraction = 0.7;  // corners inside the rim (0.7·√2 < 1) ...
  bulging.bulge = 0.45;          // ... but the sides' midpoints at 0.7 × 1.45 > 1 outside it
  require_error([&] { spherical_cap_ogrid(1.0, 0.5, 8, 0.01, bulging); },
                {"block_fraction × (1 + bulge)", "must be below 1"});
  require_error([&] { spherical_cap_ogrid_quality(1.0, 0.5, 8, bulging); }, {"block_fraction × (1 + bulge)"});
  require_error([&] { spherical_cap_ogrid(std::numeric_limits<double>::infinity(), 0.5, 8, 0.01); },
                {"radius = inf", "must be finite and > 0"});
  bulging.bulge = 0.4;  // 0.7 × 1.4 = 0.98: inside
  CHECK(spherical_cap_ogrid(1.0, 0.5, 8, 0.01, bulging).particle_count() > 0);
}

TEST_CASE("The nearest particle of a NaN point is an Error, not particle 0", "[bad_input][geometry]") {
  const ShellModel model = ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(model.nearest_particle(Vector3(0.1, 0.1, 0.0)) == 24);
  require_error([&] { model.nearest_particle(Vector3(nan, 0.0, 0.0)); }, {"nearest_particle point", "must be finite"});
  require_error([&] { model.nearest_stress_point(Vector3(0.0, nan, 0.0)); }, {"nearest_stress_point point"});
}

TEST_CASE("A symmetry plane or hard support with a bad vector names it and changes no particle",
          "[bad_input][geometry]") {
  const ShellModel model = ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.01);
  ElasticSolver solver(model, steel);
  // The plate's normals are +z: a plane normal along them leaves no rotation axis.
  require_error([&] { solver.symmetry_plane(model.set("x_min"), Vector3::UnitZ()); },
                {"plane_normal = 0 0 1", "must not lie along the particle's normal", "at particle 0"});
  require_error([&] { solver.symmetry_plane(model.set("x_min"), Vector3::Zero()); },
                {"plane_normal = 0 0 0", "finite and non-zero"});
  require_error([&] { solver.simply_support_hard(model.set("x_min"), Vector3::UnitZ()); },
                {"edge_tangent = 0 0 1", "must not lie along the particle's normal"});
  // Nothing was fixed by the refused calls: the plate moves freely along x.
  solver.prescribe_velocity(model.set("x_min"), [](const Vector3&, double) { return Vector3(1.0, 0.0, 0.0); });
  solver.step();
  CHECK(solver.displacement(0).x() > 0.0);
}
