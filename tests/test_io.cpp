#include <sphshell/io/binary_stream.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/svg_plot.hpp>
#include <sphshell/io/vtu_writer.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;

namespace {

class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::random_device entropy;
    path_ = fs::temp_directory_path() / ("sphshell_test_io_" + std::to_string(entropy()));
    fs::create_directories(path_);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  ~TemporaryDirectory() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

std::string xml_unescape(std::string text) {
  const std::pair<const char*, const char*> entities[] = {
      {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&apos;", "'"}, {"&amp;", "&"}};
  for (const auto& [entity, character] : entities) {
    for (std::size_t at = text.find(entity); at != std::string::npos;
         at = text.find(entity, at + 1))
      text.replace(at, std::strlen(entity), character);
  }
  return text;
}

using Attributes = std::map<std::string, std::string>;

Attributes parse_attributes(const std::string& tag) {
  Attributes attributes;
  const std::regex attribute(R"re(([A-Za-z_][A-Za-z0-9_]*)="([^"]*)")re");
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), attribute);
       it != std::sregex_iterator(); ++it)
    attributes[(*it)[1]] = xml_unescape((*it)[2]);
  return attributes;
}

struct Tag {
  std::string name;
  Attributes attributes;
  std::string parent;
};

// Walks the tags of an XML text, checking that they nest properly; returns
// every element with its parent's name and the names still open at the end.
std::vector<Tag> parse_tags(const std::string& xml, std::vector<std::string>& open_elements) {
  std::vector<Tag> tags;
  const std::regex tag_pattern(R"(<([^>]*)>)");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), tag_pattern);
       it != std::sregex_iterator(); ++it) {
    const std::string body = (*it)[1];
    REQUIRE(!body.empty());
    if (body[0] == '?') continue;
    if (body[0] == '/') {
      REQUIRE(!open_elements.empty());
      REQUIRE(open_elements.back() == body.substr(1));
      open_elements.pop_back();
      continue;
    }
    const std::string name = body.substr(0, body.find_first_of(" /"));
    tags.push_back({name, parse_attributes(body), open_elements.empty() ? "" : open_elements.back()});
    if (body.back() != '/') open_elements.push_back(name);
  }
  return tags;
}

struct DecodedArray {
  std::string section;
  Attributes attributes;
  std::string bytes;
};

struct DecodedVtu {
  Attributes file_attributes;
  Attributes piece_attributes;
  std::vector<DecodedArray> arrays;

  const DecodedArray& array(const std::string& section, const std::string& name) const {
    for (const DecodedArray& candidate : arrays)
      if (candidate.section == section && candidate.attributes.at("Name") == name) return candidate;
    FAIL("no array " << name << " in " << section);
    throw std::logic_error("unreachable");
  }
};

bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

// An independent reader for the subset of the VTK XML format the writer uses:
// XML head, then "_" and UInt64-prefixed raw blocks, then the closing tags.
DecodedVtu read_vtu(const std::string& path) {
  const std::string content = read_whole_file(path);
  const std::string appended_tag = "<AppendedData encoding=\"raw\">";
  const std::size_t appended_at = content.find(appended_tag);
  REQUIRE(appended_at != std::string::npos);
  const std::size_t underscore = content.find('_', appended_at + appended_tag.size());
  REQUIRE(underscore != std::string::npos);
  const std::string head = content.substr(0, underscore);

  std::vector<std::string> open_elements;
  const std::vector<Tag> tags = parse_tags(head, open_elements);
  REQUIRE(open_elements == std::vector<std::string>{"VTKFile", "AppendedData"});

  DecodedVtu decoded;
  std::uint64_t data_end = 0;
  const std::size_t data_start = underscore + 1;
  for (const Tag& tag : tags) {
    if (tag.name == "VTKFile") decoded.file_attributes = tag.attributes;
    if (tag.name == "Piece") decoded.piece_attributes = tag.attributes;
    if (tag.name != "DataArray") continue;
    REQUIRE(tag.attributes.at("format") == "appended");
    const std::uint64_t offset = std::stoull(tag.attributes.at("offset"));
    REQUIRE(data_start + offset + 8 <= content.size());
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, content.data() + data_start + offset, 8);
    REQUIRE(data_start + offset + 8 + bytes <= content.size());
    decoded.arrays.push_back(
        {tag.parent, tag.attributes, content.substr(data_start + offset + 8, bytes)});
    data_end = std::max<std::uint64_t>(data_end, offset + 8 + bytes);
  }
  REQUIRE(decoded.file_attributes.at("type") == "UnstructuredGrid");
  REQUIRE(decoded.file_attributes.at("header_type") == "UInt64");
  REQUIRE(decoded.file_attributes.at("byte_order") ==
          (host_is_little_endian() ? "LittleEndian" : "BigEndian"));
  // The blocks fill the appended section exactly; the closing tags follow.
  std::vector<std::string> still_open = open_elements;
  parse_tags(content.substr(data_start + data_end), still_open);
  CHECK(still_open.empty());
  return decoded;
}

