// What the solver's ParaView frames hold: the shell
// as cells over the particles, removed stress points as gaps, the coordinate
// convention, through-thickness points named by position, the encodings.
// Read back with the tests' own reader (tests/support/vtu_reader.hpp) and
// compared with the Solver's accessors.
#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/vtu_format.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "support/mesh_files.hpp"
#include "support/vtu_reader.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;
using test_support::ScratchDirectory;

namespace {

using CrackSolver =
    Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::LemaitreDamage, crack::LineSegments>;
const material::LemaitreDamage::Parameters steel{210e9, 0.3, 235e6, 0.0, 0.02, 0.37, 0.24};

// Exact doubles in the files, so values compare with ==.
SolverOptions exact_frames(const std::string& directory) {
  SolverOptions options;
  options.output_directory = directory;
  options.output_interval = 1e-5;
  options.frame_encoding = io::VtuEncoding::binary;
  options.frame_precision = io::VtuPrecision::float64;
  return options;
}

// 0.2 m × 0.1 m strip (21 × 11 particles, 200 stress points), pre-cracked
// along the stress-point column x = 0.105 (10 stress points leave), pulled.
CrackSolver pulled_strip(const SolverOptions& options) {
  CrackSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005), steel, options);
  solver.add_precrack({Vector3(0.105, -0.002, 0.0), Vector3(0.105, 0.102, 0.0)});
  solver.clamp(solver.model().set("x_min"));
  solver.prescribe_velocity(solver.model().set("x_max"), [](const Vector3&, double) { return Vector3(2.0, 0.0, 0.0); });
  return solver;
}

std::string last_frame(const std::string& directory, const std::string& series) {
  const auto entries = test_support::read_pvd(directory + "/" + series + ".pvd");
  REQUIRE(!entries.empty());
  return directory + "/" + entries.back().file;
}

std::vector<double> flatten(const std::vector<Vector3>& points) {
  std::vector<double> values;
  for (const Vector3& p : points) values.insert(values.end(), {p.x(), p.y(), p.z()});
  return values;
}

