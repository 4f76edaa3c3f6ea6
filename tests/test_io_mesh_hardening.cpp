// Mesh readers and model builders against the input that real files and
// real mistakes produce: decks as Gmsh exports them, byte order marks,
// misspelled keywords, shapes the solver cannot use, paths that are not
// files, files and models too large for memory. Each case states what it
// checks; each must end in a model or in a sphshell::Error naming the file,
// the line and the element, never in another exception type.
#include "support/mesh_files.hpp"

#include <sphshell/approx/mls.hpp>
#include <sphshell/io/abaqus_reader.hpp>
#include <sphshell/io/gmsh_reader.hpp>
#include <sphshell/kernel/cubic_spline.hpp>
#include <sphshell/material/elastic.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/gauss.hpp>

#include <catch2/catch.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;

namespace {

using ElasticSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<2>, material::Elastic>;
const material::Elastic::Parameters steel{210e9, 0.3};

// The message of the sphshell::Error `work` throws; "" when it returns. Any
// other exception type fails the test with its type and text.
template <class Work>
std::string error_of(Work&& work) {
  try {
    work();
  } catch (const Error& error) {
    return error.what();
  } catch (const std::exception& other) {
    FAIL("not a sphshell::Error but " << typeid(other).name() << ": " << other.what());
  }
  return "";
}

void check_message(const std::string& message, std::initializer_list<std::string> parts) {
  INFO("message: " << message);
  REQUIRE(!message.empty());
  for (const std::string& part : parts) CHECK(message.find(part) != std::string::npos);
}

// A two-quad strip, written by hand: nodes 1..6, elements 1 and 2.
//   4---5---6
//   | 1 | 2 |
//   1---2---3
// Line numbers: *NODE on 1, node k on 1 + k, *ELEMENT on 8, element k on 8 + k.
const std::string strip_nodes = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 2, 0, 0\n4, 0, 1, 0\n5, 1, 1, 0\n6, 2, 1, 0\n";
std::string abaqus_strip(const std::string& nodes = strip_nodes,
                         const std::string& elements = "1, 1, 2, 5, 4\n2, 2, 3, 6, 5\n") {
  return nodes + "*ELEMENT, TYPE=S4, ELSET=STRIP\n" + elements +
         "*SHELL SECTION, ELSET=STRIP, MATERIAL=STEEL\n0.002\n*STEP\n*STATIC\n*END STEP\n";
}

// The same strip as a Gmsh 4.1 ASCII file; node k's coordinates on line 12 + k,
// element k on line 22 + k.
std::string gmsh_strip(const std::string& coordinates = "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n") {
  return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n" + coordinates +
         "$EndNodes\n$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 5 4\n2 2 3 6 5\n$EndElements\n";
}

// A flat nx × ny quad plate of lx × ly as Gmsh 4.1 writes it to an Abaqus
// deck (File > Export, .inp) from a transfinite surface with physical
// groups: the corner points first, then each curve's inner nodes in the
// curve's direction (bottom, right, top, left: the last two run backwards),
// then the surface's; the curves' 2-node T3D2 elements, one *ELEMENT block
// per curve, before the faces' CPS4 elements; an *ELSET per physical group
// with ten labels a line, each followed by ", "; no section (a mesher knows
// no thickness). Physical groups: "clamped" (the left curve), "bottom" and
// "plate" (the surface).
struct GmshStyleDeck {
  std::string text;
  std::vector<Vector3> nodes;  // by label - 1
};
GmshStyleDeck gmsh_exported_deck(double lx, double ly, int nx, int ny) {
  GmshStyleDeck deck;
  std::vector<std::vector<int>> label(static_cast<std::size_t>(nx + 1), std::vector<int>(static_cast<std::size_t>(ny + 1), 0));
  auto add = [&](int i, int j) {
    deck.nodes.emplace_back(lx * i / nx, ly * j / ny, 0.0);
    label[i][j] = static_cast<int>(deck.nodes.size());
  };
  add(0, 0), add(nx, 0), add(nx, ny), add(0, ny);
  for (int i = 1; i < nx; ++i) add(i, 0);
  for (int j = 1; j < ny; ++j) add(nx, j);
  for (int i = nx - 1; i > 0; --i) add(i, ny);
  for (int j = ny - 1; j > 0; --j) add(0, j);
  for (int j = 1; j < ny; ++j)
    for (int i = 1; i < nx; ++i) add(i, j);
  std::ostringstream out;
  out.precision(17);
  out << "*Heading\n /tmp/plate.inp\n*NODE\n";
  for (std::size_t k = 0; k < deck.nodes.size(); ++k)
    out << k + 1 << ", " << deck.nodes[k].x() << ", " << deck.nodes[k].y() << ", " << deck.nodes[k].z() << "\n";
  out << "******* E L E M E N T S *************\n";
  int next = 1;
  std::vector<int> bottom, left, faces;
  auto curve = [&](int number, std::vector<std::pair<int, int>> points, std::vector<int>* group) {
    out << "*ELEMENT, type=T3D2, ELSET=Line" << number << "\n";
    for (std::size_t k = 0; k + 1 < points.size(); ++k) {
      out << next << ", " << label[points[k].first][points[k].second] << ", "
          << label[points[k + 1].first][points[k + 1].second] << "\n";
      if (group) group->push_back(next);
      ++next;
    }
  };
  std::vector<std::pair<int, int>> b, r, t, l;
  for (int i = 0; i <= nx; ++i) b.emplace_back(i, 0);
  for (int j = 0; j <= ny; ++j) r.emplace_back(nx, j);
  for (int i = nx; i >= 0; --i) t.emplace_back(i, ny);
  for (int j = ny; j >= 0; --j) l.emplace_back(0, j);
  curve(1, b, &bottom), curve(2, r, nullptr), curve(3, t, nullptr), curve(4, l, &left);
  out << "*ELEMENT, type=CPS4, ELSET=Surface1\n";
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      out << next << ", " << label[i][j] << ", " << label[i + 1][j] << ", " << label[i + 1][j + 1] << ", "
          << label[i][j + 1] << "\n";
      faces.push_back(next++);
    }
  auto elset = [&](const std::string& name, const std::vector<int>& members) {
    out << "*ELSET,ELSET=" << name << "\n";
    for (std::size_t k = 0; k < members.size(); ++k) {
      if (k && k % 10 == 0) out << "\n";
      out << members[k] << ", ";
    }
    out << "\n";
  };
  elset("clamped", left), elset("bottom", bottom), elset("plate", faces);
  deck.text = out.str();
  return deck;
}

