#pragma once
// Reads a shell mesh from a Gmsh .msh file, format 4.1, ASCII or binary
// (little-endian, 8-byte size_t, as 64-bit Gmsh writes it).
//
// Sections read: $MeshFormat, $PhysicalNames, $Entities, $Nodes, $Elements;
// any other section ($Periodic, $NodeData, ...) is skipped whole, but a name
// within two letters of a known section's is an Error (a misspelling).
// Elements: 3-node triangles (type 2) and 4-node quadrilaterals (type 3)
// become the shell's cells. Points (type 15) and 2-node lines (type 1) only
// carry node sets. Any other type (second-order, volume) is an Error naming it.
// Named physical groups become particle sets: a group of dimension 0 or 1
// holds the nodes of its point or line elements, a group of dimension 2 the
// nodes of its triangles and quadrilaterals. Physical groups without a name
// are not sets. A .msh file has no thickness: it is the reader's argument,
// and ShellModel::set_thickness or set_stress_point_thickness change regions.
// Counts in the file are checked against the bytes left before anything is
// reserved for them. Particles, stress points, sets, the checks of shapes and
// coordinates and the memory estimate follow io/mesh_data.hpp's conventions.

#include <sphshell/core/error.hpp>
#include <sphshell/io/mesh_data.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::io {

namespace detail {

class GmshParser {
 public:
  GmshParser(std::string path, std::string data) : path_(std::move(path)), data_(std::move(data)) {
    if (starts_with_bom(data_)) position_ = 3;  // a UTF-8 byte order mark before $MeshFormat
  }

  MeshData parse() {
    MeshData mesh;
    mesh.describe = [this](const MeshOrigin& origin) { return where(origin.position); };
    bool format = false, entities = false, names = false, nodes = false, elements = false;
    for (;;) {
      skip_space();
      if (position_ >= data_.size()) break;
      const std::size_t start = position_;
      const std::string header = trim(rest_of_line());
      if (header.empty() || header[0] != '$' || header.compare(0, 4, "$End") == 0)
        fail_at(start, "expected a section header such as $Nodes, found '" + header.substr(0, 40) + "'");
      const std::string section = header.substr(1);
      if (!format && section != "MeshFormat")
        fail_at(start, "the file must begin with $MeshFormat (is it a Gmsh .msh file?)");
      sections_.push_back({start, section});
      if (section == "MeshFormat") {
        read_format();
        format = true;
      } else if (section == "PhysicalNames") {
        read_physical_names();
        names = true;
      } else if (section == "Entities") {
        read_entities();
        entities = true;
      } else if (section == "Nodes") {
        read_nodes(mesh);
        nodes = true;
      } else if (section == "Elements") {
        read_elements(mesh);
        elements = true;
      } else {
        // Sections the format defines beyond the mesh are skipped; a name one
        // or two letters from a known one is a misspelling (a lost $Nodes or
        // $PhysicalNames would otherwise pass unseen).
        static const std::vector<std::string> known = {
            "MeshFormat", "PhysicalNames", "Entities", "PartitionedEntities", "Nodes", "Elements", "Periodic",
            "GhostElements", "Parametrizations", "NodeData", "ElementData", "ElementNodeData",
            "InterpolationScheme", "Comments"};
        const std::string nearest = nearest_name(section, known, [](const std::string& name) { return name; });
        if (section != nearest && edit_distance(section, nearest) <= kMisspelledSection)
          fail_at(start, "unknown section $" + section + "; did you mean $" + nearest + "?");
        skip_section(section, start);
        continue;
      }
      expect_end(section);
    }
    mesh.end = {0, data_.size()};
    const std::string file = where(data_.size()) + " (its end)";
    if (!format) mesh_error(file, "the file is empty (no $MeshFormat section)");
    if (!nodes) mesh_error(file, "the file has no $Nodes section");
    if (!elements) mesh_error(file, "the file has no $Elements section");
    if (names && !entities)
      mesh_error(file, "the file has $PhysicalNames but no $Entities section, so its physical groups cannot be "
                       "mapped to elements");
    collect_sets(mesh);
    return mesh;
  }

 private:
  struct Section {
    std::size_t start;
    std::string name;
  };
  struct PhysicalName {
    std::string name;
    std::size_t position;
  };
  struct NodeListElement {  // a point or line element: it only carries nodes to sets
    std::vector<long long> nodes;
    std::size_t position;
  };
  using EntityKey = std::pair<int, int>;  // dimension, tag

