// Mesh readers (io/gmsh_reader.hpp, io/abaqus_reader.hpp) and the cell-based
// model they build (ShellModel::from_cells): the paper's plate read from each
// format is the builder's plate, sets and sections arrive as written, and
// every malformed file gives an Error naming the file, the place and the
// problem.
#include "support/mesh_files.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/io/abaqus_reader.hpp>
#include <sphshell/io/gmsh_reader.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};

// The paper's plate: 0.5 m × 0.5 m, d = 10 mm, 51 × 51 particles.
constexpr double kSide = 0.5, kThickness = 0.01;
constexpr int kNodesPerSide = 51;

ShellModel paper_plate() { return ShellModel::rectangular_plate(kSide, kSide, kNodesPerSide, kNodesPerSide, kThickness); }

const std::vector<std::string> plate_edges = {"x_min", "x_max", "y_min", "y_max"};

// The plate as Gmsh would classify it: the centre as a physical point, each
// edge a curve in its own group and in "boundary", the surface as "plate".
test_support::GmshMesh gmsh_plate(const ShellModel& plate) {
  test_support::GmshMesh mesh{plate.particle_position, plate.cells(), {}};
  mesh.entities.push_back({0, {{plate.set("centre")[0]}}, {}, {"centre"}});
  for (const std::string& edge : plate_edges) {
    test_support::GmshEntity curve{1, {}, {}, {edge, "boundary"}};
    const ParticleSet& nodes = plate.set(edge);
    for (std::size_t k = 0; k + 1 < nodes.size(); ++k) curve.node_elements.push_back({nodes[k], nodes[k + 1]});
    mesh.entities.push_back(curve);
  }
  test_support::GmshEntity surface{2, {}, {}, {"plate"}};
  for (std::size_t c = 0; c < plate.cells().size(); ++c) surface.cells.push_back(static_cast<int>(c));
  mesh.entities.push_back(surface);
  return mesh;
}

test_support::AbaqusMesh abaqus_plate(const ShellModel& plate) {
  test_support::AbaqusMesh mesh;
  mesh.nodes = plate.particle_position;
  mesh.cells = plate.cells();
  for (const char* name : {"x_min", "x_max", "y_min", "y_max", "boundary", "centre"})
    mesh.node_sets.push_back({name, plate.set(name)});
  std::vector<int> all(plate.cells().size());
  for (std::size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c);
  mesh.element_sets.push_back({"plate", all});
  mesh.sections.push_back({"PLATE", kThickness});  // case differs from the *ELSET: still the same set
  return mesh;
}

fs::path write_gmsh(const test_support::ScratchDirectory& directory, const std::string& name,
                    const test_support::GmshMesh& mesh, bool binary) {
  const fs::path path = directory / name;
  test_support::write_text(path, test_support::gmsh_text(mesh, binary));
  return path;
}

// The builder's plate, exactly: same positions, normals, areas, thicknesses
// and sets; stress-point positions differ only by the rounding of the corner
// mean against the builder's cell-centre formula.
void check_same_as_builder(const ShellModel& read, const ShellModel& plate) {
  REQUIRE(read.particle_count() == plate.particle_count());
  REQUIRE(read.stress_point_count() == plate.stress_point_count());
  CHECK(read.particle_position == plate.particle_position);
  CHECK(read.particle_normal == plate.particle_normal);
  CHECK(read.particle_area == plate.particle_area);
  CHECK(read.stress_point_normal == plate.stress_point_normal);
  CHECK(read.stress_point_area == plate.stress_point_area);
  double largest_shift = 0.0;
  for (std::size_t p = 0; p < plate.stress_point_count(); ++p)
    largest_shift = std::max(largest_shift, (read.stress_point_position[p] - plate.stress_point_position[p]).norm());
  INFO("largest stress-point shift " << largest_shift << " m");
  CHECK(largest_shift <= 4 * 2.3e-16 * kSide);
  for (std::size_t i = 0; i < plate.particle_count(); ++i) CHECK(read.particle_thickness(i) == kThickness);
  for (std::size_t p = 0; p < plate.stress_point_count(); ++p) CHECK(read.stress_point_thickness(p) == kThickness);
  CHECK(read.thickness() == kThickness);
  CHECK(read.quads() == plate.quads());
  CHECK(read.minimum_spacing() == plate.minimum_spacing());
  for (const std::string& name : plate.set_names()) {
    INFO("set " << name);
    REQUIRE(read.has_set(name));
    CHECK(read.set(name) == plate.set(name));
  }
  REQUIRE(read.has_set("plate"));
  CHECK(read.set("plate") == plate.all_particles());
}