bool mentions(const test_support::Vtu& vtu, const std::string& text) {
  for (const std::string& comment : vtu.comments)
    if (comment.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("Frames draw the shell as cells, and removed stress points leave gaps", "[io][output][frames]") {
  ScratchDirectory scratch("frames_cells");
  const std::string directory = (scratch / "frames").string();
  CrackSolver solver = pulled_strip(exact_frames(directory));
  solver.run_until(1e-4);
  const ShellModel& model = solver.model();
  REQUIRE(solver.precrack_stress_point_count() == 10);

  const test_support::Vtu stress = test_support::read_vtu(last_frame(directory, "stress_points"));
  CHECK(stress.array("FieldData", "TimeValue").values[0] == solver.time());
  // One quad per active stress point over its four particles, in index order.
  std::vector<double> active, connectivity;
  for (std::size_t s = 0; s < solver.stress_point_count(); ++s) {
    if (solver.is_removed(static_cast<int>(s))) continue;
    active.push_back(static_cast<double>(s));
    for (int corner : model.cells()[s]) connectivity.push_back(corner);
  }
  CHECK(active.size() == 190);
  CHECK(stress.cells() == 190);
  CHECK(stress.array("CellData", "stress_point").values == active);
  CHECK(stress.array("Cells", "connectivity").values == connectivity);
  CHECK(stress.array("Cells", "types").values == std::vector<double>(190, 9.0));  // VTK_QUAD
  CHECK(stress.points() == solver.particle_count());
  // Deformed coordinates: the current positions, and the displacement beside them.
  CHECK(stress.array("Points", "Points").values == flatten(solver.positions()));
  std::vector<Vector3> displacement;
  for (std::size_t i = 0; i < solver.particle_count(); ++i) displacement.push_back(solver.displacement(static_cast<int>(i)));
  CHECK(stress.array("PointData", "displacement").values == flatten(displacement));
  CHECK(mentions(stress, "deformed (current) positions"));
  CHECK(mentions(stress, "Warp By Vector would apply it a second time"));
  // Cell data at the active stress points, in the same order.
  const test_support::VtuArray& stress_values = stress.array("CellData", "equivalent_stress");
  REQUIRE(stress_values.components() == 3);
  for (std::size_t c = 0; c < active.size(); ++c)
    for (int k = 0; k < 3; ++k)
      CHECK(stress_values.values[3 * c + std::size_t(k)] ==
            solver.equivalent_stress(static_cast<int>(active[c]), k));
  CHECK(stress.array("CellData", "thickness").values == std::vector<double>(190, 0.005));
  CHECK(stress.find("CellData", "membrane_force") != nullptr);
  CHECK(stress.find("CellData", "damage") != nullptr);

  // The particles: the same 190 quads (every particle still has one), point data.
  const test_support::Vtu particles = test_support::read_vtu(last_frame(directory, "particles"));
  CHECK(particles.cells() == 190);
  CHECK(particles.array("Cells", "connectivity").values == connectivity);
  CHECK(particles.array("PointData", "velocity").values == flatten(solver.velocities()));
  CHECK(particles.array("PointData", "fragment").attributes.at("type") == "Int32");

  // The crack: its segments as lines.
  const test_support::Vtu cracks = test_support::read_vtu(last_frame(directory, "cracks"));
  CHECK(cracks.cells() == solver.crack().segments().size());
  CHECK(cracks.cells() >= 1);
  CHECK(cracks.array("Cells", "types").values == std::vector<double>(cracks.cells(), 3.0));  // VTK_LINE
}

TEST_CASE("A slit between particle rows shows: the cells it cuts become vertices", "[io][output][frames]") {
  // The pre-crack x = 0.1025 runs between the particle column x = 0.10 and the
  // stress-point column x = 0.105: it removes no stress point, but cuts the
  // ten cells of that column (their stress points no longer see the corners
  // at x = 0.10).
  ScratchDirectory scratch("frames_slit");
  const std::string directory = (scratch / "frames").string();
  CrackSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 21, 11, 0.005), steel, exact_frames(directory));
  solver.add_precrack({Vector3(0.1025, -0.002, 0.0), Vector3(0.1025, 0.102, 0.0)});
  REQUIRE(solver.precrack_stress_point_count() == 0);
  solver.run_until(1e-5);
  const ShellModel& model = solver.model();
  std::vector<double> cut, drawn_types, drawn_indices;
  for (std::size_t s = 0; s < solver.stress_point_count(); ++s)
    if (std::abs(model.stress_point_position[s].x() - 0.105) < 1e-9) cut.push_back(static_cast<double>(s));
    else drawn_indices.push_back(static_cast<double>(s));
  REQUIRE(cut.size() == 10);
  const test_support::Vtu stress = test_support::read_vtu(last_frame(directory, "stress_points"));
  CHECK(stress.cells() == 200);
  std::vector<double> types(190, 9.0);
  types.insert(types.end(), 10, 1.0);  // the cut ones as vertices, after the quads
  CHECK(stress.array("Cells", "types").values == types);
  std::vector<double> order = drawn_indices;
  order.insert(order.end(), cut.begin(), cut.end());
  CHECK(stress.array("CellData", "stress_point").values == order);
  // The vertices sit at the stress points, after the particles.
  CHECK(stress.points() == solver.particle_count() + 10);
  const std::vector<double> points = stress.array("Points", "Points").values;
  const std::vector<Vector3> current = solver.stress_point_positions();
  for (std::size_t j = 0; j < cut.size(); ++j)
    for (int c = 0; c < 3; ++c)
      CHECK(points[3 * (solver.particle_count() + j) + std::size_t(c)] == current[std::size_t(cut[j])][c]);
  const test_support::Vtu particles = test_support::read_vtu(last_frame(directory, "particles"));
  CHECK(particles.cells() == 190);  // every particle is still a corner of a drawn quad
}

