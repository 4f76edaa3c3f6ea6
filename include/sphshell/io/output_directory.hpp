#pragma once
// The output folder and the files of the frame series in it: creating the
// folder (or an Error with the system's reason), a file's identity, which
// files belong to the library's series, and removing an earlier run's frames.

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sphshell/core/error.hpp>
#include <string>
#include <system_error>

namespace sphshell::io {

// A folder that exists, or is created; anything else is an Error naming it
// and the system's reason (not a folder, under a file, on a read-only or
// virtual file system such as /proc). lead starts the message, noun names
// the folder: ("", "output_directory") or ("probe file 'p.csv': ", "its folder").
inline void make_directory(const std::string& directory, const std::string& lead, const std::string& noun) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(directory, error);
  if (fs::is_directory(status)) return;
  if (fs::exists(status)) throw Error("sphshell: " + lead + noun + " '" + directory + "' is a file, not a folder");
  error.clear();
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(fs::status(directory, error)))
    throw Error("sphshell: " + lead + "cannot create " + noun + " '" + directory + "' (" +
                (error ? error.message() : std::string("not created")) + ")");
}

// A file's identity: its absolute, normalized path (two names of one file agree).
inline std::string identity_of(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::path absolute = fs::absolute(path, error);
  if (error) absolute = path;
  const fs::path canonical = fs::weakly_canonical(absolute, error);
  return (error ? absolute.lexically_normal() : canonical).string();
}

// A frame file of this library's series: particles, stress_points,
// cracks or bodies (the rigid bodies' surfaces, part 1 of particles.pvd,
// so no collection of their own), then "_<number>.vtu", a distributed run's piece
// "_<number>_r<rank>.vtu" and parallel file "_<number>.pvtu", or ".pvd",
// each optionally ".tmp" (a write cut short by a kill). The frame's number
// (its digits), "" for a collection; nothing for a file of no series.
inline std::optional<std::string> frame_file_digits(std::string name) {
  auto ends_with = [](const std::string& text, const std::string& tail) {
    return text.size() > tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
  };
  auto digits_only = [](const std::string& text) {
    return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (ends_with(name, ".tmp")) name.resize(name.size() - 4);
  for (const std::string series : {"particles", "stress_points", "cracks", "bodies"}) {
    if (name.compare(0, series.size(), series) != 0) continue;
    const std::string rest = name.substr(series.size());
    if (rest == ".pvd") {
      if (series == "bodies") return std::nullopt;
      return std::string();
    }
    for (const std::string extension : {".vtu", ".pvtu"}) {
      if (rest.empty() || rest[0] != '_' || !ends_with(rest, extension)) continue;
      std::string number = rest.substr(1, rest.size() - 1 - extension.size());
      const std::size_t piece = number.find("_r");
      if (extension == ".vtu" && piece != std::string::npos && digits_only(number.substr(piece + 2)))
        number.resize(piece);
      if (digits_only(number)) return number;
    }
  }
  return std::nullopt;
}
inline bool is_frame_file(const std::string& name) { return frame_file_digits(name).has_value(); }

// Removes an earlier run's frame file; a failure is an Error with the reason.
inline void remove_file(const std::string& path) {
  std::error_code error;
  std::filesystem::remove(path, error);
  if (error) throw Error("sphshell: cannot remove the earlier frame file '" + path + "' (" + error.message() + ")");
}

}  // namespace sphshell::io
