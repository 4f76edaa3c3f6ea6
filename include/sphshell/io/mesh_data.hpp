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
// - A particle shared by elements of different thickness takes their
//   area-weighted mean (its mass then equals the shares of its elements').
//   The model's thickness() is that of the element with the lowest label.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
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
};

[[noreturn]] inline void mesh_error(const std::string& where, const std::string& problem) {
  throw Error("sphshell: " + where + ": " + problem);
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

// An element's area from its corners, as ShellModel::from_cells computes it,
// so a degenerate element can be named here.
inline double element_area(const MeshElement& element, const std::vector<Vector3>& corners) {
  const Vector3 doubled = element.node_count == 3
                              ? Vector3((corners[1] - corners[0]).cross(corners[2] - corners[0]))
                              : Vector3((corners[2] - corners[0]).cross(corners[3] - corners[1]));
  return 0.5 * doubled.norm();
}

inline std::string element_name(const MeshData& mesh, const MeshElement& element) {
  return "element " + std::to_string(element.label) + " (" + mesh.describe(element.origin) + ")";
}

// The mesh as a ShellModel (see the conventions at the top). `file` names the
// mesh for messages that concern it as a whole.
inline ShellModel build_shell_model(MeshData& mesh, const std::string& file, double default_thickness) {
  if (mesh.elements.empty())
    mesh_error("mesh file '" + file + "'", "holds no 3-node triangular or 4-node quadrilateral shell element");
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
    if (!(element_area(element, corners) > 0.0))
      mesh_error(mesh.describe(element.origin), "element " + std::to_string(element.label) +
                                                    " has zero area (its nodes are collinear or coincide)");
    const auto p = [&](std::size_t k) { return particle_of.at(element.nodes[k]); };
    cells.push_back(element.node_count == 3 ? Cell(p(0), p(1), p(2)) : Cell(p(0), p(1), p(2), p(3)));
  }
  if (const std::optional<CellEdgeProblem> problem = ShellModel::find_cell_edge_problem(cells)) {
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

  std::vector<double> thickness(mesh.elements.size());
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const MeshElement& element = mesh.elements[e];
    thickness[e] = element.thickness > 0.0 ? element.thickness : default_thickness;
    if (!(thickness[e] > 0.0))
      mesh_error(mesh.describe(element.origin),
                 "element " + std::to_string(element.label) + " has no shell section (no thickness)");
  }
  ShellModel model = ShellModel::from_cells(std::move(positions), cells, thickness.front());

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
