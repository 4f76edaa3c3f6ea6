// Geometric cuts (ShellModel::add_cut, shell/cuts.hpp): a strip cut across its
// width is two pieces — the free piece falls exactly as a free body, the
// clamped piece is the cantilever it would be alone and bends as the closed
// form says — with crack::None and through crack rebuilds with
// crack::LineSegments; a slit of coincident particles is legal with a cut and
// an Error without; every bad cut is an Error naming it; a checkpoint carries
// the cuts.

#include <sphshell/sphshell.hpp>

#include "support/mesh_files.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic>;
using CrackingSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic, crack::LineSegments>;

constexpr double youngs_modulus = 210e9, density = 7850.0, gravity = 9.81;

// A flat strip along x of width `width`, particles on a grid of spacing
// `width / (rows − 1)`: the clamped piece has `clamped_columns` columns from
// x = 0 to x = (clamped_columns − 1)·Δ, the free piece `free_columns` columns
// from there on, its first column a second copy of the clamped piece's last
// (the two faces of the cut; the pieces share no cell). Particle (column c,
// row r) of the clamped piece is r·clamped_columns + c, of the free piece
// clamped_count + r·free_columns + c. free_columns = 0: the clamped piece alone.
struct Strip {
  int clamped_columns, free_columns, rows;
  double spacing, thickness;

  int clamped_count() const { return clamped_columns * rows; }
  int clamped(int column, int row) const { return row * clamped_columns + column; }
  int free(int column, int row) const { return clamped_count() + row * free_columns + column; }
  double cut_x() const { return (clamped_columns - 1) * spacing; }
  double width() const { return (rows - 1) * spacing; }

  ShellModel model() const {
    std::vector<Vector3> positions;
    std::vector<Quad> quads;
    auto piece = [&](int columns, double x0) {
      const int first = static_cast<int>(positions.size());
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < columns; ++c) positions.emplace_back(x0 + c * spacing, r * spacing, 0.0);
      for (int r = 0; r + 1 < rows; ++r)
        for (int c = 0; c + 1 < columns; ++c) {
          const int a = first + r * columns + c;
          quads.push_back({a, a + 1, a + columns + 1, a + columns});
        }
    };
    piece(clamped_columns, 0.0);
    if (free_columns > 0) piece(free_columns, cut_x());
    std::vector<Vector3> normals(positions.size(), Vector3::UnitZ());
    return ShellModel::from_quads(std::move(positions), std::move(normals), quads, thickness);
  }
  // The cut between the pieces, across the whole width.
  std::vector<Vector3> cut() const { return {Vector3(cut_x(), 0.0, 0.0), Vector3(cut_x(), width(), 0.0)}; }
  ParticleSet clamped_piece() const {
    ParticleSet set(static_cast<std::size_t>(clamped_count()));
    for (int i = 0; i < clamped_count(); ++i) set[static_cast<std::size_t>(i)] = i;
    return set;
  }
  ParticleSet free_piece() const {
    ParticleSet set;
    for (int i = clamped_count(); i < clamped_count() + free_columns * rows; ++i) set.push_back(i);
    return set;
  }
  ParticleSet clamped_edge() const {
    ParticleSet set;
    for (int r = 0; r < rows; ++r) set.push_back(clamped(0, r));
    return set;
  }
  ParticleSet clamped_tip() const {
    ParticleSet set;
    for (int r = 0; r < rows; ++r) set.push_back(clamped(clamped_columns - 1, r));
    return set;
  }
};

const Strip strip{13, 7, 4, 0.025, 0.01};