template <class Value>
std::vector<Value> values_of(const DecodedArray& array) {
  REQUIRE(array.bytes.size() % sizeof(Value) == 0);
  std::vector<Value> values(array.bytes.size() / sizeof(Value));
  std::memcpy(values.data(), array.bytes.data(), array.bytes.size());
  return values;
}

bool bitwise_equal(const std::vector<double>& expected, const std::string& bytes) {
  return bytes.size() == expected.size() * sizeof(double) &&
         std::memcmp(bytes.data(), expected.data(), bytes.size()) == 0;
}

std::vector<double> awkward_doubles(std::size_t count, unsigned seed) {
  std::mt19937_64 generator(seed);
  std::uniform_real_distribution<double> uniform(-1e3, 1e3);
  std::vector<double> values(count);
  for (double& value : values) value = uniform(generator);
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(),
                             -0.0,
                             std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::denorm_min(),
                             1.0 / 3.0,
                             -std::numeric_limits<double>::max()};
  for (std::size_t i = 0; i < std::size(specials) && i < count; ++i) values[i * 2 % count] = specials[i];
  return values;
}

}  // namespace

TEST_CASE("VTU point cloud: structure and bit-exact round trip", "[io][vtu]") {
  TemporaryDirectory directory;
  const std::size_t count = 7;
  const std::vector<double> coordinates = awkward_doubles(3 * count, 1);
  std::vector<Vector3> positions;
  for (std::size_t i = 0; i < count; ++i)
    positions.emplace_back(coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]);

  const std::vector<io::PointField> fields = {
      {"damage", 1, awkward_doubles(count, 2), {}},
      {"velocity [m/s]", 3, awkward_doubles(3 * count, 3), {"vx", "vy", "vz"}},
      {"stress <ip 1> & \"mid\"", 5, awkward_doubles(5 * count, 4), {"xx", "yy", "xy", "xz", "yz"}},
      {"no component names", 2, awkward_doubles(2 * count, 5), {}}};
  const std::string path = directory.file("frame.vtu");
  io::write_vtu_points(path, positions, fields);
  CHECK_FALSE(fs::exists(path + ".tmp"));

  const DecodedVtu vtu = read_vtu(path);
  CHECK(vtu.piece_attributes.at("NumberOfPoints") == "7");
  CHECK(vtu.piece_attributes.at("NumberOfCells") == "7");

  const DecodedArray& points = vtu.array("Points", "Points");
  CHECK(points.attributes.at("type") == "Float64");
  CHECK(points.attributes.at("NumberOfComponents") == "3");
  CHECK(bitwise_equal(coordinates, points.bytes));

  // Indices that fit in Int32 are written as Int32.
  std::vector<std::int32_t> identity(count), ends(count);
  for (std::size_t i = 0; i < count; ++i) {
    identity[i] = static_cast<std::int32_t>(i);
    ends[i] = static_cast<std::int32_t>(i + 1);
  }
  CHECK(vtu.array("Cells", "connectivity").attributes.at("type") == "Int32");
  CHECK(vtu.array("Cells", "offsets").attributes.at("type") == "Int32");
  CHECK(values_of<std::int32_t>(vtu.array("Cells", "connectivity")) == identity);
  CHECK(values_of<std::int32_t>(vtu.array("Cells", "offsets")) == ends);
  CHECK(values_of<std::uint8_t>(vtu.array("Cells", "types")) ==
        std::vector<std::uint8_t>(count, 1));

  for (const io::PointField& field : fields) {
    INFO("field " << field.name);
    const DecodedArray& array = vtu.array("PointData", field.name);
    CHECK(array.attributes.at("type") == "Float64");
    CHECK(array.attributes.at("NumberOfComponents") == std::to_string(field.components));
    CHECK(bitwise_equal(field.values, array.bytes));
    for (std::size_t k = 0; k < field.component_names.size(); ++k)
      CHECK(array.attributes.at("ComponentName" + std::to_string(k)) == field.component_names[k]);
    if (field.component_names.empty()) CHECK(array.attributes.count("ComponentName0") == 0);
  }
  CHECK(std::isnan(values_of<double>(vtu.array("PointData", "damage"))[0]));
}

