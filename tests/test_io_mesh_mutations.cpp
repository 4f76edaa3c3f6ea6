// The mesh readers against damaged files: the test meshes of
// support/mesh_files.hpp (an Abaqus deck of a plate with node sets, element
// sets, a section and an included node file; a mixed quad and triangle deck;
// the plate as Gmsh 4.1 ASCII and binary) truncated, with bytes replaced,
// with fields of node and element lines lost or doubled, and with keywords
// misspelled, at places a seeded generator picks. Each variant must read to
// the very model of the intact file or end in a sphshell::Error that names a
// line (or a byte of binary data): never another exception type, a crash, or
// a model that differs without a word.
//
// What no reader can notice is left out: a byte replaced by another digit (a
// different but valid number), a member dropped from a set's list, a set or
// a parameter value renamed. Bytes are replaced by control characters, which
// no text mesh holds, or by a letter in place of a digit.
#include "support/mesh_files.hpp"

#include <sphshell/io/abaqus_reader.hpp>
#include <sphshell/io/gmsh_reader.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <exception>
#include <functional>
#include <random>
#include <string>
#include <typeinfo>
#include <vector>

using namespace sphshell;
namespace fs = std::filesystem;

namespace {

// The seed: a fixed one, so a failure names a variant that can be rerun.
constexpr unsigned kSeed = 20261206;
constexpr int kVariantsPerKind = 40;

// A 6 × 5 node plate of 0.25 m cells with sets, as the reader tests write it.
ShellModel small_plate() { return ShellModel::rectangular_plate(1.25, 1.0, 6, 5, 0.01); }

test_support::AbaqusMesh abaqus_plate(const ShellModel& plate) {
  test_support::AbaqusMesh mesh;
  mesh.nodes = plate.particle_position;
  mesh.cells = plate.cells();
  for (const char* name : {"x_min", "y_max", "centre"}) mesh.node_sets.push_back({name, plate.set(name)});
  std::vector<int> all(plate.cells().size());
  for (std::size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c);
  mesh.element_sets.push_back({"plate", all});
  mesh.sections.push_back({"PLATE", 0.01});
  return mesh;
}

test_support::AbaqusMesh abaqus_mixed() {
  test_support::AbaqusMesh mesh;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) mesh.nodes.push_back(Vector3(0.25 * i, 0.25 * j, 0.05 * i * j));
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i) {
      const int a = j * 4 + i, b = a + 1, c = a + 5, d = a + 4;
      if (i == 0) {
        mesh.cells.push_back(Cell(a, b, c, d));
      } else {
        mesh.cells.push_back(Cell(a, b, c));
        mesh.cells.push_back(Cell(a, c, d));
      }
    }
  mesh.sections.push_back({"ALL_QUADS", 0.004});
  mesh.sections.push_back({"ALL_TRIANGLES", 0.003});
  return mesh;
}

test_support::GmshMesh gmsh_plate(const ShellModel& plate) {
  test_support::GmshMesh mesh{plate.particle_position, plate.cells(), {}};
  mesh.entities.push_back({0, {{plate.set("centre")[0]}}, {}, {"centre"}});
  test_support::GmshEntity edge{1, {}, {}, {"x_min"}};
  const ParticleSet& nodes = plate.set("x_min");
  for (std::size_t k = 0; k + 1 < nodes.size(); ++k) edge.node_elements.push_back({nodes[k], nodes[k + 1]});
  mesh.entities.push_back(edge);
  test_support::GmshEntity surface{2, {}, {}, {"plate"}};
  for (std::size_t c = 0; c < plate.cells().size(); ++c) surface.cells.push_back(static_cast<int>(c));
  mesh.entities.push_back(surface);
  return mesh;
}

// Everything a reader puts in a model.
bool same_model(const ShellModel& a, const ShellModel& b) {
  if (a.particle_position != b.particle_position || a.particle_normal != b.particle_normal) return false;
  if (a.stress_point_position != b.stress_point_position || a.stress_point_area != b.stress_point_area) return false;
  if (a.cells().size() != b.cells().size() || a.set_names() != b.set_names()) return false;
  for (std::size_t c = 0; c < a.cells().size(); ++c)
    if (!std::equal(a.cells()[c].begin(), a.cells()[c].end(), b.cells()[c].begin(), b.cells()[c].end())) return false;
  for (const std::string& name : a.set_names())
    if (a.set(name) != b.set(name)) return false;
  for (std::size_t i = 0; i < a.particle_count(); ++i)
    if (a.particle_thickness(i) != b.particle_thickness(i)) return false;
  for (std::size_t p = 0; p < a.stress_point_count(); ++p)
    if (a.stress_point_thickness(p) != b.stress_point_thickness(p)) return false;
  return true;
}

