#pragma once
// Time histories of a few quantities (displacement at a point, crack length,
// energies) as CSV: one header line, then one row per call.

#include <sphshell/core/error.hpp>
#include <sphshell/io/binary_stream.hpp>
#include <sphshell/io/output_file.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::io {

namespace detail {

// RFC 4180 quoting, needed only for names that contain separators or quotes.
inline std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char character : text) {
    if (character == '"') quoted += '"';
    quoted += character;
  }
  return quoted + "\"";
}

}  // namespace detail

// Column names should carry their units, e.g. "time [s]", "w_centre [m]".
// Numbers are written as the shortest decimal that reads back to the same
// double (NaN and infinities as "nan", "inf", "-inf"); every row is flushed so
// the file is usable while the run goes on, or after it crashed. A failed
// write throws Error naming the file and the system's reason.
class CsvProbe {
 public:
  // What a file held when a checkpoint was written: its length and the FNV-1a
  // hash of its content (a restarted run continues the file from there).
  struct Resume {
    std::uint64_t bytes = 0;
    std::uint64_t hash = fnv1a_offset_basis;
  };

  CsvProbe(const std::string& path, std::vector<std::string> columns)
      : path_(path), columns_(std::move(columns)) {
    check_columns();
    errno = 0;
    stream_.open(path_, std::ios::trunc | std::ios::binary);  // binary: the length counted is the length on disk
    if (!stream_) fail("cannot open CSV probe '" + path_ + "' for writing");
    std::string header;
    for (std::size_t i = 0; i < columns_.size(); ++i)
      header += (i == 0 ? "" : ",") + detail::csv_field(columns_[i]);
    put(header + '\n');
  }

  // Continues a file a checkpoint recorded: its first resume.bytes bytes must
  // be what they were then (else an Error: the file was rewritten since);
  // anything after them (rows of the run after the checkpoint) is cut off.
  CsvProbe(const std::string& path, std::vector<std::string> columns, const Resume& resume)
      : path_(path), columns_(std::move(columns)), bytes_(resume.bytes), hash_(resume.hash) {
    check_columns();
    std::ifstream existing(path_, std::ios::binary);
    if (!existing) fail("cannot reopen CSV probe '" + path_ + "' to continue it after a checkpoint");
    std::uint64_t hash = fnv1a_offset_basis, read = 0;
    char buffer[1 << 16];
    while (read < resume.bytes && existing) {
      const auto want = static_cast<std::streamsize>(std::min<std::uint64_t>(sizeof buffer, resume.bytes - read));
      existing.read(buffer, want);
      hash = fnv1a(buffer, static_cast<std::size_t>(existing.gcount()), hash);
      read += static_cast<std::uint64_t>(existing.gcount());
    }
    existing.close();
    const std::string hint =
        ": it was rewritten since, e.g. by adding the probe before loading the checkpoint; add probes after "
        "restoring, or keep a copy of the file with the checkpoint";
    if (read < resume.bytes)
      throw Error("sphshell: CSV probe '" + path_ + "' holds " + std::to_string(read) + " bytes, fewer than the " +
                  std::to_string(resume.bytes) + " it had at the checkpoint" + hint);
    if (hash != resume.hash)
      throw Error("sphshell: CSV probe '" + path_ + "' no longer holds the rows it had at the checkpoint (its first " +
                  std::to_string(resume.bytes) + " bytes differ)" + hint);
    std::error_code error;
    std::filesystem::resize_file(path_, resume.bytes, error);
    if (error) throw Error("sphshell: cannot cut CSV probe '" + path_ + "' back to its checkpoint (" + error.message() + ")");
    errno = 0;
    stream_.open(path_, std::ios::app | std::ios::binary);
    if (!stream_) fail("cannot open CSV probe '" + path_ + "' for appending");
  }

  void write_row(const std::vector<double>& values) {
    if (values.size() != columns_.size())
      throw Error("sphshell: CSV probe '" + path_ + "' expects " +
                  std::to_string(columns_.size()) + " values per row, got " +
                  std::to_string(values.size()));
    std::string line;
    for (std::size_t i = 0; i < values.size(); ++i)
      line += (i == 0 ? "" : ",") + detail::round_trip_decimal(values[i]);
    put(line + '\n');
  }

  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }
  // The file's length and content hash so far (a checkpoint records them).
  Resume written() const { return {bytes_, hash_}; }

 private:
  void check_columns() const {
    if (columns_.empty()) throw Error("sphshell: CSV probe '" + path_ + "' needs at least one column");
    for (const std::string& column : columns_)
      if (column.empty()) throw Error("sphshell: CSV probe '" + path_ + "' has an empty column name");
  }
  void put(const std::string& text) {
    stream_ << text;
    flush();
    bytes_ += text.size();
    hash_ = fnv1a(text, hash_);
  }
  void flush() {
    stream_.flush();
    if (!stream_) fail("failed while writing CSV probe '" + path_ + "'");
  }
  // The message with the system's reason (errno), e.g. a full disk.
  [[noreturn]] static void fail(const std::string& what) {
    const int error_number = errno;
    throw Error("sphshell: " + what + (error_number != 0 ? " (" + detail::errno_text(error_number) + ")" : ""));
  }

  std::string path_;
  std::vector<std::string> columns_;
  std::ofstream stream_;
  std::uint64_t bytes_ = 0;
  std::uint64_t hash_ = fnv1a_offset_basis;
};

}  // namespace sphshell::io