// A cantilever under pressure, 30 steps, clamped along x = 0, on a model read
// from a deck and on the builder's plate (its particles in another order):
// the largest displacement of the read model, and the largest difference of a
// particle's displacement from its twin's on the builder's plate.
struct TwinRuns {
  double largest = 0.0;
  double difference = 0.0;
};
TwinRuns run_beside_builder(const ShellModel& read, const ParticleSet& read_clamped, const ShellModel& plate) {
  auto run = [](const ShellModel& model, const ParticleSet& clamped) {
    SolverOptions options;
    options.nonlinear = false;
    ElasticSolver solver(model, steel, options);
    solver.clamp(clamped);
    solver.add_uniform_pressure(model.all_particles(), 1e4, time_function::Step{}, PressureDirection::fixed);
    for (int step = 0; step < 30; ++step) solver.step();
    return solver;
  };
  const ElasticSolver from_deck = run(read, read_clamped);
  const ElasticSolver from_builder = run(plate, plate.set("x_min"));
  TwinRuns runs;
  for (std::size_t k = 0; k < read.particle_count(); ++k) {
    const int twin = plate.nearest_particle(read.particle_position[k]);
    const Vector3 u = from_deck.displacement(static_cast<int>(k));
    REQUIRE(u.allFinite());
    runs.largest = std::max(runs.largest, u.norm());
    runs.difference = std::max(runs.difference, (u - from_builder.displacement(twin)).norm());
  }
  return runs;
}

}  // namespace