// 50 explicit steps of the clamped plate under a suddenly applied pressure.
std::vector<Vector3> short_run(const ShellModel& model) {
  SolverOptions options;
  options.nonlinear = false;
  ElasticSolver solver(model, steel, options);
  solver.clamp(model.set("boundary"));
  solver.add_uniform_pressure(model.all_particles(), 1e5, time_function::Step{}, PressureDirection::fixed);
  for (int step = 0; step < 50; ++step) solver.step();
  std::vector<Vector3> displacements;
  for (std::size_t i = 0; i < model.particle_count(); ++i) displacements.push_back(solver.displacement(static_cast<int>(i)));
  return displacements;
}

void check_same_run(const std::vector<Vector3>& read, const std::vector<Vector3>& reference) {
  REQUIRE(read.size() == reference.size());
  double largest = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < read.size(); ++i) {
    largest = std::max(largest, reference[i].norm());
    difference = std::max(difference, (read[i] - reference[i]).norm());
  }
  INFO("largest displacement " << largest << " m, largest difference " << difference << " m");
  CHECK(largest > 0.0);
  CHECK(difference <= 1e-14 * largest);
}

// Runs `read` and returns the Error's message ("" if none was thrown).
template <class Read>
std::string error_of(Read&& read) {
  try {
    read();
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

void check_message(const std::string& message, std::initializer_list<std::string> parts) {
  INFO("message: " << message);
  REQUIRE(!message.empty());
  for (const std::string& part : parts) CHECK(message.find(part) != std::string::npos);
}

// A tiny two-quad strip, written by hand: nodes 1..6, elements 1 and 2.
//   4---5---6
//   | 1 | 2 |
//   1---2---3
// Line numbers: $Nodes on 4, coordinates of node k on 12 + k, $Elements on 20,
// element k on 22 + k.
const std::string gmsh_header = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
const std::string strip_nodes =
    "$Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n$EndNodes\n";
std::string gmsh_strip(const std::string& elements_section) { return gmsh_header + strip_nodes + elements_section; }
const std::string strip_elements = "$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 3 6 5\n$EndElements\n";

// Line numbers: *NODE on 1, *ELEMENT on 8, element k on 8 + k.
std::string abaqus_strip(const std::string& extra, const std::string& element_lines = "1, 1, 2, 5, 4\n2, 2, 3, 6, 5\n") {
  return "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 2, 0, 0\n4, 0, 1, 0\n5, 1, 1, 0\n6, 2, 1, 0\n"
         "*ELEMENT, TYPE=S4, ELSET=STRIP\n" +
         element_lines + extra;
}
const std::string strip_section = "*SHELL SECTION, ELSET=STRIP, MATERIAL=STEEL\n0.002\n";

}  // namespace

TEST_CASE("The paper plate read from Gmsh ASCII, Gmsh binary and Abaqus files is the builder's plate",
          "[io][mesh]") {
  const ShellModel plate = paper_plate();
  const std::vector<Vector3> reference = short_run(plate);

  SECTION("Gmsh 4.1 ASCII") {
    const test_support::ScratchDirectory directory("plate_ascii");
    const fs::path path = write_gmsh(directory, "plate.msh", gmsh_plate(plate), false);
    const ShellModel read = io::read_gmsh(path.string(), kThickness);
    check_same_as_builder(read, plate);
    check_same_run(short_run(read), reference);
  }
  SECTION("Gmsh 4.1 binary") {
    const test_support::ScratchDirectory directory("plate_binary");
    const fs::path path = write_gmsh(directory, "plate.msh", gmsh_plate(plate), true);
    const ShellModel read = io::read_gmsh(path.string(), kThickness);
    check_same_as_builder(read, plate);
    check_same_run(short_run(read), reference);
  }
  SECTION("Abaqus, nodes in an included file in a subfolder") {
    const test_support::ScratchDirectory directory("plate_inp");
    fs::create_directories(directory / "mesh");
    const test_support::AbaqusFiles files = test_support::abaqus_text(abaqus_plate(plate), "mesh/nodes.inp");
    test_support::write_text(directory / "plate.inp", files.deck);
    test_support::write_text(directory / "mesh" / "nodes.inp", files.nodes);
    const ShellModel read = io::read_abaqus((directory / "plate.inp").string());
    check_same_as_builder(read, plate);
    check_same_run(short_run(read), reference);
  }
}

TEST_CASE("A mixed mesh of quads and triangles keeps its cells and leaves quads() empty", "[io][mesh]") {
  // 4 × 2 cells of 0.25 m: the left half quads, the right half each split into two triangles.
  test_support::AbaqusMesh mesh;
  const int nx = 5, ny = 3;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) mesh.nodes.push_back(Vector3(0.25 * i, 0.25 * j, 0.0));
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx + 1, d = a + nx;
      if (i < 2) {
        mesh.cells.push_back(Cell(a, b, c, d));
      } else {
        mesh.cells.push_back(Cell(a, b, c));
        mesh.cells.push_back(Cell(a, c, d));
      }
    }
  mesh.sections.push_back({"ALL_QUADS", 0.004});
  mesh.sections.push_back({"ALL_TRIANGLES", 0.004});
  const test_support::ScratchDirectory directory("mixed");
  test_support::write_text(directory / "mixed.inp", test_support::abaqus_text(mesh).deck);
  const ShellModel model = io::read_abaqus((directory / "mixed.inp").string());
  REQUIRE(model.stress_point_count() == 4 + 8);
  CHECK(model.quads().empty());
  REQUIRE(model.cells().size() == 12);
  double particle_total = 0.0, stress_total = 0.0;
  for (double a : model.particle_area) particle_total += a;
  for (double a : model.stress_point_area) stress_total += a;
  CHECK(particle_total == Approx(1.0 * 0.5).epsilon(1e-14));
  CHECK(stress_total == Approx(1.0 * 0.5).epsilon(1e-14));
  for (std::size_t p = 0; p < model.stress_point_count(); ++p) {
    const bool triangle = model.cells()[p].is_triangle();
    // Stress points in label order, which follows the cell order here.
    CHECK(model.stress_point_area[p] == Approx(triangle ? 0.03125 : 0.0625).epsilon(1e-14));
    CHECK(model.stress_point_normal[p] == Vector3::UnitZ());
  }
  for (const Vector3& n : model.particle_normal) CHECK(n == Vector3::UnitZ());
  // A triangle's stress point at its centroid.
  const Cell& first_triangle = model.cells()[2];
  REQUIRE(first_triangle.is_triangle());
  const Vector3 centroid = (model.particle_position[first_triangle[0]] + model.particle_position[first_triangle[1]] +
                            model.particle_position[first_triangle[2]]) / 3.0;
  CHECK((model.stress_point_position[2] - centroid).norm() < 1e-16);
  // The corner particle (1, 0) belongs to one triangle only: a third of its area.
  const int corner = model.nearest_particle(Vector3(1.0, 0.0, 0.0));
  CHECK(model.particle_area[corner] == Approx(0.03125 / 3.0).epsilon(1e-14));
  // Spacing: a quad's area, twice a triangle's, so equal here.
  CHECK(model.minimum_spacing() == Approx(0.25).epsilon(1e-14));
  CHECK(model.maximum_spacing() == Approx(0.25).epsilon(1e-14));
}

