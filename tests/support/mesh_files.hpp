#pragma once
// Writes small shell meshes as Gmsh 4.1 .msh (ASCII or little-endian binary)
// and Abaqus/CalculiX .inp files, for the mesh-reader tests. Written from the
// format descriptions, independently of the readers: node tag = index + 1,
// element tag = cell index + 1 (points and lines numbered after the cells).

#include <sphshell/io/output_file.hpp>
#include <sphshell/shell/model.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace sphshell::test_support {

// A fresh directory under the system's temporary directory (never the source
// tree), named after the test and the process (ctest runs test cases in
// parallel processes), removed when it goes out of scope.
class ScratchDirectory {
 public:
  explicit ScratchDirectory(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("sphshell_mesh_tests_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream stream(path, std::ios::binary);
  stream << text;
  if (!stream) throw std::runtime_error("cannot write " + path.string());
}

inline std::string exact(double value) { return io::detail::round_trip_decimal(value); }

// ---------------------------------------------------------------- Gmsh -----

struct GmshEntity {
  int dimension = 2;
  std::vector<std::vector<int>> node_elements;  // dimension 0: {node}, 1: {node, node}
  std::vector<int> cells;                       // dimension 2: indices into GmshMesh::cells
  std::vector<std::string> groups;              // names of the physical groups it belongs to
};

struct GmshMesh {
  std::vector<Vector3> nodes;
  std::vector<Cell> cells;
  std::vector<GmshEntity> entities;
};

class GmshWriter {
 public:
  GmshWriter(const GmshMesh& mesh, bool binary) : mesh_(mesh), binary_(binary) {}

  std::string text() {
    out_.str("");
    // Physical tags per (dimension, name), numbered from 1 in order of appearance.
    for (const GmshEntity& entity : mesh_.entities)
      for (const std::string& group : entity.groups)
        if (!physical_.count({entity.dimension, group}))
          physical_[{entity.dimension, group}] = static_cast<int>(physical_.size()) + 1;
    out_ << "$MeshFormat\n4.1 " << (binary_ ? 1 : 0) << " 8\n";
    if (binary_) {
      put_int(1);
      out_ << "\n";
    }
    out_ << "$EndMeshFormat\n";
    if (!physical_.empty()) {
      out_ << "$PhysicalNames\n" << physical_.size() << "\n";
      for (const auto& [key, tag] : physical_) out_ << key.first << " " << tag << " \"" << key.second << "\"\n";
      out_ << "$EndPhysicalNames\n";
    }
    write_entities();
    write_nodes();
    write_elements();
    return out_.str();
  }

 private:
  void put_int(std::int32_t value) {
    if (binary_) {
      out_.write(reinterpret_cast<const char*>(&value), sizeof value);
    } else {
      out_ << value << " ";
    }
  }
  void put_size(std::uint64_t value) {
    if (binary_) {
      out_.write(reinterpret_cast<const char*>(&value), sizeof value);
    } else {
      out_ << value << " ";
    }
  }
  void put_real(double value) {
    if (binary_) {
      out_.write(reinterpret_cast<const char*>(&value), sizeof value);
    } else {
      out_ << exact(value) << " ";
    }
  }
  void end_line() {
    if (!binary_) out_ << "\n";
  }
  int tag_of(std::size_t entity) const {  // entity tags count per dimension from 1
    int tag = 0;
    for (std::size_t e = 0; e <= entity; ++e) tag += mesh_.entities[e].dimension == mesh_.entities[entity].dimension;
    return tag;
  }
  std::vector<int> nodes_of(const GmshEntity& entity) const {
    std::vector<int> nodes;
    for (const auto& element : entity.node_elements) nodes.insert(nodes.end(), element.begin(), element.end());
    for (int c : entity.cells) nodes.insert(nodes.end(), mesh_.cells[c].begin(), mesh_.cells[c].end());
    return nodes;
  }

  void write_entities() {
    out_ << "$Entities\n";
    std::size_t counts[4] = {0, 0, 0, 0};
    for (const GmshEntity& entity : mesh_.entities) ++counts[entity.dimension];
    for (std::size_t count : counts) put_size(count);
    end_line();
    for (int dimension = 0; dimension < 4; ++dimension)
      for (std::size_t e = 0; e < mesh_.entities.size(); ++e) {
        const GmshEntity& entity = mesh_.entities[e];
        if (entity.dimension != dimension) continue;
        put_int(tag_of(e));
        Vector3 low = Vector3::Constant(1e300), high = Vector3::Constant(-1e300);
        for (int node : nodes_of(entity)) {
          low = low.cwiseMin(mesh_.nodes[node]);
          high = high.cwiseMax(mesh_.nodes[node]);
        }
        for (int c = 0; c < 3; ++c) put_real(low[c]);
        if (dimension > 0)
          for (int c = 0; c < 3; ++c) put_real(high[c]);
        put_size(entity.groups.size());
        for (const std::string& group : entity.groups) put_int(physical_.at({dimension, group}));
        if (dimension > 0) put_size(0);  // bounding entities: not needed by a reader of the mesh
        end_line();
      }
    if (binary_) out_ << "\n";
    out_ << "$EndEntities\n";
  }

  // Each node goes to the first entity of the lowest dimension that uses it, as
  // Gmsh classifies nodes on points, then curves, then surfaces.
  void write_nodes() {
    std::vector<int> owner(mesh_.nodes.size(), -1);
    for (int dimension = 0; dimension < 3; ++dimension)
      for (std::size_t e = 0; e < mesh_.entities.size(); ++e)
        if (mesh_.entities[e].dimension == dimension)
          for (int node : nodes_of(mesh_.entities[e]))
            if (owner[node] < 0) owner[node] = static_cast<int>(e);
    std::map<int, std::vector<int>> blocks;
    for (std::size_t node = 0; node < owner.size(); ++node) blocks[owner[node]].push_back(static_cast<int>(node));
    out_ << "$Nodes\n";
    put_size(blocks.size());
    put_size(mesh_.nodes.size());
    put_size(1);
    put_size(mesh_.nodes.size());
    end_line();
    for (const auto& [entity, nodes] : blocks) {
      put_int(entity < 0 ? 2 : mesh_.entities[entity].dimension);
      put_int(entity < 0 ? 1 : tag_of(entity));
      put_int(0);
      put_size(nodes.size());
      end_line();
      for (int node : nodes) {
        put_size(node + 1);
        end_line();
      }
      for (int node : nodes) {
        for (int c = 0; c < 3; ++c) put_real(mesh_.nodes[node][c]);
        end_line();
      }
    }
    if (binary_) out_ << "\n";
    out_ << "$EndNodes\n";
  }

  void write_elements() {
    struct Block {
      int dimension, tag, type;
      std::vector<std::pair<std::uint64_t, std::vector<int>>> elements;
    };
    std::vector<Block> blocks;
    std::uint64_t next_tag = mesh_.cells.size() + 1;
    std::size_t total = 0;
    for (std::size_t e = 0; e < mesh_.entities.size(); ++e) {
      const GmshEntity& entity = mesh_.entities[e];
      if (entity.dimension < 2) {
        Block block{entity.dimension, tag_of(e), entity.dimension == 0 ? 15 : 1, {}};
        for (const auto& nodes : entity.node_elements) block.elements.push_back({next_tag++, nodes});
        total += block.elements.size();
        blocks.push_back(block);
        continue;
      }
      for (int type : {2, 3}) {  // triangles, then quadrilaterals
        Block block{2, tag_of(e), type, {}};
        for (int c : entity.cells)
          if (mesh_.cells[c].size() == (type == 2 ? 3u : 4u))
            block.elements.push_back({static_cast<std::uint64_t>(c) + 1,
                                      std::vector<int>(mesh_.cells[c].begin(), mesh_.cells[c].end())});
        total += block.elements.size();
        if (!block.elements.empty()) blocks.push_back(block);
      }
    }
    out_ << "$Elements\n";
    put_size(blocks.size());
    put_size(total);
    put_size(1);
    put_size(next_tag - 1);
    end_line();
    for (const Block& block : blocks) {
      put_int(block.dimension);
      put_int(block.tag);
      put_int(block.type);
      put_size(block.elements.size());
      end_line();
      for (const auto& [tag, nodes] : block.elements) {
        put_size(tag);
        for (int node : nodes) put_size(node + 1);
        end_line();
      }
    }
    if (binary_) out_ << "\n";
    out_ << "$EndElements\n";
  }

  const GmshMesh& mesh_;
  bool binary_;
  std::ostringstream out_;
  std::map<std::pair<int, std::string>, int> physical_;
};

inline std::string gmsh_text(const GmshMesh& mesh, bool binary) { return GmshWriter(mesh, binary).text(); }

// -------------------------------------------------------------- Abaqus -----

struct AbaqusMesh {
  std::vector<Vector3> nodes;
  std::vector<Cell> cells;
  std::string quad_type = "S4R", triangle_type = "S3";
  std::vector<std::pair<std::string, std::vector<int>>> node_sets;     // node indices
  std::vector<std::pair<std::string, std::vector<int>>> element_sets;  // cell indices
  std::vector<std::pair<std::string, double>> sections;                // element set, thickness
};

// Labels one-based; a set whose labels run in equal steps is written with
// GENERATE. `node_include` names a file (relative to the deck) that gets the
// *NODE block through *INCLUDE; empty writes it inline.
struct AbaqusFiles {
  std::string deck;
  std::string nodes;  // the included file's text, when node_include is given
};

inline void write_labels(std::ostringstream& out, const std::string& keyword, const std::string& name,
                         const std::vector<int>& indices) {
  bool progression = indices.size() >= 3;
  for (std::size_t k = 2; progression && k < indices.size(); ++k)
    progression = indices[k] - indices[k - 1] == indices[1] - indices[0] && indices[1] > indices[0];
  if (progression) {
    out << keyword << ", " << keyword.substr(1) << "=" << name << ", GENERATE\n"
        << indices.front() + 1 << ", " << indices.back() + 1 << ", " << indices[1] - indices[0] << "\n";
    return;
  }
  out << keyword << ", " << keyword.substr(1) << "=" << name << "\n";
  for (std::size_t k = 0; k < indices.size(); ++k)
    out << indices[k] + 1 << ((k % 16 == 15 || k + 1 == indices.size()) ? "\n" : ", ");
}

inline AbaqusFiles abaqus_text(const AbaqusMesh& mesh, const std::string& node_include = "") {
  AbaqusFiles files;
  std::ostringstream deck, nodes;
  deck << "** written by the sphshell mesh-reader tests\n*Heading\n shell mesh\n";
  nodes << "*Node\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    nodes << i + 1 << ", " << exact(mesh.nodes[i].x()) << ", " << exact(mesh.nodes[i].y()) << ", "
          << exact(mesh.nodes[i].z()) << "\n";
  if (node_include.empty()) {
    deck << nodes.str();
  } else {
    deck << "*INCLUDE, INPUT=" << node_include << "\n";
    files.nodes = nodes.str();
  }
  for (const bool triangles : {false, true}) {
    std::vector<int> chosen;
    for (std::size_t c = 0; c < mesh.cells.size(); ++c)
      if (mesh.cells[c].is_triangle() == triangles) chosen.push_back(static_cast<int>(c));
    if (chosen.empty()) continue;
    // A keyword line continued on the next one.
    deck << "*ELEMENT, TYPE=" << (triangles ? mesh.triangle_type : mesh.quad_type) << ",\n    ELSET="
         << (triangles ? "ALL_TRIANGLES" : "ALL_QUADS") << "\n";
    for (int c : chosen) {
      deck << c + 1;
      for (int corner : mesh.cells[c]) deck << ", " << corner + 1;
      deck << "\n";
    }
  }
  for (const auto& [name, indices] : mesh.node_sets) write_labels(deck, "*NSET", name, indices);
  for (const auto& [name, indices] : mesh.element_sets) write_labels(deck, "*ELSET", name, indices);
  deck << "*Material, name=STEEL\n*Elastic\n210e9, 0.3\n";
  for (const auto& [set, thickness] : mesh.sections)
    deck << "** section\n*Shell Section, elset=" << set << ", material=STEEL\n" << exact(thickness) << ", 5\n";
  deck << "*STEP\n*STATIC\n*BOUNDARY\n1, 1, 3\n*END STEP\n";
  files.deck = deck.str();
  return files;
}

}  // namespace sphshell::test_support
