#pragma once
// The solver's output: ParaView frames (particles, stress points and, with a
// crack policy, crack segments, each series in a .pvd collection) on the
// output schedule and at the end of every run_until, and CSV probes. It
// reads the run through the solver (its friend) and the domain part's share
// (domain/domain.hpp), so it holds no state of the run but the schedules and
// the files: the frames (drawn by solver/frame_piece.hpp, written by
// io/frame_series.hpp) and the probe files (solver/output_probes.hpp). A
// distributed run writes each frame in pieces, one per process
// (particles_N_rR.vtu, stress_points_N_rR.vtu: its local particles, with
// global_id, and the cells of the stress points it owns), and the first
// process a .pvtu naming the pieces and the whole cracks_N.vtu; the
// collections list the .pvtu files. A probe's file is written by the
// process that owns what it probes. Each frame file holds its time as
// FieldData TimeValue and says in a comment at its top what it draws and
// where its points sit.
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
// collections are rewritten together (io::write_together), so at any moment
// the collections list the same frames and every listed file is complete,
// but for the microseconds of the final atomic swaps.

#include <sphshell/core/error.hpp>
#include <sphshell/core/frame.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/directory_lock.hpp>
#include <sphshell/io/frame_series.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/rigid_body_surfaces.hpp>
#include <sphshell/solver/frame_piece.hpp>
#include <sphshell/solver/integration_points.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/solver/output_probes.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::solver {

