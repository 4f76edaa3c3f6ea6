#pragma once
// VTK XML UnstructuredGrid (.vtu) output for ParaView: surfaces of triangles
// and quadrilaterals, point clouds (VTK_VERTEX cells) and line sets (crack
// segments), with point data, cell data and the frame's time, and the
// parallel file (.pvtu) of a grid written in pieces.
//
// Format: file version 1.0 with 64-bit block headers. The encoding and the
// precision are chosen per file (io/vtu_format.hpp, VtuFormat):
//   ascii   every array inline as decimal text (shortest round-trip decimals);
//   binary  all arrays in one appended raw section (host byte order, declared
//           in the header): no encoding cost, values exact;
//   zlib    as binary, each array deflated in blocks of compression_block_bytes
//           (VTK's vtkZLibDataCompressor layout: a UInt64 header of block
//           count, block size, last block size and compressed sizes).
// Real arrays are Float32 or Float64 as chosen; integer arrays (flags,
// indices) Int32; cell connectivity and offsets Int32 while the indices fit,
// Int64 beyond; cell types UInt8. A finite frame time is written as the
// FieldData array TimeValue (what ParaView shows as the time of a lone file),
// and an optional note as an XML comment at the top, for a person reading the
// file.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/io/vtu_format.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#ifdef SPHSHELL_HAVE_ZLIB
#include <zlib.h>
#endif

namespace sphshell::io {

// Whether a field holds real numbers (written in the file's precision) or
// integers (flags, indices; written as Int32, each value must be a whole
// number in Int32's range).
enum class FieldValues { real, integer };

// A named array attached to every point (or cell): values are stored tuple by
// tuple, values[i * components + k] being component k of point i. Component
// names are optional; when given there must be one per component (ParaView
// shows them instead of 0, 1, 2, ...).
struct Field {
  std::string name;
  int components = 1;
  std::vector<double> values;
  std::vector<std::string> component_names = {};
  FieldValues kind = FieldValues::real;
};
using PointField = Field;
using CellField = Field;

// VTK's cell type numbers (vtkCellType.h) for the cells the library writes.
enum class VtkCellType : std::uint8_t { vertex = 1, line = 3, triangle = 5, quad = 9 };

// The cells of a grid, each a type and its corner point indices.
class VtuCells {
 public:
  void add(VtkCellType type, const int* begin, const int* end) {
    for (const int* corner = begin; corner != end; ++corner) connectivity_.push_back(*corner);
    offsets_.push_back(static_cast<std::int64_t>(connectivity_.size()));
    types_.push_back(static_cast<std::uint8_t>(type));
  }
  void add_vertex(int point) { add(VtkCellType::vertex, &point, &point + 1); }
  void add_line(int first, int second) {
    const int ends[2] = {first, second};
    add(VtkCellType::line, ends, ends + 2);
  }
  // A triangle (3 corners) or quadrilateral (4), corners in order round it.
  void add_polygon(const int* begin, const int* end) {
    const auto corners = end - begin;
    if (corners != 3 && corners != 4)
      throw Error("sphshell: VTU polygon with " + std::to_string(corners) + " corners (need 3 or 4)");
    add(corners == 3 ? VtkCellType::triangle : VtkCellType::quad, begin, end);
  }

  std::size_t size() const { return types_.size(); }
  const std::vector<std::int64_t>& connectivity() const { return connectivity_; }
  const std::vector<std::int64_t>& offsets() const { return offsets_; }
  const std::vector<std::uint8_t>& types() const { return types_; }

