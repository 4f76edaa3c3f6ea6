#pragma once
// ParaView collection (.pvd): a time series of .vtu frames.

#include <sphshell/core/error.hpp>
#include <sphshell/io/output_file.hpp>

#include <cmath>
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::io {

// The file is rewritten completely (and atomically) on every add(), so a run
// that crashes still leaves a valid collection of the frames written so far.
class PvdCollection {
 public:
  struct Entry {
    double time;
    int part;
    std::string file;  // relative to the .pvd's directory
  };

  // Writes an empty collection at once, so an unwritable path fails here
  // rather than after the first expensive frame.
  explicit PvdCollection(std::string path) : path_(std::move(path)) { write(); }

  // vtu_file is the path as the program opened it (absolute, or relative to
  // the current directory); it is stored relative to the .pvd's directory so
  // the output folder can be moved or copied as a whole.
  void add(double time, const std::string& vtu_file, int part = 0) {
    if (!std::isfinite(time))
      throw Error("sphshell: PVD collection '" + path_ + "': time of frame '" + vtu_file +
                  "' must be finite, got " + detail::round_trip_decimal(time));
    if (part < 0)
      throw Error("sphshell: PVD collection '" + path_ + "': part of frame '" + vtu_file +
                  "' must be >= 0, got " + std::to_string(part));
    entries_.push_back({time, part, relative_to_collection(vtu_file)});
    write();
  }

  void write() const {
    detail::ReplacingOutputFile file(path_);
    std::ostream& out = file.stream();
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\">\n"
        << "  <Collection>\n";
    for (const Entry& entry : entries_)
      out << "    <DataSet timestep=\"" << detail::round_trip_decimal(entry.time)
          << "\" group=\"\" part=\"" << entry.part << "\" file=\""
          << detail::xml_escape(entry.file) << "\"/>\n";
    out << "  </Collection>\n"
        << "</VTKFile>\n";
    file.commit();
  }

  const std::string& path() const { return path_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::string relative_to_collection(const std::string& vtu_file) const {
    namespace fs = std::filesystem;
    const fs::path frame = fs::absolute(vtu_file).lexically_normal();
    const fs::path directory = fs::absolute(path_).lexically_normal().parent_path();
    const fs::path relative = frame.lexically_relative(directory);
    return (relative.empty() ? frame : relative).generic_string();
  }

  std::string path_;
  std::vector<Entry> entries_;
};

}  // namespace sphshell::io
