#pragma once
// An independent reader, for the tests, of the VTK XML files the library
// writes: .vtu (ascii, raw appended or zlib-compressed appended; Float32,
// Float64, Int32, Int64, UInt8) and .pvd collections. Written from the VTK
// file-format description, not from the writer: it walks the XML tags,
// checks that they nest, and decodes each DataArray to doubles (and, for
// binary files, keeps its raw bytes for bit-exact checks). zlib blocks are
// inflated with zlib itself when the tests are built with it.

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef SPHSHELL_HAVE_ZLIB
#include <zlib.h>
#endif

namespace sphshell::test_support {

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

[[noreturn]] inline void malformed(const std::string& what) { throw std::runtime_error("malformed VTK file: " + what); }

inline std::string xml_unescape(std::string text) {
  const std::pair<const char*, const char*> entities[] = {
      {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&apos;", "'"}, {"&amp;", "&"}};
  for (const auto& [entity, character] : entities)
    for (std::size_t at = text.find(entity); at != std::string::npos; at = text.find(entity, at + 1))
      text.replace(at, std::strlen(entity), character);
  return text;
}

using Attributes = std::map<std::string, std::string>;

struct XmlElement {
  std::string name;
  Attributes attributes;
  std::string parent;
  std::string text;  // character data up to the next tag
};

// The elements of an XML text in document order; comments are collected
// apart. `open` holds the elements still open at the end.
inline std::vector<XmlElement> parse_xml(const std::string& xml, std::vector<std::string>& open,
                                         std::vector<std::string>* comments = nullptr) {
  std::vector<XmlElement> elements;
  const std::regex attribute(R"re(([A-Za-z_][A-Za-z0-9_]*)="([^"]*)")re");
  std::size_t at = 0;
  while ((at = xml.find('<', at)) != std::string::npos) {
    if (xml.compare(at, 4, "<!--") == 0) {
      const std::size_t end = xml.find("-->", at + 4);
      if (end == std::string::npos) malformed("unterminated comment");
      if (comments) comments->push_back(xml.substr(at + 4, end - at - 4));
      at = end + 3;
      continue;
    }
    const std::size_t close = xml.find('>', at);
    if (close == std::string::npos) malformed("unterminated tag");
    const std::string body = xml.substr(at + 1, close - at - 1);
    at = close + 1;
    if (body.empty()) malformed("empty tag");
    if (body[0] == '?') continue;
    if (body[0] == '/') {
      if (open.empty() || open.back() != body.substr(1)) malformed("unbalanced </" + body.substr(1) + ">");
      open.pop_back();
      continue;
    }
    XmlElement element;
    element.name = body.substr(0, body.find_first_of(" /\n"));
    for (auto it = std::sregex_iterator(body.begin(), body.end(), attribute); it != std::sregex_iterator(); ++it)
      element.attributes[(*it)[1]] = xml_unescape((*it)[2]);
    element.parent = open.empty() ? "" : open.back();
    if (body.back() != '/') {
      open.push_back(element.name);
      element.text = xml.substr(at, xml.find('<', at) - at);
    }
    elements.push_back(std::move(element));
  }
  return elements;
}

struct VtuArray {
  std::string section;  // FieldData, PointData, CellData, Points or Cells
  Attributes attributes;
  std::string bytes;            // decoded raw bytes (binary files)
  std::vector<double> values;   // every value, converted to double
  std::string name() const { return attributes.at("Name"); }
  int components() const {
    const auto it = attributes.find("NumberOfComponents");
    return it == attributes.end() ? 1 : std::atoi(it->second.c_str());
  }
};

struct Vtu {
  Attributes file;
  Attributes piece;
  std::vector<std::string> comments;
  std::vector<VtuArray> arrays;
  std::string encoding;  // "ascii", "raw" or "zlib"

  const VtuArray* find(const std::string& section, const std::string& name) const {
    for (const VtuArray& array : arrays)
      if (array.section == section && array.name() == name) return &array;
    return nullptr;
  }
  const VtuArray& array(const std::string& section, const std::string& name) const {
    const VtuArray* found = find(section, name);
    if (!found) throw std::runtime_error("no array " + name + " in " + section);
    return *found;
  }
  std::size_t points() const { return std::stoul(piece.at("NumberOfPoints")); }
  std::size_t cells() const { return std::stoul(piece.at("NumberOfCells")); }
  std::vector<std::string> names(const std::string& section) const {
    std::vector<std::string> found;
    for (const VtuArray& array : arrays)
      if (array.section == section) found.push_back(array.name());
    return found;
  }
};

inline std::size_t type_size(const std::string& type) {
  if (type == "Float64" || type == "Int64" || type == "UInt64") return 8;
  if (type == "Float32" || type == "Int32" || type == "UInt32") return 4;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int8" || type == "UInt8") return 1;
  malformed("unknown type " + type);
}

template <class T>
T load(const char* at) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return value;
}

inline std::vector<double> to_doubles(const std::string& type, const std::string& bytes) {
  const std::size_t size = type_size(type);
  if (bytes.size() % size != 0) malformed("array bytes not a multiple of its type");
  std::vector<double> values(bytes.size() / size);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const char* at = bytes.data() + i * size;
    if (type == "Float64") values[i] = load<double>(at);
    else if (type == "Float32") values[i] = load<float>(at);
    else if (type == "Int64") values[i] = static_cast<double>(load<std::int64_t>(at));
    else if (type == "Int32") values[i] = load<std::int32_t>(at);
    else if (type == "UInt8") values[i] = load<std::uint8_t>(at);
    else malformed("unsupported type " + type);
  }
  return values;
}

// Host is little-endian on every machine the project runs on; the reader
// checks the declared order rather than swapping.
inline Vtu read_vtu(const std::string& path) {
  const std::string content = read_file(path);
  Vtu vtu;
  const std::size_t appended_tag = content.find("<AppendedData");
  std::size_t data_start = std::string::npos;
  std::string head = content;
  if (appended_tag != std::string::npos) {
    const std::size_t underscore = content.find('_', appended_tag);
    if (underscore == std::string::npos) malformed("no '_' after AppendedData");
    head = content.substr(0, underscore);
    data_start = underscore + 1;
  }
  std::vector<std::string> open;
  const std::vector<XmlElement> elements = parse_xml(head, open, &vtu.comments);
  bool compressed = false;
  for (const XmlElement& element : elements) {
    if (element.name == "VTKFile") {
      vtu.file = element.attributes;
      if (element.attributes.count("compressor")) {
        if (element.attributes.at("compressor") != "vtkZLibDataCompressor") malformed("unknown compressor");
        compressed = true;
      }
      if (element.attributes.at("byte_order") != "LittleEndian") malformed("only little-endian files are read");
      if (element.attributes.at("header_type") != "UInt64") malformed("only UInt64 headers are read");
    }
    if (element.name == "Piece") vtu.piece = element.attributes;
  }
  vtu.encoding = appended_tag == std::string::npos ? "ascii" : (compressed ? "zlib" : "raw");
  std::uint64_t data_end = 0;
  for (const XmlElement& element : elements) {
    if (element.name != "DataArray") continue;
    VtuArray array{element.parent, element.attributes, {}, {}};
    const std::string type = element.attributes.at("type");
    const std::string format = element.attributes.at("format");
    if (format == "ascii") {
      std::istringstream text(element.text);
      // A Float32 value is the float its decimal reads back to.
      for (std::string word; text >> word;)
        array.values.push_back(type == "Float32" ? static_cast<double>(std::strtof(word.c_str(), nullptr))
                                                 : std::strtod(word.c_str(), nullptr));
    } else if (format == "appended") {
      if (data_start == std::string::npos) malformed("appended array without AppendedData");
      const std::size_t at = data_start + std::stoull(element.attributes.at("offset"));
      if (!compressed) {
        if (at + 8 > content.size()) malformed("block header past the end");
        const std::uint64_t size = load<std::uint64_t>(content.data() + at);
        if (at + 8 + size > content.size()) malformed("block past the end");
        array.bytes = content.substr(at + 8, size);
        data_end = std::max<std::uint64_t>(data_end, at + 8 + size - data_start);
      } else {
        const std::uint64_t blocks = load<std::uint64_t>(content.data() + at);
        const std::uint64_t block_size = load<std::uint64_t>(content.data() + at + 8);
        const std::uint64_t last_size = load<std::uint64_t>(content.data() + at + 16);
        std::size_t next = at + 24 + 8 * blocks;
        for (std::uint64_t b = 0; b < blocks; ++b) {
          const std::uint64_t compressed_size = load<std::uint64_t>(content.data() + at + 24 + 8 * b);
          const std::uint64_t expected = (b + 1 == blocks && last_size != 0) ? last_size : block_size;
#ifdef SPHSHELL_HAVE_ZLIB
          std::string block(expected, '\0');
          uLongf size = static_cast<uLongf>(expected);
          if (uncompress(reinterpret_cast<Bytef*>(block.data()), &size,
                         reinterpret_cast<const Bytef*>(content.data() + next), static_cast<uLong>(compressed_size)) !=
                  Z_OK ||
              size != expected)
            malformed("zlib block does not inflate to its size");
          array.bytes += block;
#else
          (void)expected;
          malformed("zlib file, but the tests were built without zlib");
#endif
          next += compressed_size;
        }
        data_end = std::max<std::uint64_t>(data_end, next - data_start);
      }
      array.values = to_doubles(type, array.bytes);
    } else {
      malformed("unknown DataArray format " + format);
    }
    vtu.arrays.push_back(std::move(array));
  }
  // The closing tags follow the appended blocks.
  if (data_start != std::string::npos) {
    std::vector<std::string> still_open = open;
    parse_xml(content.substr(data_start + data_end), still_open);
    if (!still_open.empty()) malformed("elements left open");
  } else if (!open.empty()) {
    malformed("elements left open");
  }
  return vtu;
}

struct PvdEntry {
  double time;
  std::string part;
  std::string file;
};

inline std::vector<PvdEntry> read_pvd(const std::string& path) {
  std::vector<std::string> open;
  const std::vector<XmlElement> elements = parse_xml(read_file(path), open);
  if (!open.empty()) malformed(path + ": elements left open");
  if (elements.empty() || elements[0].name != "VTKFile" || elements[0].attributes.at("type") != "Collection")
    malformed(path + ": not a collection");
  std::vector<PvdEntry> entries;
  for (const XmlElement& element : elements)
    if (element.name == "DataSet")
      entries.push_back({std::strtod(element.attributes.at("timestep").c_str(), nullptr), element.attributes.at("part"),
                         element.attributes.at("file")});
  return entries;
}

}  // namespace sphshell::test_support