TEST_CASE("VTU line set: segments as VTK_LINE cells with point and cell data", "[io][vtu]") {
  TemporaryDirectory directory;
  const std::vector<Vector3> points = {{0, 0, 0}, {0.01, 0, 0}, {0.02, 0.005, 0}, {0.03, 0.005, 0}};
  const std::vector<std::array<int, 2>> segments = {{0, 1}, {1, 2}, {2, 3}};
  const std::vector<io::PointField> point_fields = {{"damage", 1, {0.24, 0.24, 0.3, 0.24}, {}}};
  const std::vector<io::CellField> cell_fields = {
      {"formed at step", 1, {10, 12, 15}, {}},
      {"direction", 3, {1, 0, 0, 0.894, 0.447, 0, 1, 0, 0}, {"x", "y", "z"}}};
  const std::string path = directory.file("crack.vtu");
  io::write_vtu_lines(path, points, segments, point_fields, cell_fields);

  const DecodedVtu vtu = read_vtu(path);
  CHECK(vtu.piece_attributes.at("NumberOfPoints") == "4");
  CHECK(vtu.piece_attributes.at("NumberOfCells") == "3");
  CHECK(values_of<std::int32_t>(vtu.array("Cells", "connectivity")) ==
        std::vector<std::int32_t>{0, 1, 1, 2, 2, 3});
  CHECK(values_of<std::int32_t>(vtu.array("Cells", "offsets")) ==
        std::vector<std::int32_t>{2, 4, 6});
  CHECK(values_of<std::uint8_t>(vtu.array("Cells", "types")) == std::vector<std::uint8_t>{3, 3, 3});
  CHECK(bitwise_equal(point_fields[0].values, vtu.array("PointData", "damage").bytes));
  CHECK(bitwise_equal(cell_fields[0].values, vtu.array("CellData", "formed at step").bytes));
  CHECK(bitwise_equal(cell_fields[1].values, vtu.array("CellData", "direction").bytes));
  CHECK(vtu.array("CellData", "direction").attributes.at("ComponentName1") == "y");

  SECTION("without fields") {
    io::write_vtu_lines(path, points, segments);
    const DecodedVtu bare = read_vtu(path);
    CHECK(bare.piece_attributes.at("NumberOfCells") == "3");
    CHECK(bare.arrays.size() == 4);
  }
}

TEST_CASE("VTU with no points is still a valid file", "[io][vtu]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("empty.vtu");
  io::write_vtu_points(path, {}, {{"damage", 1, {}, {}}});
  const DecodedVtu vtu = read_vtu(path);
  CHECK(vtu.piece_attributes.at("NumberOfPoints") == "0");
  CHECK(vtu.array("PointData", "damage").bytes.empty());
  CHECK(vtu.array("Points", "Points").bytes.empty());
}

