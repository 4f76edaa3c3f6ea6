#pragma once
// Reads a shell mesh from an Abaqus or CalculiX input deck (.inp).
//
// Keywords read (case-insensitive, spaces inside them ignored):
// - *NODE (NSET=), one node per line: label, x, y[, z]; an empty or missing
//   coordinate is 0. Direction cosines after z (user normals), SYSTEM other
//   than R and INPUT= are an Error.
// - *ELEMENT, TYPE=..., ELSET= with the 4-node shells S4, S4R, S4R5, S4RS, S4T,
//   S4RT and the 3-node shells S3, S3R, S3RS, STRI3, S3T, S3RT (CalculiX's S4,
//   S4R, S3 among them). The plane-stress and membrane faces CPS3, CPS4,
//   CPS4R, M3D3, M3D4, M3D4R (what a mesher such as Gmsh writes for a surface)
//   are read as shell geometry: they take the thickness of a *SHELL SECTION
//   naming them, else the reader's thickness argument (a *SOLID SECTION or
//   *MEMBRANE SECTION thickness is not read). The 2-node lines T3D2, T2D2, B31,
//   B21 (and their H variants) only carry their nodes to the element sets
//   they are in (Gmsh writes a surface's curves so), like Gmsh line elements.
//   Second-order shells (S6, S8, S8R, ...) and any other type are an Error
//   naming it. A data line that ends with a comma before its nodes are
//   complete continues on the next line.
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
// a comma continues on the next line; a UTF-8 byte order mark is skipped.
// Keywords that would change the geometry and are not read (*NGEN, *NFILL,
// *NCOPY, *NMAP, *ELGEN, *ELCOPY, *NORMAL, *NODAL THICKNESS, *SHELL GENERAL
// SECTION, *SYSTEM with data, *PART, *ASSEMBLY, *INSTANCE) are an Error. The
// keywords of materials, sections of other kinds, interactions, steps, loads,
// boundary conditions and output requests in the list skipped_keywords() are
// skipped with their data lines. Any other keyword, and a parameter a read
// keyword does not take, is an Error naming it and the nearest known one (a
// misspelled *ELEMENT would otherwise drop every element after it). A node
// line needs x and y (z may be left out); a control character in a line, or
// a data line before the first keyword, is an Error.
// Element sets become particle sets of their elements' nodes under their own
// name, beside the node sets; particles, stress points, sets and thicknesses
// follow io/mesh_data.hpp's conventions.

