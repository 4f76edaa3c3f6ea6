#pragma once
// VTK XML UnstructuredGrid (.vtu) output for ParaView: particle or stress-point
// clouds as VTK_VERTEX cells, crack segments as VTK_LINE cells.
//
// Format: file version 1.0 with 64-bit block headers and all arrays in one
// appended raw binary section (host byte order, declared in the header). Raw
// binary is the most compact uncompressed form, costs no encoding time, and
// round-trips every double bit-exactly, NaN and infinities included; the XML
// head stays human-readable. Floating-point data are Float64, cell indices
// Int64.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/output_file.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace sphshell::io {

// A named array attached to every point (or cell): values are stored tuple by
// tuple, values[i * components + k] being component k of point i. Component
// names are optional; when given there must be one per component (ParaView
// shows them instead of 0, 1, 2, ...).
struct Field {
  std::string name;
  int components = 1;
  std::vector<double> values;
  std::vector<std::string> component_names = {};
};
using PointField = Field;
using CellField = Field;

namespace detail {

constexpr std::uint8_t vtk_vertex = 1;
constexpr std::uint8_t vtk_line = 3;

inline bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first_byte = 0;
  std::memcpy(&first_byte, &probe, 1);
  return first_byte == 1;
}

[[noreturn]] inline void invalid_output(const std::string& path, const std::string& what) {
  throw Error("sphshell: cannot write '" + path + "': " + what);
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
  }
}

// One array of the appended section: its XML attributes and where its bytes
// come from.
struct AppendedArray {
  std::string attributes;
  const void* data;
  std::uint64_t bytes;
};

inline std::string field_attributes(const Field& field) {
  std::ostringstream attributes;
  attributes << "type=\"Float64\" Name=\"" << xml_escape(field.name)
             << "\" NumberOfComponents=\"" << field.components << "\"";
  for (std::size_t k = 0; k < field.component_names.size(); ++k)
    attributes << " ComponentName" << k << "=\"" << xml_escape(field.component_names[k]) << "\"";
  return attributes.str();
}

inline void write_unstructured_grid(const std::string& path, const std::vector<Vector3>& points,
                                    const std::vector<std::int64_t>& connectivity,
                                    const std::vector<std::int64_t>& offsets,
                                    const std::vector<std::uint8_t>& types,
                                    const std::vector<Field>& point_fields,
                                    const std::vector<Field>& cell_fields) {
  validate_fields(path, point_fields, points.size(), "point");
  validate_fields(path, cell_fields, types.size(), "cell");

  std::vector<double> coordinates;
  coordinates.reserve(3 * points.size());
  for (const Vector3& point : points) {
    coordinates.push_back(point.x());
    coordinates.push_back(point.y());
    coordinates.push_back(point.z());
  }

  std::vector<AppendedArray> point_arrays, cell_arrays;
  for (const Field& field : point_fields)
    point_arrays.push_back({field_attributes(field), field.values.data(),
                            field.values.size() * sizeof(double)});
  for (const Field& field : cell_fields)
    cell_arrays.push_back({field_attributes(field), field.values.data(),
                           field.values.size() * sizeof(double)});
  const AppendedArray points_array{"type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"",
                                   coordinates.data(), coordinates.size() * sizeof(double)};
  const std::vector<AppendedArray> cell_topology = {
      {"type=\"Int64\" Name=\"connectivity\"", connectivity.data(),
       connectivity.size() * sizeof(std::int64_t)},
      {"type=\"Int64\" Name=\"offsets\"", offsets.data(), offsets.size() * sizeof(std::int64_t)},
      {"type=\"UInt8\" Name=\"types\"", types.data(), types.size() * sizeof(std::uint8_t)}};

  // Arrays are appended in the order their tags appear; each block is a
  // UInt64 byte count followed by the bytes.
  std::vector<const AppendedArray*> appended_order;
  std::uint64_t next_offset = 0;
  std::ostringstream head;
  auto declare = [&](const AppendedArray& array, const char* indent) {
    head << indent << "<DataArray " << array.attributes << " format=\"appended\" offset=\""
         << next_offset << "\"/>\n";
    next_offset += sizeof(std::uint64_t) + array.bytes;
    appended_order.push_back(&array);
  };

  head << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
       << (host_is_little_endian() ? "LittleEndian" : "BigEndian")
       << "\" header_type=\"UInt64\">\n"
       << "  <UnstructuredGrid>\n"
       << "    <Piece NumberOfPoints=\"" << points.size() << "\" NumberOfCells=\"" << types.size()
       << "\">\n";
  head << "      <PointData>\n";
  for (const AppendedArray& array : point_arrays) declare(array, "        ");
  head << "      </PointData>\n";
  head << "      <CellData>\n";
  for (const AppendedArray& array : cell_arrays) declare(array, "        ");
  head << "      </CellData>\n";
  head << "      <Points>\n";
  declare(points_array, "        ");
  head << "      </Points>\n";
  head << "      <Cells>\n";
  for (const AppendedArray& array : cell_topology) declare(array, "        ");
  head << "      </Cells>\n"
       << "    </Piece>\n"
       << "  </UnstructuredGrid>\n"
       << "  <AppendedData encoding=\"raw\">\n"
       << "   _";

  ReplacingOutputFile file(path);
  std::ostream& out = file.stream();
  out << head.str();
  for (const AppendedArray* array : appended_order) {
    out.write(reinterpret_cast<const char*>(&array->bytes), sizeof(array->bytes));
    if (array->bytes > 0)
      out.write(static_cast<const char*>(array->data), static_cast<std::streamsize>(array->bytes));
  }
  out << "\n  </AppendedData>\n</VTKFile>\n";
  file.commit();
}

}  // namespace detail

// A point cloud (particles, stress points, ...): one VTK_VERTEX cell per point
// so every ParaView representation shows it; fields hold one tuple per point.
// Throws Error naming the file and field on an unwritable path or a field
// whose size does not match. Values are written as they are, NaN included.
inline void write_vtu_points(const std::string& path, const std::vector<Vector3>& positions,
                             const std::vector<PointField>& fields) {
  const std::size_t count = positions.size();
  std::vector<std::int64_t> connectivity(count), offsets(count);
  for (std::size_t i = 0; i < count; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  const std::vector<std::uint8_t> types(count, detail::vtk_vertex);
  detail::write_unstructured_grid(path, positions, connectivity, offsets, types, fields, {});
}

// Line segments (crack segments) between indexed points: segment {i, j} joins
// points[i] and points[j]. Point fields hold one tuple per point, cell fields
// one per segment (e.g. the step at which a segment formed).
inline void write_vtu_lines(const std::string& path, const std::vector<Vector3>& points,
                            const std::vector<std::array<int, 2>>& segments,
                            const std::vector<PointField>& point_fields = {},
                            const std::vector<CellField>& cell_fields = {}) {
  std::vector<std::int64_t> connectivity, offsets;
  connectivity.reserve(2 * segments.size());
  offsets.reserve(segments.size());
  for (std::size_t s = 0; s < segments.size(); ++s) {
    for (const int end : segments[s]) {
      if (end < 0 || static_cast<std::size_t>(end) >= points.size())
        detail::invalid_output(path, "segment " + std::to_string(s) + " refers to point " +
                                         std::to_string(end) + " of " +
                                         std::to_string(points.size()));
      connectivity.push_back(end);
    }
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
  }
  const std::vector<std::uint8_t> types(segments.size(), detail::vtk_line);
  detail::write_unstructured_grid(path, points, connectivity, offsets, types, point_fields,
                                  cell_fields);
}

}  // namespace sphshell::io