TEST_CASE("VTU errors name the file and the field, and leave existing output alone",
          "[io][vtu]") {
  TemporaryDirectory directory;
  const std::vector<Vector3> positions = {{0, 0, 0}, {1, 0, 0}};
  const std::string path = directory.file("frame.vtu");
  io::write_vtu_points(path, positions, {{"damage", 1, {0.1, 0.2}, {}}});
  const std::string good = read_whole_file(path);

  CHECK_THROWS_WITH(io::write_vtu_points(path, positions, {{"velocity", 3, {1, 2, 3}, {}}}),
                    Catch::Contains("frame.vtu") && Catch::Contains("velocity") &&
                        Catch::Contains("expected 2 x 3 = 6"));
  CHECK_THROWS_WITH(io::write_vtu_points(path, positions, {{"u", 2, {1, 2, 3, 4}, {"x"}}}),
                    Catch::Contains("'u'") && Catch::Contains("component names"));
  CHECK_THROWS_WITH(io::write_vtu_points(path, positions, {{"u", 0, {}, {}}}),
                    Catch::Contains("'u'") && Catch::Contains("components"));
  CHECK_THROWS_WITH(
      io::write_vtu_points(path, positions, {{"d", 1, {0, 0}, {}}, {"d", 1, {0, 0}, {}}}),
      Catch::Contains("duplicate") && Catch::Contains("'d'"));
  CHECK_THROWS_WITH(io::write_vtu_points(path, positions, {{"", 1, {0, 0}, {}}}),
                    Catch::Contains("empty name"));
  CHECK_THROWS_WITH(io::write_vtu_lines(path, positions, {{0, 2}}),
                    Catch::Contains("segment 0") && Catch::Contains("point 2"));
  CHECK_THROWS_WITH(io::write_vtu_lines(path, positions, {{0, 1}}, {}, {{"id", 1, {}, {}}}),
                    Catch::Contains("cell field 'id'"));
  CHECK(read_whole_file(path) == good);

  const std::string unwritable = directory.file("no/such/dir/frame.vtu");
  CHECK_THROWS_WITH(io::write_vtu_points(unwritable, positions, {}),
                    Catch::Contains(unwritable));
}

namespace {

struct PvdEntry {
  double time;
  std::string part;
  std::string file;
};

std::vector<PvdEntry> read_pvd(const std::string& path) {
  std::vector<std::string> open_elements;
  const std::vector<Tag> tags = parse_tags(read_whole_file(path), open_elements);
  REQUIRE(open_elements.empty());
  REQUIRE(!tags.empty());
  REQUIRE(tags[0].name == "VTKFile");
  REQUIRE(tags[0].attributes.at("type") == "Collection");
  std::vector<PvdEntry> entries;
  for (const Tag& tag : tags) {
    if (tag.name != "DataSet") continue;
    REQUIRE(tag.parent == "Collection");
    entries.push_back({std::strtod(tag.attributes.at("timestep").c_str(), nullptr),
                       tag.attributes.at("part"), tag.attributes.at("file")});
  }
  return entries;
}

}  // namespace

TEST_CASE("PVD collection lists the frames with exact times and relative paths", "[io][pvd]") {
  TemporaryDirectory directory;
  fs::create_directories(directory.path() / "frames");
  const std::string pvd = directory.file("run.pvd");
  io::PvdCollection collection(pvd);
  CHECK(read_pvd(pvd).empty());

  const std::vector<double> times = {0.0, 1.5e-4, 1.0 / 3.0};
  for (std::size_t i = 0; i < times.size(); ++i) {
    const std::string frame = directory.file("frames/particles_" + std::to_string(i) + ".vtu");
    io::write_vtu_points(frame, {{0, 0, 0}}, {});
    collection.add(times[i], frame);
    // Valid after every add: a crash between frames keeps the ones written.
    const std::vector<PvdEntry> entries = read_pvd(pvd);
    REQUIRE(entries.size() == i + 1);
    CHECK(entries[i].time == times[i]);
    CHECK(entries[i].part == "0");
    CHECK(entries[i].file == "frames/particles_" + std::to_string(i) + ".vtu");
    CHECK(fs::exists(directory.path() / entries[i].file));
  }
  collection.add(times[2], directory.file("frames/crack_2.vtu"), 1);
  const std::vector<PvdEntry> entries = read_pvd(pvd);
  REQUIRE(entries.size() == 4);
  CHECK(entries[3].part == "1");
  CHECK(entries[3].time == 1.0 / 3.0);
  CHECK(collection.entries().size() == 4);
  CHECK_FALSE(fs::exists(pvd + ".tmp"));
}

TEST_CASE("PVD collection errors", "[io][pvd]") {
  TemporaryDirectory directory;
  const std::string unwritable = directory.file("missing/run.pvd");
  CHECK_THROWS_WITH(io::PvdCollection{unwritable}, Catch::Contains(unwritable));
  io::PvdCollection collection(directory.file("run.pvd"));
  CHECK_THROWS_WITH(collection.add(std::numeric_limits<double>::quiet_NaN(), "f.vtu"),
                    Catch::Contains("time") && Catch::Contains("f.vtu"));
  CHECK_THROWS_AS(collection.add(0.0, "f.vtu", -1), Error);
  CHECK(read_pvd(directory.file("run.pvd")).empty());
}