#include <sphshell/core/error.hpp>
#include <sphshell/io/mesh_data.hpp>
#include <sphshell/shell/model.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
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
    mesh.end = end_;
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
    std::string name;                          // upper case, without spaces
    std::string written;                       // as in the file
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
    std::uintmax_t size = 0;
    try {
      size = require_regular_file(path, include == nullptr ? "mesh file" : "the included file");
    } catch (const Error& error) {
      if (include == nullptr) throw;
      fail(include->origin, std::string(error.what()).substr(std::string("sphshell: ").size()) +
                                " (INPUT= is relative to the including file)");
    }
    input_bytes_ += static_cast<double>(size);
    require_memory("reading mesh file '" + path + "' (" + std::to_string(size) + " bytes, with the files before it)",
                   parsed_bytes_per_input_byte * input_bytes_);
    errno = 0;
    std::ifstream stream(path, std::ios::binary);
    if (!stream) {
      const std::string reason = system_reason(errno);
      if (include == nullptr) throw Error("sphshell: cannot open mesh file '" + path + "': " + reason);
      fail(include->origin, "cannot open the included file '" + path + "': " + reason +
                                " (INPUT= is relative to the including file)");
    }
    stack.push_back(canonical);
    const std::size_t file = files_.size();
    files_.push_back(path);
    std::string raw;
    std::size_t number = 0;
    bool continuing = false;  // the last keyword line ended with a comma
    while (std::getline(stream, raw)) {
      ++number;
      if (number == 1 && starts_with_bom(raw)) raw.erase(0, 3);
      const std::size_t control = find_control_byte(raw);
      if (control != std::string::npos)
        fail({file, number}, "the line holds the byte " + byte_text(static_cast<unsigned char>(raw[control])) +
                                 " at column " + std::to_string(control + 1) +
                                 ", a control character (a binary or corrupted file?)");
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
    if (stream.bad()) throw Error("sphshell: failed while reading mesh file '" + path + "': " + system_reason(errno));
    if (continuing) fail(lines_.back().origin, "the keyword line ends with a comma but no line continues it");
    if (include == nullptr) end_ = {file, number};
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
    keyword.written = fields[0];
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

  // The keywords this reader knows, as written in the manuals: those it
  // reads, those that change the geometry and are refused, and those it
  // skips with their data lines (they describe materials, the analysis and
  // its output, not the mesh). Any other keyword is an Error naming it and
  // the nearest of these: a misspelled *ELEMENT would otherwise drop every
  // element after it.
  static const std::vector<std::string>& read_keywords() {
    static const std::vector<std::string> names = {"NODE", "ELEMENT", "NSET", "ELSET", "SHELL SECTION", "INCLUDE",
                                                   "SYSTEM"};
    return names;
  }
  static const std::vector<std::string>& refused_keywords() {
    static const std::vector<std::string> names = {
        "NGEN",     "NFILL",    "NCOPY",    "NMAP",        "ELGEN",    "ELCOPY",       "NORMAL",
        "NODAL THICKNESS",      "SHELL GENERAL SECTION",   "PART",     "END PART",     "ASSEMBLY",
        "END ASSEMBLY",         "INSTANCE", "END INSTANCE"};
    return names;
  }
  static const std::vector<std::string>& skipped_keywords() {
    static const std::vector<std::string> names = {
        // model data that is not the mesh
        "HEADING", "PREPRINT", "PARAMETER", "PHYSICAL CONSTANTS", "MATERIAL", "ELASTIC", "PLASTIC", "DENSITY",
        "EXPANSION", "CONDUCTIVITY", "SPECIFIC HEAT", "DAMPING", "HYPERELASTIC", "HYPERFOAM", "DEPVAR",
        "USER MATERIAL", "CREEP", "DEFORMATION PLASTICITY", "DAMAGE INITIATION", "DAMAGE EVOLUTION",
        "SHEAR FAILURE", "TENSILE FAILURE", "RATE DEPENDENT", "ORIENTATION", "TRANSFORM", "SOLID SECTION",
        "MEMBRANE SECTION", "BEAM SECTION", "BEAM GENERAL SECTION", "TRUSS SECTION", "SECTION CONTROLS",
        "HOURGLASS STIFFNESS", "TRANSVERSE SHEAR STIFFNESS", "SURFACE", "SURFACE INTERACTION",
        "SURFACE BEHAVIOR", "FRICTION", "CONTACT PAIR", "CONTACT", "CONTACT INCLUSIONS",
        "CONTACT PROPERTY ASSIGNMENT", "TIE", "COUPLING", "KINEMATIC", "DISTRIBUTING", "EQUATION", "MPC",
        "RIGID BODY", "MASS", "ROTARY INERTIA", "SPRING", "DASHPOT", "AMPLITUDE", "INITIAL CONDITIONS",
        "FILM", "RADIATE", "GAP", "USER ELEMENT",
        // history data: steps, loads, output requests
        "STEP", "END STEP", "STATIC", "DYNAMIC", "FREQUENCY", "BUCKLE", "VISCO", "HEAT TRANSFER",
        "COUPLED TEMPERATURE-DISPLACEMENT", "CONTROLS", "SOLVER CONTROLS", "BOUNDARY", "CLOAD", "DLOAD", "DSLOAD",
        "TEMPERATURE", "CFLUX", "DFLUX", "CHANGE MATERIAL", "MODEL CHANGE", "OUTPUT", "NODE OUTPUT",
        "ELEMENT OUTPUT", "CONTACT OUTPUT", "ENERGY OUTPUT", "NODE PRINT", "EL PRINT", "NODE FILE", "EL FILE",
        "CONTACT FILE", "CONTACT PRINT", "SECTION PRINT", "ENERGY PRINT", "RESTART", "MONITOR", "FILE FORMAT",
        "TIME POINTS", "BULK VISCOSITY", "VARIABLE MASS SCALING", "FIXED MASS SCALING", "DIAGNOSTICS",
        "SUBMODEL", "PRINT", "NODE RESPONSE", "MODAL DAMPING", "SELECT EIGENMODES"};
    return names;
  }
  // The parameters a read keyword takes; another is an Error with a suggestion
  // (a misspelled ELSET= would otherwise drop the set).
  static const std::vector<std::string>& parameters_of(const std::string& keyword) {
    static const std::map<std::string, std::vector<std::string>> parameters = {
        {"NODE", {"NSET", "SYSTEM", "INPUT"}},
        {"ELEMENT", {"TYPE", "ELSET", "INPUT", "FILE"}},
        {"NSET", {"NSET", "ELSET", "GENERATE", "INSTANCE", "INTERNAL", "UNSORTED"}},
        {"ELSET", {"ELSET", "GENERATE", "INSTANCE", "INTERNAL", "UNSORTED"}},
        {"SHELLSECTION",
         {"ELSET", "MATERIAL", "OFFSET", "ORIENTATION", "SECTION INTEGRATION", "CONTROLS", "COMPOSITE",
          "NODAL THICKNESS", "POISSON", "DENSITY", "TEMPERATURE", "THICKNESS MODULUS", "SYMMETRIC", "LAYUP",
          "SHELL THICKNESS", "STACK DIRECTION", "THICKNESS", "ROTARY INERTIA"}},
        {"INCLUDE", {"INPUT", "PASSWORD"}},
        {"SYSTEM", {}}};
    return parameters.at(keyword);
  }
  static bool listed(const std::string& name, const std::vector<std::string>& names) {
    for (const std::string& candidate : names)
      if (normalized(candidate) == name) return true;
    return false;
  }
  void check_parameters(const Keyword& keyword, const InputLine& line) const {
    const std::vector<std::string>& known = parameters_of(keyword.name);
    for (const auto& entry : keyword.value) {
      if (listed(entry.first, known)) continue;
      std::string message = "*" + upper(keyword.written) + " has no parameter " + entry.first;
      if (!known.empty())
        message += "; did you mean " + nearest_name(entry.first, known, normalized) + "=?";
      fail(line.origin, message);
    }
  }

  void begin_block(const InputLine& line) {
    const Keyword keyword = parse_keyword(line);
    const std::string& name = keyword.name;
    block_ = Block::skip;
    block_origin_ = line.origin;
    seen_keyword_ = true;
    if (listed(name, read_keywords())) check_parameters(keyword, line);
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
      line_elements_ = false;
      if (among(element_type_, {"S4", "S4R", "S4R5", "S4RS", "S4T", "S4RT", "CPS4", "CPS4R", "M3D4", "M3D4R"})) {
        element_nodes_ = 4;
      } else if (among(element_type_, {"S3", "S3R", "S3RS", "STRI3", "S3T", "S3RT", "CPS3", "M3D3"})) {
        element_nodes_ = 3;
      } else if (among(element_type_, {"T3D2", "T2D2", "T3D2H", "T2D2H", "B31", "B21", "B31H", "B21H"})) {
        element_nodes_ = 2;
        line_elements_ = true;
      } else if (among(element_type_, {"S6", "S8", "S8R", "S8R5", "S9R5", "STRI65", "S8T", "S8RT", "S6T"})) {
        fail(line.origin, "element TYPE=" + element_type_ +
                              " is a second-order shell; only the 3- and 4-node shells (S3, S3R, S4, S4R, ...) are read");
      } else {
        fail(line.origin, "element TYPE=" + element_type_ +
                              " is not a 3- or 4-node shell, a plane-stress or membrane face or a 2-node line; read are the "
                              "shells S3, S3R, S3RS, STRI3, S4, S4R, S4R5, S4RS; plane-stress and "
                              "membrane faces CPS3, CPS4, CPS4R, M3D3, M3D4, M3D4R; 2-node lines T3D2, T2D2, B31, "
                              "B21 (node sets only)");
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
    } else if (listed(name, refused_keywords())) {
      fail(line.origin, "*" + name + " changes the geometry and is not read (write nodes and elements out "
                                     "explicitly, as a flat input file)");
    } else if (!listed(name, skipped_keywords())) {
      std::vector<std::string> known = read_keywords();
      known.insert(known.end(), refused_keywords().begin(), refused_keywords().end());
      known.insert(known.end(), skipped_keywords().begin(), skipped_keywords().end());
      fail(line.origin, "unknown keyword *" + keyword.written + "; did you mean *" + nearest_name(name, known, normalized) +
                            "? (this reader reads *NODE, *ELEMENT, *NSET, *ELSET, *SHELL SECTION and *INCLUDE "
                            "and skips the keywords of materials, steps, loads and output that it knows)");
    }
  }

  void finish_block() {
    if (block_ == Block::element && !pending_element_.empty())
      fail(pending_origin_, "the element data line ends with a comma but no line continues it");
    if (block_ == Block::shell_section && sections_.back().thickness == 0.0)
      fail(block_origin_, "*SHELL SECTION has no data line with the thickness");
    block_ = Block::skip;
  }

  void check_coordinate(double value, const MeshOrigin& origin, const std::string& what) const {
    if (std::abs(value) > largest_coordinate)
      fail(origin, what + " is " + number_text(value) +
                       ", beyond the limit of ±" + number_text(largest_coordinate) + " (a unit or format mistake?)");
  }
  static std::string number_text(double value) {
    std::ostringstream text;
    text.precision(6);
    text << value;
    return text.str();
  }

  long long label(const std::string& field, const MeshOrigin& origin, const char* what) const {
    long long value = 0;
    if (!parse_integer(field, value)) fail(origin, std::string(what) + " is '" + field + "', not an integer");
    if (value <= 0) fail(origin, std::string(what) + " is " + field + "; labels must be positive");
    return value;
  }

  void data_line(const InputLine& line, MeshData& mesh) {
    if (!seen_keyword_)
      fail(line.origin, "a data line before the first keyword: '" + line.text.substr(0, 40) +
                            "' (is this an Abaqus or CalculiX input file?)");
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
      check_coordinate(x[c - 1], line.origin, "coordinate " + std::to_string(c) + " of node " + fields[0]);
    }
    // x and y at least: a line of a label alone (or a label and one number) is
    // a line broken or shifted, not a node at the origin.
    if (fields.size() < 3 || fields[1].empty() || fields[2].empty())
      fail(line.origin, "node " + fields[0] + " lacks its coordinates: a node line is label, x, y[, z] (only z may "
                            "be left out)");
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
    if (line_elements_) {
      if (record.nodes[0] == record.nodes[1])
        fail(pending_origin_, "element " + all[0] + " of TYPE=" + element_type_ + " lists node " + all[1] +
                                  " twice (a degenerate line)");
      line_elements_of_.push_back(record);
    } else {
      mesh.elements.push_back(record);
    }
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
    // Shell elements first, then the 2-node lines (which only carry nodes to
    // sets), both in one index: e < shells is mesh.elements[e], else a line.
    const std::size_t shells = mesh.elements.size();
    const auto element_at = [&](std::size_t e) -> const MeshElement& {
      return e < shells ? mesh.elements[e] : line_elements_of_[e - shells];
    };
    std::unordered_map<long long, std::size_t> element_index;
    for (std::size_t e = 0; e < shells + line_elements_of_.size(); ++e) {
      const auto [found, inserted] = element_index.emplace(element_at(e).label, e);
      if (!inserted)
        fail(element_at(e).origin, "element " + std::to_string(element_at(e).label) + " is defined twice (also at " +
                                       where(element_at(found->second).origin) + ")");
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
        if (e >= shells)
          fail(section.origin, "*SHELL SECTION's element set " + section.name + " holds element " +
                                   std::to_string(element_at(e).label) + " (" + where(element_at(e).origin) +
                                   "), a 2-node line, not a shell");
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
          for (std::size_t n = 0; n < element_at(e).node_count; ++n)
            set.nodes.emplace_back(element_at(e).nodes[n], origin);
      mesh.sets.push_back(std::move(set));
    }
    for (const std::string& key : element_set_order_) {
      MeshSet set{display_.at(key), element_sets_.at(key).origin, {}};
      for (const auto& [e, origin] : elements_of(key, element_sets_.at(key).origin))
        for (std::size_t n = 0; n < element_at(e).node_count; ++n)
          set.nodes.emplace_back(element_at(e).nodes[n], origin);
      mesh.sets.push_back(std::move(set));
    }
  }

  std::vector<std::string> files_;
  double input_bytes_ = 0.0;  // of the files read so far
  MeshOrigin end_;            // the main file's last line
  bool seen_keyword_ = false;
  std::vector<InputLine> lines_;
  Block block_ = Block::skip;
  MeshOrigin block_origin_;
  std::string current_set_;
  bool generate_ = false;
  std::string element_type_;
  std::size_t element_nodes_ = 0;
  bool line_elements_ = false;                // the *ELEMENT block holds 2-node lines
  std::vector<MeshElement> line_elements_of_;  // they only carry nodes to sets
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
  return detail::guard_reading(path, [&] {
    detail::AbaqusParser parser(path);
    detail::MeshData mesh = parser.parse();
    return detail::build_shell_model(mesh, path, 0.0);
  });
}

// As above; elements in no *SHELL SECTION (plane-stress and membrane faces
// among them) take thickness d (m).
inline ShellModel read_abaqus(const std::string& path, double thickness_without_section) {
  sphshell::detail::require_positive("thickness_without_section", thickness_without_section);
  return detail::guard_reading(path, [&] {
    detail::AbaqusParser parser(path);
    detail::MeshData mesh = parser.parse();
    return detail::build_shell_model(mesh, path, thickness_without_section);
  });
}

}  // namespace sphshell::io
