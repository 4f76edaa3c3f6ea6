#pragma once
// The solver's output: ParaView frames (particles, stress points and, with a
// crack policy, crack segments, each series in a .pvd collection) on the
// output schedule and at the end of every run_until, and CSV probes. It
// reads the run through the solver (its friend) and the domain part's share
// (domain/domain.hpp), so it holds no state of the run but its own schedule
// and files. A distributed run writes each frame in pieces, one per process
// (particles_N_rR.vtu, stress_points_N_rR.vtu: its local particles, with
// global_id, and the cells of the stress points it owns), and the first
// process a .pvtu naming the pieces and the whole cracks_N.vtu; the
// collections list the .pvtu files. A probe's file is written by the
// process that owns what it probes.
//
// A frame draws the shell as its cells (ShellModel::cells(): the quads or
// triangles whose centres are the stress points), so ParaView's default
// Surface view shows a surface:
//   particles_N.vtu      the particles as the corners of the same cells
//                        (plus a vertex cell for a particle none holds), with
//                        the particle data as point data;
//   stress_points_N.vtu  one cell per active stress point over its corner
//                        particles, with the stress-point data as cell data; a
//                        removed stress point has no cell, so a crack is a gap,
//                        and one whose cell a crack cuts (it no longer sees a
//                        corner) is a vertex cell at its own position, so that
//                        a slit between rows of particles shows as a gap too;
//   cracks_N.vtu         the crack segments as lines.
// A model from the general constructor has no cells: its frames are point
// clouds (one vertex cell per particle, and per active stress point).
// Points sit at the deformed or the reference positions
// (OutputOptions::frame_coordinates); every file says which in a comment at
// its top and carries the point array "displacement". Each file holds its
// time as FieldData TimeValue.
//
// Collisions: the output directory is the solver's alone while it lives (a
// lock file, io/directory_lock.hpp); a probe file, the checkpoint_path, the
// frames, the collections and the lock file must all be different files,
// which is checked when the solver is built and when a probe is added, before
// the first step. A file in the folder that is named like a frame but that no
// run of this library can have written (a folder, a number past any frame's)
// is kept and named on the notes stream (MonitoringOptions::progress_stream).
//
// Kill safety: a frame's files are written (each atomically) before the
// three collections are rewritten together (io::write_together), so at any
// moment the collections list the same frames and every listed file is
// complete, but for the microseconds of the final atomic swaps.
//
// A probe is a type whose column names and row values sit together:
//   std::vector<std::string> columns() const;
//   template <class Solver> std::vector<double> row(const Solver&) const;

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/directory_lock.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/rigid_body_surfaces.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/particles.hpp>
#include <sphshell/solver/section_states.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace sphshell::solver {

// The thickness output points of a rule named by where they sit: their height
// ζ along the director as a fraction of the wall thickness d, the first
// (ζ < 0, the side the director points away from) "bottom", the last "top",
// ζ = 0 "mid"; e.g. Gauss<3>: "bottom zeta=-0.387d", "mid zeta=0",
// "top zeta=+0.387d". A resultant rule (Global) has one, "whole section".
template <class Rule>
std::vector<std::string> thickness_point_names() {
  if constexpr (Rule::num_points == 0) {
    return {"whole section"};
  } else {
    std::vector<std::string> names;
    const int count = Rule::num_points;
    for (int k = 0; k < count; ++k) {
      // Reference points lie on [-1, 1]: ζ/d is half of one.
      const double fraction = 0.5 * Rule::reference_points[std::size_t(k)];
      char height[32];
      if (fraction == 0.0)
        std::snprintf(height, sizeof height, "zeta=0");
      else
        std::snprintf(height, sizeof height, "zeta=%+.3gd", fraction);
      std::string name;
      if (fraction == 0.0)
        name = "mid ";
      else if (k == 0)
        name = "bottom ";
      else if (k == count - 1)
        name = "top ";
      names.push_back(name + height);
    }
    return names;
  }
}

// One particle's history: t, displacement, velocity, rotation vector.
struct ParticleProbe {
  int particle;
  std::vector<std::string> columns() const {
    return {"t [s]", "ux [m]", "uy [m]", "uz [m]", "vx [m/s]", "vy [m/s]", "vz [m/s]", "rx [rad]", "ry [rad]", "rz [rad]"};
  }
  template <class Solver>
  std::vector<double> row(const Solver& solver) const {
    const Vector3 u = solver.displacement(particle), v = solver.velocities()[particle], r = solver.rotation(particle);
    return {solver.time(), u.x(), u.y(), u.z(), v.x(), v.y(), v.z(), r.x(), r.y(), r.z()};
  }
};

