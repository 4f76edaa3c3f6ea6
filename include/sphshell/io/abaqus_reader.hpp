#pragma once
// Reads a shell mesh from an Abaqus or CalculiX input deck (.inp).
//
// Keywords read (case-insensitive, spaces inside them ignored):
// - *NODE (NSET=), one node per line: label, x, y[, z]; an empty or missing
//   coordinate is 0. Direction cosines after z (user normals), SYSTEM other
//   than R and INPUT= are an Error.
// - *ELEMENT, TYPE=..., ELSET= with the 4-node shells S4, S4R, S4R5, S4RS, S4T,
//   S4RT and the 3-node shells S3, S3R, S3RS, STRI3, S3T, S3RT (CalculiX's S4,
//   S4R, S3 among them). Second-order shells (S6, S8, S8R, ...) and any other
//   type are an Error naming it. A data line that ends with a comma before its
//   nodes are complete continues on the next line.
// - *NSET, NSET=... and *ELSET, ELSET=..., with or without GENERATE (first,
//   last[, increment]); members may name sets defined before; *NSET, ELSET=
//   takes the nodes of an element set's elements. A name used again adds to
//   the set; a member listed twice counts once. Set names match regardless of
//   case and keep the spelling of their first definition.
// - *SHELL SECTION, ELSET=... with the thickness first on its data line.
//   COMPOSITE, NODAL THICKNESS and an OFFSET other than 0 are an Error, the
//   other parameters (MATERIAL, ORIENTATION, ...) are ignored. An element in
//   two sections is an Error; one in none takes the reader's default
//   thickness, or is an Error when there is none.
// - *INCLUDE, INPUT=file, the file relative to the including file's folder;
//   its lines take the place of the *INCLUDE line.
// Comment lines (**) and blank lines are skipped; a keyword line ending with
// a comma continues on the next line. Keywords that would change the geometry
// and are not read (*NGEN, *NFILL, *NCOPY, *NMAP, *ELGEN, *ELCOPY, *NORMAL,
// *NODAL THICKNESS, *SHELL GENERAL SECTION, *SYSTEM with data, *PART,
// *ASSEMBLY, *INSTANCE) are an Error; every other keyword (materials, steps,
// loads, boundary conditions, output requests) is skipped with its data lines.
// Element sets become particle sets of their elements' nodes under their own
// name, beside the node sets; particles, stress points, sets and thicknesses
// follow io/mesh_data.hpp's conventions.

#include <sphshell/core/error.hpp>
#include <sphshell/io/mesh_data.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sphshell::io {

namespace detail {

class AbaqusParser {
 public:
  explicit AbaqusParser(const std::string& path) {
    std::vector<std::string> stack;
    flatten(path, stack, nullptr);
  }

  MeshData parse() {
    MeshData mesh;
    mesh.describe = [this](const MeshOrigin& origin) { return where(origin); };
    for (std::size_t l = 0; l < lines_.size(); ++l) {
      const InputLine& line = lines_[l];
      if (line.text[0] == '*') {
        finish_block();
        begin_block(line);
      } else {
        data_line(line, mesh);
      }
    }
    finish_block();
    finish(mesh);
    return mesh;
  }

 private:
  struct InputLine {
    std::string text;  // trimmed; keyword lines with their continuations joined
    MeshOrigin origin;
  };
  struct Keyword {
    std::string name;                          // upper case, single spaces
    std::map<std::string, std::string> value;  // parameter (upper case): value as written
  };
  enum class Block { skip, node, element, node_set, element_set, shell_section, system };
  struct NamedSet {
    std::string key;  // upper-case name
    MeshOrigin origin;
    std::vector<std::pair<long long, MeshOrigin>> members;
    std::vector<std::pair<std::string, MeshOrigin>> element_sets;  // *NSET, ELSET=: their elements' nodes
  };
  struct Section {
    std::string key;
    std::string name;  // as written
    MeshOrigin origin;
    double thickness = 0.0;
  };

