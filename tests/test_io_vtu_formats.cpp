// The VTU writer's encodings (ascii, raw binary, zlib) and precisions, surface
// cells, and its errors, read back with the tests' own reader
// (tests/support/vtu_reader.hpp).
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>

#include "support/mesh_files.hpp"
#include "support/vtu_reader.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;
using test_support::read_vtu;
using test_support::ScratchDirectory;

namespace {

std::vector<double> random_values(std::size_t count, unsigned seed) {
  std::mt19937_64 generator(seed);
  std::uniform_real_distribution<double> uniform(-1e3, 1e3);
  std::vector<double> values(count);
  for (double& value : values) value = uniform(generator);
  return values;
}

// Two quads and a triangle over six points, a vertex cell and a line.
io::VtuGrid mixed_grid() {
  io::VtuGrid grid;
  grid.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0.5, 0}};
  const int quad_a[] = {0, 1, 4, 3};
  const int quad_b[] = {1, 2, 5, 4};
  const int triangle[] = {2, 6, 5};
  grid.cells.add_polygon(quad_a, quad_a + 4);
  grid.cells.add_polygon(quad_b, quad_b + 4);
  grid.cells.add_polygon(triangle, triangle + 3);
  grid.cells.add_vertex(6);
  grid.cells.add_line(0, 6);
  grid.point_fields = {{"u", 3, random_values(21, 1), {"ux", "uy", "uz"}}};
  grid.cell_fields = {{"stress", 2, random_values(10, 2), {"bottom", "top"}},
                      {"index", 1, {10, 11, 12, -13, 2147483647}, {}, io::FieldValues::integer}};
  grid.time = 1.0 / 3.0;
  grid.note = "a note for a person";
  return grid;
}

}  // namespace

TEST_CASE("VTU encodings and precisions read back the same grid", "[io][vtu]") {
  ScratchDirectory directory("vtu_formats");
  const io::VtuGrid grid = mixed_grid();
  std::vector<io::VtuFormat> formats = {{io::VtuEncoding::ascii, io::VtuPrecision::float64},
                                        {io::VtuEncoding::ascii, io::VtuPrecision::float32},
                                        {io::VtuEncoding::binary, io::VtuPrecision::float64},
                                        {io::VtuEncoding::binary, io::VtuPrecision::float32}};
  if (io::vtu_zlib_available) {
    formats.push_back({io::VtuEncoding::zlib, io::VtuPrecision::float64});
    formats.push_back({io::VtuEncoding::zlib, io::VtuPrecision::float32});
  }
  for (const io::VtuFormat& format : formats) {
    const bool single = format.precision == io::VtuPrecision::float32;
    INFO("encoding " << io::to_string(format.encoding) << ", " << io::to_string(format.precision));
    const std::string path = (directory / "grid.vtu").string();
    io::write_vtu(path, grid, format);
    CHECK_FALSE(fs::exists(path + ".tmp"));
    const test_support::Vtu vtu = read_vtu(path);
    CHECK(vtu.encoding == (format.encoding == io::VtuEncoding::ascii    ? "ascii"
                           : format.encoding == io::VtuEncoding::binary ? "raw"
                                                                        : "zlib"));
    CHECK(vtu.points() == 7);
    CHECK(vtu.cells() == 5);
    REQUIRE(vtu.comments.size() == 1);
    CHECK(vtu.comments[0] == " a note for a person ");
    CHECK(vtu.array("FieldData", "TimeValue").values == std::vector<double>{1.0 / 3.0});
    // VTK cell types: quad 9, triangle 5, vertex 1, line 3.
    CHECK(vtu.array("Cells", "types").values == std::vector<double>{9, 9, 5, 1, 3});
    CHECK(vtu.array("Cells", "offsets").values == std::vector<double>{4, 8, 11, 12, 14});
    CHECK(vtu.array("Cells", "connectivity").values ==
          std::vector<double>{0, 1, 4, 3, 1, 2, 5, 4, 2, 6, 5, 6, 0, 6});
    const std::string real = single ? "Float32" : "Float64";
    CHECK(vtu.array("Points", "Points").attributes.at("type") == real);
    std::vector<double> coordinates;
    for (const Vector3& p : grid.points) coordinates.insert(coordinates.end(), {p.x(), p.y(), p.z()});
    CHECK(vtu.array("Points", "Points").values == coordinates);
    for (const io::Field* field : {&grid.point_fields[0], &grid.cell_fields[0]}) {
      const test_support::VtuArray& array =
          vtu.array(field == &grid.point_fields[0] ? "PointData" : "CellData", field->name);
      CHECK(array.attributes.at("type") == real);
      CHECK(array.components() == field->components);
      CHECK(array.attributes.at("ComponentName1") == field->component_names[1]);
      REQUIRE(array.values.size() == field->values.size());
      for (std::size_t i = 0; i < field->values.size(); ++i) {
        // Float32 holds the nearest float; text holds the shortest decimal that
        // reads back to the same float or double.
        const double expected = single ? static_cast<double>(static_cast<float>(field->values[i])) : field->values[i];
        CHECK(array.values[i] == expected);
      }
    }
    const test_support::VtuArray& index = vtu.array("CellData", "index");
    CHECK(index.attributes.at("type") == "Int32");
    CHECK(index.values == grid.cell_fields[1].values);
  }
}

