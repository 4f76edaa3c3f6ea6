#pragma once
// Output of a distributed run (docs/distributed.md, "Output"): ParaView frames
// in pieces and probes written by the rank that owns what they probe.
//
// Frames: each rank writes one .vtu piece with the particles it owns
// (particles_NNNNNN_rR.vtu: deformed or reference positions as
// OutputOptions::frame_coordinates says, one vertex cell per particle, and the
// point arrays global_id, displacement, velocity, director, with fragment when
// there are cracks) and one with the active stress points it owns
// (stress_points_NNNNNN_rR.vtu: a vertex cell at each, the serial frame's
// stress-point cell arrays); after every piece is on disk rank 0 writes a
// .pvtu for each naming the pieces, with cracks the crack segments
// (cracks_NNNNNN.vtu, the whole crack set), and adds them to particles.pvd,
// stress_points.pvd and cracks.pvd together, so ParaView opens each series
// as a whole. Every file is replaced atomically (io/output_file.hpp): a kill
// leaves the last complete frame readable.
//
// Probes: every rank registers the probe; the owner of the particle opens
// the CSV and writes its rows, the same columns and values as the serial
// probe (solver::ParticleProbe), on the serial schedule.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/directory_lock.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output.hpp>

#include <array>
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
  // Collective: rank 0 creates the directory, takes it (its lock file, as a
  // serial Solver does: io/directory_lock.hpp) and starts the empty series;
  // an Error there stops every rank.
  DistributedFrames(const Communicator& comm, const OutputOptions& options, bool with_cracks)
      : options_(options), with_cracks_(with_cracks) {
    if (options_.output_directory.empty()) return;
    collectively(comm, [&] {
      if (comm.is_root()) {
        io::make_directory(options_.output_directory, "", "output_directory");
        lock_ = std::make_unique<io::DirectoryLock>(options_.output_directory, "output_directory");
        start_series({});
      }
    });
  }
  bool enabled() const { return !options_.output_directory.empty(); }
  bool writes_on_schedule() const { return enabled() && options_.output_interval > 0.0; }
  long last_frame_step() const { return last_frame_step_; }
  double next_frame_time() const { return next_frame_time_; }
  void schedule_next(double next) { next_frame_time_ = next; }

  // Writes this rank's pieces (particles, stress points), then rank 0 the
  // .pvtu files, the crack frame (`cracks`: rank 0's, with cracks) and the
  // series entries, all series together. Collective.
  void write(const Communicator& comm, const FramePiece& piece, const io::VtuGrid& stress_points,
             const io::VtuGrid* cracks, long step) {
    if (!enabled())
      sphshell::detail::invalid_parameter("output_directory", std::string(), "a frame needs an output folder");
    const std::string number = frame_number(frames_written_);
    const io::VtuGrid particles = grid_of(piece);
    collectively(comm, [&] {
      io::write_vtu(path(piece_name("particles_" + number, comm.rank())), particles, format());
      io::write_vtu(path(piece_name("stress_points_" + number, comm.rank())), stress_points, format());
    });
    collectively(comm, [&] {
      if (!comm.is_root()) return;
      write_pvtu(path("particles_" + number + ".pvtu"), "particles_" + number, comm.size(), particles);
      write_pvtu(path("stress_points_" + number + ".pvtu"), "stress_points_" + number, comm.size(), stress_points);
      series_[0]->stage(piece.time, path("particles_" + number + ".pvtu"));
      series_[1]->stage(piece.time, path("stress_points_" + number + ".pvtu"));
      if (with_cracks_) {
        io::write_vtu(path("cracks_" + number + ".vtu"), *cracks, format());
        series_[2]->stage(piece.time, path("cracks_" + number + ".vtu"));
      }
      io::write_together(collections());
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
    for (const std::optional<io::PvdCollection>& series : series_) {
      std::vector<SeriesEntry> entries;
      if (series)
        for (const io::PvdCollection::Entry& entry : series->entries()) entries.push_back({entry.time, entry.file});
      out(entries);
    }
  }
  template <class Reader>
  void load(Reader& in) {
    std::int64_t frames = 0, last_step = 0;
    double next_frame = 0.0;
    std::string directory;
    std::array<std::vector<SeriesEntry>, series_count> entries;
    in(frames, last_step, next_frame, directory);
    for (std::vector<SeriesEntry>& list : entries) in(list);
    last_frame_step_ = static_cast<long>(last_step);
    next_frame_time_ = next_frame;
    frames_written_ = 0;
    if (!enabled() || directory != io::identity_of(options_.output_directory)) return;
    frames_written_ = static_cast<long>(frames);
    if (series_[0]) start_series(entries);  // rank 0
  }

  std::string path(const std::string& file) const { return options_.output_directory + "/" + file; }
  static std::string frame_number(long frame) {
    char number[32];
    std::snprintf(number, sizeof number, "%06ld", frame);
    return number;
  }
  static std::string piece_name(const std::string& frame, int rank) { return frame + "_r" + std::to_string(rank) + ".vtu"; }

 private:
  struct SeriesEntry {
    double time = 0.0;
    std::string file;  // relative to the output directory
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.time, self.file);
    }
  };
  static constexpr std::size_t series_count = 3;  // particles, stress points, cracks

  // Rank 0: the series with these entries, written together.
  void start_series(const std::array<std::vector<SeriesEntry>, series_count>& entries) {
    const char* names[series_count] = {"particles.pvd", "stress_points.pvd", "cracks.pvd"};
    for (std::size_t k = 0; k < series_count; ++k) {
      series_[k].reset();
      if (k == 2 && !with_cracks_) continue;
      series_[k].emplace(path(names[k]), false);
      for (const SeriesEntry& entry : entries[k]) series_[k]->stage(entry.time, path(entry.file));
    }
    io::write_together(collections());
  }
  std::vector<const io::PvdCollection*> collections() const {
    std::vector<const io::PvdCollection*> list;
    for (const std::optional<io::PvdCollection>& series : series_)
      if (series) list.push_back(&*series);
    return list;
  }

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

  // The parallel file of one frame: its pieces and the arrays they hold
  // (names, types and components as `layout`, a piece, has them).
  void write_pvtu(const std::string& file_path, const std::string& frame, int pieces, const io::VtuGrid& layout) const {
    const std::string real = options_.frame_precision == io::VtuPrecision::float32 ? "Float32" : "Float64";
    auto array = [&](std::ostream& out, const io::Field& field) {
      out << "      <PDataArray type=\"" << (field.kind == io::FieldValues::integer ? "Int32" : real) << "\" Name=\""
          << field.name << "\"";
      if (field.components > 1) out << " NumberOfComponents=\"" << field.components << "\"";
      out << "/>\n";
    };
    io::detail::ReplacingOutputFile file(file_path);
    std::ostream& out = file.stream();
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        << "  <PUnstructuredGrid GhostLevel=\"0\">\n"
        << "    <PPointData>\n";
    for (const io::PointField& field : layout.point_fields) array(out, field);
    out << "    </PPointData>\n"
        << "    <PCellData>\n";
    for (const io::CellField& field : layout.cell_fields) array(out, field);
    out << "    </PCellData>\n"
        << "    <PPoints>\n"
        << "      <PDataArray type=\"" << real << "\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
        << "    </PPoints>\n";
    for (int r = 0; r < pieces; ++r) out << "    <Piece Source=\"" << piece_name(frame, r) << "\"/>\n";
    out << "  </PUnstructuredGrid>\n"
        << "</VTKFile>\n";
    file.commit();
  }

  OutputOptions options_;
  bool with_cracks_ = false;
  std::unique_ptr<io::DirectoryLock> lock_;  // rank 0's, held while the solver lives
  std::array<std::optional<io::PvdCollection>, series_count> series_;  // rank 0
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