TEST_CASE("Particle normals are the area-weighted mean of their elements' normals", "[io][mesh]") {
  // A roof of two triangles of different size meeting at the ridge x = 0:
  // left slope 45° (area √2/2), right slope tan⁻¹(1/2) (area √5/4·...).
  test_support::GmshMesh mesh;
  mesh.nodes = {Vector3(-1, 0, 0), Vector3(0, 0, 1), Vector3(0, 1, 1), Vector3(2, 0, 0)};
  mesh.cells = {Cell(0, 1, 2), Cell(1, 3, 2)};
  mesh.entities.push_back({2, {}, {0, 1}, {}});
  const test_support::ScratchDirectory directory("roof");
  const fs::path path = write_gmsh(directory, "roof.msh", mesh, false);
  const ShellModel model = io::read_gmsh(path.string(), 0.01);
  // Independent: each triangle's area and unit normal by hand.
  const Vector3 left_normal = Vector3(-1, 0, 1).normalized(), right_normal = Vector3(1, 0, 2).normalized();
  const double left_area = 0.5 * std::sqrt(2.0), right_area = 0.5 * std::sqrt(5.0);
  const Vector3 ridge = (left_area * left_normal + right_area * right_normal).normalized();
  CHECK((model.particle_normal[1] - ridge).norm() < 1e-15);
  CHECK((model.particle_normal[0] - left_normal).norm() < 1e-15);
  CHECK((model.stress_point_normal[1] - right_normal).norm() < 1e-15);
  CHECK(model.stress_point_area[1] == Approx(right_area).epsilon(1e-15));
  CHECK(model.particle_area[1] == Approx((left_area + right_area) / 3).epsilon(1e-15));
}