  // --- input: files, includes, continuation ------------------------------------
  std::string where(const MeshOrigin& origin) const {
    return "mesh file '" + files_.at(origin.file) + "', line " + std::to_string(origin.position);
  }
  [[noreturn]] void fail(const MeshOrigin& origin, const std::string& problem) const {
    mesh_error(where(origin), problem);
  }

  void flatten(const std::string& path, std::vector<std::string>& stack, const InputLine* include) {
    std::error_code error;
    const std::string canonical = std::filesystem::weakly_canonical(path, error).string();
    if (std::find(stack.begin(), stack.end(), canonical) != stack.end())
      fail(include->origin, "*INCLUDE of '" + path + "' includes itself (directly or through other files)");
    std::ifstream stream(path, std::ios::binary);
    if (!stream) {
      if (include == nullptr) throw Error("sphshell: cannot open mesh file '" + path + "'");
      fail(include->origin, "cannot open the included file '" + path + "' (INPUT= is relative to the including file)");
    }
    stack.push_back(canonical);
    const std::size_t file = files_.size();
    files_.push_back(path);
    std::string raw;
    std::size_t number = 0;
    bool continuing = false;  // the last keyword line ended with a comma
    while (std::getline(stream, raw)) {
      ++number;
      const std::string text = trim(raw);
      if (text.empty() || text.compare(0, 2, "**") == 0) continue;
      if (continuing) {
        lines_.back().text += text;
      } else {
        lines_.push_back({text, {file, number}});
      }
      const bool keyword = lines_.back().text[0] == '*';
      continuing = keyword && lines_.back().text.back() == ',';
      if (keyword && !continuing) {
        const Keyword parsed = parse_keyword(lines_.back());
        if (parsed.name == "INCLUDE") {
          const InputLine include_line = lines_.back();
          lines_.pop_back();
          const auto input = parsed.value.find("INPUT");
          if (input == parsed.value.end() || input->second.empty())
            fail(include_line.origin, "*INCLUDE needs INPUT=<file>");
          std::filesystem::path included(input->second);
          if (included.is_relative()) included = std::filesystem::path(path).parent_path() / included;
          flatten(included.string(), stack, &include_line);
        }
      }
    }
    if (stream.bad()) throw Error("sphshell: failed while reading mesh file '" + path + "'");
    if (continuing) fail(lines_.back().origin, "the keyword line ends with a comma but no line continues it");
    stack.pop_back();
  }

  // Splits at commas outside double quotes, trimming each field.
  static std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (const char character : text) {
      if (character == '"') quoted = !quoted;
      if (character == ',' && !quoted) {
        fields.emplace_back();
      } else {
        fields.back() += character;
      }
    }
    for (std::string& field : fields) field = trim(field);
    return fields;
  }
  static std::string unquote(const std::string& text) {
    if (text.size() >= 2 && text.front() == '"' && text.back() == '"') return text.substr(1, text.size() - 2);
    return text;
  }
  // Upper case without spaces, so "*Shell Section" and "*SHELLSECTION" agree.
  static std::string normalized(const std::string& text) {
    std::string result;
    for (const char character : upper(text))
      if (character != ' ' && character != '\t') result += character;
    return result;
  }

  Keyword parse_keyword(const InputLine& line) const {
    const std::vector<std::string> fields = split(line.text.substr(1));
    Keyword keyword;
    keyword.name = normalized(fields[0]);
    if (keyword.name.empty()) fail(line.origin, "a keyword line without a keyword");
    for (std::size_t f = 1; f < fields.size(); ++f) {
      if (fields[f].empty()) continue;
      const std::size_t equals = fields[f].find('=');
      const std::string name = normalized(fields[f].substr(0, equals));
      const std::string value = equals == std::string::npos ? "" : unquote(trim(fields[f].substr(equals + 1)));
      keyword.value[name] = value;
    }
    return keyword;
  }

