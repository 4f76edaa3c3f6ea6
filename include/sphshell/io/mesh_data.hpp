#pragma once
// What the mesh readers (io/gmsh_reader.hpp, io/abaqus_reader.hpp) share: the
// mesh as read (labelled nodes, shell elements, named node sets, each with
// where in the file it came from) and its conversion into a ShellModel.
//
// Conventions, the same for every format:
// - Particles are the nodes that shell elements use, in increasing node label;
//   nodes of no shell element (geometry points, reference nodes) are dropped.
// - Stress points are the elements, in increasing element label.
// - Named sets hold particle indices in increasing order, each once. A set
//   naming a node of no shell element is an Error. Two sets of the same name
//   (a node set and an element set of one region, as preprocessors often
//   write) are kept once when they hold the same particles, else an Error.
// - Elements listed the other way round from their neighbours (across shared
//   edges) are turned to agree with the orientation most elements of their
//   connected part have; ShellModel::turned_cells lists them (stress point
//   indices). A one-sided surface (a Moebius strip) is an Error naming two
//   elements that cannot agree.
// - A particle shared by elements of different thickness takes their
//   area-weighted mean (its mass then equals the shares of its elements').
//   The model's thickness() is that of the element with the lowest label.
// - The file must be a regular file (not a directory or a device); its size
//   times parsed_bytes_per_input_byte must fit in the memory available before
//   it is read. An allocation that fails anyway is an Error with the estimate.
// - A UTF-8 byte order mark at the start of a file is skipped.
// - Coordinates beyond ±largest_coordinate are refused (a unit or format
//   mistake); so is every element whose shape the solver cannot use: corners
//   that coincide or lie on one line, a corner of (nearly) 180° (more than
//   straight_corner_degrees), a bow-tie quad, and an element whose normal
//   points against the mean normal of the elements at one of its nodes (it
//   folds back, or is attached at a single node with the opposite
//   orientation). Each names the element, its file and line.

#include <sphshell/approx/memory_estimate.hpp>
#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <ios>
#include <new>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace sphshell::io::detail {

// A place in a mesh file: which file (index into the reader's list, for
// includes) and where in it (a line, or a byte offset in binary data).
struct MeshOrigin {
  std::size_t file = 0;
  std::size_t position = 0;
};

struct MeshElement {
  long long label = 0;
  std::array<long long, 4> nodes{};
  std::size_t node_count = 0;
  MeshOrigin origin;
  double thickness = 0.0;  // 0: none given (a reader's default applies)
};

struct MeshSet {
  std::string name;
  MeshOrigin origin;  // where the set is (first) defined
  std::vector<std::pair<long long, MeshOrigin>> nodes;  // node label, where it is listed
};

struct MeshData {
  std::map<long long, Vector3> nodes;  // by label
  std::vector<MeshElement> elements;
  std::vector<MeshSet> sets;
  // Text for an origin, such as "mesh file 'plate.inp', line 12".
  std::function<std::string(const MeshOrigin&)> describe;
  // The end of the (main) file, for what concerns the mesh as a whole.
  MeshOrigin end;
};

[[noreturn]] inline void mesh_error(const std::string& where, const std::string& problem) {
  throw Error("sphshell: " + where + ": " + problem);
}

// Limits of what a mesh file may hold (see the conventions at the top).
// A coordinate beyond a million kilometres (in metres; a thousand in mm) is
// no shell's: a unit or format mistake, and its squares overflow.
inline constexpr double largest_coordinate = 1e9;
// A corner this close to straight makes a quad a triangle with a node on its
// edge: its two corner triangles give no independent direction.
inline constexpr double straight_corner_degrees = 179.0;
// The reader's own structures per byte of a text mesh: the line records, the
// node and element maps and their origins take up to about this many bytes
// for each byte of a short node or element line.
inline constexpr double parsed_bytes_per_input_byte = 16.0;

// A UTF-8 byte order mark, which some editors put before the first line.
inline constexpr char utf8_bom[] = "\xEF\xBB\xBF";
inline bool starts_with_bom(const std::string& text) { return text.compare(0, 3, utf8_bom) == 0; }

// The operating system's reason for the last failure (errno), for messages.
inline std::string system_reason(int code) { return code != 0 ? std::strerror(code) : "unknown reason"; }