TEST_CASE("Abaqus sets, generated sets, includes, sections and continuation lines", "[io][mesh]") {
  const test_support::ScratchDirectory directory("inp_features");
  fs::create_directories(directory / "parts");
  // 3 × 1 quads; a second section makes the right quad thicker.
  test_support::write_text(directory / "parts" / "nodes.inp",
                           "** nodes of the strip\n*node, nset=Nall\n1, 0, 0\n2, 1., 0.\n3, 2.0, 0.0, 0.0\n"
                           "4, 3.0, 0, \n5, 0, 1\n6, 1, 1\n7, 2, 1, ,\n8, 3, 1\n");
  const std::string deck =
      "**\n** a strip of three quads\n**\n"
      "*INCLUDE, INPUT=parts/nodes.inp\n"
      "*Element, type=S4R,\n elset=Left\n1, 1, 2, 6, 5\n"
      "*ELEMENT, TYPE=S4, ELSET=Right\n2, 2, 3,\n 7, 6\n3, 3, 4, 8, 7\n"
      "*ELSET, ELSET=Thick\n3\n"
      "*Elset, Elset=Every, generate\n1, 3\n"
      "*NSET, NSET=Ends, GENERATE\n1, 5, 4\n"
      "*NSET, NSET=ENDS\n4, 8\n"          // adds to "Ends"
      "*NSET, NSET=Corner\n1\n"
      "*NSET, NSET=Both\nCorner, 8, 8\n"  // a set named inside a set; 8 twice counts once
      "*NSET, NSET=FromElements, ELSET=Thick\n"
      "*Nset, nset=Left\n1, 2, 6, 5\n"    // same name as the element set, same nodes: one set
      "*MATERIAL, NAME=STEEL\n*ELASTIC\n 210e9, 0.3\n"
      "*SHELL SECTION, ELSET=left, MATERIAL=STEEL, OFFSET=0.\n 0.01, 5\n"
      "*SHELL SECTION, ELSET=Right, MATERIAL=STEEL\n0.01\n"
      "*FREQUENCY\n10\n";
  // Elements 2 and 3 are in "Right" and element 3 in "Thick": give "Thick" no section of its own.
  test_support::write_text(directory / "strip.inp", deck);
  const ShellModel model = io::read_abaqus((directory / "strip.inp").string());
  REQUIRE(model.particle_count() == 8);
  REQUIRE(model.stress_point_count() == 3);
  CHECK(model.quads().size() == 3);
  CHECK(model.particle_position[3] == Vector3(3, 0, 0));
  CHECK(model.particle_position[6] == Vector3(2, 1, 0));
  CHECK(model.set("Ends") == ParticleSet{0, 3, 4, 7});
  CHECK(model.set("Both") == ParticleSet{0, 7});
  CHECK(model.set("FromElements") == ParticleSet{2, 3, 6, 7});
  CHECK(model.set("Thick") == ParticleSet{2, 3, 6, 7});
  CHECK(model.set("Every") == model.all_particles());
  CHECK(model.set("Nall") == model.all_particles());
  CHECK(model.set("Left") == ParticleSet{0, 1, 4, 5});
  CHECK(model.set("Right") == ParticleSet{1, 2, 3, 5, 6, 7});
  CHECK_FALSE(model.has_set("ENDS"));

  SECTION("two sections of different thickness") {
    const std::string thicker = std::string(deck).replace(deck.find("0.01\n*FREQ"), 4, "0.03");
    test_support::write_text(directory / "strip2.inp", thicker);
    const ShellModel two = io::read_abaqus((directory / "strip2.inp").string());
    CHECK(two.stress_point_thickness(0) == 0.01);
    CHECK(two.stress_point_thickness(1) == 0.03);
    CHECK(two.stress_point_thickness(2) == 0.03);
    CHECK(two.particle_thickness(0) == 0.01);
    CHECK(two.particle_thickness(2) == 0.03);
    // Nodes 2 and 6 share a 0.01 quad and a 0.03 quad of equal area: the mean.
    CHECK(two.particle_thickness(1) == Approx(0.02).epsilon(1e-15));
    CHECK(two.particle_thickness(5) == Approx(0.02).epsilon(1e-15));
  }
  SECTION("an element in no section takes the default thickness, or is an Error") {
    const std::string partial = std::string(deck).erase(deck.find("*SHELL SECTION, ELSET=Right"));
    test_support::write_text(directory / "strip3.inp", partial);
    const ShellModel defaulted = io::read_abaqus((directory / "strip3.inp").string(), 0.005);
    CHECK(defaulted.stress_point_thickness(0) == 0.01);
    CHECK(defaulted.stress_point_thickness(2) == 0.005);
    check_message(error_of([&] { io::read_abaqus((directory / "strip3.inp").string()); }),
                  {"strip3.inp", "line 9", "element 2 has no shell section"});
  }
}