  // --- keyword blocks -----------------------------------------------------------
  static bool among(const std::string& name, std::initializer_list<const char*> names) {
    for (const char* candidate : names)
      if (name == candidate) return true;
    return false;
  }
  std::string required(const Keyword& keyword, const InputLine& line, const char* parameter) const {
    const auto found = keyword.value.find(parameter);
    if (found == keyword.value.end() || found->second.empty())
      fail(line.origin, "*" + keyword.name + " needs " + parameter + "=");
    return found->second;
  }
  std::string optional(const Keyword& keyword, const char* parameter) const {
    const auto found = keyword.value.find(parameter);
    return found == keyword.value.end() ? std::string() : found->second;
  }
  // The set of that name (created if new), its key case-insensitive.
  NamedSet& named(std::map<std::string, NamedSet>& sets, std::vector<std::string>& order, const std::string& name,
                  const MeshOrigin& origin) {
    const std::string key = upper(name);
    if (display_.count(key) == 0) display_[key] = name;
    auto [found, inserted] = sets.try_emplace(key);
    if (inserted) {
      found->second.key = key;
      found->second.origin = origin;
      order.push_back(key);
    }
    return found->second;
  }

  void begin_block(const InputLine& line) {
    const Keyword keyword = parse_keyword(line);
    const std::string& name = keyword.name;
    block_ = Block::skip;
    block_origin_ = line.origin;
    if (name == "NODE") {
      if (keyword.value.count("INPUT")) fail(line.origin, "INPUT= on *NODE is not read; use *INCLUDE");
      const std::string system = upper(optional(keyword, "SYSTEM"));
      if (!system.empty() && system != "R")
        fail(line.origin, "*NODE, SYSTEM=" + system + " (non-Cartesian coordinates) is not read");
      current_set_ = optional(keyword, "NSET");
      if (!current_set_.empty()) named(node_sets_, node_set_order_, current_set_, line.origin);
      block_ = Block::node;
    } else if (name == "ELEMENT") {
      if (keyword.value.count("INPUT")) fail(line.origin, "INPUT= on *ELEMENT is not read; use *INCLUDE");
      element_type_ = upper(required(keyword, line, "TYPE"));
      if (among(element_type_, {"S4", "S4R", "S4R5", "S4RS", "S4T", "S4RT"})) {
        element_nodes_ = 4;
      } else if (among(element_type_, {"S3", "S3R", "S3RS", "STRI3", "S3T", "S3RT"})) {
        element_nodes_ = 3;
      } else if (among(element_type_, {"S6", "S8", "S8R", "S8R5", "S9R5", "STRI65", "S8T", "S8RT", "S6T"})) {
        fail(line.origin, "element TYPE=" + element_type_ +
                              " is a second-order shell; only the 3- and 4-node shells (S3, S3R, S4, S4R, ...) are read");
      } else {
        fail(line.origin, "element TYPE=" + element_type_ +
                              " is not a 3- or 4-node shell (S3, S3R, S3RS, STRI3, S4, S4R, S4R5, S4RS)");
      }
      current_set_ = optional(keyword, "ELSET");
      if (!current_set_.empty()) named(element_sets_, element_set_order_, current_set_, line.origin);
      pending_element_.clear();
      block_ = Block::element;
    } else if (name == "NSET" || name == "ELSET") {
      if (keyword.value.count("INSTANCE"))
        fail(line.origin, "*" + name + ", INSTANCE= (assemblies of part instances) is not read");
      const bool nodes = name == "NSET";
      current_set_ = required(keyword, line, nodes ? "NSET" : "ELSET");
      generate_ = keyword.value.count("GENERATE") != 0;
      if (nodes) {
        NamedSet& set = named(node_sets_, node_set_order_, current_set_, line.origin);
        const std::string elements = optional(keyword, "ELSET");
        if (!elements.empty()) set.element_sets.emplace_back(upper(elements), line.origin);
      } else {
        named(element_sets_, element_set_order_, current_set_, line.origin);
      }
      block_ = nodes ? Block::node_set : Block::element_set;
    } else if (name == "SHELLSECTION") {
      if (keyword.value.count("COMPOSITE"))
        fail(line.origin, "*SHELL SECTION, COMPOSITE (layered sections) is not read");
      if (keyword.value.count("NODALTHICKNESS"))
        fail(line.origin, "*SHELL SECTION, NODAL THICKNESS is not read; give the thickness on the data line");
      if (keyword.value.count("OFFSET")) {
        const std::string offset = keyword.value.at("OFFSET");
        double value = 0.0;
        if (!parse_real(offset, value) || value != 0.0)
          fail(line.origin, "*SHELL SECTION, OFFSET=" + offset +
                                " moves the reference surface off the mid-surface; only OFFSET=0 is read");
      }
      const std::string set = required(keyword, line, "ELSET");
      sections_.push_back({upper(set), set, line.origin, 0.0});
      block_ = Block::shell_section;
    } else if (name == "SYSTEM") {
      block_ = Block::system;
    } else if (among(name, {"NGEN", "NFILL", "NCOPY", "NMAP", "ELGEN", "ELCOPY", "NORMAL", "NODALTHICKNESS",
                            "SHELLGENERALSECTION", "PART", "ENDPART", "ASSEMBLY", "ENDASSEMBLY", "INSTANCE",
                            "ENDINSTANCE"})) {
      fail(line.origin, "*" + name + " changes the geometry and is not read (write nodes and elements out "
                                     "explicitly, as a flat input file)");
    }
  }