// One stress point's history: t, then each integral-point quantity at each
// thickness output point (in the rule's order, ζ ascending), the column named
// by the point's number and position, e.g. "equivalent_stress_1 (bottom
// zeta=-0.453d) [Pa]".
template <int OutputPoints>
struct StressPointProbe {
  explicit StressPointProbe(int point) : stress_point(point) {}
  int stress_point;
  std::vector<std::string> point_names;  // thickness_point_names of the rule (set by SolverOutput::add_probe)
  std::vector<std::string> columns() const {
    std::vector<std::string> names{"t [s]"};
    for (const IntegralPointQuantityInfo& info : integral_point_quantities)
      for (int k = 1; k <= OutputPoints; ++k)
        names.push_back(info.name + ("_" + std::to_string(k)) + " (" + point_names.at(std::size_t(k - 1)) + ")" +
                        info.unit);
    return names;
  }
  template <class Solver>
  std::vector<double> row(const Solver& solver) const {
    std::vector<double> values{solver.time()};
    for (const IntegralPointQuantityInfo& info : integral_point_quantities)
      for (int k = 0; k < OutputPoints; ++k) values.push_back(solver.integral_point_quantity(info.quantity, stress_point, k));
    return values;
  }
};

template <class Solver>
class FramePiece;

// Holds the schedule and the open files; every member that reads the run takes
// the solver (its friend: the members read the process's share through the
// solver's domain part, solver.domain_).
template <int OutputPoints>
class SolverOutput {
 public:
  static constexpr int output_points = OutputPoints;
  using StressProbe = StressPointProbe<output_points>;

  // Collective: the first process creates the output directory at once, so
  // that a path that cannot be one fails before the run rather than at its
  // first frame, and takes it (its lock file) for this solver. Notes on kept
  // files go to `notes` (std::clog when null).
  template <class Domain>
  SolverOutput(const Domain& domain, const OutputOptions& options, std::ostream* notes = nullptr)
      : options_(options), notes_(notes) {
    if (options_.output_directory.empty()) return;
    domain.collectively([&] {
      if (domain.is_root()) io::make_directory(options_.output_directory, "", "output_directory");
    });
    domain.collectively([&] {
      directory_key_ = io::identity_of(options_.output_directory);
      if (directory_key_.size() > 1 && directory_key_.back() == '/') directory_key_.pop_back();
      if (!options_.checkpoint_path.empty()) {
        const std::string use = output_file_use(domain.checkpoint_file(options_.checkpoint_path));
        if (!use.empty())
          detail::invalid_parameter("checkpoint_path", options_.checkpoint_path,
                                    "it is " + use + "; give the checkpoint a file of its own");
      }
      if (domain.is_root()) lock_ = std::make_unique<io::DirectoryLock>(options_.output_directory, "output_directory");
    });
  }

  // Every process registers the probe; the one that owns what it probes
  // writes its file. A probe on a file a loaded checkpoint recorded continues
  // that file (no header, no row now: the file has both).
  template <class Probe, class Solver>
  void add_probe(const std::string& csv_path, Probe probe, const Solver& solver) {
    const auto& domain = solver.domain_;
    const std::string key = io::identity_of(csv_path);
    for (const OpenProbe& open : probes_)
      if (open.key == key)
        throw Error("sphshell: probe file '" + csv_path + "' is already the file of another probe (added as '" +
                    open.path + "'); give each probe a file of its own");
    // Files the run writes itself: every process's checkpoint file and the frames.
    if (!options_.checkpoint_path.empty())
      for (int process = 0; process < domain.size(); ++process) {
        const std::string file = domain.checkpoint_file_of(options_.checkpoint_path, process);
        if (key == io::identity_of(file))
          throw Error("sphshell: probe file '" + csv_path + "' is " +
                      (domain.is_distributed ? "rank " + std::to_string(process) + "'s" : std::string("the")) +
                      " checkpoint file '" + file + "' (checkpoint_path '" + options_.checkpoint_path +
                      "'; the checkpoint would replace it); give the probe a file of its own");
      }
    const std::string use = output_file_use(csv_path);
    if (!use.empty())
      throw Error("sphshell: probe file '" + csv_path + "' is " + use + "; give the probe a file of its own");
    if constexpr (std::is_same_v<Probe, StressProbe>)
      probe.point_names = thickness_point_names<typename Solver::rule_type>();
    OpenProbe open{csv_path, key, ProbeVariant{std::move(probe)}, std::nullopt, 0};
    if (const auto* particle = std::get_if<ParticleProbe>(&open.probe)) {
      if (!domain.owns(particle->particle)) return probes_.push_back(std::move(open));
    } else {
      const long row = domain.owned_stress_row(static_cast<std::size_t>(std::get<StressProbe>(open.probe).stress_point));
      if (row < 0) return probes_.push_back(std::move(open));
      open.local_point = solver.points_->point(PointGroup::stress_points, static_cast<std::size_t>(row));
    }
    create_parent_directory(csv_path);
    for (auto record = restored_probes_.begin(); record != restored_probes_.end(); ++record)
      if (record->key == key) {
        check_same_probe(*record, open.probe, csv_path);
        open.file.emplace(csv_path, columns_of(open.probe), record->written);
        restored_probes_.erase(record);
        return probes_.push_back(std::move(open));
      }
    open.file.emplace(csv_path, columns_of(open.probe));
    write_probe(open, solver);
    probes_.push_back(std::move(open));
  }