TEST_CASE("Gmsh physical groups of points, curves and surfaces become node sets", "[io][mesh]") {
  const std::string text =
      gmsh_header +
      "$PhysicalNames\n4\n0 1 \"corner\"\n1 2 \"bottom edge\"\n2 3 \"left\"\n2 4 \"right\"\n$EndPhysicalNames\n"
      "$Entities\n1 1 2 0\n"
      "7 0 0 0 1 1\n"
      "3 0 0 0 2 0 0 1 2 2 7 -8\n"
      "1 0 0 0 1 1 0 1 3 0\n"
      "2 1 0 0 2 1 0 2 4 5 0\n"
      "$EndEntities\n"
      "$Comments\nany text $Elements is not a section start here\n$EndComments\n" +
      strip_nodes +
      "$Elements\n4 5 1 5\n"
      "0 7 15 1\n10 1\n"
      "1 3 1 2\n11 1 2\n12 2 3\n"
      "2 1 3 1\n1 1 2 5 4\n"
      "2 2 3 1\n2 2 3 6 5\n"
      "$EndElements\n";
  const test_support::ScratchDirectory directory("gmsh_groups");
  test_support::write_text(directory / "groups.msh", text);
  const ShellModel model = io::read_gmsh((directory / "groups.msh").string(), 0.001);
  CHECK(model.set("corner") == ParticleSet{0});
  CHECK(model.set("bottom edge") == ParticleSet{0, 1, 2});
  CHECK(model.set("left") == ParticleSet{0, 1, 3, 4});
  CHECK(model.set("right") == ParticleSet{1, 2, 4, 5});
  CHECK(model.set_names().size() == 4);
}

// Element 2 listed the other way round from element 1 (they run along the
// edge 2-5 in the same direction): it is turned to agree, and the model is
// the one of the strip written consistently.
TEST_CASE("An element listed the other way round from its neighbour is turned to agree", "[io][mesh]") {
  const test_support::ScratchDirectory directory("flip");
  test_support::write_text(directory / "flip.msh",
                           gmsh_strip("$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 5 6 3\n$EndElements\n"));
  test_support::write_text(directory / "strip.msh", gmsh_strip(strip_elements));
  const ShellModel flipped = io::read_gmsh((directory / "flip.msh").string(), 0.01);
  const ShellModel consistent = io::read_gmsh((directory / "strip.msh").string(), 0.01);
  CHECK(flipped.turned_cells == std::vector<int>{1});
  CHECK(consistent.turned_cells.empty());
  CHECK(flipped.particle_normal == consistent.particle_normal);
  CHECK(flipped.stress_point_normal == consistent.stress_point_normal);
  CHECK(flipped.quads() == consistent.quads());
  test_support::write_text(directory / "flip.inp", abaqus_strip(strip_section, "1, 1, 2, 5, 4\n2, 2, 5, 6, 3\n"));
  const ShellModel deck = io::read_abaqus((directory / "flip.inp").string());
  CHECK(deck.turned_cells == std::vector<int>{1});
  CHECK(deck.quads() == consistent.quads());
  // A third element on the edge 2-5: a junction (a stiffener).
  test_support::write_text(directory / "junction.inp",
                           abaqus_strip("*NODE\n7, 1, 0.5, 1\n*ELEMENT, TYPE=S3, ELSET=STRIP\n3, 2, 5, 7\n" +
                                        strip_section));
  check_message(error_of([&] { io::read_abaqus((directory / "junction.inp").string()); }),
                {"junction.inp", "element 1 (", "element 3 (", "between nodes 2 and 5", "junction of three or more"});
}

