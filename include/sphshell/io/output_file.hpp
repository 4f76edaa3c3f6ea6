#pragma once
// Helpers shared by the writers: crash-safe file replacement, exact decimal
// numbers, XML escaping.

#include <sphshell/core/error.hpp>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <unistd.h>
#endif

namespace sphshell::io::detail {

[[noreturn]] inline void output_error(const std::string& path, const std::string& what) {
  throw Error("sphshell: " + what + " '" + path + "'");
}

// The system's text for an errno value ("No space left on device").
inline std::string errno_text(int error_number) { return std::generic_category().message(error_number); }

// Writes to "<path>.tmp" and renames it over path on commit(), so readers (and
// a run that crashes or is killed mid-write) only ever see the previous or the
// complete new file. An uncommitted temporary is removed on destruction.
// A failed write names the file and the system's reason (errno), e.g. a full
// disk. commit() is finish() (flush, close, check) then replace() (the
// rename); files that must change together are all finished before any is
// replaced, so the window in which they disagree is a few renames.
class ReplacingOutputFile {
 public:
  explicit ReplacingOutputFile(std::string path)
      : path_(std::move(path)), temporary_path_(path_ + ".tmp") {
    errno = 0;
    stream_.open(temporary_path_, std::ios::binary | std::ios::trunc);
    if (!stream_) fail("cannot open for writing (temporary " + temporary_path_ + ")");
  }
  ReplacingOutputFile(const ReplacingOutputFile&) = delete;
  ReplacingOutputFile& operator=(const ReplacingOutputFile&) = delete;
  ~ReplacingOutputFile() {
    if (!committed_) stream_.close();
    if (!committed_ || exchanged_) {
      std::error_code ignored;
      std::filesystem::remove(temporary_path_, ignored);
    }
  }

  std::ofstream& stream() { return stream_; }

  // Throws, naming the file and errno's text, if a write so far has failed.
  // Writers call it after each large block, while errno still tells why.
  void check() {
    if (!stream_) fail("failed while writing");
  }

  void finish() {
    check();
    stream_.flush();
    check();
    stream_.close();
    if (stream_.fail()) fail("failed while writing");
  }

  // After finish(): the temporary's data on the disk now (fdatasync), so that
  // a power cut after the replacement cannot leave an empty file.
  void sync_to_disk() {
#if defined(__unix__) || defined(__APPLE__)
    const int descriptor = ::open(temporary_path_.c_str(), O_RDONLY);
    if (descriptor < 0) fail("cannot reopen to sync");
    const int status = ::fdatasync(descriptor);
    const int error_number = errno;
    ::close(descriptor);
    errno = error_number;
    if (status != 0) fail("cannot sync to disk");
#endif
  }

  void replace() {
    std::error_code error;
    std::filesystem::rename(temporary_path_, path_, error);
    if (error) output_error(path_, "cannot replace (" + error.message() + ")");
    committed_ = true;
  }

  // As replace(), for files that must change together: on Linux the
  // temporary and the file swap places atomically (renameat2 with
  // RENAME_EXCHANGE), which takes microseconds where ext4's rename over an
  // existing file takes milliseconds (measured 6 µs against 4.5 ms); the
  // previous content, now under the temporary's name, is removed by
  // remove_previous() or the destructor. Elsewhere, and where the file system
  // cannot swap or the file is new, a rename.
  void replace_quickly() {
#if defined(__linux__) && defined(RENAME_EXCHANGE)
    if (::renameat2(AT_FDCWD, temporary_path_.c_str(), AT_FDCWD, path_.c_str(), RENAME_EXCHANGE) == 0) {
      committed_ = true;
      exchanged_ = true;
      return;
    }
#endif
    replace();
  }

  void remove_previous() {
    if (!exchanged_) return;
    std::error_code ignored;
    std::filesystem::remove(temporary_path_, ignored);
    exchanged_ = false;
  }

  void commit() {
    finish();
    replace();
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    const int error_number = errno;
    throw Error("sphshell: " + what + " '" + path_ + "'" +
                (error_number != 0 ? " (" + errno_text(error_number) + ")" : std::string()));
  }

  std::string path_;
  std::string temporary_path_;
  std::ofstream stream_;
  bool committed_ = false;
  bool exchanged_ = false;  // the temporary holds the previous content
};

// Shortest decimal that reads back to the same double ("nan", "inf" as such).
inline std::string round_trip_decimal(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

inline std::string round_trip_decimal(float value) {
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