 private:
  std::vector<std::int64_t> connectivity_;
  std::vector<std::int64_t> offsets_;
  std::vector<std::uint8_t> types_;
};

// Everything one .vtu holds.
struct VtuGrid {
  std::vector<Vector3> points;
  VtuCells cells;
  std::vector<PointField> point_fields;
  std::vector<CellField> cell_fields;
  // The frame's time (s), written as FieldData TimeValue when finite.
  double time = std::numeric_limits<double>::quiet_NaN();
  // Written as an XML comment at the top of the file (no "--" inside).
  std::string note;
};

namespace detail {

// Uncompressed bytes per zlib block. Deflate's window is 32 KiB, so larger
// blocks gain little; VTK writes 32 KiB blocks, readers accept any size.
constexpr std::size_t compression_block_bytes = std::size_t{1} << 16;

inline bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first_byte = 0;
  std::memcpy(&first_byte, &probe, 1);
  return first_byte == 1;
}

[[noreturn]] inline void invalid_output(const std::string& path, const std::string& what) {
  throw Error("sphshell: cannot write '" + path + "': " + what);
}

inline void validate_format(const std::string& path, const VtuFormat& format) {
  if (format.encoding != VtuEncoding::ascii && format.encoding != VtuEncoding::binary &&
      format.encoding != VtuEncoding::zlib)
    invalid_output(path, "encoding " + std::to_string(static_cast<int>(format.encoding)) +
                             " is not a VtuEncoding (ascii, binary or zlib)");
  if (format.precision != VtuPrecision::float32 && format.precision != VtuPrecision::float64)
    invalid_output(path, "precision " + std::to_string(static_cast<int>(format.precision)) +
                             " is not a VtuPrecision (float32 or float64)");
  if (format.encoding == VtuEncoding::zlib && !vtu_zlib_available)
    invalid_output(path,
                   "zlib encoding needs sphshell built with zlib (SPHSHELL_HAVE_ZLIB defined and -lz linked, "
                   "which the CMake target and pkg-config file do when zlib was found); use binary or ascii");
}

inline void validate_fields(const std::string& path, const std::vector<Field>& fields,
                            std::size_t tuples, const char* location) {
  std::set<std::string> names;
  for (const Field& field : fields) {
    const std::string label = std::string(location) + " field '" + field.name + "'";
    if (field.name.empty()) invalid_output(path, std::string(location) + " field with empty name");
    if (!names.insert(field.name).second) invalid_output(path, "duplicate " + label);
    if (field.components < 1)
      invalid_output(path, label + " has " + std::to_string(field.components) +
                               " components (need >= 1)");
    const std::size_t expected = tuples * static_cast<std::size_t>(field.components);
    if (field.values.size() != expected)
      invalid_output(path, label + " has " + std::to_string(field.values.size()) +
                               " values, expected " + std::to_string(tuples) + " x " +
                               std::to_string(field.components) + " = " +
                               std::to_string(expected));
    if (!field.component_names.empty() &&
        field.component_names.size() != static_cast<std::size_t>(field.components))
      invalid_output(path, label + " has " + std::to_string(field.component_names.size()) +
                               " component names for " + std::to_string(field.components) +
                               " components");
    if (field.kind == FieldValues::integer)
      for (std::size_t i = 0; i < field.values.size(); ++i) {
        const double value = field.values[i];
        if (!(value == std::floor(value)) || value < std::numeric_limits<std::int32_t>::min() ||
            value > std::numeric_limits<std::int32_t>::max())
          invalid_output(path, label + " is an integer field but value " + std::to_string(i) + " is " +
                                   round_trip_decimal(value));
      }
    else if (field.kind != FieldValues::real)
      invalid_output(path, label + " has an unknown kind");
  }
}

// One DataArray: its XML attributes (type, name, components) and its values
// as the bytes a binary file stores, or the text an ascii file stores.
struct EncodedArray {
  std::string attributes;
  std::string data;
  std::size_t components = 1;  // values per line in ascii
};

template <class Value>
void append_bytes(std::string& data, Value value) {
  char bytes[sizeof(Value)];
  std::memcpy(bytes, &value, sizeof(Value));
  data.append(bytes, sizeof(Value));
}

template <class Value>
void append_text(std::string& data, Value value) {
  if constexpr (std::is_floating_point_v<Value>)
    data += round_trip_decimal(value);
  else
    data += std::to_string(value);
  data += ' ';
}

// values converted to Stored, as bytes or as text.
template <class Stored, class Source>
std::string encode_values(const std::vector<Source>& values, bool as_text) {
  std::string data;
  data.reserve(values.size() * (as_text ? 12 : sizeof(Stored)));
  for (const Source& value : values) {
    if (as_text)
      append_text(data, static_cast<Stored>(value));
    else
      append_bytes(data, static_cast<Stored>(value));
  }
  return data;
}

inline std::string real_type(VtuPrecision precision) {
  return precision == VtuPrecision::float32 ? "Float32" : "Float64";
}

inline std::string encode_reals(const std::vector<double>& values, const VtuFormat& format) {
  const bool text = format.encoding == VtuEncoding::ascii;
  return format.precision == VtuPrecision::float32 ? encode_values<float>(values, text)
                                                   : encode_values<double>(values, text);
}

inline EncodedArray encode_field(const Field& field, const VtuFormat& format) {
  std::ostringstream attributes;
  const bool integer = field.kind == FieldValues::integer;
  attributes << "type=\"" << (integer ? std::string("Int32") : real_type(format.precision)) << "\" Name=\""
             << xml_escape(field.name) << "\" NumberOfComponents=\"" << field.components << "\"";
  for (std::size_t k = 0; k < field.component_names.size(); ++k)
    attributes << " ComponentName" << k << "=\"" << xml_escape(field.component_names[k]) << "\"";
  return {attributes.str(),
          integer ? encode_values<std::int32_t>(field.values, format.encoding == VtuEncoding::ascii)
                  : encode_reals(field.values, format),
          static_cast<std::size_t>(field.components)};
}

// Connectivity and offsets as Int32 while every value fits, else Int64.
inline EncodedArray encode_indices(const char* name, const std::vector<std::int64_t>& values,
                                   bool narrow, const VtuFormat& format) {
  const bool text = format.encoding == VtuEncoding::ascii;
  return {std::string("type=\"") + (narrow ? "Int32" : "Int64") + "\" Name=\"" + name + "\"",
          narrow ? encode_values<std::int32_t>(values, text) : encode_values<std::int64_t>(values, text), 16};
}

#ifdef SPHSHELL_HAVE_ZLIB
// VTK's compressed block layout: header [blocks, block size, last block size,
// compressed size of each block] as UInt64, then the compressed blocks.
inline std::string deflate_blocks(const std::string& path, const std::string& data) {
  const std::size_t full_blocks = data.size() / compression_block_bytes;
  const std::size_t last_block = data.size() % compression_block_bytes;
  const std::size_t blocks = full_blocks + (last_block > 0 ? 1 : 0);
  std::vector<std::uint64_t> header{blocks, compression_block_bytes, last_block};
  std::string compressed;
  std::vector<Bytef> buffer(compressBound(static_cast<uLong>(compression_block_bytes)));
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t begin = b * compression_block_bytes;
    const std::size_t size = std::min(compression_block_bytes, data.size() - begin);
    uLongf compressed_size = static_cast<uLongf>(buffer.size());
    const int status = compress2(buffer.data(), &compressed_size, reinterpret_cast<const Bytef*>(data.data() + begin),
                                 static_cast<uLong>(size), Z_DEFAULT_COMPRESSION);
    if (status != Z_OK) invalid_output(path, "zlib compression failed (zlib status " + std::to_string(status) + ")");
    header.push_back(compressed_size);
    compressed.append(reinterpret_cast<const char*>(buffer.data()), compressed_size);
  }
  std::string block;
  block.reserve(header.size() * sizeof(std::uint64_t) + compressed.size());
  for (const std::uint64_t value : header) append_bytes(block, value);
  return block + compressed;
}
#endif