TEST_CASE("Malformed Gmsh files are Errors naming the file, the place and the problem", "[io][mesh][errors]") {
  const test_support::ScratchDirectory directory("gmsh_errors");
  auto read = [&](const std::string& name, const std::string& text) {
    test_support::write_text(directory / name, text);
    return error_of([&] { io::read_gmsh((directory / name).string(), 0.01); });
  };
  check_message(read("no_elements.msh", gmsh_strip("")), {"no_elements.msh", "no $Elements section"});
  check_message(read("no_nodes.msh", gmsh_header + strip_elements),
                {"no_nodes.msh", "no $Nodes section"});
  check_message(read("not_gmsh.msh", "*NODE\n1, 0, 0, 0\n"), {"not_gmsh.msh", "line 1", "expected a section header"});
  check_message(read("old.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"),
                {"old.msh", "line 2", "format version 2.2", "only 4.1"});
  check_message(read("second_order.msh", gmsh_strip("$Elements\n1 1 1 1\n2 1 9 1\n1 1 2 5 4 7 8\n$EndElements\n")),
                {"second_order.msh", "line 22", "element type 9", "6-node second-order triangle"});
  check_message(read("volume.msh", gmsh_strip("$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 5 6 1 2\n$EndElements\n")),
                {"volume.msh", "element type 5", "8-node hexahedron"});
  check_message(read("missing_node.msh", gmsh_strip("$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 3 9 5\n$EndElements\n")),
                {"missing_node.msh", "line 24", "element 2 names node 9", "does not define"});
  check_message(read("not_a_number.msh", gmsh_strip(strip_elements).replace(gmsh_strip("").find("2 0 0\n"), 1, "x")),
                {"not_a_number.msh", "line 15", "node coordinate is 'x'", "not a finite number"});
  check_message(read("short_count.msh", gmsh_strip("$Elements\n1 3 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 3 6 5\n$EndElements\n")),
                {"short_count.msh", "line 24", "announces 3 elements but its blocks hold 2"});
  check_message(read("long_block.msh", gmsh_strip("$Elements\n1 3 1 3\n2 1 3 3\n1 1 2 5 4\n2 2 3 6 5\n$EndElements\n")),
                {"long_block.msh", "line 25", "an element tag is '$EndElements', not an integer"});
  check_message(read("unterminated.msh", gmsh_strip("$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 3 6 5\n")),
                {"unterminated.msh", "expected $EndElements"});

  SECTION("binary: a truncated block, a wrong data size, big-endian data") {
    test_support::GmshMesh strip{{Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(1, 1, 0), Vector3(0, 1, 0)},
                                 {Cell(0, 1, 2, 3)},
                                 {{2, {}, {0}, {"square"}}}};
    const std::string good = test_support::gmsh_text(strip, true);
    test_support::write_text(directory / "good.msh", good);
    CHECK(io::read_gmsh((directory / "good.msh").string(), 0.01).set("square").size() == 4);
    const std::size_t elements = good.find("$Elements\n") + 10;
    // Cut inside the element block's data (after its 4 header values and a few bytes).
    check_message(read("truncated.msh", good.substr(0, elements + 4 * 8 + 4 * 3 + 8 + 12)),
                  {"truncated.msh", "binary $Elements block, byte", "truncated binary data"});
    std::string wide = good;
    wide.replace(wide.find("4.1 1 8"), 7, "4.1 1 4");
    check_message(read("size4.msh", wide), {"size4.msh", "line 2", "data size 4"});
    std::string big = good;
    const std::size_t marker = big.find("4.1 1 8\n") + 8;
    big[marker] = 0, big[marker + 3] = 1;
    check_message(read("big_endian.msh", big), {"big_endian.msh", "big-endian"});
  }
  SECTION("every truncation of a valid file is an Error, never a crash or a wrong mesh") {
    for (const bool binary : {false, true}) {
      test_support::GmshMesh strip{{Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(1, 1, 0), Vector3(0, 1, 0)},
                                   {Cell(0, 1, 2), Cell(0, 2, 3)},
                                   {{1, {{0, 1}}, {}, {"edge"}}, {2, {}, {0, 1}, {"square"}}}};
      const std::string good = test_support::gmsh_text(strip, binary);
      const std::size_t complete = good.rfind("$EndElements") + std::string("$EndElements").size();
      int errors = 0;
      for (std::size_t length = 0; length < complete; ++length) {
        INFO((binary ? "binary" : "ASCII") << " file cut after " << length << " of " << good.size() << " bytes");
        errors += !read("cut.msh", good.substr(0, length)).empty();
      }
      CHECK(errors == static_cast<int>(complete));
    }
  }
  SECTION("physical groups") {
    const std::string names = gmsh_header + "$PhysicalNames\n1\n2 5 \"ghost\"\n$EndPhysicalNames\n";
    check_message(read("names_only.msh", names + strip_nodes + strip_elements),
                  {"names_only.msh", "$PhysicalNames but no $Entities"});
    const std::string entities = "$Entities\n0 0 1 0\n1 0 0 0 2 1 0 0 0\n$EndEntities\n";
    check_message(read("empty_group.msh", names + entities + strip_nodes + strip_elements),
                  {"empty_group.msh", "line 6", "physical group 'ghost'", "holds no element"});
    // A second name for the same group would silently replace the first.
    const std::string twice = gmsh_header + "$PhysicalNames\n2\n2 5 \"ghost\"\n2 5 \"spirit\"\n$EndPhysicalNames\n";
    check_message(read("named_twice.msh", twice + entities + strip_nodes + strip_elements),
                  {"named_twice.msh", "physical group (dimension 2, tag 5) is named twice"});
    const std::string wide = gmsh_header + "$PhysicalNames\n1\n2 4294967301 \"ghost\"\n$EndPhysicalNames\n";
    check_message(read("wide_tag.msh", wide + entities + strip_nodes + strip_elements),
                  {"wide_tag.msh", "tag does not fit in an int"});
  }
  check_message(error_of([&] { io::read_gmsh((directory / "absent.msh").string(), 0.01); }),
                {"cannot open mesh file", "absent.msh"});
  check_message(error_of([&] { io::read_gmsh((directory / "good.msh").string(), -1.0); }), {"thickness", "-1"});
}