// Gmsh exports a surface mesh to Abaqus with its curves as T3D2 elements and
// its faces as CPS4: the deck reads, with the thickness argument, to the
// builder's plate (same particles, cells and a set per group) and runs.
TEST_CASE("A surface mesh as Gmsh exports it to Abaqus reads and runs", "[io][mesh][hardening]") {
  const int nx = 12, ny = 8;
  const double lx = 0.3, ly = 0.2, d = 0.002;
  const GmshStyleDeck deck = gmsh_exported_deck(lx, ly, nx, ny);
  const test_support::ScratchDirectory directory("gmsh_export");
  test_support::write_text(directory / "plate.inp", deck.text);
  const ShellModel read = io::read_abaqus((directory / "plate.inp").string(), d);
  const ShellModel plate = ShellModel::rectangular_plate(lx, ly, nx + 1, ny + 1, d);
  REQUIRE(read.particle_count() == plate.particle_count());
  REQUIRE(read.stress_point_count() == plate.stress_point_count());
  // Particles in label order: particle k is node k + 1.
  double largest_gap = 0.0;
  for (std::size_t k = 0; k < deck.nodes.size(); ++k) {
    largest_gap = std::max(largest_gap, (read.particle_position[k] - deck.nodes[k]).norm());
    CHECK(read.particle_normal[k] == Vector3::UnitZ());
  }
  CHECK(largest_gap == 0.0);
  double area = 0.0;
  for (double a : read.stress_point_area) area += a;
  CHECK(area == Approx(lx * ly).epsilon(1e-14));
  for (std::size_t p = 0; p < read.stress_point_count(); ++p) CHECK(read.stress_point_thickness(p) == d);
  // The curves' sets hold the nodes of their line elements.
  auto on = [&](const char* name, auto&& where) {
    ParticleSet expected;
    for (std::size_t k = 0; k < read.particle_count(); ++k)
      if (where(read.particle_position[k])) expected.push_back(static_cast<int>(k));
    INFO("set " << name);
    REQUIRE(read.has_set(name));
    CHECK(read.set(name) == expected);
  };
  on("clamped", [](const Vector3& x) { return x.x() == 0.0; });
  on("bottom", [](const Vector3& x) { return x.y() == 0.0; });
  on("Line2", [&](const Vector3& x) { return x.x() == lx; });
  on("plate", [](const Vector3&) { return true; });

  // A cantilever under pressure: the read deck and the builder's plate (its
  // particles in another order) move alike.
  const TwinRuns runs = run_beside_builder(read, read.set("clamped"), plate);
  INFO("largest displacement " << runs.largest << " m, largest difference from the builder's plate "
                               << runs.difference);
  CHECK(runs.largest > 0.0);
  CHECK(runs.difference <= 1e-9 * runs.largest);
}