  void finish_block() {
    if (block_ == Block::element && !pending_element_.empty())
      fail(pending_origin_, "the element data line ends with a comma but no line continues it");
    if (block_ == Block::shell_section && sections_.back().thickness == 0.0)
      fail(block_origin_, "*SHELL SECTION has no data line with the thickness");
    block_ = Block::skip;
  }

  long long label(const std::string& field, const MeshOrigin& origin, const char* what) const {
    long long value = 0;
    if (!parse_integer(field, value)) fail(origin, std::string(what) + " is '" + field + "', not an integer");
    if (value <= 0) fail(origin, std::string(what) + " is " + field + "; labels must be positive");
    return value;
  }

  void data_line(const InputLine& line, MeshData& mesh) {
    std::vector<std::string> fields = split(line.text);
    switch (block_) {
      case Block::skip: return;
      case Block::system: fail(line.origin, "*SYSTEM with data (a local system for node coordinates) is not read");
      case Block::node: return node_line(line, fields, mesh);
      case Block::element: return element_line(line, fields, mesh);
      case Block::node_set: return set_line(line, fields, node_sets_, node_set_order_, true);
      case Block::element_set: return set_line(line, fields, element_sets_, element_set_order_, false);
      case Block::shell_section: {
        Section& section = sections_.back();
        if (section.thickness != 0.0) return;  // integration data or the like
        double thickness = 0.0;
        if (!parse_real(fields[0], thickness))
          fail(line.origin, "the shell thickness is '" + fields[0] + "', not a number");
        if (!(thickness > 0.0)) fail(line.origin, "the shell thickness is " + fields[0] + "; it must be > 0");
        section.thickness = thickness;
        return;
      }
    }
  }

  void node_line(const InputLine& line, const std::vector<std::string>& fields, MeshData& mesh) {
    const long long node = label(fields[0], line.origin, "the node number");
    Vector3 x = Vector3::Zero();
    for (std::size_t c = 1; c < fields.size(); ++c) {
      if (fields[c].empty()) continue;
      if (c > 3)
        fail(line.origin, "node " + fields[0] + " gives a direction after its coordinates; user normals on *NODE are not read");
      if (!parse_real(fields[c], x[c - 1]))
        fail(line.origin, "coordinate " + std::to_string(c) + " of node " + fields[0] + " is '" + fields[c] +
                              "', not a number");
    }
    const auto [found, inserted] = node_origin_.emplace(node, line.origin);
    if (!inserted)
      fail(line.origin, "node " + fields[0] + " is defined twice (also at " + where(found->second) + ")");
    mesh.nodes[node] = x;
    if (!current_set_.empty()) node_sets_.at(upper(current_set_)).members.emplace_back(node, line.origin);
  }