// How far the free piece's displacements stray from falling freely under
// gravity for n steps (x_n = ½ g (n Δt)² with the central difference's half
// first step), relative to that fall; and its largest rotation.
template <class S>
void check_free_fall(const S& solver, const Strip& geometry) {
  const double t = static_cast<double>(solver.steps()) * solver.time_step();
  const Vector3 fall(0.0, 0.0, -0.5 * gravity * t * t);
  double stray = 0.0, rotation = 0.0;
  for (int i : geometry.free_piece()) {
    stray = std::max(stray, (solver.displacement(i) - fall).norm());
    rotation = std::max(rotation, solver.rotation(i).norm());
  }
  INFO("free piece: fall " << fall.norm() << " m, largest stray " << stray << " m, largest rotation " << rotation);
  CHECK(stray <= 1e-9 * fall.norm());
  CHECK(rotation <= 1e-9 * fall.norm() / geometry.spacing);
}

SolverOptions undamped(double time_step) {
  SolverOptions options;
  options.density = density;
  options.time_step = time_step;
  return options;
}

}  // namespace

TEST_CASE("A strip cut across its width is two pieces: a free body and the cantilever alone", "[cuts][solver]") {
  ShellModel model = strip.model();
  model.add_cut(strip.cut());
  const ShellModel alone_model = Strip{strip.clamped_columns, 0, strip.rows, strip.spacing, strip.thickness}.model();
  // One time step for both, below both stable bounds.
  const double time_step =
      0.5 * std::min(ElasticSolver(model, {youngs_modulus, 0.3}, undamped(0.0)).stable_time_step(),
                     ElasticSolver(alone_model, {youngs_modulus, 0.3}, undamped(0.0)).stable_time_step());
  ElasticSolver cut(model, {youngs_modulus, 0.3}, undamped(time_step));
  ElasticSolver alone(alone_model, {youngs_modulus, 0.3}, undamped(time_step));
  for (ElasticSolver* solver : {&cut, &alone}) {
    solver->clamp(strip.clamped_edge());
    solver->add_gravity(solver->model().all_particles(), Vector3(0.0, 0.0, -gravity));
  }
  for (int step = 0; step < 400; ++step) {
    cut.step();
    alone.step();
  }
  check_free_fall(cut, strip);
  // The clamped piece moves as the same cantilever without the free piece.
  double largest = 0.0, difference = 0.0;
  for (int i : strip.clamped_piece()) {
    largest = std::max(largest, alone.displacement(i).norm());
    difference = std::max(difference, (cut.displacement(i) - alone.displacement(i)).norm());
  }
  INFO("clamped piece: largest displacement " << largest << " m, largest difference from the lone cantilever "
                                              << difference << " m");
  CHECK(largest > 1e-7);
  CHECK(difference <= 1e-12 * largest);
}

TEST_CASE("The clamped piece of a cut strip bends as a cantilever, and the free piece stays at rest", "[cuts][solver]") {
  // ν = 0, so the strip bends as a beam: tip deflection P L³ / (3 E I) under
  // an end load P, shear deformation adding 0.6 (d/L)² of it (< 0.1 % here).
  const Strip beam{21, 6, 5, 0.025, 0.02};
  const double length = beam.cut_x(), width = beam.width();
  const double inertia = width * std::pow(beam.thickness, 3) / 12.0;
  const double bending = youngs_modulus * inertia;
  const double omega = 3.516 * std::sqrt(bending / (density * width * beam.thickness)) / (length * length);
  const double load = 1e-4 * bending / (length * length);  // linear range: w/L = 1/3 of 1e-4
  ShellModel model = beam.model();
  model.add_cut(beam.cut());
  SolverOptions options;
  options.nonlinear = false;
  options.density = density;
  options.damping = 1.5 * omega;  // every mode decays as e^(−c t / 2) (mass-proportional damping)
  options.rotary_inertia_scale = 4.0;
  ElasticSolver solver(std::move(model), {youngs_modulus, 0.0}, options);
  solver.clamp(beam.clamped_edge());
  const ParticleSet tip = beam.clamped_tip();
  solver.add_point_force(tip, Vector3(0.0, 0.0, -load / static_cast<double>(tip.size())));
  solver.run_until(5 * 2 * M_PI / omega);
  double deflection = 0.0;
  for (int i : tip) deflection += -solver.displacement(i).z() / static_cast<double>(tip.size());
  const double expected = load * std::pow(length, 3) / (3.0 * bending);
  double free_motion = 0.0;
  for (int i : beam.free_piece()) free_motion = std::max(free_motion, solver.displacement(i).norm());
  WARN("cut strip: cantilever tip deflection " << deflection << " m, closed form " << expected << " m ("
                                               << 100.0 * (deflection / expected - 1.0) << " %); free piece moved "
                                               << free_motion << " m");
  CHECK(deflection == Approx(expected).epsilon(0.03));
  CHECK(free_motion <= 1e-9 * expected);
}