  // Checkpoints (solver/checkpoint.hpp): the schedule (frames written, the
  // latest frame's step, the next frame and probe times), the frame series
  // (the collections' entries, on the first process) and each probe file
  // this process writes (path, what it probes, its length and content hash).
  template <class Writer>
  void save(Writer& out) const {
    out(static_cast<std::int64_t>(frames_written_), static_cast<std::int64_t>(last_frame_step_), next_frame_time_,
        next_probe_time_);
    out(options_.output_directory.empty() ? std::string() : io::identity_of(options_.output_directory));
    const bool series = particle_collection_ != nullptr;
    out(series);
    if (series)
      for (const io::PvdCollection* collection :
           {particle_collection_.get(), stress_point_collection_.get(), crack_collection_.get()})
        out(collection ? entries_of(*collection) : std::vector<SeriesEntry>{});
    std::vector<ProbeRecord> records;
    for (const OpenProbe& open : probes_) {
      if (!open.file) continue;
      ProbeRecord record;
      record.key = open.key;
      record.kind = static_cast<std::uint32_t>(open.probe.index());
      record.index = probed_index(open.probe);
      record.written = open.file->written();
      records.push_back(record);
    }
    out(records);
  }

  // The schedule as it was; the series continues in the same
  // output_directory (its collections as they were, the frames written after
  // the checkpoint removed) and starts anew at the next frame in another one.
  // Probes already added continue their files (or restart them, if the
  // checkpoint has none of theirs); the others continue when added.
  template <class Reader, class Solver>
  void load(Reader& in, const Solver& solver) {
    std::int64_t frames = 0, last_step = 0;
    double next_frame = 0.0, next_probe = 0.0;
    std::string directory;
    bool series = false;
    std::array<std::vector<SeriesEntry>, 3> entries;
    std::vector<ProbeRecord> records;
    in(frames, last_step, next_frame, next_probe, directory, series);
    if (series)
      for (std::vector<SeriesEntry>& list : entries) in(list);
    in(records);
    for (const ProbeRecord& record : records)
      if (record.kind > 1) in.fail("a probe of unknown kind " + std::to_string(record.kind));

    last_frame_step_ = static_cast<long>(last_step);
    next_frame_time_ = next_frame;
    next_probe_time_ = next_probe;
    particle_collection_.reset();
    stress_point_collection_.reset();
    crack_collection_.reset();
    frames_written_ = 0;
    // A series is recorded once a frame was written (serially; distributed, by the first process).
    if (!options_.output_directory.empty() && directory == io::identity_of(options_.output_directory)) {
      frames_written_ = static_cast<long>(frames);
      if (series) restore_series(entries, Solver::crack_type::enabled);
    }
    restored_probes_ = records;
    for (OpenProbe& open : probes_) {
      if (!open.file) continue;  // another process's
      auto record = std::find_if(restored_probes_.begin(), restored_probes_.end(),
                                 [&](const ProbeRecord& r) { return r.key == open.key; });
      if (record == restored_probes_.end()) {
        open.file.emplace(open.path, columns_of(open.probe));  // a probe new to the run: starts now
        write_probe(open, solver);
        continue;
      }
      check_same_probe(*record, open.probe, open.path);
      open.file.emplace(open.path, columns_of(open.probe), record->written);
      restored_probes_.erase(record);
    }
  }

  // Before the first step: the reference configuration at t = 0.
  template <class Solver>
  void start(const Solver& solver) {
    if (!writes_frames()) return;
    if (frames_written_ == 0) write_frame(solver);
    next_frame_time_ = solver.time() + options_.output_interval;
  }

  // After a step: the frames and probe rows that are due. A frame is due at
  // the step nearest its time (within half a step), as run_until's end is.
  template <class Solver>
  void write_scheduled(const Solver& solver) {
    const double time = solver.time();
    const double frame_tolerance = 0.5 * solver.time_step();
    if (writes_frames() && time >= next_frame_time_ - frame_tolerance) {
      if (last_frame_step_ != solver.steps()) write_frame(solver);
      // Past every frame time this step covered, if the interval is below a step.
      const double passed = std::floor((time + frame_tolerance - next_frame_time_) / options_.output_interval);
      next_frame_time_ += options_.output_interval * (std::max(0.0, passed) + 1.0);
    }
    const double probe_tolerance = schedule_tolerance * solver.time_step();
    if (!probes_.empty() && time >= next_probe_time_ - probe_tolerance) {
      for (OpenProbe& probe : probes_)
        if (probe.file) write_probe(probe, solver);
      next_probe_time_ = time + options_.probe_interval;
    }
  }

  // At the end of run_until: the last state is always a frame (unless the
  // schedule wrote it at this step already).
  template <class Solver>
  void finish(const Solver& solver) {
    if (writes_frames() && last_frame_step_ != solver.steps()) write_frame(solver);
  }