  void element_line(const InputLine& line, std::vector<std::string> fields, MeshData& mesh) {
    const bool continued = !fields.empty() && fields.back().empty() && line.text.back() == ',';
    while (!fields.empty() && fields.back().empty()) fields.pop_back();
    if (pending_element_.empty()) pending_origin_ = line.origin;
    pending_element_.insert(pending_element_.end(), fields.begin(), fields.end());
    const std::size_t needed = element_nodes_ + 1;
    if (pending_element_.size() < needed && continued) return;
    const std::vector<std::string> all = std::move(pending_element_);
    pending_element_.clear();
    const long long element = label(all[0], pending_origin_, "the element number");
    if (all.size() != needed)
      fail(pending_origin_, "element " + all[0] + " of TYPE=" + element_type_ + " lists " +
                                std::to_string(all.size() - 1) + " nodes; it needs " + std::to_string(element_nodes_));
    MeshElement record;
    record.label = element;
    record.node_count = element_nodes_;
    record.origin = pending_origin_;
    for (std::size_t n = 0; n < element_nodes_; ++n)
      record.nodes[n] = label(all[n + 1], pending_origin_, "a node number of an element");
    mesh.elements.push_back(record);
    if (!current_set_.empty())
      element_sets_.at(upper(current_set_)).members.emplace_back(element, pending_origin_);
  }

  void set_line(const InputLine& line, const std::vector<std::string>& fields, std::map<std::string, NamedSet>& sets,
                std::vector<std::string>& order, bool nodes) {
    NamedSet& set = named(sets, order, current_set_, line.origin);
    const char* what = nodes ? "node" : "element";
    if (generate_) {
      std::vector<long long> values;
      for (const std::string& field : fields)
        if (!field.empty()) values.push_back(label(field, line.origin, "a GENERATE value"));
      if (values.size() < 2 || values.size() > 3)
        fail(line.origin, "a GENERATE line needs first, last[, increment]; it has " + std::to_string(values.size()) +
                              " values");
      const long long step = values.size() == 3 ? values[2] : 1;
      if (values[1] < values[0])
        fail(line.origin, "GENERATE from " + std::to_string(values[0]) + " to " + std::to_string(values[1]) +
                              ": the last is below the first");
      // Counted first: each label a file defines takes a line of its own, so a
      // range longer than the input cannot be defined (and would only fill memory).
      const long long count = (values[1] - values[0]) / step + 1;
      if (count > static_cast<long long>(lines_.size()))
        fail(line.origin, "GENERATE from " + std::to_string(values[0]) + " to " + std::to_string(values[1]) + " by " +
                              std::to_string(step) + " names " + std::to_string(count) + " " + what +
                              "s, more than the input's " + std::to_string(lines_.size()) + " lines can define");
      for (long long k = 0; k < count; ++k) set.members.emplace_back(values[0] + k * step, line.origin);
      return;
    }
    for (const std::string& field : fields) {
      if (field.empty()) continue;
      long long member = 0;
      if (parse_integer(field, member)) {
        set.members.push_back({label(field, line.origin, (std::string("a ") + what + " number").c_str()), line.origin});
        continue;
      }
      const auto referenced = sets.find(upper(unquote(field)));
      if (referenced == sets.end() || &referenced->second == &set)
        fail(line.origin, "'" + field + "' is neither a " + what + " number nor a " + what +
                              " set defined before this line");
      const NamedSet copy = referenced->second;  // the target may grow while we copy
      set.members.insert(set.members.end(), copy.members.begin(), copy.members.end());
      set.element_sets.insert(set.element_sets.end(), copy.element_sets.begin(), copy.element_sets.end());
    }
  }