TEST_CASE("VTU zlib blocks follow VTK's layout and shrink smooth data", "[io][vtu]") {
  if (!io::vtu_zlib_available) {
    WARN("built without zlib: skipped");
    return;
  }
  ScratchDirectory directory("vtu_zlib");
  // 100 000 points: several 64 KiB blocks and a partial last one.
  const std::size_t count = 100000;
  std::vector<Vector3> points(count);
  std::vector<double> smooth(count);
  for (std::size_t i = 0; i < count; ++i) {
    points[i] = Vector3(0.001 * static_cast<double>(i % 1000), 0.001 * static_cast<double>(i / 1000), 0.0);
    smooth[i] = std::sin(1e-4 * static_cast<double>(i));
  }
  const std::string raw = (directory / "raw.vtu").string();
  const std::string compressed = (directory / "zlib.vtu").string();
  io::write_vtu_points(raw, points, {{"s", 1, smooth, {}}}, {io::VtuEncoding::binary, io::VtuPrecision::float64});
  io::write_vtu_points(compressed, points, {{"s", 1, smooth, {}}}, {io::VtuEncoding::zlib, io::VtuPrecision::float64});
  const test_support::Vtu a = read_vtu(raw), b = read_vtu(compressed);
  CHECK(b.array("PointData", "s").bytes == a.array("PointData", "s").bytes);
  CHECK(b.array("Points", "Points").bytes == a.array("Points", "Points").bytes);
  CHECK(b.array("Cells", "connectivity").values == a.array("Cells", "connectivity").values);
  CHECK(b.file.at("compressor") == "vtkZLibDataCompressor");
  // Vertex connectivity, offsets and types are runs of a pattern: they deflate
  // well, so the file is far below the raw one.
  CHECK(fs::file_size(compressed) < fs::file_size(raw) * 3 / 4);
}

TEST_CASE("VTU write errors: bad cells, integer fields, notes, formats", "[io][vtu]") {
  ScratchDirectory directory("vtu_errors");
  const std::string path = (directory / "bad.vtu").string();
  io::VtuGrid grid;
  grid.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  const int corners[] = {0, 1, 3};
  grid.cells.add_polygon(corners, corners + 3);
  CHECK_THROWS_WITH(io::write_vtu(path, grid), Catch::Contains("bad.vtu") && Catch::Contains("point 3 of 3"));
  const int two[] = {0, 1};
  CHECK_THROWS_WITH(grid.cells.add_polygon(two, two + 2), Catch::Contains("2 corners"));

  grid.cells = {};
  grid.cells.add_vertex(0);
  grid.cell_fields = {{"flag", 1, {0.5}, {}, io::FieldValues::integer}};
  CHECK_THROWS_WITH(io::write_vtu(path, grid), Catch::Contains("'flag'") && Catch::Contains("integer"));
  grid.cell_fields = {{"flag", 1, {3e9}, {}, io::FieldValues::integer}};
  CHECK_THROWS_WITH(io::write_vtu(path, grid), Catch::Contains("'flag'"));
  grid.cell_fields = {};
  grid.note = "two -- dashes";
  CHECK_THROWS_WITH(io::write_vtu(path, grid), Catch::Contains("--"));
  grid.note = "";
  CHECK_THROWS_WITH(io::write_vtu(path, grid, {static_cast<io::VtuEncoding>(7), io::VtuPrecision::float32}),
                    Catch::Contains("not a VtuEncoding"));
  CHECK_THROWS_WITH(io::write_vtu(path, grid, {io::VtuEncoding::binary, static_cast<io::VtuPrecision>(7)}),
                    Catch::Contains("not a VtuPrecision"));
  if (!io::vtu_zlib_available)
    CHECK_THROWS_WITH(io::write_vtu(path, grid, {io::VtuEncoding::zlib, io::VtuPrecision::float32}),
                      Catch::Contains("zlib"));
  CHECK_FALSE(fs::exists(path));
  CHECK_FALSE(fs::exists(path + ".tmp"));
}

TEST_CASE("Collections written together all list the new frame", "[io][pvd]") {
  ScratchDirectory directory("pvd_together");
  io::PvdCollection a((directory / "a.pvd").string(), false), b((directory / "b.pvd").string(), false);
  CHECK_FALSE(fs::exists(directory / "a.pvd"));  // deferred: nothing until written
  for (int frame = 0; frame < 3; ++frame) {
    a.stage(0.1 * frame, (directory / ("a_" + std::to_string(frame) + ".vtu")).string());
    b.stage(0.1 * frame, (directory / ("b_" + std::to_string(frame) + ".vtu")).string());
    io::write_together({&a, &b});
    const auto listed_a = test_support::read_pvd((directory / "a.pvd").string());
    const auto listed_b = test_support::read_pvd((directory / "b.pvd").string());
    REQUIRE(listed_a.size() == static_cast<std::size_t>(frame + 1));
    REQUIRE(listed_b.size() == listed_a.size());
    CHECK(listed_a.back().file == "a_" + std::to_string(frame) + ".vtu");
    CHECK(listed_b.back().time == listed_a.back().time);
  }
  CHECK_FALSE(fs::exists(directory / "a.pvd.tmp"));
  CHECK_FALSE(fs::exists(directory / "b.pvd.tmp"));
}