TEST_CASE("A cut holds through crack rebuilds with crack::LineSegments", "[cuts][solver][crack]") {
  ShellModel model = strip.model();
  model.add_cut(strip.cut());
  CrackingSolver solver(std::move(model), {youngs_modulus, 0.3}, undamped(0.0));
  // A pre-crack along the column of stress points next to the cut, from the
  // edge y = 0 to the second stress point: it rebuilds the rows around the
  // cut (the particles on it and the stress points beside it).
  const double x = strip.cut_x() - 0.5 * strip.spacing;
  solver.add_precrack({Vector3(x, 0.0, 0.0), Vector3(x, 1.5 * strip.spacing, 0.0)});
  REQUIRE(solver.precrack_stress_point_count() == 2);
  solver.clamp(strip.clamped_edge());
  solver.add_gravity(solver.model().all_particles(), Vector3(0.0, 0.0, -gravity));
  for (int step = 0; step < 400; ++step) solver.step();
  check_free_fall(solver, strip);
}

TEST_CASE("A slit of coincident particles is legal with a cut and an Error without", "[cuts][bad_input]") {
  const ShellModel model = strip.model();
  REQUIRE(model.coincident_particles().size() == static_cast<std::size_t>(strip.rows));
  CHECK(model.coincident_particles().front() ==
        std::pair<int, int>(strip.clamped(strip.clamped_columns - 1, 0), strip.free(0, 0)));
  const std::string first_pair = "particles " + std::to_string(strip.clamped(strip.clamped_columns - 1, 0)) +
                                 " and " + std::to_string(strip.free(0, 0));
  CHECK_THROWS_WITH(ElasticSolver(model, {youngs_modulus, 0.3}),
                    Catch::Contains(first_pair) && Catch::Contains("no cut separates them") &&
                        Catch::Contains("add_cut"));
  CHECK_THROWS_WITH(CrackingSolver(model, {youngs_modulus, 0.3}), Catch::Contains(first_pair));
  // A cut over only part of the slit leaves the other pairs glued.
  ShellModel half = model;
  half.add_cut({Vector3(strip.cut_x(), 0.0, 0.0), Vector3(strip.cut_x(), strip.spacing, 0.0)});
  CHECK_THROWS_WITH(ElasticSolver(half, {youngs_modulus, 0.3}),
                    Catch::Contains("particles " + std::to_string(strip.clamped(strip.clamped_columns - 1, 2))));
  ShellModel cut = model;
  cut.add_cut(strip.cut());
  CHECK_NOTHROW(ElasticSolver(cut, {youngs_modulus, 0.3}));
}

