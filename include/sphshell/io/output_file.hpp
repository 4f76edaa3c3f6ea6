#pragma once
// Helpers shared by the writers: crash-safe file replacement, exact decimal
// numbers, XML escaping.

#include <sphshell/core/error.hpp>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

namespace sphshell::io::detail {

[[noreturn]] inline void output_error(const std::string& path, const std::string& what) {
  throw Error("sphshell: " + what + " '" + path + "'");
}

// Writes to "<path>.tmp" and renames it over path on commit(), so readers (and
// a run that crashes mid-write) only ever see the previous or the complete new
// file. An uncommitted temporary is removed on destruction.
class ReplacingOutputFile {
 public:
  explicit ReplacingOutputFile(std::string path)
      : path_(std::move(path)), temporary_path_(path_ + ".tmp") {
    stream_.open(temporary_path_, std::ios::binary | std::ios::trunc);
    if (!stream_) output_error(path_, "cannot open for writing (temporary " + temporary_path_ + ")");
  }
  ReplacingOutputFile(const ReplacingOutputFile&) = delete;
  ReplacingOutputFile& operator=(const ReplacingOutputFile&) = delete;
  ~ReplacingOutputFile() {
    if (!committed_) {
      stream_.close();
      std::error_code ignored;
      std::filesystem::remove(temporary_path_, ignored);
    }
  }

  std::ofstream& stream() { return stream_; }

  void commit() {
    stream_.flush();
    const bool written = static_cast<bool>(stream_);
    stream_.close();
    if (!written || stream_.fail()) output_error(path_, "failed while writing");
    std::error_code error;
    std::filesystem::rename(temporary_path_, path_, error);
    if (error) output_error(path_, "cannot replace (" + error.message() + ")");
    committed_ = true;
  }

 private:
  std::string path_;
  std::string temporary_path_;
  std::ofstream stream_;
  bool committed_ = false;
};

// Shortest decimal that reads back to the same double ("nan", "inf" as such).
inline std::string round_trip_decimal(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

inline std::string xml_escape(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char character : text) {
    switch (character) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      case '\'': escaped += "&apos;"; break;
      default: escaped += character;
    }
  }
  return escaped;
}

}  // namespace sphshell::io::detail