// The same plate as Gmsh 4.8.4 itself exported it (tests/data/gmsh_4.8_plate.geo
// says how): its coordinates carry Gmsh's round-off (0.024999999999952 for
// 0.025), so nodes are matched to the builder's plate within 1e-12 m and the
// runs agree to 1e-6 of the largest displacement.
TEST_CASE("A deck that Gmsh 4.8 exported reads and runs as the builder's plate", "[io][mesh][hardening]") {
  const int nx = 12, ny = 8;
  const double lx = 0.3, ly = 0.2, d = 0.002, position_tolerance = 1e-12;
  const ShellModel read = io::read_abaqus(std::string(SPHSHELL_TEST_DATA_DIR) + "/gmsh_4.8_plate.inp", d);
  const ShellModel plate = ShellModel::rectangular_plate(lx, ly, nx + 1, ny + 1, d);
  REQUIRE(read.particle_count() == plate.particle_count());
  REQUIRE(read.stress_point_count() == plate.stress_point_count());
  double largest_gap = 0.0;
  for (std::size_t k = 0; k < read.particle_count(); ++k) {
    const int twin = plate.nearest_particle(read.particle_position[k]);
    largest_gap = std::max(largest_gap, (read.particle_position[k] - plate.particle_position[twin]).norm());
    CHECK(read.particle_normal[k].isApprox(Vector3::UnitZ(), 1e-12));
  }
  CHECK(largest_gap <= position_tolerance);
  double area = 0.0;
  for (double a : read.stress_point_area) area += a;
  CHECK(area == Approx(lx * ly).epsilon(1e-12));
  auto count_where = [&](auto&& where) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < read.particle_count(); ++k) n += where(read.particle_position[k]) ? 1 : 0;
    return n;
  };
  REQUIRE(read.has_set("clamped"));
  REQUIRE(read.has_set("bottom"));
  REQUIRE(read.has_set("plate"));
  CHECK(read.set("clamped").size() == static_cast<std::size_t>(ny + 1));
  CHECK(read.set("bottom").size() == static_cast<std::size_t>(nx + 1));
  CHECK(read.set("plate").size() == read.particle_count());
  for (int i : read.set("clamped")) CHECK(std::abs(read.particle_position[i].x()) <= position_tolerance);
  for (int i : read.set("bottom")) CHECK(std::abs(read.particle_position[i].y()) <= position_tolerance);
  CHECK(count_where([&](const Vector3& x) { return std::abs(x.x()) <= position_tolerance; }) ==
        read.set("clamped").size());

  const TwinRuns runs = run_beside_builder(read, read.set("clamped"), plate);
  INFO("largest displacement " << runs.largest << " m, largest difference from the builder's plate "
                               << runs.difference);
  CHECK(runs.largest > 0.0);
  CHECK(runs.difference <= 1e-6 * runs.largest);
}

// A misspelled keyword used to be skipped as unknown, and with it every
// element after it: the model came back smaller without a word.
TEST_CASE("An unknown or misspelled keyword is an Error naming it and the nearest known one", "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("keywords");
  auto read = [&](const std::string& name, const std::string& text) {
    test_support::write_text(directory / name, text);
    return error_of([&] { io::read_abaqus((directory / name).string()); });
  };
  // The second element block misspelled: half the strip.
  const std::string two_blocks = strip_nodes + "*ELEMENT, TYPE=S4, ELSET=STRIP\n1, 1, 2, 5, 4\n"
                                 "*ELEMNT, TYPE=S4, ELSET=STRIP\n2, 2, 3, 6, 5\n"
                                 "*SHELL SECTION, ELSET=STRIP, MATERIAL=STEEL\n0.002\n";
  check_message(read("elemnt.inp", two_blocks), {"elemnt.inp", "line 10", "unknown keyword *ELEMNT", "*ELEMENT"});
  check_message(read("shell.inp", std::string(abaqus_strip()).replace(abaqus_strip().find("*SHELL SECTION"), 14,
                                                                        "*SHEL SECTION")),
                {"shell.inp", "line 11", "unknown keyword *SHEL SECTION", "did you mean *SHELL SECTION"});
  // A misspelled parameter of a keyword that is read: the set would be lost.
  check_message(read("elset.inp", std::string(abaqus_strip()).replace(abaqus_strip().find("ELSET=STRIP"), 5, "ELSTE")),
                {"elset.inp", "line 8", "*ELEMENT has no parameter ELSTE", "did you mean ELSET="});
  // A data line before any keyword (a file that is not a deck).
  check_message(read("no_keyword.inp", "1, 0, 0, 0\n" + abaqus_strip()), {"no_keyword.inp", "line 1", "before the first keyword"});
  // The keywords of materials, steps and output are skipped: the deck reads.
  const std::string with_history = abaqus_strip() +
                                   "*MATERIAL, NAME=STEEL\n*ELASTIC\n210e9, 0.3\n*DENSITY\n7800\n*STEP, NLGEOM\n"
                                   "*DYNAMIC, EXPLICIT\n, 1e-3\n*BOUNDARY\nSTRIP, ENCASTRE\n*NODE OUTPUT\nU\n"
                                   "*EL PRINT\nS\n*OUTPUT, FIELD\n*END STEP\n";
  CHECK(read("history.inp", with_history).empty());
}

