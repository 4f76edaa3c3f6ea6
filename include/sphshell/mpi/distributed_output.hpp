#pragma once
// Output of a distributed run (docs/distributed.md, "Output"): ParaView frames
// in pieces and probes written by the rank that owns what they probe.
//
// Frames: each rank writes its pieces of every frame, drawn as the serial
// frame is (solver::FramePiece, solver/output.hpp: the shell as its cells,
// cracks as gaps): particles_NNNNNN_rR.vtu with its local particles (the
// ones it owns, and the ghosts that are corners of its cells; point arrays
// as the serial frame's, and global_id) and the cells of the active stress
// points it owns, and stress_points_NNNNNN_rR.vtu with the same cells and the
// stress-point cell arrays. After every piece is on disk rank 0 writes a
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
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace sphshell::mpi {

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
  void write(const Communicator& comm, const io::VtuGrid& particles, const io::VtuGrid& stress_points,
             const io::VtuGrid* cracks, long step) {
    if (!enabled())
      sphshell::detail::invalid_parameter("output_directory", std::string(), "a frame needs an output folder");
    const std::string number = frame_number(frames_written_);
    collectively(comm, [&] {
      io::write_vtu(path(piece_name("particles_" + number, comm.rank())), particles, format());
      io::write_vtu(path(piece_name("stress_points_" + number, comm.rank())), stress_points, format());
    });
    collectively(comm, [&] {
      if (!comm.is_root()) return;
      write_pvtu(path("particles_" + number + ".pvtu"), "particles_" + number, comm.size(), particles);
      write_pvtu(path("stress_points_" + number + ".pvtu"), "stress_points_" + number, comm.size(), stress_points);
      series_[0]->stage(particles.time, path("particles_" + number + ".pvtu"));
      series_[1]->stage(particles.time, path("stress_points_" + number + ".pvtu"));
      if (with_cracks_) {
        io::write_vtu(path("cracks_" + number + ".vtu"), *cracks, format());
        series_[2]->stage(particles.time, path("cracks_" + number + ".vtu"));
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
  // What a file would be to this output directory: a frame's piece or
  // parallel file, a collection ("particles…", "stress_points…" or
  // "cracks…" ending in .vtu, .pvtu or .pvd, or those with .tmp), or the
  // lock file; "" for none of them.
  std::string file_use(const std::string& file_path) const {
    if (!enabled()) return "";
    const std::filesystem::path file(io::identity_of(file_path));
    if (file.parent_path().string() != io::identity_of(options_.output_directory)) return "";
    std::string name = file.filename().string();
    if (name == io::DirectoryLock::file_name)
      return "the lock file of output_directory '" + options_.output_directory + "'";
    auto ends_with = [&](const std::string& tail) {
      return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
    };
    if (ends_with(".tmp")) name.resize(name.size() - 4);
    for (const std::string series : {"particles", "stress_points", "cracks"})
      if (name.compare(0, series.size(), series) == 0 && (ends_with(".vtu") || ends_with(".pvtu") || ends_with(".pvd")))
        return "named like a frame file (a piece, a .pvtu or a collection of the series) of output_directory '" +
               options_.output_directory + "'";
    return "";
  }
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


// The output part of a distributed Solver (solver.hpp, the domain's part in
// place of solver::SolverOutput, with its interface): frames in pieces, and
// probes written by the owner of what they probe. It reads the solver's
// local state (a friend of it).
template <int OutputPoints>
class DistributedOutput {
 public:
  using StressProbe = solver::StressPointProbe<OutputPoints>;

  // Collective: rank 0 takes the output directory.
  DistributedOutput(const Communicator& comm, const OutputOptions& options, bool with_cracks)
      : frames_(comm, options, with_cracks), options_(options) {}

  // Probes are added after loading a checkpoint (the owner's file continues from it).
  void check_can_load() const {
    if (!probes_.empty())
      throw Error("sphshell: load_checkpoint: " + std::to_string(probes_.size()) +
                  " probe(s) were added before it; a distributed run adds its probes after loading a checkpoint");
  }

  // Every rank registers the probe; the owner opens the file.
  template <class Probe, class Solver>
  void add_probe(const std::string& csv_path, const Probe& probe, const Solver& solver) {
    for (const DistributedProbe& open : probes_)
      if (open.path == csv_path)
        throw Error("sphshell: probe file '" + csv_path + "' is already the file of another probe; give each probe "
                    "a file of its own");
    // Files the run writes itself: every rank's checkpoint file and the frames.
    const std::string key = io::identity_of(csv_path);
    if (!options_.checkpoint_path.empty())
      for (int rank = 0; rank < solver.domain_.size(); ++rank) {
        const std::string checkpoint =
            std::decay_t<decltype(solver.domain_)>::checkpoint_file_of(options_.checkpoint_path, rank);
        if (key == io::identity_of(checkpoint))
          throw Error("sphshell: probe file '" + csv_path + "' is rank " + std::to_string(rank) +
                      "'s checkpoint file '" + checkpoint + "' (checkpoint_path '" + options_.checkpoint_path +
                      "'; the checkpoint would replace it); give the probe a file of its own");
      }
    const std::string use = frames_.file_use(csv_path);
    if (!use.empty())
      throw Error("sphshell: probe file '" + csv_path + "' is " + use + "; give the probe a file of its own");
    DistributedProbe added;
    added.path = csv_path;
    if constexpr (std::is_same_v<Probe, StressProbe>) {
      added.kind = DistributedProbe::Kind::stress_point;
      added.index = probe.stress_point;
      const long row = solver.domain_.owned_stress_row(static_cast<std::size_t>(probe.stress_point));
      if (row >= 0) {
        added.local_point = solver.points_->point(solver::PointGroup::stress_points, static_cast<std::size_t>(row));
        open_probe(added, stress_probe<typename Solver::rule_type>(probe.stress_point).columns(), solver);
      }
    } else {
      added.index = probe.particle;
      if (solver.domain_.owns(probe.particle)) open_probe(added, probe.columns(), solver);
    }
    probes_.push_back(std::move(added));
  }

  // Before the first step: the reference configuration at t = 0.
  template <class Solver>
  void start(const Solver& solver) {
    if (frames_.writes_on_schedule() && frames_.last_frame_step() < 0) {
      write_frame(solver);
      frames_.schedule_next(solver.time() + options_.output_interval);
    }
  }
  // The serial schedule (solver::SolverOutput::write_scheduled).
  template <class Solver>
  void write_scheduled(const Solver& solver) {
    const double time = solver.time(), time_step = solver.time_step();
    if (frames_.writes_on_schedule() && time >= frames_.next_frame_time() - 0.5 * time_step) {
      if (frames_.last_frame_step() != solver.steps()) write_frame(solver);
      const double interval = options_.output_interval;
      const double passed = std::floor((time + 0.5 * time_step - frames_.next_frame_time()) / interval);
      frames_.schedule_next(frames_.next_frame_time() + interval * (std::max(0.0, passed) + 1.0));
    }
    if (!probes_.empty() && time >= next_probe_time_ - probe_schedule_tolerance * time_step) {
      for (DistributedProbe& probe : probes_)
        if (probe.file) write_probe_row(probe, solver);
      next_probe_time_ = time + options_.probe_interval;
    }
  }
  template <class Solver>
  void finish(const Solver& solver) {
    if (frames_.writes_on_schedule() && frames_.last_frame_step() != solver.steps()) write_frame(solver);
  }

  // One frame now (collective): each rank's particle and stress-point
  // pieces, rank 0 the .pvtu files, the crack frame and the series.
  template <class Solver>
  void write_frame(const Solver& solver) {
    const solver::FramePiece<Solver> piece(solver, options_.frame_coordinates);
    const io::VtuGrid particles = piece.particle_grid(), stress_points = piece.stress_point_grid();
    if constexpr (Solver::crack_type::enabled) {
      const io::VtuGrid cracks = piece.crack_grid();  // collective
      frames_.write(solver.domain().communicator(), particles, stress_points, &cracks, solver.steps());
    } else {
      frames_.write(solver.domain().communicator(), particles, stress_points, nullptr, solver.steps());
    }
  }

  // Checkpoints: the frame schedule and series, the probe schedule and the
  // owned probes' files (for probes added after a restart to continue them).
  template <class Writer>
  void save(Writer& out) const {
    frames_.save(out);
    out(next_probe_time_);
    std::uint64_t open_files = 0;
    for (const DistributedProbe& probe : probes_) open_files += probe.file ? 1 : 0;
    out(open_files);
    for (const DistributedProbe& probe : probes_)
      if (probe.file) {
        const io::CsvProbe::Resume written = probe.file->written();
        out(probe.path, static_cast<std::uint32_t>(probe.kind), static_cast<std::int64_t>(probe.index),
            written.bytes, written.hash);
      }
  }
  template <class Reader, class Solver>
  void load(Reader& in, const Solver&) {
    frames_.load(in);
    in(next_probe_time_);
    std::uint64_t open_files = 0;
    in(open_files);
    restored_probes_.clear();
    for (std::uint64_t n = 0; n < open_files; ++n) {
      RestoredProbe record;
      std::uint32_t kind = 0;
      std::int64_t index = 0;
      in(record.path, kind, index, record.written.bytes, record.written.hash);
      if (kind > 1) in.fail("a probe of unknown kind " + std::to_string(kind));
      record.kind = static_cast<DistributedProbe::Kind>(kind);
      record.index = static_cast<int>(index);
      restored_probes_.push_back(std::move(record));
    }
  }

 private:
  // As the serial output's probe schedule (solver/output.hpp).
  static constexpr double probe_schedule_tolerance = 1e-9;
  struct RestoredProbe {
    std::string path;
    DistributedProbe::Kind kind = DistributedProbe::Kind::particle;
    int index = 0;
    io::CsvProbe::Resume written;
  };

  template <class Rule>
  static StressProbe stress_probe(int stress_point) {
    StressProbe probe(stress_point);
    probe.point_names = solver::thickness_point_names<Rule>();
    return probe;
  }
  // What solver::ParticleProbe and StressPointProbe read, for what the owner holds.
  template <class Solver>
  struct OwnedView {
    const Solver& solver;
    std::size_t local_point;
    struct Field {
      const std::vector<Vector3>& local;
      const Solver& solver;
      const Vector3& operator[](int global) const {
        return local[static_cast<std::size_t>(solver.domain_.local_of(static_cast<std::size_t>(global)))];
      }
    };
    double time() const { return solver.time(); }
    Field velocities() const { return {solver.particles_.velocity, solver}; }
    std::size_t local(int global) const {
      return static_cast<std::size_t>(solver.domain_.local_of(static_cast<std::size_t>(global)));
    }
    Vector3 displacement(int global) const {
      return solver.particles_.position[local(global)] - solver.reference_position_[local(global)];
    }
    Vector3 rotation(int global) const {
      return solver::rotation_vector(solver.reference_normal_[local(global)], solver.particles_.director[local(global)]);
    }
    double integral_point_quantity(solver::IntegralPointQuantity quantity, int, int k) const {
      return solver.states_->quantity(quantity, local_point, k);
    }
  };
  template <class Solver>
  void write_probe_row(DistributedProbe& probe, const Solver& solver) const {
    const OwnedView<Solver> view{solver, probe.local_point};
    if (probe.kind == DistributedProbe::Kind::particle)
      probe.file->write_row(solver::ParticleProbe{probe.index}.row(view));
    else
      // A row needs no column names: no rule's names are built per row.
      probe.file->write_row(StressProbe(probe.index).row(view));
  }
  // The owner's file of a new probe: the file a loaded checkpoint recorded
  // for the same probe continues from the checkpoint's rows; else a new
  // file starts with the row of now.
  template <class Solver>
  void open_probe(DistributedProbe& probe, std::vector<std::string> columns, const Solver& solver) {
    for (auto record = restored_probes_.begin(); record != restored_probes_.end(); ++record)
      if (record->path == probe.path && record->kind == probe.kind && record->index == probe.index) {
        probe.file = std::make_unique<io::CsvProbe>(probe.path, std::move(columns), record->written);
        restored_probes_.erase(record);
        return;
      }
    probe.file = std::make_unique<io::CsvProbe>(probe.path, std::move(columns));
    write_probe_row(probe, solver);
  }
  DistributedFrames frames_;
  OutputOptions options_;
  std::vector<DistributedProbe> probes_;
  std::vector<RestoredProbe> restored_probes_;  // recorded by a loaded checkpoint, not added again yet
  double next_probe_time_ = 0.0;
};

}  // namespace sphshell::mpi