// The lines of a text and where each starts.
std::vector<std::size_t> line_starts(const std::string& text) {
  std::vector<std::size_t> starts{0};
  for (std::size_t k = 0; k + 1 < text.size(); ++k)
    if (text[k] == '\n') starts.push_back(k + 1);
  return starts;
}
std::string line_at(const std::string& text, std::size_t start) {
  return text.substr(start, text.find('\n', start) - start);
}

enum class Format { abaqus, gmsh };

struct Input {
  std::string name;
  Format format;
  bool binary;
  std::string text;  // the file that is mutated
  std::vector<std::pair<std::string, std::string>> companions;  // other files it includes: name, text
};

// The lines whose fields a shift may move: node and element lines of a deck
// (a set's list or a section's data may lose a member and stay valid), any
// data line of a Gmsh file (its counts make every shift show).
std::vector<std::size_t> shiftable_lines(const Input& input, const std::string& text,
                                         const std::vector<std::size_t>& starts) {
  std::vector<std::size_t> lines;
  bool geometry = false;  // inside a deck's *NODE or *ELEMENT block
  for (std::size_t l = 0; l < starts.size(); ++l) {
    const std::string line = line_at(text, starts[l]);
    if (line.empty()) continue;
    if (input.format == Format::gmsh) {
      if (line[0] != '$') lines.push_back(l);
      continue;
    }
    if (line.compare(0, 2, "**") == 0) continue;
    if (line[0] == '*') {
      std::string keyword;
      for (std::size_t k = 1; k < line.size() && line[k] != ','; ++k)
        keyword += static_cast<char>(std::toupper(static_cast<unsigned char>(line[k])));
      geometry = keyword == "NODE" || keyword == "ELEMENT";
      continue;
    }
    if (geometry) lines.push_back(l);
  }
  return lines;
}

struct Variant {
  std::string description;
  std::string text;
};

std::vector<Variant> mutations(const Input& input, std::mt19937& random) {
  std::vector<Variant> variants;
  auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(random); };
  const std::string& text = input.text;
  const std::vector<std::size_t> starts = line_starts(text);
  auto line_of = [&](std::size_t offset) {
    return std::upper_bound(starts.begin(), starts.end(), offset) - starts.begin();
  };

  // Truncated anywhere.
  for (int k = 0; k < kVariantsPerKind; ++k) {
    const std::size_t length = pick(text.size());
    variants.push_back({"cut after byte " + std::to_string(length) + " (line " + std::to_string(line_of(length)) + ")",
                        text.substr(0, length)});
  }
  if (input.binary) return variants;  // binary data: any other change is another valid number

  // A byte replaced by a control character, or a digit by a letter.
  const std::string controls = std::string("\x01\x02\x03\x04\x05\x06\x07\x08\x0B\x0C\x0E\x10\x1B\x1F\x7F", 15) +
                               std::string(1, '\0');
  for (int k = 0; k < kVariantsPerKind; ++k) {
    std::string changed = text;
    const std::size_t at = pick(text.size());
    changed[at] = controls[pick(controls.size())];
    variants.push_back({"byte " + std::to_string(at) + " (line " + std::to_string(line_of(at)) +
                            ") replaced by a control character",
                        changed});
  }
  std::vector<std::size_t> digits;
  for (std::size_t k = 0; k < text.size(); ++k)
    if (text[k] >= '0' && text[k] <= '9') digits.push_back(k);
  for (int k = 0; k < kVariantsPerKind; ++k) {
    std::string changed = text;
    const std::size_t at = digits[pick(digits.size())];
    changed[at] = "xqO#"[pick(4)];
    variants.push_back({"digit at byte " + std::to_string(at) + " (line " + std::to_string(line_of(at)) +
                            ") replaced by '" + changed[at] + "'",
                        changed});
  }

  // A field of a node or element line lost (the rest shift left) or doubled
  // (the rest shift right).
  const std::vector<std::size_t> data = shiftable_lines(input, text, starts);
  const char separator = input.format == Format::abaqus ? ',' : ' ';
  for (int k = 0; k < kVariantsPerKind; ++k) {
    const std::size_t l = data[pick(data.size())];
    const std::string line = line_at(text, starts[l]);
    std::vector<std::string> fields(1);
    for (char c : line) {
      if (c == separator) fields.emplace_back();
      else fields.back() += c;
    }
    while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
    const std::size_t f = pick(fields.size());
    const bool lose = pick(2) == 0 && fields.size() > 1;
    if (lose) fields.erase(fields.begin() + static_cast<std::ptrdiff_t>(f));
    else fields.insert(fields.begin() + static_cast<std::ptrdiff_t>(f), fields[f]);
    std::string shifted;
    for (std::size_t g = 0; g < fields.size(); ++g) shifted += (g ? std::string(1, separator) : "") + fields[g];
    std::string changed = text;
    changed.replace(starts[l], line.size(), shifted);
    variants.push_back({"line " + std::to_string(l + 1) + " '" + line + "' with field " + std::to_string(f + 1) +
                            (lose ? " lost" : " doubled"),
                        changed});
  }

  // A letter of a keyword (Abaqus *NAME) or section header (Gmsh $Name) changed.
  std::vector<std::pair<std::size_t, std::size_t>> keywords;  // first letter, letters
  for (std::size_t start : starts) {
    const char mark = input.format == Format::abaqus ? '*' : '$';
    if (text[start] != mark || (start + 1 < text.size() && text[start + 1] == '*')) continue;
    std::size_t end = start + 1;
    while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
    if (end > start + 1) keywords.emplace_back(start + 1, end - start - 1);
  }
  for (int k = 0; k < kVariantsPerKind; ++k) {
    const auto [first, letters] = keywords[pick(keywords.size())];
    std::string changed = text;
    const std::size_t at = first + pick(letters);
    char replacement = changed[at];
    while (std::toupper(static_cast<unsigned char>(replacement)) == std::toupper(static_cast<unsigned char>(changed[at])))
      replacement = static_cast<char>('A' + pick(26));
    changed[at] = replacement;
    variants.push_back({"keyword '" + line_at(text, first - 1) + "' on line " + std::to_string(line_of(first)) +
                            " misspelled as '" + line_at(changed, first - 1) + "'",
                        changed});
  }
  return variants;
}