TEST_CASE("Malformed Abaqus files are Errors naming the file, the line and the problem", "[io][mesh][errors]") {
  const test_support::ScratchDirectory directory("inp_errors");
  auto read = [&](const std::string& name, const std::string& text) {
    test_support::write_text(directory / name, text);
    return error_of([&] { io::read_abaqus((directory / name).string()); });
  };
  test_support::write_text(directory / "ok.inp", abaqus_strip(strip_section));
  CHECK(io::read_abaqus((directory / "ok.inp").string()).stress_point_thickness(1) == 0.002);

  check_message(read("missing_include.inp", abaqus_strip(strip_section) + "*INCLUDE, INPUT=loads/nowhere.inp\n"),
                {"missing_include.inp", "line 13", "cannot open the included file", "nowhere.inp"});
  check_message(read("self_include.inp", "*INCLUDE, INPUT=self_include.inp\n"),
                {"self_include.inp", "line 1", "includes itself"});
  check_message(read("not_a_number.inp", abaqus_strip(strip_section).replace(abaqus_strip("").find("3, 2, 0, 0"), 10, "3, abc, 0, 0")),
                {"not_a_number.inp", "line 4", "coordinate 1 of node 3 is 'abc', not a number"});
  check_message(read("bad_thickness.inp", abaqus_strip("*SHELL SECTION, ELSET=STRIP\nthick\n")),
                {"bad_thickness.inp", "line 12", "shell thickness is 'thick', not a number"});
  check_message(read("no_thickness.inp", abaqus_strip("*SHELL SECTION, ELSET=STRIP\n*STEP\n")),
                {"no_thickness.inp", "line 11", "no data line with the thickness"});
  check_message(read("unknown_set.inp", abaqus_strip("*SHELL SECTION, ELSET=Plate, MATERIAL=STEEL\n0.01\n")),
                {"unknown_set.inp", "line 11", "names element set 'Plate'", "does not define"});
  check_message(read("second_order.inp", abaqus_strip(strip_section).replace(abaqus_strip("").find("S4"), 2, "S8R")),
                {"second_order.inp", "line 8", "TYPE=S8R", "second-order shell"});
  check_message(read("solid.inp", abaqus_strip(strip_section).replace(abaqus_strip("").find("S4"), 2, "C3D8")),
                {"solid.inp", "line 8", "TYPE=C3D8", "not a 3- or 4-node shell"});
  check_message(read("missing_node.inp", abaqus_strip(strip_section, "1, 1, 2, 5, 4\n2, 2, 3, 9, 5\n")),
                {"missing_node.inp", "line 10", "element 2 names node 9", "does not define"});
  check_message(read("short_element.inp", abaqus_strip(strip_section, "1, 1, 2, 5\n")),
                {"short_element.inp", "line 9", "element 1 of TYPE=S4 lists 3 nodes; it needs 4"});
  check_message(read("dangling.inp", abaqus_strip(strip_section, "1, 1, 2, 5, 4\n2, 2, 3,\n")),
                {"dangling.inp", "line 10", "ends with a comma but no line continues it"});
  check_message(read("degenerate.inp", abaqus_strip(strip_section, "1, 1, 2, 2, 4\n")),
                {"degenerate.inp", "line 9", "lists node 2 twice"});
  check_message(read("collinear.inp", abaqus_strip(strip_section, "1, 1, 2, 3\n").replace(abaqus_strip("").find("S4"), 2, "S3")),
                {"collinear.inp", "line 9", "element 1 has zero area"});
  check_message(read("no_section.inp", abaqus_strip("")), {"no_section.inp", "line 9", "element 1 has no shell section"});
  check_message(read("unknown_member.inp", abaqus_strip(strip_section + "*NSET, NSET=EDGE\n1, EDGES\n")),
                {"unknown_member.inp", "line 14", "'EDGES' is neither a node number nor a node set defined before"});
  check_message(read("undefined_node.inp", abaqus_strip(strip_section + "*NSET, NSET=EDGE\n1, 99\n")),
                {"undefined_node.inp", "line 14", "set EDGE names node 99, which the file does not define"});
  check_message(read("lonely_node.inp", abaqus_strip(strip_section + "*NODE, NSET=REFERENCE\n7, 5, 5, 5\n")),
                {"lonely_node.inp", "line 14", "set REFERENCE names node 7", "belongs to no shell element"});
  check_message(read("collision.inp", abaqus_strip(strip_section + "*NSET, NSET=Strip\n1, 2\n")),
                {"collision.inp", "set name", "line 8", "for different nodes"});
  check_message(read("twice.inp", abaqus_strip(strip_section + "*NODE\n3, 5, 5, 5\n")),
                {"twice.inp", "line 14", "node 3 is defined twice", "line 4"});
  check_message(read("generate.inp", abaqus_strip(strip_section + "*NSET, NSET=A, GENERATE\n5, 1\n")),
                {"generate.inp", "line 14", "the last is below the first"});
  // A range no file of this size can define is refused before it fills memory.
  check_message(read("generate_huge.inp", abaqus_strip(strip_section + "*NSET, NSET=A, GENERATE\n1, 100000000000\n")),
                {"generate_huge.inp", "line 14", "names 100000000000 nodes, more than the input's"});
  check_message(read("generate_end.inp",
                     abaqus_strip(strip_section + "*NSET, NSET=A, GENERATE\n1, 9223372036854775807, 2\n")),
                {"generate_end.inp", "line 14", "names 4611686018427387904 nodes"});
  check_message(read("ngen.inp", abaqus_strip(strip_section + "*NGEN, NSET=LINE\n1, 3\n")),
                {"ngen.inp", "line 13", "*NGEN changes the geometry"});
  check_message(read("offset.inp", abaqus_strip("*SHELL SECTION, ELSET=STRIP, OFFSET=SPOS\n0.01\n")),
                {"offset.inp", "line 11", "OFFSET=SPOS"});
  check_message(read("normals.inp", abaqus_strip(strip_section).replace(abaqus_strip("").find("1, 0, 0, 0\n"), 10, "1, 0, 0, 0, 0, 0, 1")),
                {"normals.inp", "line 2", "user normals"});
  check_message(read("part.inp", "*Part, name=PLATE\n" + abaqus_strip(strip_section)), {"part.inp", "line 1", "*PART"});
  check_message(read("empty.inp", "** nothing\n"), {"empty.inp", "no 3-node triangular or 4-node quadrilateral"});
  check_message(error_of([&] { io::read_abaqus((directory / "absent.inp").string()); }),
                {"cannot open mesh file", "absent.inp"});
}