// A UTF-8 byte order mark before the first line used to give "found
// '$MeshFormat'" (Gmsh) or "element 1 names node 1, which the file does not
// define" (Abaqus: the *NODE line was not seen as a keyword).
TEST_CASE("A UTF-8 byte order mark before the first line is skipped", "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("bom");
  test_support::write_text(directory / "bom.msh", "\xEF\xBB\xBF" + gmsh_strip());
  test_support::write_text(directory / "plain.msh", gmsh_strip());
  const ShellModel gmsh = io::read_gmsh((directory / "bom.msh").string(), 0.002);
  CHECK(gmsh.particle_position == io::read_gmsh((directory / "plain.msh").string(), 0.002).particle_position);
  test_support::write_text(directory / "bom.inp", "\xEF\xBB\xBF" + abaqus_strip());
  const ShellModel abaqus = io::read_abaqus((directory / "bom.inp").string());
  CHECK(abaqus.particle_position == gmsh.particle_position);
  CHECK(abaqus.stress_point_count() == 2);
}

// Shapes the solver cannot use used to pass the readers and be refused later
// by the solver or the model's checks with a particle index; now the reader
// names the element, the file and the line.
TEST_CASE("Degenerate shapes and absurd coordinates are refused by the reader, by element and line",
          "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("shapes");
  auto read = [&](const std::string& name, const std::string& text) {
    test_support::write_text(directory / name, text);
    return error_of([&] { io::read_abaqus((directory / name).string()); });
  };
  // Node 2 on the straight line from node 1 to node 3: a quad with a 180° corner.
  check_message(read("straight.inp", abaqus_strip(strip_nodes, "1, 1, 2, 3, 5\n")),
                {"straight.inp", "line 9", "element 1 has a straight corner at node 2"});
  // Nodes listed across the quad: its edges cross.
  const std::string skewed = std::string(strip_nodes).replace(strip_nodes.find("5, 1, 1, 0"), 10, "5, 1.5, 1, 0");
  check_message(read("bowtie.inp", abaqus_strip(skewed, "1, 1, 2, 4, 5\n")),
                {"bowtie.inp", "line 9", "element 1 has crossing edges (a bow-tie)"});
  check_message(read("collinear.inp", std::string(abaqus_strip(strip_nodes, "1, 1, 2, 3\n")).replace(
                                          abaqus_strip().find("TYPE=S4"), 7, "TYPE=S3")),
                {"collinear.inp", "line 9", "element 1 has zero area", "collinear"});
  // 1e200 overflows every area and distance.
  check_message(read("huge.inp", abaqus_strip(std::string(strip_nodes).replace(strip_nodes.find("3, 2, 0, 0"), 10,
                                                                                "3, 1e200, 0, 0"))),
                {"huge.inp", "line 4", "coordinate 1 of node 3 is 1e+200", "beyond the limit"});
  // A node line cut after its label, and one shifted by a lost field
  // (node 5 moves onto node 2).
  check_message(read("bare.inp", abaqus_strip(std::string(strip_nodes).replace(strip_nodes.find("5, 1, 1, 0"), 10, "5"))),
                {"bare.inp", "line 6", "node 5 lacks its coordinates"});
  check_message(read("shifted.inp",
                     abaqus_strip(std::string(strip_nodes).replace(strip_nodes.find("5, 1, 1, 0"), 10, "5, 1, 0"))),
                {"shifted.inp", "line 9", "element 1 has zero area: nodes 2 and 5 are at the same place"});
  // Gmsh: the same coordinate limit, by line.
  test_support::write_text(directory / "huge.msh", gmsh_strip("0 0 0\n1 0 0\n2 0 -1e200\n0 1 0\n1 1 0\n2 1 0\n"));
  check_message(error_of([&] { io::read_gmsh((directory / "huge.msh").string(), 0.01); }),
                {"huge.msh", "line 15", "coordinate 3 of node 3 is -1e+200"});
}