ShellModel read(const Input& input, const fs::path& path) {
  return input.format == Format::abaqus ? io::read_abaqus(path.string()) : io::read_gmsh(path.string(), 0.01);
}

}  // namespace

TEST_CASE("Damaged mesh files read to the same model or end in an Error naming a line", "[io][mesh][mutation]") {
  const ShellModel plate = small_plate();
  const test_support::AbaqusFiles included = test_support::abaqus_text(abaqus_plate(plate), "nodes.inp");
  const std::vector<Input> inputs = {
      {"plate.inp", Format::abaqus, false, test_support::abaqus_text(abaqus_plate(plate)).deck, {}},
      {"included.inp", Format::abaqus, false, included.deck, {{"nodes.inp", included.nodes}}},
      {"nodes_part.inp", Format::abaqus, false, included.nodes, {{"included.inp", included.deck}}},
      {"mixed.inp", Format::abaqus, false, test_support::abaqus_text(abaqus_mixed()).deck, {}},
      {"plate.msh", Format::gmsh, false, test_support::gmsh_text(gmsh_plate(plate), false), {}},
      {"binary.msh", Format::gmsh, true, test_support::gmsh_text(gmsh_plate(plate), true), {}}};
  const test_support::ScratchDirectory directory("mutations");
  std::mt19937 random(kSeed);
  int variants = 0, same = 0, refused = 0;
  for (const Input& input : inputs) {
    // The included node file is damaged in its place: the deck that includes it is read.
    const bool node_part = input.name == "nodes_part.inp";
    const fs::path path = directory / input.name;
    const fs::path read_path = node_part ? directory / "included.inp" : path;
    for (const auto& [name, text] : input.companions) test_support::write_text(directory / name, text);
    test_support::write_text(path, input.text);
    const ShellModel intact = read(input, read_path);
    for (const Variant& variant : mutations(input, random)) {
      ++variants;
      INFO(input.name << ": " << variant.description);
      test_support::write_text(path, variant.text);
      std::string message;
      bool matches = false;
      try {
        matches = same_model(read(input, read_path), intact);
      } catch (const Error& error) {
        message = error.what();
      } catch (const std::exception& other) {
        FAIL("not a sphshell::Error but " << typeid(other).name() << ": " << other.what());
      }
      if (message.empty()) {
        CHECK(matches);  // read without an Error: it must be the intact file's model
        same += matches;
        continue;
      }
      ++refused;
      INFO("message: " << message);
      const bool names_a_place = message.find(", line ") != std::string::npos ||
                                 message.find(", binary $") != std::string::npos;
      CHECK(names_a_place);
    }
    test_support::write_text(path, input.text);
  }
  WARN("mesh mutations (seed " << kSeed << "): " << variants << " variants, " << same
                                << " read to the intact model, " << refused << " refused naming a line");
  CHECK(variants >= 600);
  CHECK(same + refused == variants);
}
