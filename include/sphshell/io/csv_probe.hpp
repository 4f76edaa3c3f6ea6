#pragma once
// Time histories of a few quantities (displacement at a point, crack length,
// energies) as CSV: one header line, then one row per call.

#include <sphshell/core/error.hpp>
#include <sphshell/io/output_file.hpp>

#include <cerrno>
#include <fstream>
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
  CsvProbe(const std::string& path, std::vector<std::string> columns)
      : path_(path), columns_(std::move(columns)) {
    if (columns_.empty()) throw Error("sphshell: CSV probe '" + path_ + "' needs at least one column");
    for (const std::string& column : columns_)
      if (column.empty()) throw Error("sphshell: CSV probe '" + path_ + "' has an empty column name");
    errno = 0;
    stream_.open(path_, std::ios::trunc);
    if (!stream_) fail("cannot open CSV probe '" + path_ + "' for writing");
    for (std::size_t i = 0; i < columns_.size(); ++i)
      stream_ << (i == 0 ? "" : ",") << detail::csv_field(columns_[i]);
    stream_ << '\n';
    flush();
  }

  void write_row(const std::vector<double>& values) {
    if (values.size() != columns_.size())
      throw Error("sphshell: CSV probe '" + path_ + "' expects " +
                  std::to_string(columns_.size()) + " values per row, got " +
                  std::to_string(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i)
      stream_ << (i == 0 ? "" : ",") << detail::round_trip_decimal(values[i]);
    stream_ << '\n';
    flush();
  }

  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
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
};

}  // namespace sphshell::io