// A path to read as a mesh: it must exist and be a regular file (a directory
// or a device would fail half-way, or never end). An Error naming the path
// and the reason otherwise.
inline std::uintmax_t require_regular_file(const std::string& path, const std::string& what) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error) throw Error("sphshell: cannot open " + what + " '" + path + "': " + error.message());
  const auto kind = status.type();
  if (kind != std::filesystem::file_type::regular) {
    const char* name = kind == std::filesystem::file_type::directory   ? "a directory"
                       : kind == std::filesystem::file_type::character ? "a character device"
                       : kind == std::filesystem::file_type::block     ? "a block device"
                       : kind == std::filesystem::file_type::fifo      ? "a pipe"
                       : kind == std::filesystem::file_type::socket    ? "a socket"
                                                                       : "not a file";
    throw Error("sphshell: cannot read " + what + " '" + path + "': it is " + name + ", not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw Error("sphshell: cannot read " + what + " '" + path + "': " + error.message());
  return size;
}

// The memory `what` needs against what the machine offers (approx/memory_estimate.hpp):
// an Error with both figures, before anything is allocated.
inline void require_memory(const std::string& what, double bytes) {
  const double available = approx::available_memory();
  if (bytes > available)
    throw Error("sphshell: " + what + " needs about " + approx::format_bytes(bytes) + " of memory; " +
                approx::format_bytes(available) +
                " available (MemAvailable, the cgroup limit and ulimit -v)");
}

// Runs a public reader's work; an allocation or stream failure that gets
// through the estimates becomes an Error naming the file and the estimate.
template <class Work>
auto guard_reading(const std::string& path, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const std::bad_alloc&) {
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    const double estimate = error ? 0.0 : parsed_bytes_per_input_byte * static_cast<double>(size);
    throw Error("sphshell: out of memory reading mesh file '" + path + "' (std::bad_alloc; estimated " +
                approx::format_bytes(estimate) + ", " + approx::format_bytes(approx::available_memory()) +
                " available)");
  } catch (const std::ios_base::failure& failure) {
    throw Error("sphshell: failed while reading mesh file '" + path + "': " + failure.what());
  }
}

// The edit distance between two names, for "did you mean" suggestions.
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}
// The candidate nearest to `name` (compared by `key`), for a suggestion.
template <class Key>
std::string nearest_name(const std::string& name, const std::vector<std::string>& candidates, Key&& key) {
  std::string best;
  std::size_t best_distance = static_cast<std::size_t>(-1);
  for (const std::string& candidate : candidates) {
    const std::size_t distance = edit_distance(key(name), key(candidate));
    if (distance < best_distance) best_distance = distance, best = candidate;
  }
  return best;
}

// A byte that has no place in a text mesh (a control character other than
// tab and carriage return): a binary or corrupted file. Its index, or npos.
inline std::size_t find_control_byte(const std::string& text) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    const auto byte = static_cast<unsigned char>(text[k]);
    if ((byte < 0x20 && byte != '\t' && byte != '\r' && byte != '\n') || byte == 0x7F) return k;
  }
  return std::string::npos;
}
inline std::string byte_text(unsigned char byte) {
  static const char digits[] = "0123456789ABCDEF";
  return std::string("0x") + digits[byte >> 4] + digits[byte & 15];
}

inline std::string trim(const std::string& text) {
  const char* space = " \t\r\n\f\v";
  const std::size_t first = text.find_first_not_of(space);
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(space) - first + 1);
}

inline std::string upper(std::string text) {
  for (char& character : text)
    if (character >= 'a' && character <= 'z') character = static_cast<char>(character - 'a' + 'A');
  return text;
}

// Whole-field number parsing; false when text is not entirely a number.
inline bool parse_integer(const std::string& text, long long& value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end && begin != end;
}

inline bool parse_real(const std::string& text, double& value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end && begin != end && std::isfinite(value);
}