  // One frame now, whatever the schedule (collective). Serially its files
  // are particles_N.vtu, stress_points_N.vtu and, with cracks, cracks_N.vtu;
  // distributed, each process writes its pieces (particles_N_rR.vtu,
  // stress_points_N_rR.vtu), then the first process a .pvtu naming the pieces
  // of each and the whole cracks_N.vtu. The collections list the frame once
  // every file of it is complete.
  template <class Solver>
  void write_frame(const Solver& solver) {
    if (options_.output_directory.empty())
      detail::invalid_parameter("output_directory", "(empty)", "set it to write ParaView frames");
    const auto& domain = solver.domain_;
    constexpr bool with_cracks = Solver::crack_type::enabled;
    char digits[32];
    std::snprintf(digits, sizeof digits, "%06ld", frames_written_);
    const std::string number(digits);
    const io::VtuFormat format{options_.frame_encoding, options_.frame_precision};
    const FramePiece<Solver> piece(solver, options_.frame_coordinates);
    std::array<io::VtuGrid, 2> grids{piece.particle_grid(), piece.stress_point_grid()};
    io::VtuGrid cracks;
    if constexpr (with_cracks) cracks = piece.crack_grid();  // collective
    domain.collectively([&] {
      if (domain.is_root() && !particle_collection_) start_series(with_cracks);
    });
    const std::array<std::string, 2> frames{"particles_" + number, "stress_points_" + number};
    domain.collectively([&] {
      for (std::size_t k = 0; k < grids.size(); ++k)
        io::write_vtu(series_path(domain.piece_file_of(frames[k], domain.rank())), grids[k], format);
    });
    domain.collectively([&] {
      if (!domain.is_root()) return;
      std::array<std::string, 3> listed;
      for (std::size_t k = 0; k < grids.size(); ++k) {
        listed[k] = series_path(domain.is_distributed ? frames[k] + ".pvtu" : domain.piece_file_of(frames[k], 0));
        if (domain.is_distributed) write_pvtu(listed[k], frames[k], domain, grids[k]);
      }
      listed[2] = series_path("cracks_" + number + ".vtu");
      if (with_cracks) io::write_vtu(listed[2], cracks, format);
      // Every file of the frame is complete before any collection lists it.
      particle_collection_->stage(solver.time(), listed[0]);
      if (!solver.bodies_.empty()) {  // the rigid bodies' surfaces: part 1 of the particle series
        const std::string bodies = series_path("bodies_" + number + ".vtu");
        io::write_vtu(bodies, io::rigid_body_grid(solver.bodies_, solver.particles_.position, solver.time()), format);
        particle_collection_->stage(solver.time(), bodies, 1);
      }
      stress_point_collection_->stage(solver.time(), listed[1]);
      std::vector<const io::PvdCollection*> collections{particle_collection_.get(), stress_point_collection_.get()};
      if (with_cracks) {
        crack_collection_->stage(solver.time(), listed[2]);
        collections.push_back(crack_collection_.get());
      }
      io::write_together(collections);
    });
    ++frames_written_;
    last_frame_step_ = solver.steps();
  }

  // The frames written so far in this run.
  long frames_written() const { return frames_written_; }