inline std::string appended_block(const std::string& path, const std::string& data, const VtuFormat& format) {
#ifdef SPHSHELL_HAVE_ZLIB
  if (format.encoding == VtuEncoding::zlib) return deflate_blocks(path, data);
#else
  (void)path;
  (void)format;
#endif
  std::string block;
  append_bytes(block, static_cast<std::uint64_t>(data.size()));
  return block + data;
}

inline void write_grid(const std::string& path, const VtuGrid& grid, const VtuFormat& format) {
  validate_format(path, format);
  validate_fields(path, grid.point_fields, grid.points.size(), "point");
  validate_fields(path, grid.cell_fields, grid.cells.size(), "cell");
  if (grid.note.find("--") != std::string::npos) invalid_output(path, "the note must not contain \"--\"");
  std::int64_t largest_index = static_cast<std::int64_t>(grid.cells.connectivity().size());
  for (std::size_t c = 0; c < grid.cells.connectivity().size(); ++c) {
    const std::int64_t point = grid.cells.connectivity()[c];
    if (point < 0 || static_cast<std::size_t>(point) >= grid.points.size())
      invalid_output(path, "a cell refers to point " + std::to_string(point) + " of " +
                               std::to_string(grid.points.size()));
    largest_index = std::max(largest_index, point);
  }
  const bool narrow_indices = largest_index <= std::numeric_limits<std::int32_t>::max();

  std::vector<double> coordinates;
  coordinates.reserve(3 * grid.points.size());
  for (const Vector3& point : grid.points) coordinates.insert(coordinates.end(), {point.x(), point.y(), point.z()});

  const bool text = format.encoding == VtuEncoding::ascii;
  std::vector<EncodedArray> field_data, point_data, cell_data;
  if (std::isfinite(grid.time))
    field_data.push_back({"type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\"",
                          encode_values<double>(std::vector<double>{grid.time}, text), 1});
  for (const Field& field : grid.point_fields) point_data.push_back(encode_field(field, format));
  for (const Field& field : grid.cell_fields) cell_data.push_back(encode_field(field, format));
  const std::vector<EncodedArray> point_coordinates{
      {"type=\"" + real_type(format.precision) + "\" Name=\"Points\" NumberOfComponents=\"3\"",
       encode_reals(coordinates, format), 3}};
  const std::vector<EncodedArray> cell_topology{
      encode_indices("connectivity", grid.cells.connectivity(), narrow_indices, format),
      encode_indices("offsets", grid.cells.offsets(), narrow_indices, format),
      {"type=\"UInt8\" Name=\"types\"", encode_values<std::uint8_t>(grid.cells.types(), text), 16}};

  // The XML with each array inline (ascii) or as an offset into the appended
  // section, whose blocks follow in the order of the tags.
  std::ostringstream head;
  std::vector<std::string> appended;
  std::uint64_t next_offset = 0;
  auto declare = [&](const std::vector<EncodedArray>& arrays, const char* indent) {
    for (const EncodedArray& array : arrays) {
      head << indent << "<DataArray " << array.attributes;
      if (text) {
        head << " format=\"ascii\">\n" << indent << "  ";
        // One tuple per line: a person can find point i on line i.
        std::size_t values_on_line = 0;
        for (std::size_t at = 0; at < array.data.size(); ++at) {
          if (array.data[at] != ' ') {
            head << array.data[at];
            continue;
          }
          if (++values_on_line == array.components && at + 1 < array.data.size()) {
            head << '\n' << indent << "  ";
            values_on_line = 0;
          } else if (at + 1 < array.data.size()) {
            head << ' ';
          }
        }
        head << '\n' << indent << "</DataArray>\n";
      } else {
        appended.push_back(appended_block(path, array.data, format));
        head << " format=\"appended\" offset=\"" << next_offset << "\"/>\n";
        next_offset += appended.back().size();
      }
    }
  };

  head << "<?xml version=\"1.0\"?>\n";
  if (!grid.note.empty()) head << "<!-- " << grid.note << " -->\n";
  head << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
       << (host_is_little_endian() ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\""
       << (format.encoding == VtuEncoding::zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n"
       << "  <UnstructuredGrid>\n";
  if (!field_data.empty()) {
    head << "    <FieldData>\n";
    declare(field_data, "      ");
    head << "    </FieldData>\n";
  }
  head << "    <Piece NumberOfPoints=\"" << grid.points.size() << "\" NumberOfCells=\"" << grid.cells.size()
       << "\">\n";
  head << "      <PointData>\n";
  declare(point_data, "        ");
  head << "      </PointData>\n";
  head << "      <CellData>\n";
  declare(cell_data, "        ");
  head << "      </CellData>\n";
  head << "      <Points>\n";
  declare(point_coordinates, "        ");
  head << "      </Points>\n";
  head << "      <Cells>\n";
  declare(cell_topology, "        ");
  head << "      </Cells>\n"
       << "    </Piece>\n"
       << "  </UnstructuredGrid>\n";

  ReplacingOutputFile file(path);
  std::ostream& out = file.stream();
  out << head.str();
  if (!text) {
    out << "  <AppendedData encoding=\"raw\">\n   _";
    for (const std::string& block : appended) {
      out.write(block.data(), static_cast<std::streamsize>(block.size()));
      file.check();
    }
    out << "\n  </AppendedData>\n";
  }
  out << "</VTKFile>\n";
  file.commit();
}

}  // namespace detail

// Any grid: points, cells of any of the types above, point and cell data.
// Throws Error naming the file (and field) on an unwritable path, a full disk
// (with the system's reason), a field whose size does not match or a cell
// that refers to a missing point. Values are written as they are, NaN
// included (Float32 keeps NaN and infinities; finite values beyond its range
// become infinities).
inline void write_vtu(const std::string& path, const VtuGrid& grid, const VtuFormat& format = {}) {
  detail::write_grid(path, grid, format);
}

// A point cloud (particles, stress points, ...): one VTK_VERTEX cell per point
// so every ParaView representation shows it; fields hold one tuple per point.
inline void write_vtu_points(const std::string& path, const std::vector<Vector3>& positions,
                             const std::vector<PointField>& fields, const VtuFormat& format = {}) {
  VtuGrid grid;
  grid.points = positions;
  for (std::size_t i = 0; i < positions.size(); ++i) grid.cells.add_vertex(static_cast<int>(i));
  grid.point_fields = fields;
  detail::write_grid(path, grid, format);
}

// Line segments (crack segments) between indexed points: segment {i, j} joins
// points[i] and points[j]. Point fields hold one tuple per point, cell fields
// one per segment (e.g. the step at which a segment formed).
inline void write_vtu_lines(const std::string& path, const std::vector<Vector3>& points,
                            const std::vector<std::array<int, 2>>& segments,
                            const std::vector<PointField>& point_fields = {},
                            const std::vector<CellField>& cell_fields = {}, const VtuFormat& format = {}) {
  VtuGrid grid;
  grid.points = points;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    for (const int end : segments[s])
      if (end < 0 || static_cast<std::size_t>(end) >= points.size())
        detail::invalid_output(path, "segment " + std::to_string(s) + " refers to point " +
                                         std::to_string(end) + " of " + std::to_string(points.size()));
    grid.cells.add_line(segments[s][0], segments[s][1]);
  }
  grid.point_fields = point_fields;
  grid.cell_fields = cell_fields;
  detail::write_grid(path, grid, format);
}