TEST_CASE("Reference coordinates: Warp By Vector of displacement gives the deformed shell", "[io][output][frames]") {
  ScratchDirectory scratch("frames_reference");
  const std::string directory = (scratch / "frames").string();
  SolverOptions options = exact_frames(directory);
  options.frame_coordinates = FrameCoordinates::reference;
  CrackSolver solver = pulled_strip(options);
  solver.run_until(5e-5);
  for (const char* series : {"particles", "stress_points"}) {
    INFO(series);
    const test_support::Vtu vtu = test_support::read_vtu(last_frame(directory, series));
    const std::vector<double> points = vtu.array("Points", "Points").values;
    CHECK(points == flatten(solver.model().particle_position));
    const std::vector<double> displacement = vtu.array("PointData", "displacement").values;
    const std::vector<double> current = flatten(solver.positions());
    REQUIRE(displacement.size() == current.size());
    double largest = 0.0;
    for (std::size_t v = 0; v < current.size(); ++v) {
      CHECK(points[v] + displacement[v] == Approx(current[v]).margin(1e-15));
      largest = std::max(largest, std::abs(displacement[v]));
    }
    CHECK(largest > 1e-5);  // the pulled end moved 2 m/s × 50 µs = 0.1 mm
    CHECK(mentions(vtu, "the reference positions"));
  }
}

TEST_CASE("Through-thickness points are named by their height", "[io][output][frames]") {
  using thickness::Gauss;
  // ζ/d = ±√(3/5)/2 = ±0.387 for Gauss<3>; Gauss<5>'s ±0.906/2, ±0.538/2.
  CHECK(solver::thickness_point_names<Gauss<3>>() ==
        std::vector<std::string>{"bottom zeta=-0.387d", "mid zeta=0", "top zeta=+0.387d"});
  CHECK(solver::thickness_point_names<Gauss<5>>() ==
        std::vector<std::string>{"bottom zeta=-0.453d", "zeta=-0.269d", "mid zeta=0", "zeta=+0.269d",
                                 "top zeta=+0.453d"});
  CHECK(solver::thickness_point_names<Gauss<2>>() ==
        std::vector<std::string>{"bottom zeta=-0.289d", "top zeta=+0.289d"});
  CHECK(solver::thickness_point_names<thickness::Simpson<3>>() ==
        std::vector<std::string>{"bottom zeta=-0.5d", "mid zeta=0", "top zeta=+0.5d"});
  CHECK(solver::thickness_point_names<Gauss<1>>() == std::vector<std::string>{"mid zeta=0"});
  CHECK(solver::thickness_point_names<thickness::Global>() == std::vector<std::string>{"whole section"});

  ScratchDirectory scratch("frames_names");
  const std::string directory = (scratch / "frames").string();
  CrackSolver solver = pulled_strip(exact_frames(directory));
  solver.add_stress_point_probe(directory + "/sp.csv", 0);
  solver.run_until(1e-5);
  const test_support::Vtu stress = test_support::read_vtu(last_frame(directory, "stress_points"));
  const test_support::VtuArray& plastic = stress.array("CellData", "equivalent_plastic_strain");
  CHECK(plastic.attributes.at("ComponentName0") == "bottom zeta=-0.387d");
  CHECK(plastic.attributes.at("ComponentName2") == "top zeta=+0.387d");
  CHECK(mentions(stress, "bottom (zeta < 0, the side the director points away from)"));
  const std::string header = test_support::read_file(directory + "/sp.csv");
  CHECK_THAT(header, Catch::StartsWith("t [s],equivalent_stress_1 (bottom zeta=-0.387d) [Pa],equivalent_stress_2 "
                                       "(mid zeta=0) [Pa],equivalent_stress_3 (top zeta=+0.387d) [Pa],"));
}