  static void create_parent_directory(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) io::make_directory(parent.string(), "probe file '" + path + "': ", "its folder");
  }

 private:
  // Probe rows within this fraction of a step of their time are due.
  static constexpr double schedule_tolerance = 1e-9;

  using ProbeVariant = std::variant<ParticleProbe, StressProbe>;

  // A probe: its CSV file as added and its identity (the absolute,
  // normalized path, to keep two probes off one file), what it probes, and,
  // on the process that owns that, the open file (and a stress point's local
  // point).
  struct OpenProbe {
    std::string path, key;
    ProbeVariant probe;
    std::optional<io::CsvProbe> file;
    std::size_t local_point;
  };

  // A probe file as a checkpoint recorded it: kind 0 a particle probe, 1 a
  // stress-point probe, of particle or stress point `index`.
  struct ProbeRecord {
    std::string key;
    std::uint32_t kind = 0;
    std::int64_t index = 0;
    io::CsvProbe::Resume written;
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.key, self.kind, self.index, self.written.bytes, self.written.hash);
    }
  };
  // One entry of a .pvd collection (the file relative to it).
  struct SeriesEntry {
    double time = 0.0;
    std::int32_t part = 0;
    std::string file;
    template <class S, class F>
    static void for_each_field(S& self, F&& field) {
      field(self.time, self.part, self.file);
    }
  };

  static std::vector<std::string> columns_of(const ProbeVariant& probe) {
    return std::visit([](const auto& p) { return p.columns(); }, probe);
  }
  static std::int64_t probed_index(const ProbeVariant& probe) {
    if (const auto* particle = std::get_if<ParticleProbe>(&probe)) return particle->particle;
    return std::get<StressProbe>(probe).stress_point;
  }
  static void check_same_probe(const ProbeRecord& record, const ProbeVariant& probe, const std::string& path) {
    static const char* const kinds[] = {"particle", "stress point"};
    if (record.kind != probe.index() || record.index != probed_index(probe))
      throw Error("sphshell: probe file '" + path + "' is, in the checkpoint, the file of the " + kinds[record.kind] +
                  " probe of " + kinds[record.kind] + " " + std::to_string(record.index) + ", not of " +
                  kinds[probe.index()] + " " + std::to_string(probed_index(probe)) +
                  ": give this probe another file, or probe what the run probed");
  }
  static std::vector<SeriesEntry> entries_of(const io::PvdCollection& collection) {
    std::vector<SeriesEntry> entries;
    for (const io::PvdCollection::Entry& entry : collection.entries())
      entries.push_back({entry.time, static_cast<std::int32_t>(entry.part), entry.file});
    return entries;
  }

  // What a file of the output directory is to the series ("the frame file
  // 'particles_000003.vtu' of output_directory '...'"), "" for none of them.
  std::string output_file_use(const std::string& path) const {
    if (directory_key_.empty()) return "";
    const std::filesystem::path file(io::identity_of(path));
    if (file.parent_path().string() != directory_key_) return "";
    const std::string name = file.filename().string();
    if (name == io::DirectoryLock::file_name)
      return "the lock file of output_directory '" + options_.output_directory + "'";
    if (io::is_frame_file(name))
      return "a frame file ('" + name + "', a frame or collection of the series) of output_directory '" +
             options_.output_directory + "'";
    return "";
  }

  // A file named like a frame that no run wrote: kept, and named.
  void note_kept(const std::string& name, const std::string& why) const {
    std::ostream& out = notes_ ? *notes_ : std::clog;
    out << "sphshell: output_directory '" << options_.output_directory << "': kept '" << name
        << "', which is named like a frame file but is " << why
        << "; move it out of the folder to keep it out of the series' way\n";
    out.flush();
  }

  // The frames number files with a long: digits past one are no frame's.
  static constexpr long unreadable_number = -2;

  // The number N of a frame file "<series>_N.vtu" (a piece, a .pvtu, or
  // their .tmp), -1 for any other name, unreadable_number for digits no long holds.
  static long frame_number(const std::string& name) {
    const std::optional<std::string> digits = io::frame_file_digits(name);
    if (!digits || digits->empty()) return -1;  // no frame file, or a collection
    long number = 0;
    const auto [end, error] = std::from_chars(digits->data(), digits->data() + digits->size(), number);
    if (error != std::errc() || end != digits->data() + digits->size()) return unreadable_number;
    return number;
  }

  // The collections as the checkpoint had them, rewritten together; the
  // frames the run wrote after the checkpoint (numbers from frames_written_
  // on) are removed, so the folder is as it was then.
  void restore_series(const std::array<std::vector<SeriesEntry>, 3>& entries, bool with_cracks) {
    io::make_directory(options_.output_directory, "", "output_directory");
    particle_collection_ = std::make_unique<io::PvdCollection>(series_path("particles.pvd"), false);
    stress_point_collection_ = std::make_unique<io::PvdCollection>(series_path("stress_points.pvd"), false);
    std::vector<io::PvdCollection*> collections{particle_collection_.get(), stress_point_collection_.get()};
    if (with_cracks) {
      crack_collection_ = std::make_unique<io::PvdCollection>(series_path("cracks.pvd"), false);
      collections.push_back(crack_collection_.get());
    }
    for (std::size_t k = 0; k < collections.size(); ++k)
      for (const SeriesEntry& entry : entries[k]) collections[k]->stage(entry.time, series_path(entry.file), entry.part);
    io::write_together({collections.begin(), collections.end()});
    namespace fs = std::filesystem;
    std::error_code error;
    std::vector<fs::path> later;
    for (fs::directory_iterator entry(options_.output_directory, error), end; !error && entry != end;
         entry.increment(error)) {
      const std::string name = entry->path().filename().string();
      if (!io::is_frame_file(name)) continue;
      std::error_code kind_error;
      if (!entry->is_regular_file(kind_error)) {
        note_kept(name, "not a file (a folder, say)");
        continue;
      }
      const long number = frame_number(name);
      if (number == unreadable_number)
        note_kept(name, "numbered past any frame");
      else if (number >= frames_written_)
        later.push_back(entry->path());
    }
    if (error)
      throw Error("sphshell: cannot list output_directory '" + options_.output_directory + "' (" + error.message() +
                  ")");
    for (const fs::path& file : later) io::remove_file(file.string());
  }

  bool writes_frames() const { return !options_.output_directory.empty() && options_.output_interval > 0.0; }

  std::string series_path(const std::string& name) const { return options_.output_directory + "/" + name; }

  // The collections of this run, empty, in place of an earlier run's: first
  // a stale cracks.pvd of a run with cracks when this one has none, then the
  // collections are replaced together (so that at no moment do they list
  // different frames, or frames that are gone), then the earlier frames and
  // the temporaries of a killed run are removed. Other files stay.
  void start_series(bool with_cracks) {
    io::make_directory(options_.output_directory, "", "output_directory");
    if (!with_cracks) io::remove_file(series_path("cracks.pvd"));
    particle_collection_ = std::make_unique<io::PvdCollection>(series_path("particles.pvd"), false);
    stress_point_collection_ = std::make_unique<io::PvdCollection>(series_path("stress_points.pvd"), false);
    std::vector<const io::PvdCollection*> collections{particle_collection_.get(), stress_point_collection_.get()};
    if (with_cracks) {
      crack_collection_ = std::make_unique<io::PvdCollection>(series_path("cracks.pvd"), false);
      collections.push_back(crack_collection_.get());
    }
    io::write_together(collections);
    namespace fs = std::filesystem;
    std::error_code error;
    std::vector<fs::path> stale;
    for (fs::directory_iterator entry(options_.output_directory, error), end; !error && entry != end;
         entry.increment(error)) {
      const std::string name = entry->path().filename().string();
      if (!io::is_frame_file(name) || name.compare(name.size() - 4, 4, ".pvd") == 0) continue;
      std::error_code kind_error;
      if (!entry->is_regular_file(kind_error))
        note_kept(name, "not a file (a folder, say)");
      else if (frame_number(name) == unreadable_number)
        note_kept(name, "numbered past any frame");
      else
        stale.push_back(entry->path());
    }
    if (error)
      throw Error("sphshell: cannot list output_directory '" + options_.output_directory + "' (" + error.message() +
                  ")");
    for (const fs::path& file : stale) io::remove_file(file.string());
  }

  // What ParticleProbe and StressPointProbe read, of what this process owns
  // (particles by their global number; the probed stress point's local point).
  template <class Solver>
  struct OwnedView {
    const Solver& solver;
    std::size_t local_point;
    struct Field {
      const std::vector<Vector3>& local;
      const OwnedView& view;
      const Vector3& operator[](int global) const { return local[view.local(global)]; }
    };
    double time() const { return solver.time(); }
    Field velocities() const { return {solver.particles_.velocity, *this}; }
    std::size_t local(int global) const {
      return static_cast<std::size_t>(solver.domain_.local_of(static_cast<std::size_t>(global)));
    }
    Vector3 displacement(int global) const {
      return solver.particles_.position[local(global)] - solver.reference_position_[local(global)];
    }
    Vector3 rotation(int global) const {
      return rotation_vector(solver.reference_normal_[local(global)], solver.particles_.director[local(global)]);
    }
    double integral_point_quantity(IntegralPointQuantity quantity, int, int k) const {
      return solver.states_->quantity(quantity, local_point, k);
    }
  };
  template <class Solver>
  static void write_probe(OpenProbe& open, const Solver& solver) {
    const OwnedView<Solver> view{solver, open.local_point};
    open.file->write_row(std::visit([&](const auto& probe) { return probe.row(view); }, open.probe));
  }

  // The parallel file of one frame: its pieces and the arrays they hold
  // (names, types and components as `layout`, a piece, has them).
  template <class Domain>
  void write_pvtu(const std::string& file_path, const std::string& frame, const Domain& domain,
                  const io::VtuGrid& layout) const {
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
    for (int r = 0; r < domain.size(); ++r) out << "    <Piece Source=\"" << domain.piece_file_of(frame, r) << "\"/>\n";
    out << "  </PUnstructuredGrid>\n"
        << "</VTKFile>\n";
    file.commit();
  }

 public:
  // The note at the top of a frame file: what it draws, at which time, and where its points sit.
  static std::string frame_note(const std::string& what, double time, bool deformed) {
    std::ostringstream text;
    text.precision(17);
    text << "sphshell frame, t = " << time << " s: " << what << "\n     Points: "
         << (deformed ? "the deformed (current) positions. The point array displacement (current minus reference "
                          "position) is for colouring: Warp By Vector would apply it a second time."
                        : "the reference positions. Warp By Vector with the point array displacement (scale 1) "
                          "shows the deformed shell.");
    return text.str();
  }

 private:
  OutputOptions options_;
  std::ostream* notes_ = nullptr;
  std::string directory_key_;                // identity_of(output_directory), "" without one
  std::unique_ptr<io::DirectoryLock> lock_;  // the first process's, held while the solver lives
  std::vector<OpenProbe> probes_;
  // The first process's.
  std::unique_ptr<io::PvdCollection> particle_collection_, stress_point_collection_, crack_collection_;
  long frames_written_ = 0;
  long last_frame_step_ = -1;  // the step of the latest frame; -1 before the first
  double next_frame_time_ = 0.0;
  double next_probe_time_ = 0.0;
  std::vector<ProbeRecord> restored_probes_;  // probe files of a loaded checkpoint, not yet added again
};