TEST_CASE("Bad cuts are Errors naming them", "[cuts][bad_input]") {
  const double dx = strip.spacing, x = strip.cut_x();
  auto error_of = [](std::vector<Vector3> polyline) {
    ShellModel model = strip.model();
    model.add_cut(strip.cut());
    try {
      model.add_cut(std::move(polyline));
    } catch (const Error& error) {
      return std::string(error.what());
    }
    return std::string("(no error)");
  };
  CHECK_THAT(error_of({Vector3(x, 0, 0)}), Catch::Contains("cut 1 polyline size") && Catch::Contains("at least 2"));
  CHECK_THAT(error_of({Vector3(dx, 0.5 * dx, 0), Vector3(dx, 0.5 * dx, 0)}),
             Catch::Contains("length of cut 1 piece 0-1") && Catch::Contains("zero length"));
  CHECK_THAT(error_of({Vector3(0.3 * dx, 0, 0), Vector3(0.3 * dx, 1e-12, 0)}),
             Catch::Contains("length of cut 1 piece 0-1"));
  CHECK_THAT(error_of({Vector3(0.3 * dx, 0, 0), Vector3(5.0, 5.0, 0)}),
             Catch::Contains("cut 1 point 1") && Catch::Contains("outside the model"));
  CHECK_THAT(error_of({Vector3(0.3 * dx, 0, 0), Vector3(0.3 * dx, dx, 0.5 * dx)}),
             Catch::Contains("cut 1 point 1") && Catch::Contains("off the shell's surface"));
  CHECK_THAT(error_of({Vector3(0.3 * dx, 0, 0), Vector3(std::nan(""), dx, 0)}),
             Catch::Contains("cut 1 point 1") && Catch::Contains("finite"));
  // Through the stress points of the first column of cells.
  CHECK_THAT(error_of({Vector3(0.5 * dx, 0, 0), Vector3(0.5 * dx, strip.width(), 0)}),
             Catch::Contains("cut 1 distance to stress point 0") && Catch::Contains("no stress point"));
  // Along a row of particles that are not duplicated: the first is an end (allowed), the second is not.
  CHECK_THAT(error_of({Vector3(0, dx, 0), Vector3(4 * dx, dx, 0)}),
             Catch::Contains("cut 1 distance to particle " + std::to_string(strip.clamped(1, 1))) &&
                 Catch::Contains("duplicated"));
  // Across cells, between their stress points and corners.
  CHECK_THAT(error_of({Vector3(0.2 * dx, 0, 0), Vector3(1.2 * dx, strip.width(), 0)}),
             Catch::Contains("cut 1 piece 0-1") && Catch::Contains("crosses cell 0"));
  // One interior cell edge between particles that are not duplicated: both
  // are its ends (tips), so it is a legal short slit.
  ShellModel model = strip.model();
  CHECK_NOTHROW(model.add_cut({Vector3(dx, dx, 0), Vector3(2 * dx, dx, 0)}));
}

TEST_CASE("A checkpoint carries the model's cuts", "[cuts][checkpoint]") {
  const test_support::ScratchDirectory scratch("cuts_checkpoint");
  const std::string path = (scratch / "cut.ckp").string();
  // A plate with a short slit along one interior cell edge (ends at particles).
  const ShellModel plain = ShellModel::rectangular_plate(0.1, 0.1, 5, 5, 0.002);
  ShellModel slit = plain;
  slit.add_cut({Vector3(0.025, 0.05, 0), Vector3(0.05, 0.05, 0)});
  ElasticSolver writer(slit, {youngs_modulus, 0.3});
  writer.clamp(slit.set("x_min"));
  writer.add_uniform_pressure(slit.all_particles(), 1e4);
  for (int step = 0; step < 5; ++step) writer.step();
  writer.save_checkpoint(path);
  ElasticSolver without(plain, {youngs_modulus, 0.3});
  CHECK_THROWS_WITH(without.load_checkpoint(path), Catch::Contains("cuts differ"));
  ElasticSolver with(slit, {youngs_modulus, 0.3});
  CHECK_NOTHROW(with.load_checkpoint(path));
  CHECK(with.steps() == 5);
}