// What is wrong with an element's shape, completing "element L ...", or ""
// when the solver can use it: coincident or collinear corners, a straight
// (≈ 180°) corner, a bow-tie quad (the limits of shell/model_checks.hpp and
// straight_corner_degrees).
inline std::string element_shape_problem(const MeshElement& element, const std::vector<Vector3>& corners) {
  const std::size_t n = element.node_count;
  const auto node = [&](std::size_t k) { return std::to_string(element.nodes[k % n]); };
  double longest_squared = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double length_squared = (corners[(k + 1) % n] - corners[k]).squaredNorm();
    if (!(length_squared > 0.0))
      return "has zero area: nodes " + node(k) + " and " + node(k + 1) + " are at the same place";
    longest_squared = std::max(longest_squared, length_squared);
  }
  Vector3 largest_corner = Vector3::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const Vector3 corner = (corners[(k + 1) % n] - corners[k]).cross(corners[(k + n - 1) % n] - corners[k]);
    if (corner.norm() > largest_corner.norm()) largest_corner = corner;
  }
  const double fraction = sphshell::detail::model_checks::degenerate_area_fraction;
  if (!(0.5 * largest_corner.norm() > fraction * longest_squared))
    return "has zero area: its nodes are collinear (a degenerate element)";
  const double straight = std::cos(straight_corner_degrees * 3.14159265358979323846 / 180.0);
  for (std::size_t k = 0; k < n; ++k) {
    const Vector3 next = corners[(k + 1) % n] - corners[k], previous = corners[(k + n - 1) % n] - corners[k];
    if (next.dot(previous) < straight * next.norm() * previous.norm())
      return "has a straight corner at node " + node(k) + " (more than " +
             std::to_string(static_cast<int>(straight_corner_degrees)) +
             " degrees): a degenerate element; split it or move the node";
  }
  if (n == 3) return "";
  const Vector3 doubled = (corners[2] - corners[0]).cross(corners[3] - corners[1]);
  const bool diagonals_span = 0.5 * doubled.norm() > fraction * longest_squared;
  const Vector3 axis = diagonals_span ? doubled.normalized() : largest_corner.normalized();
  int reversed_turns = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const Vector3 next = corners[(k + 1) % 4] - corners[k], previous = corners[(k + 3) % 4] - corners[k];
    if (next.cross(previous).dot(axis) < 0.0) ++reversed_turns;
  }
  if (reversed_turns >= 2 || !diagonals_span)
    return "has crossing edges (a bow-tie): list its nodes " + node(0) + ", " + node(1) + ", " + node(2) + ", " +
           node(3) + " in order around the element";
  return "";
}

inline std::string element_name(const MeshData& mesh, const MeshElement& element) {
  return "element " + std::to_string(element.label) + " (" + mesh.describe(element.origin) + ")";
}

// Every element's normal agrees with the mean normal (area-weighted, as the
// model's particle directors) at each of its nodes; one that points against
// it folds back onto its neighbours, or meets them at that node alone with
// its nodes in the opposite order: an Error naming it and an element it
// opposes, before the model's own checks would name a particle instead.
inline void check_no_fold(const MeshData& mesh, const std::vector<Cell>& cells, const std::vector<Vector3>& positions,
                          const std::vector<long long>& node_of_particle) {
  std::vector<Vector3> cell_normal(cells.size());
  std::vector<Vector3> node_normal(positions.size(), Vector3::Zero());
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const Cell& cell = cells[c];
    const auto x = [&](std::size_t k) { return positions[static_cast<std::size_t>(cell[k])]; };
    cell_normal[c] = cell.is_triangle() ? Vector3((x(1) - x(0)).cross(x(2) - x(0))) : Vector3((x(2) - x(0)).cross(x(3) - x(1)));
    for (int corner : cell) node_normal[static_cast<std::size_t>(corner)] += cell_normal[c];
  }
  for (std::size_t c = 0; c < cells.size(); ++c)
    for (int corner : cells[c]) {
      if (cell_normal[c].dot(node_normal[static_cast<std::size_t>(corner)]) > 0.0) continue;
      std::size_t opposed = c;  // the element at this node most opposite to c
      double lowest = 0.0;
      for (std::size_t d = 0; d < cells.size(); ++d) {
        if (std::find(cells[d].begin(), cells[d].end(), corner) == cells[d].end()) continue;
        const double cosine = cell_normal[c].normalized().dot(cell_normal[d].normalized());
        if (cosine < lowest) lowest = cosine, opposed = d;
      }
      const std::string node = std::to_string(node_of_particle[static_cast<std::size_t>(corner)]);
      mesh_error(mesh.describe(mesh.elements[c].origin),
                 "element " + std::to_string(mesh.elements[c].label) + " points against the elements around node " +
                     node + (opposed != c ? " (such as " + element_name(mesh, mesh.elements[opposed]) + ")" : "") +
                     ": its normal is opposite theirs; it folds back onto them, or meets them at node " + node +
                     " alone with its nodes listed in the opposite order (reverse them)");
    }
}

