#pragma once
// Output of a distributed run (docs/distributed.md, "Output"): ParaView frames
// in pieces and probes written by the rank that owns what they probe.
//
// Frames: each rank writes one .vtu piece with the particles it owns
// (particles_NNNNNN_rR.vtu: deformed or reference positions as
// OutputOptions::frame_coordinates says, one vertex cell per particle, and the
// point arrays global_id, rank, displacement, velocity, director, with
// fragment when there are cracks); after every piece is on disk rank 0 writes
// particles_NNNNNN.pvtu naming them and adds it to particles.pvd, so ParaView
// opens the series as a whole. Every file is replaced atomically
// (io/output_file.hpp): a kill leaves the last complete frame readable.
//
// Probes: every rank registers the probe; the owner of the particle opens
// the CSV and writes its rows, the same columns and values as the serial
// probe (solver::ParticleProbe), on the serial schedule.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sphshell::mpi {

// What one rank puts in its piece of a frame.
struct FramePiece {
  std::vector<Vector3> points;  // owned particles, as drawn
  std::vector<int> global_id;
  std::vector<Vector3> displacement, velocity, director;
  std::vector<double> fragment;  // empty without cracks
  double time = 0.0;
};

class DistributedFrames {
 public:
  DistributedFrames() = default;
  // Collective: rank 0 creates the directory (and the empty .pvd); an Error
  // there stops every rank.
  DistributedFrames(const Communicator& comm, const OutputOptions& options) : options_(options) {
    if (options_.output_directory.empty()) return;
    collectively(comm, [&] {
      if (comm.is_root()) {
        io::make_directory(options_.output_directory, "", "output_directory");
        series_.emplace(path("particles.pvd"));
      }
    });
  }
  bool enabled() const { return !options_.output_directory.empty(); }
  bool writes_on_schedule() const { return enabled() && options_.output_interval > 0.0; }
  long last_frame_step() const { return last_frame_step_; }
  double next_frame_time() const { return next_frame_time_; }
  void schedule_next(double next) { next_frame_time_ = next; }

  // Writes this rank's piece, then (rank 0) the .pvtu and the series entry.
  // Collective.
  void write(const Communicator& comm, const FramePiece& piece, long step) {
    if (!enabled())
      sphshell::detail::invalid_parameter("output_directory", std::string(), "a frame needs an output folder");
    const std::string frame = frame_name(frames_written_);
    collectively(comm, [&] { io::write_vtu(path(piece_name(frame, comm.rank())), grid_of(piece), format()); });
    collectively(comm, [&] {
      if (!comm.is_root()) return;
      write_pvtu(path(frame + ".pvtu"), frame, comm.size(), piece.fragment.empty() == false);
      series_->add(piece.time, path(frame + ".pvtu"));
    });
    ++frames_written_;
    last_frame_step_ = step;
  }

  // Checkpoints (DistributedSolver::save_checkpoint): the schedule and, from
  // rank 0, the series' entries. A restart in the same output_directory
  // continues the series from the checkpoint's frames (later ones leave the
  // series and are overwritten as the run passes them again); in another
  // folder, or without one when saved, the series starts anew at the next frame.
  template <class Writer>
  void save(Writer& out) const {
    out(static_cast<std::int64_t>(frames_written_), static_cast<std::int64_t>(last_frame_step_), next_frame_time_);
    out(options_.output_directory.empty() ? std::string() : io::identity_of(options_.output_directory));
    std::vector<SeriesEntry> entries;
    if (series_)
      for (const io::PvdCollection::Entry& entry : series_->entries()) entries.push_back({entry.time, entry.file});
    out(entries);
  }
  template <class Reader>
  void load(Reader& in) {
    std::int64_t frames = 0, last_step = 0;
    double next_frame = 0.0;
    std::string directory;
    std::vector<SeriesEntry> entries;
    in(frames, last_step, next_frame, directory, entries);
    last_frame_step_ = static_cast<long>(last_step);
    next_frame_time_ = next_frame;
    frames_written_ = 0;
    if (!enabled() || directory != io::identity_of(options_.output_directory)) return;
    frames_written_ = static_cast<long>(frames);
    if (series_) {  // rank 0
      series_.emplace(path("particles.pvd"), false);
      for (const SeriesEntry& entry : entries) series_->stage(entry.time, path(entry.file));
      series_->write();
    }
  }