// The grids of one frame drawn from a solver's share (solver.hpp; the
// Solver's friend): this process's particles and the active stress points
// it owns, serially all of them; a distributed run writes one piece per
// process. The shell is drawn as its cells
// (ShellModel::cells()), corners numbered in the piece's particles (a
// piece's particles are the process's local ones: owned, then ghosts, so a
// cell at the share's edge has its corners), with cracks as gaps (see the
// header comment).
template <class Solver>
class FramePiece {
 public:
  FramePiece(const Solver& solver, FrameCoordinates coordinates)
      : s_(solver), deformed_(coordinates == FrameCoordinates::deformed) {
    const ShellModel& model = s_.model();
    with_cells_ = !model.cells().empty();
    for (const std::size_t row : s_.domain_.owned_stress_rows()) {
      const Drawn point{s_.domain_.global_stress_point(row), row,
                        s_.points_->point(PointGroup::stress_points, row)};
      owned_.push_back(point);
      if (!s_.states_->active(point.point)) continue;
      (with_cells_ && (is_cut(point.stress_point) || !corners_local(point.stress_point)) ? cut_ : drawn_)
          .push_back(point);
    }
    const std::size_t n = s_.domain_.local_count();
    particles_.resize(n);
    displacement_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      displacement_[i] = s_.particles_.position[i] - s_.reference_position_[i];
      particles_[i] = deformed_ ? s_.particles_.position[i] : s_.reference_position_[i];
    }
  }

  // The particles with the cells of the drawn stress points over them (a
  // particle it owns that no drawn cell holds is a vertex cell), particle
  // data as point data; distributed, with each point's global_id.
  io::VtuGrid particle_grid() const {
    const std::size_t n = particles_.size();
    io::VtuGrid grid;
    grid.time = s_.time();
    grid.points = particles_;
    std::vector<char> covered(n, 0);
    if (with_cells_) add_drawn_cells(grid.cells, &covered);
    for (std::size_t i = 0; i < s_.domain_.owned_count(); ++i)
      if (!covered[i]) grid.cells.add_vertex(static_cast<int>(i));
    std::vector<Vector3> rotation(n);
    for (std::size_t i = 0; i < n; ++i)
      rotation[i] = rotation_vector(s_.reference_normal_[i], s_.particles_.director[i]);
    grid.point_fields = {vector_field("displacement", displacement_),
                         vector_field("velocity", s_.particles_.velocity), vector_field("rotation", rotation),
                         vector_field("director", s_.particles_.director)};
    if constexpr (Solver::crack_type::enabled) {
      io::PointField fragment{"fragment", 1, {}, {}, io::FieldValues::integer};
      for (std::size_t i = 0; i < n; ++i)
        fragment.values.push_back(s_.fracture_.is_fragment(static_cast<std::size_t>(s_.domain_.global_of(i))) ? 1 : 0);
      grid.point_fields.push_back(fragment);
    }
    if constexpr (Solver::domain_type::is_distributed) {
      io::PointField id{"global_id", 1, {}, {}, io::FieldValues::integer};
      for (std::size_t i = 0; i < n; ++i) id.values.push_back(s_.domain_.global_of(i));
      grid.point_fields.push_back(id);
    }
    grid.note = note(with_cells_ ? "the particles with the cells of the active stress points over them, but for cells "
                                   "a crack cuts (a particle no such cell holds is a vertex cell); particle data as "
                                   "point data."
                                 : "the particles, one vertex cell each (the model has no cells).");
    return grid;
  }

  // Per active stress point: one array per integral-point quantity with a
  // component per thickness output point (named by position, ζ ascending),
  // the resultants, the wall thickness and the stress point's index.
  io::VtuGrid stress_point_grid() const {
    const ShellModel& model = s_.model();
    io::VtuGrid grid;
    grid.time = s_.time();
    // Cell data follow the cells: the drawn stress points, then the cut ones.
    std::vector<Drawn> active = drawn_;
    active.insert(active.end(), cut_.begin(), cut_.end());
    if (with_cells_) {
      grid.points = particles_;
      add_drawn_cells(grid.cells, nullptr);
      std::vector<Vector3> displacement = displacement_;
      for (const Drawn& point : cut_) {
        const Vector3 current = s_.stress_point_position(point.row);
        const Vector3& reference = model.stress_point_position[point.stress_point];
        grid.cells.add_vertex(static_cast<int>(grid.points.size()));
        grid.points.push_back(deformed_ ? current : reference);
        displacement.push_back(current - reference);
      }
      grid.point_fields = {vector_field("displacement", displacement)};
    } else {
      // The stress points it owns, removed ones too; a vertex cell at each active one.
      std::vector<Vector3> displacement;
      for (std::size_t k = 0; k < owned_.size(); ++k) {
        const Vector3 current = s_.stress_point_position(owned_[k].row);
        const Vector3& reference = model.stress_point_position[owned_[k].stress_point];
        grid.points.push_back(deformed_ ? current : reference);
        displacement.push_back(current - reference);
        if (s_.states_->active(owned_[k].point)) grid.cells.add_vertex(static_cast<int>(k));
      }
      grid.point_fields = {vector_field("displacement", displacement)};
    }
    constexpr int output_points = Solver::output_points;
    const std::vector<std::string> names = thickness_point_names<typename Solver::rule_type>();
    for (const IntegralPointQuantityInfo& info : integral_point_quantities) {
      if (info.needs_damage_law && !Solver::material_type::has_damage) continue;
      io::CellField field{info.name, output_points, {}, names};
      field.values.reserve(active.size() * output_points);
      for (const Drawn& point : active)
        for (int k = 0; k < output_points; ++k) field.values.push_back(s_.states_->quantity(info.quantity, point.point, k));
      grid.cell_fields.push_back(std::move(field));
    }
    io::CellField membrane{"membrane_force", 3, {}, {"Nxx", "Nyy", "Nxy"}};
    io::CellField moment{"bending_moment", 3, {}, {"Mxx", "Myy", "Mxy"}};
    io::CellField thickness{"thickness", 1, {}};
    io::CellField index{"stress_point", 1, {}, {}, io::FieldValues::integer};
    for (const Drawn& point : active) {
      for (int c = 0; c < 3; ++c) {
        membrane.values.push_back(s_.states_->membrane_force(point.point)[c]);
        moment.values.push_back(s_.states_->bending_moment(point.point)[c]);
      }
      thickness.values.push_back(model.stress_point_thickness(point.stress_point));
      index.values.push_back(static_cast<int>(point.stress_point));
    }
    grid.cell_fields.push_back(std::move(membrane));
    grid.cell_fields.push_back(std::move(moment));
    grid.cell_fields.push_back(std::move(thickness));
    grid.cell_fields.push_back(std::move(index));
    const std::string heights =
        " Through-thickness points are named by their height zeta along the director as a fraction of the wall "
        "thickness d: bottom (zeta < 0, the side the director points away from) to top (zeta > 0).";
    grid.note = note((with_cells_ ? std::string("one cell per active stress point over its corner particles (the "
                                                "first points are the particles); a removed stress point has no "
                                                "cell, so cracks show as gaps; a stress point whose cell a crack "
                                                "cuts is a vertex cell at its own position (points after the "
                                                "particles), so slits show too; stress-point data as cell data.")
                                  : std::string("the stress points, a vertex cell per active one (the model has no "
                                                "cells); stress-point data as cell data.")) +
                     heights);
    return grid;
  }

  // The crack segments as a line set, whole (collective; a distributed run's
  // process 0 writes it): a damaged stress point's crack point follows the
  // interpolated motion of the stress point, a pre-crack point the
  // displacement of its nearest particle; their owners place them.
  io::VtuGrid crack_grid() const {
    const auto& crack = s_.crack();
    const ShellModel& model = s_.model();
    const std::vector<Vector3>& reference = crack.points();
    std::vector<std::pair<std::size_t, Vector3>> mine;
    std::vector<char> from_stress_point(reference.size(), 0);
    for (std::size_t q = 0; q < model.stress_point_count(); ++q) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(q));
      if (k >= 0) from_stress_point[static_cast<std::size_t>(k)] = 1;
    }
    for (const Drawn& point : owned_) {
      const int k = crack.crack_point_of_stress_point(static_cast<int>(point.stress_point));
      if (k >= 0) mine.push_back({static_cast<std::size_t>(k), s_.stress_point_position(point.row)});
    }
    for (std::size_t k = 0; k < reference.size(); ++k) {
      if (from_stress_point[k]) continue;
      const int nearest = model.nearest_particle(reference[k]);
      if (!s_.domain_.owns(nearest)) continue;
      const auto i = static_cast<std::size_t>(s_.domain_.local_of(static_cast<std::size_t>(nearest)));
      mine.push_back({k, reference[k] + displacement_[i]});
    }
    const std::vector<Vector3> current = s_.domain_.assembled(reference.size(), mine);
    std::vector<Vector3> displacement(reference.size());
    for (std::size_t k = 0; k < reference.size(); ++k) displacement[k] = current[k] - reference[k];
    io::VtuGrid grid;
    grid.time = s_.time();
    grid.points = deformed_ ? current : reference;
    io::CellField crack_id{"crack_id", 1, {}, {}, io::FieldValues::integer};
    for (const auto& segment : crack.segments()) {
      grid.cells.add_line(segment.start_point, segment.end_point);
      crack_id.values.push_back(segment.crack_id);
    }
    grid.point_fields = {vector_field("displacement", displacement)};
    grid.cell_fields = {crack_id};
    grid.note = note("the crack segments as lines (crack_id per segment).");
    return grid;
  }

 private:
  // A stress point of the piece: its index, its local stress-point row and its local point.
  struct Drawn {
    std::size_t stress_point, row, point;
  };

  std::string note(const std::string& what) const {
    return SolverOutput<Solver::output_points>::frame_note(what, s_.time(), deformed_);
  }
  static io::PointField vector_field(const std::string& name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}};
    field.values.reserve(3 * values.size());
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    return field;
  }

  // Whether a crack runs through stress point q's cell: q no longer sees one
  // of its corners (the crack policy's visibility, in the reference
  // configuration, as for the shape functions). Drawn whole, such a cell
  // would bridge the crack, a slit between particle rows would not show.
  bool is_cut(std::size_t q) const {
    if constexpr (Solver::crack_type::enabled) {
      const auto& crack = s_.crack();
      if (crack.segments().empty()) return false;
      const ShellModel& model = s_.model();
      const TangentFrame frame = tangent_frame(model.stress_point_normal[q]);
      for (const int corner : model.cells()[q])
        if (!crack.visible(model.stress_point_position[q], model.particle_position[std::size_t(corner)], frame))
          return true;
    }
    (void)q;
    return false;
  }
  // Whether every corner of q's cell is a particle of the piece (always, serially).
  bool corners_local(std::size_t q) const {
    for (const int corner : s_.model().cells()[q])
      if (s_.domain_.local_of(static_cast<std::size_t>(corner)) < 0) return false;
    return true;
  }
  // The drawn stress points' cells (triangles, quads) over the piece's particles.
  void add_drawn_cells(io::VtuCells& cells, std::vector<char>* covered) const {
    const std::vector<Cell>& model_cells = s_.model().cells();
    for (const Drawn& point : drawn_) {
      const Cell& cell = model_cells[point.stress_point];
      std::array<int, 4> corners{};
      for (std::size_t c = 0; c < cell.size(); ++c)
        corners[c] = static_cast<int>(s_.domain_.local_of(static_cast<std::size_t>(cell[c])));
      const int* end = corners.data() + cell.size();
      cells.add_polygon(corners.data(), end);
      if (covered)
        for (const int* corner = corners.data(); corner != end; ++corner) (*covered)[std::size_t(*corner)] = 1;
    }
  }

  const Solver& s_;
  bool deformed_;
  bool with_cells_ = false;
  std::vector<Drawn> owned_, drawn_, cut_;
  std::vector<Vector3> particles_, displacement_;
};

}  // namespace sphshell::solver