// An element attached to the rest at a single node, its nodes listed the
// other way round, used to keep its inverted normal (orientation was checked
// across shared edges only), or be refused with a particle index.
TEST_CASE("An element meeting the mesh at one node with the opposite orientation is named", "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("single_node");
  // The strip and a third quad touching node 6 only, listed clockwise.
  const std::string nodes = strip_nodes + "7, 2.5, 1, 0\n8, 2.5, 1.5, 0\n9, 2, 1.5, 0\n";
  test_support::write_text(directory / "touch.inp",
                           abaqus_strip(nodes, "1, 1, 2, 5, 4\n2, 2, 3, 6, 5\n3, 6, 9, 8, 7\n"));
  check_message(error_of([&] { io::read_abaqus((directory / "touch.inp").string()); }),
                {"touch.inp", "element 3", "line 14", "element 2 (", "node 6", "opposite"});
}

// File errors name the operating system's reason, and paths that are not
// regular files are refused before reading: a directory used to escape as
// std::ios_base::failure, a device to fill memory.
TEST_CASE("Paths that are not regular files and files that cannot be opened name the reason", "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("paths");
  check_message(error_of([&] { io::read_abaqus((directory / "absent.inp").string()); }),
                {"absent.inp", "No such file or directory"});
  check_message(error_of([&] { io::read_gmsh((directory / "absent.msh").string(), 0.01); }),
                {"absent.msh", "No such file or directory"});
  check_message(error_of([&] { io::read_abaqus(directory.path().string()); }), {"is a directory, not a regular file"});
  check_message(error_of([&] { io::read_gmsh(directory.path().string(), 0.01); }),
                {"is a directory, not a regular file"});
  check_message(error_of([&] { io::read_gmsh("/dev/zero", 0.01); }), {"/dev/zero", "character device"});
  check_message(error_of([&] { io::read_abaqus("/dev/zero"); }), {"/dev/zero", "character device"});
  test_support::write_text(directory / "deck.inp", abaqus_strip() + "*INCLUDE, INPUT=parts/missing.inp\n");
  check_message(error_of([&] { io::read_abaqus((directory / "deck.inp").string()); }),
                {"deck.inp", "line 16", "missing.inp", "No such file or directory"});

  SECTION("too many open files") {
    // Every descriptor but one taken: the deck opens, its include cannot.
    test_support::write_text(directory / "nodes.inp", strip_nodes);
    test_support::write_text(directory / "main.inp",
                             "*INCLUDE, INPUT=nodes.inp\n" + abaqus_strip(""));
    rlimit saved{};
    REQUIRE(getrlimit(RLIMIT_NOFILE, &saved) == 0);
    rlimit low = saved;
    low.rlim_cur = std::min<rlim_t>(saved.rlim_cur, 256);
    REQUIRE(setrlimit(RLIMIT_NOFILE, &low) == 0);
    std::vector<int> taken;
    for (int fd = dup(0); fd >= 0; fd = dup(0)) taken.push_back(fd);
    close(taken.back());
    taken.pop_back();
    const std::string message = error_of([&] { io::read_abaqus((directory / "main.inp").string()); });
    for (int fd : taken) close(fd);
    setrlimit(RLIMIT_NOFILE, &saved);
    check_message(message, {"main.inp", "line 1", "nodes.inp", "Too many open files"});
  }
}