  std::string path(const std::string& file) const { return options_.output_directory + "/" + file; }
  static std::string frame_name(long frame) {
    char name[32];
    std::snprintf(name, sizeof name, "particles_%06ld", frame);
    return name;
  }
  static std::string piece_name(const std::string& frame, int rank) { return frame + "_r" + std::to_string(rank) + ".vtu"; }

 private:
  io::VtuFormat format() const { return {options_.frame_encoding, options_.frame_precision}; }

  static io::PointField vector_field(const std::string& name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}};
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    return field;
  }

  io::VtuGrid grid_of(const FramePiece& piece) const {
    io::VtuGrid grid;
    grid.points = piece.points;
    grid.time = piece.time;
    for (std::size_t i = 0; i < piece.points.size(); ++i) grid.cells.add_vertex(static_cast<int>(i));
    io::PointField id{"global_id", 1, {}, {}, io::FieldValues::integer};
    for (int global : piece.global_id) id.values.push_back(global);
    grid.point_fields = {id, vector_field("displacement", piece.displacement),
                         vector_field("velocity", piece.velocity), vector_field("director", piece.director)};
    if (!piece.fragment.empty()) grid.point_fields.push_back({"fragment", 1, piece.fragment, {}, io::FieldValues::integer});
    grid.note = std::string("sphshell frame piece (one rank's owned particles), t = ") +
                io::detail::round_trip_decimal(piece.time) + " s; points: " +
                (options_.frame_coordinates == FrameCoordinates::deformed ? "deformed" : "reference") + " positions";
    return grid;
  }

  // The parallel file: the pieces and the arrays they hold (names, types and
  // components as the pieces write them).
  void write_pvtu(const std::string& file_path, const std::string& frame, int pieces, bool with_fragments) const {
    const std::string real = options_.frame_precision == io::VtuPrecision::float32 ? "Float32" : "Float64";
    io::detail::ReplacingOutputFile file(file_path);
    std::ostream& out = file.stream();
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        << "  <PUnstructuredGrid GhostLevel=\"0\">\n"
        << "    <PPointData>\n"
        << "      <PDataArray type=\"Int32\" Name=\"global_id\"/>\n"
        << "      <PDataArray type=\"" << real << "\" Name=\"displacement\" NumberOfComponents=\"3\"/>\n"
        << "      <PDataArray type=\"" << real << "\" Name=\"velocity\" NumberOfComponents=\"3\"/>\n"
        << "      <PDataArray type=\"" << real << "\" Name=\"director\" NumberOfComponents=\"3\"/>\n";
    if (with_fragments) out << "      <PDataArray type=\"Int32\" Name=\"fragment\"/>\n";
    out << "    </PPointData>\n"
        << "    <PPoints>\n"
        << "      <PDataArray type=\"" << real << "\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
        << "    </PPoints>\n";
    for (int r = 0; r < pieces; ++r) out << "    <Piece Source=\"" << piece_name(frame, r) << "\"/>\n";
    out << "  </PUnstructuredGrid>\n"
        << "</VTKFile>\n";
    file.commit();
  }

  struct SeriesEntry {
    double time = 0.0;
    std::string file;  // relative to the output directory
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.time, self.file);
    }
  };

  OutputOptions options_;
  std::optional<io::PvdCollection> series_;  // rank 0
  long frames_written_ = 0;
  long last_frame_step_ = -1;
  double next_frame_time_ = 0.0;
};

// A probe of a particle or a stress point, its file on the rank owning it.
struct DistributedProbe {
  enum class Kind { particle, stress_point };
  Kind kind = Kind::particle;
  int index = 0;  // global particle or stress point index
  std::string path;
  std::unique_ptr<io::CsvProbe> file;  // on the owner only
  std::size_t local_point = 0;         // a stress point's local point (owner only)
};

}  // namespace sphshell::mpi