namespace {

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> cells;
  std::istringstream stream(line);
  for (std::string cell; std::getline(stream, cell, ',');) cells.push_back(cell);
  return cells;
}

}  // namespace

TEST_CASE("CSV probe: header with units, full-precision rows, flushed as written",
          "[io][csv]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("probe.csv");
  const std::vector<std::vector<double>> rows = {
      {0.0, 0.1, -0.0},
      {1.0 / 3.0, 1e-300, std::numeric_limits<double>::denorm_min()},
      {2.0 / 3.0, std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()},
      {std::nextafter(1.0, 2.0), -std::numeric_limits<double>::max(), 123456789.125}};
  io::CsvProbe probe(path, {"time [s]", "w_centre [m]", "energy [J]"});
  for (std::size_t r = 0; r < rows.size(); ++r) {
    probe.write_row(rows[r]);
    // Readable while the probe is still open.
    const std::vector<std::string> lines = split_lines(read_whole_file(path));
    REQUIRE(lines.size() == r + 2);
  }
  const std::vector<std::string> lines = split_lines(read_whole_file(path));
  CHECK(lines[0] == "time [s],w_centre [m],energy [J]");
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::vector<std::string> cells = split_commas(lines[r + 1]);
    REQUIRE(cells.size() == 3);
    for (std::size_t c = 0; c < 3; ++c) {
      INFO("row " << r << " column " << c << ": " << cells[c]);
      const double parsed = std::strtod(cells[c].c_str(), nullptr);
      if (std::isnan(rows[r][c])) {
        CHECK(std::isnan(parsed));
      } else {
        CHECK(std::memcmp(&parsed, &rows[r][c], sizeof(double)) == 0);
      }
    }
  }
}

TEST_CASE("CSV probe quotes awkward column names and rejects bad rows", "[io][csv]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("probe.csv");
  io::CsvProbe probe(path, {"time [s]", "force, total [N]", "say \"hi\""});
  CHECK(split_lines(read_whole_file(path))[0] == "time [s],\"force, total [N]\",\"say \"\"hi\"\"\"");
  CHECK_THROWS_WITH(probe.write_row({1.0, 2.0}),
                    Catch::Contains("probe.csv") && Catch::Contains("expects 3") &&
                        Catch::Contains("got 2"));
  CHECK(split_lines(read_whole_file(path)).size() == 1);

  CHECK_THROWS_AS(io::CsvProbe(path, {}), Error);
  CHECK_THROWS_AS(io::CsvProbe(path, {"time [s]", ""}), Error);
  const std::string unwritable = directory.file("missing/probe.csv");
  CHECK_THROWS_WITH(io::CsvProbe(unwritable, {"t"}), Catch::Contains(unwritable));
}

TEST_CASE("SVG plot: axis ticks are whole multiples of a 1, 2, 2.5 or 5 step", "[io][svg]") {
  struct Case {
    double minimum, maximum, lower, upper, step;
  };
  for (const Case& c : {Case{0.0, 9.3, 0.0, 10.0, 2.0}, Case{0.0, 10.0, 0.0, 10.0, 2.0},
                        Case{0.0012, 0.0987, 0.0, 0.1, 0.02}, Case{-3.0, 7.0, -4.0, 8.0, 2.0},
                        Case{150.0, 300.0, 150.0, 300.0, 25.0}, Case{5.0, 5.0, 4.4, 5.6, 0.2},
                        Case{0.0, 0.0, -1.0, 1.0, 0.5}}) {
    const io::AxisTicks ticks = io::nice_ticks(c.minimum, c.maximum);
    INFO("range [" << c.minimum << ", " << c.maximum << "]");
    CHECK(ticks.step == Approx(c.step).epsilon(1e-12));
    CHECK(ticks.lower == Approx(c.lower).margin(1e-12));
    CHECK(ticks.upper == Approx(c.upper).margin(1e-12));
  }
  // A range over most of the doubles: (1e308 − (−1e308)) / 6 overflows unless
  // halved first; by hand the step is 5e307 (3.3e307 rounded up to 5 × 10^307).
  const io::AxisTicks widest = io::nice_ticks(-1e308, 1e308);
  CHECK(widest.step == Approx(5e307).epsilon(1e-12));
  CHECK(widest.lower == Approx(-1e308).epsilon(1e-12));
  CHECK(widest.upper == Approx(1e308).epsilon(1e-12));
  // A constant subnormal series: 10 % of it rounds to zero, so the range must
  // be widened by a finite positive amount instead.
  const double subnormal = std::numeric_limits<double>::denorm_min();
  const io::AxisTicks tiny = io::nice_ticks(subnormal, subnormal);
  CHECK(std::isfinite(tiny.step));
  CHECK(tiny.step > 0.0);
  CHECK(tiny.lower < subnormal);
  CHECK(tiny.upper > subnormal);
  CHECK((tiny.upper - tiny.lower) / tiny.step <= 12.0);
  CHECK_THROWS_WITH(io::nice_ticks(1.0, 0.0), Catch::Contains("[1, 0]"));
  CHECK_THROWS_WITH(io::nice_ticks(0.0, std::numeric_limits<double>::quiet_NaN()), Catch::Contains("not a finite"));
  CHECK_THROWS_WITH(io::nice_ticks(0.0, 1.0, 0), Catch::Contains("target_intervals = 0"));
}