  static constexpr int kPoint = 15, kLine = 1, kTriangle = 2, kQuadrangle = 3;
  static constexpr int kExpectedSizeT = 8;
  // An unknown section name this many edits or fewer from a known one is an Error.
  static constexpr std::size_t kMisspelledSection = 2;

  // --- messages -----------------------------------------------------------
  std::string where(std::size_t position) const {
    if (!binary_ || position < first_binary_) {
      const auto line = 1 + std::count(data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(
                                                                           std::min(position, data_.size())),
                                       '\n');
      return "mesh file '" + path_ + "', line " + std::to_string(line);
    }
    std::string section = "?";
    for (const Section& s : sections_)
      if (s.start <= position) section = s.name;
    return "mesh file '" + path_ + "', binary $" + section + " block, byte " + std::to_string(position);
  }
  [[noreturn]] void fail_at(std::size_t position, const std::string& problem) const {
    mesh_error(where(position), problem);
  }
  [[noreturn]] void fail(const std::string& problem) const { fail_at(token_start_, problem); }

  static std::string number_text(double value) {
    std::ostringstream text;
    text.precision(6);
    text << value;
    return text.str();
  }

  // --- low-level reading ----------------------------------------------------
  static bool is_space(char character) {
    return character == ' ' || character == '\t' || character == '\r' || character == '\n';
  }
  void skip_space() {
    while (position_ < data_.size() && is_space(data_[position_])) ++position_;
  }
  std::string rest_of_line() {
    const std::size_t end = std::min(data_.find('\n', position_), data_.size());
    std::string line = data_.substr(position_, end - position_);
    position_ = std::min(end + 1, data_.size());
    return line;
  }
  std::string token(const std::string& what) {
    skip_space();
    token_start_ = position_;
    while (position_ < data_.size() && !is_space(data_[position_])) ++position_;
    if (position_ == token_start_)
      fail("the file ends inside $" + current_ + " where " + what + " should follow (truncated?)");
    return data_.substr(token_start_, position_ - token_start_);
  }
  long long ascii_integer(const std::string& what) {
    const std::string text = token(what);
    long long value = 0;
    if (!parse_integer(text, value)) fail(what + " is '" + text + "', not an integer");
    return value;
  }
  template <class T>
  T binary_value(const std::string& what) {
    token_start_ = position_;
    if (data_.size() - position_ < sizeof(T))
      fail("truncated binary data: " + what + " needs " + std::to_string(sizeof(T)) + " bytes, " +
           std::to_string(data_.size() - position_) + " remain");
    T value;
    std::memcpy(&value, data_.data() + position_, sizeof(T));
    position_ += sizeof(T);
    return value;
  }
  int read_int(const std::string& what) {
    if (binary_) return binary_value<std::int32_t>(what);
    const long long value = ascii_integer(what);
    if (value < INT32_MIN || value > INT32_MAX) fail(what + " = " + std::to_string(value) + " is out of range");
    return static_cast<int>(value);
  }
  long long read_size(const std::string& what) {
    if (binary_) {
      const std::uint64_t value = binary_value<std::uint64_t>(what);
      if (value > static_cast<std::uint64_t>(INT64_MAX)) fail(what + " is out of range");
      return static_cast<long long>(value);
    }
    const long long value = ascii_integer(what);
    if (value < 0) fail(what + " = " + std::to_string(value) + " must not be negative");
    return value;
  }
  double read_real(const std::string& what) {
    if (binary_) {
      const double value = binary_value<double>(what);
      if (!std::isfinite(value)) fail(what + " is not finite");
      return value;
    }
    const std::string text = token(what);
    double value = 0.0;
    if (!parse_real(text, value)) fail(what + " is '" + text + "', not a finite number");
    return value;
  }
  // A count of items that each take at least `bytes` bytes: refuse one the rest
  // of the file cannot hold, before reserving memory for it.
  long long read_count(const std::string& what, std::size_t bytes) {
    const long long count = read_size(what);
    if (static_cast<unsigned long long>(count) > (data_.size() - position_) / bytes + 1)
      fail("truncated data: " + what + " = " + std::to_string(count) + " but only " +
           std::to_string(data_.size() - position_) + " bytes remain");
    return count;
  }
  std::size_t item_bytes(std::size_t binary_size) const { return binary_ ? binary_size : 2; }
  void begin_section_data(const char* section) {
    current_ = section;
    if (binary_ && first_binary_ == std::string::npos) first_binary_ = position_;
  }