// The mesh as a ShellModel (see the conventions at the top). `file` names the
// mesh for messages that concern it as a whole.
inline ShellModel build_shell_model(MeshData& mesh, const std::string& file, double default_thickness) {
  if (mesh.elements.empty())
    mesh_error(mesh.describe(mesh.end) + " (its end)",
               "the file holds no 3-node triangular or 4-node quadrilateral shell element");
  sphshell::detail::model_checks::require_model_memory(
      "mesh file '" + file + "'", static_cast<double>(mesh.nodes.size()), static_cast<double>(mesh.elements.size()));
  std::sort(mesh.elements.begin(), mesh.elements.end(),
            [](const MeshElement& a, const MeshElement& b) { return a.label < b.label; });
  for (std::size_t e = 1; e < mesh.elements.size(); ++e)
    if (mesh.elements[e].label == mesh.elements[e - 1].label)
      mesh_error(mesh.describe(mesh.elements[e].origin),
                 "element " + std::to_string(mesh.elements[e].label) + " is defined twice (also at " +
                     mesh.describe(mesh.elements[e - 1].origin) + ")");

  std::unordered_set<long long> used;
  for (const MeshElement& element : mesh.elements)
    for (std::size_t k = 0; k < element.node_count; ++k) {
      const long long node = element.nodes[k];
      if (mesh.nodes.count(node) == 0)
        mesh_error(mesh.describe(element.origin), "element " + std::to_string(element.label) + " names node " +
                                                      std::to_string(node) + ", which the file does not define");
      for (std::size_t l = 0; l < k; ++l)
        if (element.nodes[l] == node)
          mesh_error(mesh.describe(element.origin), "element " + std::to_string(element.label) +
                                                        " lists node " + std::to_string(node) +
                                                        " twice (a degenerate element)");
      used.insert(node);
    }

  std::unordered_map<long long, int> particle_of;
  std::vector<Vector3> positions;
  std::vector<long long> node_of_particle;
  for (const auto& [label, position] : mesh.nodes)
    if (used.count(label) != 0) {
      particle_of[label] = static_cast<int>(positions.size());
      positions.push_back(position);
      node_of_particle.push_back(label);
    }

  std::vector<Cell> cells;
  cells.reserve(mesh.elements.size());
  for (const MeshElement& element : mesh.elements) {
    std::vector<Vector3> corners;
    for (std::size_t k = 0; k < element.node_count; ++k) corners.push_back(mesh.nodes.at(element.nodes[k]));
    const std::string shape = element_shape_problem(element, corners);
    if (!shape.empty())
      mesh_error(mesh.describe(element.origin), "element " + std::to_string(element.label) + " " + shape);
    const auto p = [&](std::size_t k) { return particle_of.at(element.nodes[k]); };
    cells.push_back(element.node_count == 3 ? Cell(p(0), p(1), p(2)) : Cell(p(0), p(1), p(2), p(3)));
  }
  // Elements listed the other way round from their neighbours are turned to
  // agree with them (the orientation most elements of their part have);
  // model.turned_cells lists them. Only a mesh with such a flip is searched.
  std::vector<int> turned;
  std::optional<CellEdgeProblem> edge_problem = ShellModel::find_cell_edge_problem(cells);
  if (edge_problem && edge_problem->kind == CellEdgeProblem::Kind::flipped) {
    const sphshell::detail::model_checks::Orientation orientation = sphshell::detail::model_checks::orient_cells(cells);
    if (orientation.problem) {
      const CellEdgeProblem& problem = *orientation.problem;
      mesh_error(mesh.describe(mesh.elements[problem.second_cell].origin),
                 element_name(mesh, mesh.elements[problem.first_cell]) + " and " +
                     element_name(mesh, mesh.elements[problem.second_cell]) + " meet at the edge between nodes " +
                     std::to_string(node_of_particle[problem.edge_start]) + " and " +
                     std::to_string(node_of_particle[problem.edge_end]) +
                     " with opposite orientations however the elements are turned: the surface is one-sided "
                     "(a Moebius strip) and has no consistent normal");
    }
    for (int c : orientation.turned) {
      cells[c] = sphshell::detail::model_checks::turned(cells[c]);
      MeshElement& element = mesh.elements[c];
      std::reverse(element.nodes.begin() + 1, element.nodes.begin() + static_cast<std::ptrdiff_t>(element.node_count));
    }
    turned = orientation.turned;
    edge_problem = ShellModel::find_cell_edge_problem(cells);
  }
  if (const std::optional<CellEdgeProblem> problem = edge_problem) {
    const MeshElement& first = mesh.elements[problem->first_cell];
    const MeshElement& second = mesh.elements[problem->second_cell];
    const std::string edge = "the edge between nodes " + std::to_string(node_of_particle[problem->edge_start]) +
                             " and " + std::to_string(node_of_particle[problem->edge_end]);
    const std::string pair = element_name(mesh, first) + " and " + element_name(mesh, second);
    if (problem->kind == CellEdgeProblem::Kind::flipped)
      mesh_error("mesh file '" + file + "'",
                 pair + " run along " + edge +
                     " in the same direction, so their normals flip there; reverse the node order of one side");
    mesh_error("mesh file '" + file + "'",
               pair + " both lie on " + edge + " with a third element; a junction of three or more elements " +
                   "is not supported (a particle has one director)");
  }
  check_no_fold(mesh, cells, positions, node_of_particle);

  std::vector<double> thickness(mesh.elements.size());
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const MeshElement& element = mesh.elements[e];
    thickness[e] = element.thickness > 0.0 ? element.thickness : default_thickness;
    if (!(thickness[e] > 0.0))
      mesh_error(mesh.describe(element.origin),
                 "element " + std::to_string(element.label) + " has no shell section (no thickness)");
  }
  ShellModel model = ShellModel::from_cells(std::move(positions), cells, thickness.front());
  model.turned_cells = std::move(turned);

  // Particles: the area-weighted mean of their elements' thicknesses, exactly
  // the common value where all agree.
  std::vector<double> weighted(model.particle_count(), 0.0), weight(model.particle_count(), 0.0);
  std::vector<double> first(model.particle_count(), 0.0);
  std::vector<char> uniform(model.particle_count(), 1);
  for (std::size_t e = 0; e < cells.size(); ++e) {
    const double share = model.stress_point_area[e] / static_cast<double>(cells[e].size());
    if (thickness[e] != model.thickness()) model.set_stress_point_thickness(e, thickness[e]);
    for (int corner : cells[e]) {
      if (weight[corner] == 0.0) first[corner] = thickness[e];
      if (thickness[e] != first[corner]) uniform[corner] = 0;
      weighted[corner] += share * thickness[e];
      weight[corner] += share;
    }
  }
  for (std::size_t i = 0; i < model.particle_count(); ++i) {
    const double d = uniform[i] ? first[i] : weighted[i] / weight[i];
    if (d != model.thickness()) model.set_particle_thickness(i, d);
  }

  std::map<std::string, std::pair<ParticleSet, MeshOrigin>> added;  // name: members, where defined
  for (const MeshSet& set : mesh.sets) {
    ParticleSet members;
    for (const auto& [node, origin] : set.nodes) {
      const auto found = particle_of.find(node);
      if (found != particle_of.end()) {
        members.push_back(found->second);
        continue;
      }
      if (mesh.nodes.count(node) == 0)
        mesh_error(mesh.describe(origin),
                   "set " + set.name + " names node " + std::to_string(node) + ", which the file does not define");
      mesh_error(mesh.describe(origin), "set " + set.name + " names node " + std::to_string(node) +
                                            ", which belongs to no shell element (only nodes of shell elements "
                                            "become particles)");
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    if (members.empty()) mesh_error(mesh.describe(set.origin), "set " + set.name + " holds no node");
    const auto previous = added.find(set.name);
    if (previous != added.end()) {
      if (previous->second.first == members) continue;
      mesh_error(mesh.describe(set.origin), "set name " + set.name + " is also used at " +
                                                mesh.describe(previous->second.second) +
                                                " for different nodes; both would become the particle set " +
                                                set.name);
    }
    model.add_set(set.name, members);
    added.emplace(set.name, std::make_pair(std::move(members), set.origin));
  }
  return model;
}

}  // namespace sphshell::io::detail