TEST_CASE("SVG plot: data map onto the plot area, gaps break lines, labels are escaped", "[io][svg]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("plot.svg");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  io::PlotPanel first{"force <kN> & crack", "displacement [mm]", "force [kN]", {}};
  first.series.push_back({"line", {0.0, 5.0, 10.0}, {0.0, 5.0, 10.0}, io::PlotStyle::line});
  first.series.push_back({"gap", {0.0, 1.0, 2.0, 3.0, 4.0}, {1.0, 2.0, nan, 3.0, 4.0}, io::PlotStyle::dashed});
  first.series.push_back({"reference", {2.0, 4.0, 6.0}, {2.0, 4.0, 6.0}, io::PlotStyle::points});
  io::PlotPanel second{"second", "x", "y", {}};
  second.series.push_back({"only", {0.0, 10.0}, {0.0, 10.0}, io::PlotStyle::line});
  io::write_svg_plot(path, {first, second});
  const std::string svg = read_whole_file(path);

  // Independent mapping: x spans [0, 10]. The y axis gets headroom for the
  // legend box (18 px per series + 14 px of the 308 px plot height): with three
  // series 10 grows to 10 / (1 − 68/308) = 12.8, rounded up to 15 in steps of 2.5;
  // with one series to 10 / (1 − 32/308) = 11.2, rounded up to 12. x = 0 is the
  // left edge of the plot area, y = 0 its bottom edge; the second panel is
  // shifted by one panel width.
  const io::PlotLayout layout;
  REQUIRE(layout.plot_height() == 308.0);
  auto expected = [&](double offset, double y_upper, double x, double y) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "%.2f,%.2f", offset + layout.margin_left + x / 10.0 * layout.plot_width(),
                  layout.margin_top + (y_upper - y) / y_upper * layout.plot_height());
    return std::string(buffer);
  };
  CHECK_THAT(svg, Catch::Contains("points=\"" + expected(0, 15, 0, 0) + " " + expected(0, 15, 5, 5) + " " +
                                  expected(0, 15, 10, 10) + "\""));
  CHECK_THAT(svg, Catch::Contains("points=\"" + expected(layout.panel_width, 12, 0, 0) + " " +
                                  expected(layout.panel_width, 12, 10, 10) + "\""));
  CHECK_THAT(svg, Catch::Contains("points=\"" + expected(0, 15, 0, 1) + " " + expected(0, 15, 1, 2) + "\""));
  CHECK_THAT(svg, Catch::Contains("points=\"" + expected(0, 15, 3, 3) + " " + expected(0, 15, 4, 4) + "\""));
  const std::regex polyline("<polyline ");
  CHECK(std::distance(std::sregex_iterator(svg.begin(), svg.end(), polyline), std::sregex_iterator()) == 4);
  const std::regex marker("<circle cx=\"[0-9.]+\" cy=\"[0-9.]+\" r=\"3.5\"");
  CHECK(std::distance(std::sregex_iterator(svg.begin(), svg.end(), marker), std::sregex_iterator()) == 3 + 1);
  CHECK_THAT(svg, Catch::Contains("force &lt;kN&gt; &amp; crack"));
  CHECK_THAT(svg, Catch::Contains("width=\"" + std::to_string(int(2 * layout.panel_width)) + ".00\""));
  CHECK_THAT(svg, Catch::EndsWith("</svg>\n"));
}