  void expect_end(const std::string& section) {
    skip_space();
    token_start_ = position_;
    const std::string line = trim(rest_of_line());
    if (line != "$End" + section)
      fail("expected $End" + section + ", found '" + line.substr(0, 40) + "' (wrong counts or truncated data?)");
  }
  void skip_section(const std::string& section, std::size_t start) {
    const std::string end = "$End" + section;
    std::size_t found = data_.find(end, position_);
    while (found != std::string::npos && found > 0 && data_[found - 1] != '\n') found = data_.find(end, found + 1);
    if (found == std::string::npos) fail_at(start, "section $" + section + " has no " + end);
    position_ = found + end.size();
  }

  // --- sections ---------------------------------------------------------------
  void read_format() {
    current_ = "MeshFormat";
    const std::string version = token("the format version");
    if (version != "4.1")
      fail("format version " + version + ": only 4.1 is read (save with Mesh.MshFileVersion = 4.1)");
    const long long type = ascii_integer("the file type");
    if (type != 0 && type != 1) fail("file type " + std::to_string(type) + " is neither 0 (ASCII) nor 1 (binary)");
    const long long data_size = ascii_integer("the data size");
    if (data_size != kExpectedSizeT)
      fail("data size " + std::to_string(data_size) + ": only " + std::to_string(kExpectedSizeT) +
           "-byte size_t is read");
    if (type == 1) {
      rest_of_line();
      binary_ = true;
      const std::int32_t one = binary_value<std::int32_t>("the endianness marker");
      if (one != 1) {
        const bool swapped = one == 0x01000000;
        fail(swapped ? std::string("the binary data is big-endian; only little-endian is read")
                     : "the endianness marker is " + std::to_string(one) + ", not 1");
      }
    }
  }

  void read_physical_names() {
    current_ = "PhysicalNames";
    const long long count = ascii_integer("the number of physical names");
    for (long long k = 0; k < count; ++k) {
      const long long dimension = ascii_integer("a physical group's dimension");
      const long long tag = ascii_integer("a physical group's tag");
      skip_space();
      const std::size_t start = position_;
      token_start_ = start;
      if (position_ >= data_.size() || data_[position_] != '"') fail("a physical name must be in double quotes");
      const std::size_t close = data_.find('"', position_ + 1);
      if (close == std::string::npos || data_.find('\n', position_) < close)
        fail("a physical name lacks its closing double quote");
      const std::string name = data_.substr(position_ + 1, close - position_ - 1);
      position_ = close + 1;
      if (name.empty()) fail("a physical name is empty");
      const std::size_t control = find_control_byte(name);
      if (control != std::string::npos)
        fail("the physical name holds the byte " + byte_text(static_cast<unsigned char>(name[control])) +
             ", a control character (a corrupted file?)");
      if (dimension < 0 || dimension > 3) fail("a physical group's dimension must be 0 to 3");
      if (tag > std::numeric_limits<int>::max() || tag < std::numeric_limits<int>::min())
        fail("a physical group's tag does not fit in an int");
      const bool added =
          physical_names_.emplace(EntityKey{static_cast<int>(dimension), static_cast<int>(tag)}, PhysicalName{name, start})
              .second;
      if (!added)
        fail("physical group (dimension " + std::to_string(dimension) + ", tag " + std::to_string(tag) +
             ") is named twice");
    }
  }

  void read_entities() {
    begin_section_data("Entities");
    long long counts[4];
    const char* kinds[4] = {"points", "curves", "surfaces", "volumes"};
    for (int dimension = 0; dimension < 4; ++dimension)
      counts[dimension] = read_count(std::string("the number of ") + kinds[dimension], item_bytes(4));
    for (int dimension = 0; dimension < 4; ++dimension)
      for (long long k = 0; k < counts[dimension]; ++k) {
        const int tag = read_int("an entity tag");
        const int coordinates = dimension == 0 ? 3 : 6;  // a point, or a bounding box
        for (int c = 0; c < coordinates; ++c) read_real("an entity coordinate");
        const long long physicals = read_count("the number of physical tags", item_bytes(4));
        std::vector<int>& tags = entity_physicals_[{dimension, tag}];
        for (long long p = 0; p < physicals; ++p) tags.push_back(read_int("a physical tag"));
        if (dimension > 0) {
          const long long bounding = read_count("the number of bounding entities", item_bytes(4));
          for (long long b = 0; b < bounding; ++b) read_int("a bounding entity tag");
        }
      }
  }