TEST_CASE("Frame encodings: compressed single precision by default, ascii for reading", "[io][output][frames]") {
  const SolverOptions defaults;
  CHECK(defaults.frame_precision == io::VtuPrecision::float32);
  CHECK(defaults.frame_encoding == (io::vtu_zlib_available ? io::VtuEncoding::zlib : io::VtuEncoding::binary));
  CHECK(defaults.frame_coordinates == FrameCoordinates::deformed);
  ScratchDirectory scratch("frames_encodings");
  for (const io::VtuEncoding encoding : {io::VtuEncoding::ascii, io::VtuEncoding::binary, io::VtuEncoding::zlib}) {
    if (encoding == io::VtuEncoding::zlib && !io::vtu_zlib_available) continue;
    INFO(io::to_string(encoding));
    const std::string directory = (scratch / io::to_string(encoding)).string();
    SolverOptions options;
    options.output_directory = directory;
    options.output_interval = 1e-5;
    options.frame_encoding = encoding;
    CrackSolver solver = pulled_strip(options);
    solver.run_until(2e-5);
    const test_support::Vtu vtu = test_support::read_vtu(last_frame(directory, "particles"));
    CHECK(vtu.encoding == (encoding == io::VtuEncoding::ascii ? "ascii" : encoding == io::VtuEncoding::binary ? "raw" : "zlib"));
    CHECK(vtu.array("Points", "Points").attributes.at("type") == "Float32");
    const std::vector<double> points = vtu.array("Points", "Points").values;
    const std::vector<double> current = flatten(solver.positions());
    REQUIRE(points.size() == current.size());
    for (std::size_t v = 0; v < current.size(); ++v) CHECK(points[v] == static_cast<double>(static_cast<float>(current[v])));
  }
}

TEST_CASE("Frame options out of range are Errors naming them", "[io][output][errors]") {
  auto make = [](SolverOptions options) {
    options.output_directory = (fs::temp_directory_path() / "sphshell_frame_option_errors_unused").string();
    CrackSolver solver(ShellModel::rectangular_plate(0.2, 0.1, 5, 3, 0.005), steel, options);
  };
  SolverOptions bad_encoding;
  bad_encoding.frame_encoding = static_cast<io::VtuEncoding>(9);
  CHECK_THROWS_WITH(make(bad_encoding), Catch::Contains("frame_encoding"));
  SolverOptions bad_precision;
  bad_precision.frame_precision = static_cast<io::VtuPrecision>(9);
  CHECK_THROWS_WITH(make(bad_precision), Catch::Contains("frame_precision"));
  SolverOptions bad_coordinates;
  bad_coordinates.frame_coordinates = static_cast<FrameCoordinates>(9);
  CHECK_THROWS_WITH(make(bad_coordinates), Catch::Contains("frame_coordinates"));
}

TEST_CASE("A model without cells is written as point clouds, and says so", "[io][output][frames]") {
  // The general constructor: a 3 × 3 particle sheet, 2 × 2 stress points.
  const ShellModel grid = ShellModel::rectangular_plate(0.02, 0.02, 3, 3, 0.001);
  ShellModel model(grid.particle_position, grid.particle_normal, grid.particle_area, grid.stress_point_position,
                   grid.stress_point_normal, grid.stress_point_area, 0.001);
  REQUIRE(model.cells().empty());
  ScratchDirectory scratch("frames_cloud");
  const std::string directory = (scratch / "frames").string();
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<3>, material::Elastic> solver(model, {210e9, 0.3},
                                                                                          exact_frames(directory));
  solver.run_until(1e-6);
  const test_support::Vtu particles = test_support::read_vtu(last_frame(directory, "particles"));
  CHECK(particles.cells() == 9);
  CHECK(particles.array("Cells", "types").values == std::vector<double>(9, 1.0));  // VTK_VERTEX
  CHECK(mentions(particles, "the model has no cells"));
  const test_support::Vtu stress = test_support::read_vtu(last_frame(directory, "stress_points"));
  CHECK(stress.points() == 4);
  CHECK(stress.cells() == 4);
  CHECK(stress.array("Points", "Points").values == flatten(solver.stress_point_positions()));
}