TEST_CASE("ShellModel::from_cells, add_set and the per-point thickness refuse bad input", "[io][mesh][errors]") {
  const std::vector<Vector3> square = {Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(1, 1, 0), Vector3(0, 1, 0)};
  check_message(error_of([&] { ShellModel::from_cells(square, {Cell(0, 1, 2), Cell(0, 3, 2)}, 0.01); }),
                {"cells = 0 and 1", "between particles 2 and 0", "normals flip"});
  check_message(error_of([&] { ShellModel::from_cells(square, {Cell(0, 1, 2)}, 0.01); }),
                {"particle 3", "belongs to no cell"});
  check_message(error_of([&] { ShellModel::from_cells(square, {Cell(0, 1, 4, 3)}, 0.01); }),
                {"cell 0 corner index = 4", "[0, 4)"});
  check_message(error_of([&] { ShellModel::from_cells(square, {Cell(0, 1, 1)}, 0.01); }),
                {"cell 0 corner index = 1", "listed twice"});
  check_message(error_of([&] {
                  ShellModel::from_cells({Vector3(0, 0, 0), Vector3(1, 0, 0), Vector3(2, 0, 0)}, {Cell(0, 1, 2)}, 0.01);
                }),
                {"cell 0 area = 0", "degenerate"});
  ShellModel model = ShellModel::from_cells(square, {Cell(0, 1, 2), Cell(0, 2, 3)}, 0.01);
  CHECK(model.quads().empty());
  CHECK(model.add_set("diagonal", {0, 2}) == ParticleSet{0, 2});
  check_message(error_of([&] { model.add_set("diagonal", {1}); }), {"particle set name = diagonal", "exists"});
  check_message(error_of([&] { model.add_set("twice", {1, 3, 1}); }), {"particle set twice member = 1", "listed twice"});
  check_message(error_of([&] { model.add_set("far", {7}); }), {"particle set far member = 7", "[0, 4)"});
  check_message(error_of([&] { model.add_set("none", {}); }), {"particle set none", "needs members"});
  CHECK_FALSE(model.has_set("twice"));
  model.set_particle_thickness(2, 0.02);
  model.set_stress_point_thickness(1, 0.03);
  CHECK(model.particle_thickness(2) == 0.02);
  CHECK(model.stress_point_thickness(1) == 0.03);
  CHECK(model.minimum_thickness() == 0.01);
  check_message(error_of([&] { model.set_particle_thickness(4, 0.02); }), {"particle index = 4", "below the count (4)"});
  check_message(error_of([&] { model.set_stress_point_thickness(0, 0.0); }), {"stress point 0 thickness = 0"});
  // A quad-only model built from cells keeps quads() like from_quads.
  const ShellModel quads = ShellModel::from_cells(square, {Cell(0, 1, 2, 3)}, 0.01);
  REQUIRE(quads.quads().size() == 1);
  CHECK(quads.quads()[0] == Quad{0, 1, 2, 3});
}