  void read_nodes(MeshData& mesh) {
    begin_section_data("Nodes");
    const long long blocks = read_count("the number of node blocks", item_bytes(20));
    const long long total = read_count("the number of nodes", item_bytes(8));
    read_size("the smallest node tag");
    read_size("the largest node tag");
    long long counted = 0;
    for (long long b = 0; b < blocks; ++b) {
      const int dimension = read_int("a node block's entity dimension");
      read_int("a node block's entity tag");
      const int parametric = read_int("a node block's parametric flag");
      if (dimension < 0 || dimension > 3) fail("entity dimension " + std::to_string(dimension) + " is not 0 to 3");
      if (parametric != 0 && parametric != 1) fail("parametric flag " + std::to_string(parametric) + " is not 0 or 1");
      const long long count = read_count("the number of nodes in a block", item_bytes(8));
      std::vector<long long> tags(static_cast<std::size_t>(count));
      std::vector<std::size_t> tag_positions(tags.size());
      for (std::size_t k = 0; k < tags.size(); ++k) {
        tags[k] = read_size("a node tag");
        tag_positions[k] = token_start_;
      }
      const int extra = parametric ? dimension : 0;  // u, v, w after x, y, z
      for (std::size_t k = 0; k < tags.size(); ++k) {
        Vector3 x;
        for (int c = 0; c < 3; ++c) {
          x[c] = read_real("a node coordinate");
          if (std::abs(x[c]) > largest_coordinate)
            fail("coordinate " + std::to_string(c + 1) + " of node " + std::to_string(tags[k]) + " is " +
                 number_text(x[c]) + ", beyond the limit of ±" + number_text(largest_coordinate) +
                 " (a unit or format mistake?)");
        }
        for (int c = 0; c < extra; ++c) read_real("a node's parametric coordinate");
        if (!mesh.nodes.emplace(tags[k], x).second)
          fail_at(tag_positions[k], "node " + std::to_string(tags[k]) + " is defined twice");
      }
      counted += count;
    }
    if (counted != total)
      fail("the $Nodes header announces " + std::to_string(total) + " nodes but its blocks hold " +
           std::to_string(counted));
  }

  static std::string element_type_name(int type) {
    static const std::map<int, std::string> names = {
        {4, "4-node tetrahedron"},         {5, "8-node hexahedron"},
        {6, "6-node prism"},               {7, "5-node pyramid"},
        {8, "3-node second-order line"},   {9, "6-node second-order triangle"},
        {10, "9-node second-order quadrilateral"}, {11, "10-node second-order tetrahedron"},
        {12, "27-node second-order hexahedron"},   {16, "8-node second-order quadrilateral"},
        {17, "20-node second-order hexahedron"},   {20, "9-node third-order triangle"},
        {21, "10-node third-order triangle"},      {36, "16-node third-order quadrilateral"}};
    const auto found = names.find(type);
    return found == names.end() ? "an element type this reader does not know" : found->second;
  }

  void read_elements(MeshData& mesh) {
    begin_section_data("Elements");
    const long long blocks = read_count("the number of element blocks", item_bytes(20));
    const long long total = read_count("the number of elements", item_bytes(8));
    read_size("the smallest element tag");
    read_size("the largest element tag");
    long long counted = 0;
    for (long long b = 0; b < blocks; ++b) {
      const int dimension = read_int("an element block's entity dimension");
      const int entity = read_int("an element block's entity tag");
      const int type = read_int("an element type");
      std::size_t node_count = 0;
      switch (type) {
        case kPoint: node_count = 1; break;
        case kLine: node_count = 2; break;
        case kTriangle: node_count = 3; break;
        case kQuadrangle: node_count = 4; break;
        default:
          fail("element type " + std::to_string(type) + " (" + element_type_name(type) + ") in entity " +
                      std::to_string(entity) + " of dimension " + std::to_string(dimension) +
                      ": only 3-node triangles (type 2) and 4-node quadrilaterals (type 3) are shells; "
                      "points (15) and 2-node lines (1) may carry node sets");
      }
      const long long count = read_count("the number of elements in a block", item_bytes(8 * (node_count + 1)));
      for (long long k = 0; k < count; ++k) {
        const long long tag = read_size("an element tag");
        const std::size_t origin = token_start_;
        std::array<long long, 4> nodes{};
        for (std::size_t n = 0; n < node_count; ++n) nodes[n] = read_size("an element's node tag");
        if (type == kTriangle || type == kQuadrangle) {
          MeshElement element;
          element.label = tag;
          element.nodes = nodes;
          element.node_count = node_count;
          element.origin = {0, origin};
          shell_elements_of_[{dimension, entity}].push_back(mesh.elements.size());
          mesh.elements.push_back(element);
        } else {
          node_lists_[{dimension, entity}].push_back(
              {std::vector<long long>(nodes.begin(), nodes.begin() + static_cast<std::ptrdiff_t>(node_count)),
               origin});
        }
      }
      counted += count;
    }
    if (counted != total)
      fail("the $Elements header announces " + std::to_string(total) + " elements but its blocks hold " +
           std::to_string(counted));
  }

