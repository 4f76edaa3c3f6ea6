#pragma once
// ParaView collection (.pvd): a time series of .vtu frames.

#include <sphshell/core/error.hpp>
#include <sphshell/io/output_file.hpp>

#include <cmath>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::io {

// The file is rewritten completely (and atomically) on every add(), so a run
// that crashes still leaves a valid collection of the frames written so far.
// Several collections that must list the same frames (the solver's particles,
// stress points and cracks) stage() their entries and are written with
// write_together().
class PvdCollection {
 public:
  struct Entry {
    double time;
    int part;
    std::string file;  // relative to the .pvd's directory
  };

  // Writes an empty collection at once, so an unwritable path fails here
  // rather than after the first expensive frame; with write_now false the file
  // is first written by write() or write_together().
  explicit PvdCollection(std::string path, bool write_now = true) : path_(std::move(path)) {
    if (write_now) write();
  }

  // vtu_file is the path as the program opened it (absolute, or relative to
  // the current directory); it is stored relative to the .pvd's directory so
  // the output folder can be moved or copied as a whole.
  void add(double time, const std::string& vtu_file, int part = 0) {
    stage(time, vtu_file, part);
    write();
  }

  // Adds an entry without rewriting the file (see write_together).
  void stage(double time, const std::string& vtu_file, int part = 0) {
    if (!std::isfinite(time))
      throw Error("sphshell: PVD collection '" + path_ + "': time of frame '" + vtu_file +
                  "' must be finite, got " + detail::round_trip_decimal(time));
    if (part < 0)
      throw Error("sphshell: PVD collection '" + path_ + "': part of frame '" + vtu_file +
                  "' must be >= 0, got " + std::to_string(part));
    entries_.push_back({time, part, relative_to_collection(vtu_file)});
  }

  void write() const {
    detail::ReplacingOutputFile file(path_);
    write_to(file);
    file.commit();
  }

  // Writes the listing into file (its temporary), without committing it.
  void write_to(detail::ReplacingOutputFile& file) const {
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
  }

  const std::string& path() const { return path_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::string relative_to_collection(const std::string& vtu_file) const {
    namespace fs = std::filesystem;
    std::error_code error;
    const fs::path frame = fs::absolute(vtu_file, error).lexically_normal();
    if (error) detail::output_error(vtu_file, "cannot locate frame (" + error.message() + ")");
    const fs::path directory = fs::absolute(path_, error).lexically_normal().parent_path();
    if (error) detail::output_error(path_, "cannot locate collection (" + error.message() + ")");
    const fs::path relative = frame.lexically_relative(directory);
    return (relative.empty() ? frame : relative).generic_string();
  }

  std::string path_;
  std::vector<Entry> entries_;
};

// Rewrites every collection: all temporaries are written in full (and synced
// to the disk) before the first takes its collection's place, and those
// replacements are atomic swaps of microseconds each
// (ReplacingOutputFile::replace_quickly), so a process killed at any moment
// leaves the collections listing the same frames but for that instant.
inline void write_together(const std::vector<const PvdCollection*>& collections) {
  std::vector<std::unique_ptr<detail::ReplacingOutputFile>> files;
  for (const PvdCollection* collection : collections) {
    files.push_back(std::make_unique<detail::ReplacingOutputFile>(collection->path()));
    collection->write_to(*files.back());
    files.back()->finish();
    files.back()->sync_to_disk();
  }
  for (auto& file : files) file->replace_quickly();
  for (auto& file : files) file->remove_previous();
}

}  // namespace sphshell::io