// Every member that reads the run takes the solver (its friend: the members
// read the process's share through the solver's domain part, solver.domain_).
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
      : options_(options), frames_(options.output_directory, {options.frame_encoding, options.frame_precision}, notes) {
    if (options.output_directory.empty()) return;
    domain.collectively([&] {
      if (domain.is_root()) io::make_directory(options.output_directory, "", "output_directory");
    });
    domain.collectively([&] {
      directory_key_ = io::identity_of(options.output_directory);
      if (directory_key_.size() > 1 && directory_key_.back() == '/') directory_key_.pop_back();
      if (!options.checkpoint_path.empty()) {
        const std::string use = output_file_use(domain.checkpoint_file(options.checkpoint_path));
        if (!use.empty())
          detail::invalid_parameter("checkpoint_path", options.checkpoint_path,
                                    "it is " + use + "; give the checkpoint a file of its own");
      }
      if (domain.is_root()) lock_ = std::make_unique<io::DirectoryLock>(options.output_directory, "output_directory");
    });
  }

  // Every process registers the probe; the one that owns what it probes
  // writes its file. A probe on a file a loaded checkpoint recorded continues
  // that file (no header, no row now: the file has both).
  template <class Probe, class Solver>
  void add_probe(const std::string& csv_path, Probe probe, const Solver& solver) {
    const auto& domain = solver.domain_;
    const OutputOptions& options = options_;
    const std::string key = io::identity_of(csv_path);
    probes_.refuse_taken(key, csv_path);
    // Files the run writes itself: every process's checkpoint file and the frames.
    if (!options.checkpoint_path.empty())
      for (int process = 0; process < domain.size(); ++process) {
        const std::string file = domain.checkpoint_file_of(options.checkpoint_path, process);
        if (key == io::identity_of(file))
          throw Error("sphshell: probe file '" + csv_path + "' is " +
                      (domain.is_distributed ? "rank " + std::to_string(process) + "'s" : std::string("the")) +
                      " checkpoint file '" + file + "' (checkpoint_path '" + options.checkpoint_path +
                      "'; the checkpoint would replace it); give the probe a file of its own");
      }
    const std::string use = output_file_use(csv_path);
    if (!use.empty())
      throw Error("sphshell: probe file '" + csv_path + "' is " + use + "; give the probe a file of its own");
    std::optional<std::size_t> local_point;
    if constexpr (std::is_same_v<Probe, StressProbe>) {
      probe.point_names = thickness_point_names<typename Solver::rule_type>();
      const long row = domain.owned_stress_row(static_cast<std::size_t>(probe.stress_point));
      if (row >= 0) local_point = solver.points_->point(PointGroup::stress_points, static_cast<std::size_t>(row));
    } else if constexpr (std::is_same_v<Probe, RigidBodyProbe>) {
      if (domain.is_root()) local_point = 0;  // every process holds the body; the first writes
    } else if (domain.owns(probe.particle)) {
      local_point = 0;
    }
    probes_.add(csv_path, key, std::move(probe), local_point, owned_view(solver));
  }

  // Checkpoints (solver/checkpoint.hpp): the schedules (frames written, the
  // latest frame's step, the next frame and probe times), the frame series
  // (the collections' entries, on the first process) and each probe file
  // this process writes (path, what it probes, its length and content hash).
  template <class Writer>
  void save(Writer& out) const {
    out(static_cast<std::int64_t>(frames_.written()), static_cast<std::int64_t>(last_frame_step_), next_frame_time_,
        probes_.next_time());
    out(options_.output_directory.empty() ? std::string() : io::identity_of(options_.output_directory));
    out(frames_.has_series());
    if (frames_.has_series())
      for (std::size_t k = 0; k < series_names.size(); ++k) out(frames_.entries(k));
    probes_.save(out);
  }

  // The schedules as they were; the series continues in the same
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
    in(frames, last_step, next_frame, next_probe, directory, series);
    std::vector<std::vector<io::FrameSeries::Entry>> entries(series ? series_names.size() : 0);
    for (std::vector<io::FrameSeries::Entry>& list : entries) in(list);
    auto records = Probes::read(in);
    last_frame_step_ = static_cast<long>(last_step);
    next_frame_time_ = next_frame;
    // A series is recorded once a frame was written (serially; distributed, by the first process).
    if (!options_.output_directory.empty() && directory == io::identity_of(options_.output_directory))
      frames_.restore(static_cast<long>(frames), series_of<Solver>(), entries);
    else
      frames_.restore(0, {}, {});
    probes_.restore(std::move(records), next_probe, owned_view(solver));
  }

  // Before the first step: the reference configuration at t = 0.
  template <class Solver>
  void start(const Solver& solver) {
    if (!writes_frames()) return;
    if (frames_.written() == 0) write_frame(solver);
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
    probes_.write_scheduled(time, solver.time_step(), options_.probe_interval, owned_view(solver));
  }

  // At the end of run_until: the last state is always a frame (unless the
  // schedule wrote it at this step already).
  template <class Solver>
  void finish(const Solver& solver) {
    if (writes_frames() && last_frame_step_ != solver.steps()) write_frame(solver);
  }

  // One frame now, whatever the schedule (collective): the particles and the
  // stress points in pieces and, with cracks, the crack segments whole
  // (solver/frame_piece.hpp draws them). A further dataset of the frame is a
  // further series: drawn here, and named in series_names.
  template <class Solver>
  void write_frame(const Solver& solver) {
    if (options_.output_directory.empty())
      detail::invalid_parameter("output_directory", "(empty)", "set it to write ParaView frames");
    using Drawn = io::FrameDataset::Drawn;
    const FramePiece<Solver> piece(solver, options_.frame_coordinates);
    std::vector<io::FrameDataset> datasets;
    datasets.push_back({series_names[0], piece.particle_grid(), Drawn::in_pieces});
    datasets.push_back({series_names[1], piece.stress_point_grid(), Drawn::in_pieces});
    if constexpr (Solver::crack_type::enabled)
      datasets.push_back({series_names[2], piece.crack_grid(), Drawn::whole});  // collective
    if (!solver.bodies_.empty())  // the rigid bodies' surfaces, listed in the particle series as its part 1
      // (a plane's patch is sized to the whole shell: all positions, gathered when distributed)
      datasets.push_back({body_series, io::rigid_body_grid(solver.bodies_, solver.positions(), solver.time()),
                          Drawn::whole, series_names[0], 1});
    frames_.write(solver.domain_, solver.time(), datasets, {series_names.begin(), series_names.end()});
    last_frame_step_ = solver.steps();
  }

  // The frames written so far in this run.
  long frames_written() const { return frames_.written(); }

 private:
  using Probes = ProbeFiles<output_points>;

  // The series a run can write, in the order a checkpoint stores them, and
  // those a Solver's frames have (write_frame's datasets).
  static constexpr std::array<const char*, 3> series_names{"particles", "stress_points", "cracks"};
  // The rigid bodies' frames: files of their own, listed in the particle
  // series' collection (so ParaView opens shell and bodies together).
  static constexpr const char* body_series = "bodies";
  template <class Solver>
  static std::vector<std::string> series_of() {
    return {series_names.begin(), series_names.begin() + (Solver::crack_type::enabled ? 3 : 2)};
  }

  bool writes_frames() const { return !options_.output_directory.empty() && options_.output_interval > 0.0; }

  // What the probes read, of what this process owns (particles by their
  // global number; the probed stress point's local point; every rigid body).
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
    auto rigid_body(std::size_t id) const { return solver.rigid_body(id); }
  };
  template <class Solver>
  static auto owned_view(const Solver& solver) {
    return [&solver](std::size_t local_point) { return OwnedView<Solver>{solver, local_point}; };
  }

  // What a file of the output directory is to the series ("the frame file
  // 'particles_000003.vtu' of output_directory '...'"), "" for none of them.
  std::string output_file_use(const std::string& path) const {
    if (directory_key_.empty()) return "";
    const std::filesystem::path file(io::identity_of(path));
    if (file.parent_path().string() != directory_key_) return "";
    const std::string name = file.filename().string();
    const std::string& directory = options_.output_directory;
    if (name == io::DirectoryLock::file_name) return "the lock file of output_directory '" + directory + "'";
    if (io::is_frame_file(name))
      return "a frame file ('" + name + "', a frame or collection of the series) of output_directory '" + directory +
             "'";
    return "";
  }

  OutputOptions options_;
  io::FrameSeriesWriter frames_;
  Probes probes_;
  long last_frame_step_ = -1;  // the step of the latest frame; -1 before the first
  double next_frame_time_ = 0.0;
  std::string directory_key_;                // identity_of(output_directory), "" without one
  std::unique_ptr<io::DirectoryLock> lock_;  // the first process's, held while the solver lives
};

}  // namespace sphshell::solver