  void collect_sets(MeshData& mesh) const {
    for (const auto& [group, physical] : physical_names_) {
      const auto [dimension, tag] = group;
      const MeshOrigin origin{0, physical.position};
      if (dimension < 0 || dimension > 2)
        mesh_error(where(physical.position), "physical group '" + physical.name + "' has dimension " +
                                                 std::to_string(dimension) + ": only points, curves and "
                                                 "surfaces (0 to 2) make node sets of a shell");
      MeshSet set{physical.name, origin, {}};
      for (const auto& [entity, physicals] : entity_physicals_) {
        if (entity.first != dimension || std::find(physicals.begin(), physicals.end(), tag) == physicals.end())
          continue;
        if (dimension == 2) {
          const auto found = shell_elements_of_.find(entity);
          if (found == shell_elements_of_.end()) continue;
          for (std::size_t e : found->second)
            for (std::size_t n = 0; n < mesh.elements[e].node_count; ++n)
              set.nodes.emplace_back(mesh.elements[e].nodes[n], mesh.elements[e].origin);
        } else {
          const auto found = node_lists_.find(entity);
          if (found == node_lists_.end()) continue;
          for (const NodeListElement& element : found->second)
            for (long long node : element.nodes) set.nodes.emplace_back(node, MeshOrigin{0, element.position});
        }
      }
      if (set.nodes.empty())
        mesh_error(where(physical.position), "physical group '" + physical.name + "' (dimension " +
                                                 std::to_string(dimension) + ", tag " + std::to_string(tag) +
                                                 ") holds no element in the file");
      mesh.sets.push_back(std::move(set));
    }
  }

  std::string path_;
  std::string data_;
  std::size_t position_ = 0;
  std::size_t token_start_ = 0;
  bool binary_ = false;
  // Where the first binary section's data starts: lines are counted before it.
  std::size_t first_binary_ = std::string::npos;
  std::string current_;
  std::vector<Section> sections_;
  std::map<EntityKey, PhysicalName> physical_names_;
  std::map<EntityKey, std::vector<int>> entity_physicals_;
  std::map<EntityKey, std::vector<std::size_t>> shell_elements_of_;
  std::map<EntityKey, std::vector<NodeListElement>> node_lists_;
};

// The whole file, after checking that it is a regular file whose contents
// and parsed form fit in memory (mesh_data.hpp).
inline std::string read_whole_file(const std::string& path, const std::string& what) {
  const std::uintmax_t size = require_regular_file(path, what);
  require_memory("reading " + what + " '" + path + "' (" + std::to_string(size) + " bytes)",
                 parsed_bytes_per_input_byte * static_cast<double>(size));
  errno = 0;
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error("sphshell: cannot open " + what + " '" + path + "': " + system_reason(errno));
  std::string data;
  data.reserve(static_cast<std::size_t>(size));
  data.assign(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
  if (stream.bad()) throw Error("sphshell: failed while reading " + what + " '" + path + "': " + system_reason(errno));
  return data;
}

}  // namespace detail

// The shell in a Gmsh 4.1 .msh file (see the top of this header), every
// particle and stress point with wall thickness d (m).
inline ShellModel read_gmsh(const std::string& path, double thickness) {
  sphshell::detail::require_positive("thickness", thickness);
  return detail::guard_reading(path, [&] {
    detail::GmshParser parser(path, detail::read_whole_file(path, "mesh file"));
    detail::MeshData mesh = parser.parse();
    return detail::build_shell_model(mesh, path, thickness);
  });
}

}  // namespace sphshell::io