TEST_CASE("SVG plot: data over most of the doubles still map into the plot area", "[io][svg]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("wide.svg");
  const double largest = std::numeric_limits<double>::max();
  io::PlotPanel panel{"wide", "x", "y", {}};
  panel.series.push_back({"edges", {-largest, largest}, {-0.9 * largest, 0.9 * largest}, io::PlotStyle::line});
  io::write_svg_plot(path, {panel});
  const std::string svg = read_whole_file(path);
  CHECK_THAT(svg, !Catch::Contains("nan") && !Catch::Contains("inf"));
  // The x axis is the data range itself (rounding it out to whole steps would
  // overflow), so the line starts at the plot's left edge and ends at its right.
  const io::PlotLayout layout;
  char start[32], end[32];
  std::snprintf(start, sizeof(start), "points=\"%.2f,", layout.margin_left);
  std::snprintf(end, sizeof(end), " %.2f,", layout.margin_left + layout.plot_width());
  CHECK_THAT(svg, Catch::Contains(start) && Catch::Contains(end));
}

TEST_CASE("SVG plot errors name the series and leave existing output alone", "[io][svg]") {
  TemporaryDirectory directory;
  const std::string path = directory.file("plot.svg");
  io::PlotPanel good{"panel", "x", "y", {{"ok", {0.0, 1.0}, {0.0, 1.0}, io::PlotStyle::line}}};
  io::write_svg_plot(path, {good});
  const std::string before = read_whole_file(path);
  io::PlotPanel uneven{"panel", "x", "y", {{"uneven", {0.0, 1.0, 2.0}, {0.0, 1.0}, io::PlotStyle::line}}};
  CHECK_THROWS_WITH(io::write_svg_plot(path, {uneven}), Catch::Contains("'uneven'") && Catch::Contains("3 x values but 2"));
  io::PlotPanel infinite{"panel", "x", "y",
                         {{"infinite", {0.0, std::numeric_limits<double>::infinity()}, {0.0, 1.0}, io::PlotStyle::line}}};
  CHECK_THROWS_WITH(io::write_svg_plot(path, {infinite}), Catch::Contains("'infinite'") && Catch::Contains("inf"));
  CHECK_THROWS_WITH(io::write_svg_plot(path, {}), Catch::Contains("at least one panel"));
  io::PlotLayout cramped;
  cramped.margin_left = 600.0;
  CHECK_THROWS_WITH(io::write_svg_plot(path, {good}, cramped), Catch::Contains("no plot area"));
  // NaN slips past "width > margins"; a negative margin draws outside the panel.
  io::PlotLayout nan_width;
  nan_width.panel_width = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(io::write_svg_plot(path, {good}, nan_width), Catch::Contains("PlotLayout::panel_width = nan"));
  io::PlotLayout negative_margin;
  negative_margin.margin_left = -100.0;
  CHECK_THROWS_WITH(io::write_svg_plot(path, {good}, negative_margin),
                    Catch::Contains("PlotLayout::margin_left = -100") && Catch::Contains(">= 0"));
  CHECK(read_whole_file(path) == before);
  // A panel without data still gets axes (a run that ended before anything happened).
  io::PlotPanel empty{"empty", "x", "y", {{"nothing", {}, {}, io::PlotStyle::line}}};
  CHECK_NOTHROW(io::write_svg_plot(directory.file("empty.svg"), {empty}));
}

TEST_CASE("A fixed-length list is read in place, and a list of another length is refused naming both", "[io]") {
  io::BinaryWriter out;
  const std::vector<double> written{1.5, -2.25, 3.0};
  out(written);
  out(written);
  io::BinaryReader in(std::string(out.bytes()), "list.bin");
  std::vector<double> same(3, 0.0);
  in.read_exact(same, "values");
  CHECK(same == written);
  std::vector<double> shorter(2, 7.0);
  CHECK_THROWS_WITH(in.read_exact(shorter, "values"),
                    Catch::Contains("values: the file holds 3 entries, this solver has 2") && Catch::Contains("list.bin"));
  CHECK(shorter == std::vector<double>{7.0, 7.0});  // refused before anything was read into it
}