TEST_CASE("An annular plate slit along a radius: from_quads with duplicated particles and a cut", "[cuts][solver]") {
  // The slit annular plate's mesh: an (r, θ) grid over θ ∈ [0, 2π] whose
  // last column repeats the first at θ = 2π, joined by no cell.
  const double inner = 6.0, outer = 10.0, thickness = 0.03;
  const int radial = 5, angular = 40;
  std::vector<Vector3> positions;
  std::vector<double> angle;  // the unwrapped angle of each particle's own face
  for (int j = 0; j <= angular; ++j)
    for (int i = 0; i < radial; ++i) {
      const double theta = 2.0 * M_PI * j / angular, r = inner + (outer - inner) * i / (radial - 1);
      positions.emplace_back(r * std::cos(theta), r * std::sin(theta), 0.0);
      angle.push_back(theta);
    }
  std::vector<Quad> quads;
  for (int j = 0; j < angular; ++j)
    for (int i = 0; i + 1 < radial; ++i) {
      const int a = j * radial + i;
      quads.push_back({a, a + 1, a + radial + 1, a + radial});
    }
  const std::vector<Vector3> normals(positions.size(), Vector3::UnitZ());
  ShellModel model = ShellModel::from_quads(positions, normals, quads, thickness);
  CHECK(model.coincident_particles().size() == static_cast<std::size_t>(radial));
  const material::Elastic::Parameters steel{21e6, 0.0};
  CHECK_THROWS_WITH(ElasticSolver(model, steel), Catch::Contains("no cut separates them"));
  // Rows whose visible neighbours lie on the other side of the slit: an
  // angular distance above π on the unwrapped angle, where a strip bent into
  // the ring has none; and the rows that see a particle of a slit face.
  struct Reach {
    int across = 0, beside_the_slit = 0;
  };
  auto reach_of = [&](const ShellModel& cut_model) {
    const SolverOptions options;
    const solver::IntegrationPoints<approx::MLS<kernel::CubicSpline>> points(
        cut_model, options.physics(), options.particle_integration(), 10.5e6);
    Reach reach;
    for (solver::PointGroup group : solver::point_groups) {
      const approx::ShapeFunctions& shape = points.shape(group);
      for (std::size_t row = 0; row < shape.rows(); ++row) {
        double row_angle = 0.0;
        if (group == solver::PointGroup::particles) {
          row_angle = angle[row];
        } else {
          const Vector3& x = cut_model.stress_point_position[row];
          row_angle = std::atan2(x.y(), x.x()) + (x.y() < 0.0 ? 2.0 * M_PI : 0.0);
        }
        bool beside = false;
        for (std::size_t s = shape.row_begin[row]; s < shape.row_begin[row] + shape.row_size[row]; ++s) {
          const double neighbour_angle = angle[static_cast<std::size_t>(shape.neighbour[s])];
          if (std::abs(neighbour_angle - row_angle) > M_PI) ++reach.across;
          beside = beside || neighbour_angle == 0.0 || neighbour_angle == 2.0 * M_PI;
        }
        if (beside) ++reach.beside_the_slit;
      }
    }
    return reach;
  };
  // A cut from rim to rim: near the concave inner rim a pair's segment can
  // pass through the hole around the cut's end, as pairs see across any hole.
  ShellModel rim_to_rim = model;
  rim_to_rim.add_cut({Vector3(inner, 0.0, 0.0), Vector3(outer, 0.0, 0.0)});
  CHECK_NOTHROW(ElasticSolver(rim_to_rim, steel));
  const Reach short_cut = reach_of(rim_to_rim);
  WARN("slit annulus, cut from rim to rim: " << short_cut.across << " neighbours across the slit in "
                                              << short_cut.beside_the_slit << " rows beside it");
  CHECK(short_cut.across > 0);
  // Drawn half a spacing on into the hole (and beyond the outer rim), the cut
  // hides them: no row reaches across the slit.
  model.add_cut({Vector3(inner - 0.5, 0.0, 0.0), Vector3(outer + 0.5, 0.0, 0.0)});
  CHECK_NOTHROW(ElasticSolver(model, steel));
  const Reach reach = reach_of(model);
  CHECK(reach.beside_the_slit > 4 * radial);
  CHECK(reach.across == 0);
}