// The parallel file (.pvtu) of a grid written in pieces, one .vtu each
// (`pieces`, relative to the .pvtu): the arrays every piece holds, named,
// typed and with components as `layout` (one of the pieces) has them.
inline void write_pvtu(const std::string& path, const VtuGrid& layout, const std::vector<std::string>& pieces,
                       VtuPrecision precision) {
  const std::string real = detail::real_type(precision);
  auto array = [&](std::ostream& out, const Field& field) {
    out << "      <PDataArray type=\"" << (field.kind == FieldValues::integer ? "Int32" : real) << "\" Name=\""
        << field.name << "\"";
    if (field.components > 1) out << " NumberOfComponents=\"" << field.components << "\"";
    out << "/>\n";
  };
  detail::ReplacingOutputFile file(path);
  std::ostream& out = file.stream();
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <PUnstructuredGrid GhostLevel=\"0\">\n"
      << "    <PPointData>\n";
  for (const PointField& field : layout.point_fields) array(out, field);
  out << "    </PPointData>\n"
      << "    <PCellData>\n";
  for (const CellField& field : layout.cell_fields) array(out, field);
  out << "    </PCellData>\n"
      << "    <PPoints>\n"
      << "      <PDataArray type=\"" << real << "\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
      << "    </PPoints>\n";
  for (const std::string& piece : pieces) out << "    <Piece Source=\"" << piece << "\"/>\n";
  out << "  </PUnstructuredGrid>\n"
      << "</VTKFile>\n";
  file.commit();
}

}  // namespace sphshell::io