// A file or a model too large for memory is refused before the work, with
// the size and the limit: no std::bad_alloc after seconds of reading.
TEST_CASE("Files and models too large for memory are refused with the estimate", "[io][mesh][hardening]") {
  const test_support::ScratchDirectory directory("large");
  // A 64 GiB file of zeros, sparse: no disk space taken.
  for (const char* name : {"large.inp", "large.msh"}) {
    { std::ofstream create(directory / name); }
    fs::resize_file(directory / name, std::uintmax_t(64) << 30);
  }
  check_message(error_of([&] { io::read_abaqus((directory / "large.inp").string()); }),
                {"large.inp", "68719476736 bytes", "of memory", "available"});
  check_message(error_of([&] { io::read_gmsh((directory / "large.msh").string(), 0.01); }),
                {"large.msh", "68719476736 bytes", "of memory", "available"});
  // 1.6e9 particles fit int indices but no memory.
  check_message(error_of([&] { ShellModel::rectangular_plate(1.0, 1.0, 40000, 40000, 0.001); }),
                {"1600000000 particles", "of memory", "available"});
  check_message(error_of([&] { spherical_cap_ogrid(1.0, 0.5, 46338, 0.001); }),
                {"spherical_cap_ogrid", "of memory", "available"});
}

// A Möbius strip has no consistent normal: turning elements cannot make the
// seam agree. Before, the reader refused its seam as a flip "between two
// elements" as if reversing one of them would help.
TEST_CASE("A Moebius strip is refused as one-sided, naming two elements", "[io][mesh][hardening]") {
  constexpr double pi = 3.14159265358979323846;
  const int n = 16;
  std::ostringstream deck;
  deck.precision(17);
  deck << "*NODE\n";
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * pi * i / n;
    const Vector3 centre(std::cos(angle), std::sin(angle), 0.0);
    const Vector3 across = std::cos(angle / 2) * centre + std::sin(angle / 2) * Vector3::UnitZ();
    const Vector3 a = centre + 0.2 * across, b = centre - 0.2 * across;
    deck << 2 * i + 1 << ", " << a.x() << ", " << a.y() << ", " << a.z() << "\n";
    deck << 2 * i + 2 << ", " << b.x() << ", " << b.y() << ", " << b.z() << "\n";
  }
  deck << "*ELEMENT, TYPE=S4R, ELSET=STRIP\n";
  for (int i = 0; i + 1 < n; ++i)
    deck << i + 1 << ", " << 2 * i + 1 << ", " << 2 * i + 3 << ", " << 2 * i + 4 << ", " << 2 * i + 2 << "\n";
  // After a full turn the strip's sides have swapped: a_n is b_0 and b_n is a_0.
  deck << n << ", " << 2 * n - 1 << ", " << 2 << ", " << 1 << ", " << 2 * n << "\n";
  deck << "*SHELL SECTION, ELSET=STRIP\n0.001\n";
  const test_support::ScratchDirectory directory("moebius");
  test_support::write_text(directory / "moebius.inp", deck.str());
  check_message(error_of([&] { io::read_abaqus((directory / "moebius.inp").string()); }),
                {"moebius.inp", ", line ", "element ", "one-sided", "Moebius"});
}

// from_quads: a quad whose corners run clockwise about their normals while
// its neighbours run counter-clockwise used to be refused as inverted; it is
// turned, noted in turned_cells, and the model is the consistent one.
TEST_CASE("from_quads turns a quad listed the other way round from its neighbours", "[io][mesh][hardening]") {
  const ShellModel plate = ShellModel::rectangular_plate(1.0, 1.0, 6, 6, 0.01);
  std::vector<Quad> quads = plate.quads();
  const Quad original = quads[12];
  quads[12] = {original[0], original[3], original[2], original[1]};
  const std::vector<Vector3> normals(plate.particle_count(), Vector3::UnitZ());
  const ShellModel turned = ShellModel::from_quads(plate.particle_position, normals, quads, 0.01);
  CHECK(turned.turned_cells == std::vector<int>{12});
  CHECK(turned.quads() == plate.quads());
  CHECK(turned.particle_normal == plate.particle_normal);
  CHECK(turned.particle_area == plate.particle_area);
  CHECK(plate.turned_cells.empty());
  // Every quad clockwise: nothing to agree with, still refused by quad.
  for (Quad& quad : quads) quad = {quad[0], quad[3], quad[2], quad[1]};
  quads[12] = original;
  check_message(error_of([&] { ShellModel::from_quads(plate.particle_position, normals, quads, 0.01); }),
                {"quad 0 corners", "clockwise"});
}