  // --- after the last line -------------------------------------------------------------
  void finish(MeshData& mesh) const {
    std::unordered_map<long long, std::size_t> element_index;
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
      const auto [found, inserted] = element_index.emplace(mesh.elements[e].label, e);
      if (!inserted)
        fail(mesh.elements[e].origin, "element " + std::to_string(mesh.elements[e].label) +
                                          " is defined twice (also at " +
                                          where(mesh.elements[found->second].origin) + ")");
    }
    // The elements of an element set, each once, checked to exist.
    auto elements_of = [&](const std::string& key, const MeshOrigin& reference) {
      const auto set = element_sets_.find(key);
      if (set == element_sets_.end())
        fail(reference, "element set '" + key + "' is not defined in the file");
      std::vector<std::pair<std::size_t, MeshOrigin>> result;
      std::set<long long> seen;
      for (const auto& [element, origin] : set->second.members) {
        const auto found = element_index.find(element);
        if (found == element_index.end())
          fail(origin, "element set " + display_.at(key) + " names element " + std::to_string(element) +
                           ", which the file does not define");
        if (seen.insert(element).second) result.emplace_back(found->second, origin);
      }
      return result;
    };

    std::vector<const Section*> section_of(mesh.elements.size(), nullptr);
    for (const Section& section : sections_) {
      if (element_sets_.count(section.key) == 0)
        fail(section.origin, "*SHELL SECTION names element set '" + section.name + "', which the file does not define");
      for (const auto& [e, origin] : elements_of(section.key, section.origin)) {
        if (section_of[e] != nullptr)
          fail(section.origin, "element " + std::to_string(mesh.elements[e].label) +
                                   " is in this shell section and in the one at " + where(section_of[e]->origin));
        section_of[e] = &section;
        mesh.elements[e].thickness = section.thickness;
      }
    }

    for (const std::string& key : node_set_order_) {
      const NamedSet& named_set = node_sets_.at(key);
      MeshSet set{display_.at(key), named_set.origin, named_set.members};
      for (const auto& [elements, reference] : named_set.element_sets)
        for (const auto& [e, origin] : elements_of(elements, reference))
          for (std::size_t n = 0; n < mesh.elements[e].node_count; ++n)
            set.nodes.emplace_back(mesh.elements[e].nodes[n], origin);
      mesh.sets.push_back(std::move(set));
    }
    for (const std::string& key : element_set_order_) {
      MeshSet set{display_.at(key), element_sets_.at(key).origin, {}};
      for (const auto& [e, origin] : elements_of(key, element_sets_.at(key).origin))
        for (std::size_t n = 0; n < mesh.elements[e].node_count; ++n)
          set.nodes.emplace_back(mesh.elements[e].nodes[n], origin);
      mesh.sets.push_back(std::move(set));
    }
  }

  std::vector<std::string> files_;
  std::vector<InputLine> lines_;
  Block block_ = Block::skip;
  MeshOrigin block_origin_;
  std::string current_set_;
  bool generate_ = false;
  std::string element_type_;
  std::size_t element_nodes_ = 0;
  std::vector<std::string> pending_element_;
  MeshOrigin pending_origin_;
  std::map<long long, MeshOrigin> node_origin_;
  std::map<std::string, std::string> display_;  // upper-case key: name as first written
  std::map<std::string, NamedSet> node_sets_, element_sets_;
  std::vector<std::string> node_set_order_, element_set_order_;
  std::vector<Section> sections_;
};

}  // namespace detail

// The shell in an Abaqus/CalculiX input deck (see the top of this header);
// every element must lie in a *SHELL SECTION.
inline ShellModel read_abaqus(const std::string& path) {
  detail::AbaqusParser parser(path);
  detail::MeshData mesh = parser.parse();
  return detail::build_shell_model(mesh, path, 0.0);
}

// As above; elements in no *SHELL SECTION take thickness d (m).
inline ShellModel read_abaqus(const std::string& path, double thickness_without_section) {
  sphshell::detail::require_positive("thickness_without_section", thickness_without_section);
  detail::AbaqusParser parser(path);
  detail::MeshData mesh = parser.parse();
  return detail::build_shell_model(mesh, path, thickness_without_section);
}

}  // namespace sphshell::io
