#pragma once
// An equilibrium path as ParaView frames: a PathFollower observer
// (PathFollower::observe) that writes the solver's state at every converged
// point as one frame, drawn and written the way the solver writes its own
// (solver/frame_piece.hpp draws the particles and the stress points,
// io/frame_series.hpp writes them): in the chosen folder, particles.pvd and
// stress_points.pvd list particles_<N>.vtu and stress_points_<N>.vtu, N =
// 000000, 000001, ... the observed points in order, each at the time
// PathFrameOptions::time says; each file's note names the point (step, load
// factor, control). The point arrays are the solver's: "displacement",
// "rotation", "director" (and "velocity", zero at equilibrium); the stress
// points carry the resultants and stresses of the converged state.
//
// Kill safety, as the solver's frames: each file is written whole and then
// renamed into place, and the collections are rewritten (atomically) after
// the frame's files, so a run killed at any moment leaves collections that
// list only complete frames. The folder is the frames' own, like a solver's
// output_directory (not the same folder as one): the first frame removes the
// frame files of an earlier run in it (particles_*, stress_points_*,
// cracks_*; other files stay).

#include <sphshell/core/error.hpp>
#include <sphshell/domain/serial.hpp>
#include <sphshell/io/frame_series.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/vtu_format.hpp>
#include <sphshell/solver/frame_piece.hpp>
#include <sphshell/solver/options.hpp>
#include <sphshell/statics/path_following.hpp>

#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::statics {

// The time a path's frame is listed at in the collections. ParaView orders
// a collection's frames by their times, so the time must grow along the
// path: the load factor turns back at a limit point (use path_parameter or
// step there), and the path parameter restarts when one follower changes its
// control (load control, then arc length: use step).
enum class PathFrameTime {
  path_parameter,  // the load factor under load control, else PathPoint::control_value (m)
  load_factor,
  step  // PathPoint::step
};

struct PathFrameOptions {
  PathFrameTime time = PathFrameTime::path_parameter;
  FrameCoordinates coordinates = FrameCoordinates::deformed;  // as OutputOptions::frame_coordinates
  io::VtuFormat format = {};
  std::ostream* notes = nullptr;  // notes on kept files (std::clog when null)
};

template <class Solver>
class PathFrames {
 public:
  // The folder is created at once (an Error names one that cannot be); the
  // frames are written from the first observed point on. Copies write to the
  // same series.
  PathFrames(const Solver& solver, const std::string& directory, const PathFrameOptions& options = {})
      : state_(std::make_shared<State>(solver, directory, options)) {
    if (options.time != PathFrameTime::path_parameter && options.time != PathFrameTime::load_factor &&
        options.time != PathFrameTime::step)
      sphshell::detail::invalid_parameter("PathFrameOptions::time", static_cast<int>(options.time),
                                          "must be path_parameter, load_factor or step");
    if (options.coordinates != FrameCoordinates::deformed && options.coordinates != FrameCoordinates::reference)
      sphshell::detail::invalid_parameter("PathFrameOptions::coordinates", static_cast<int>(options.coordinates),
                                          "must be deformed or reference");
    io::make_directory(directory, "", "path frames' folder");
  }

  // The time a point's frame is listed at.
  static double time_of(const PathPoint& point, PathFrameTime time) {
    switch (time) {
      case PathFrameTime::load_factor: return point.load_factor;
      case PathFrameTime::step: return point.step;
      case PathFrameTime::path_parameter: break;
    }
    return point.control == PathControl::load ? point.load_factor : point.control_value;
  }

  void operator()(const PathPoint& point) {
    State& state = *state_;
    const double time = time_of(point, state.options.time);
    using Drawn = io::FrameDataset::Drawn;
    const solver::FramePiece<Solver> piece(state.solver, state.options.coordinates);
    std::vector<io::FrameDataset> datasets;
    datasets.push_back({"particles", piece.particle_grid(), Drawn::in_pieces});
    datasets.push_back({"stress_points", piece.stress_point_grid(), Drawn::in_pieces});
    const std::string about = description(point);
    for (io::FrameDataset& dataset : datasets) {
      dataset.grid.time = time;
      dataset.grid.note = about + "\n     " + dataset.grid.note;
    }
    state.writer.write(domain::Serial{}, time, datasets, {"particles", "stress_points", "cracks"});
  }

  // The frames written so far.
  long frames_written() const { return state_->writer.written(); }

 private:
  struct State {
    State(const Solver& s, const std::string& directory, const PathFrameOptions& o)
        : solver(s), options(o), writer(directory, o.format, o.notes) {}
    const Solver& solver;
    PathFrameOptions options;
    io::FrameSeriesWriter writer;
  };

  static std::string description(const PathPoint& point) {
    static const char* const controls[] = {"load", "displacement", "arc length"};
    std::ostringstream text;
    text << "sphshell equilibrium path, step " << point.step << ": load factor "
         << io::detail::round_trip_decimal(point.load_factor) << ", "
         << controls[static_cast<int>(point.control)] << " control";
    if (point.control != PathControl::load)
      text << ", control value " << io::detail::round_trip_decimal(point.control_value) << " m";
    text << ", relative residual " << io::detail::round_trip_decimal(point.relative_residual);
    return text.str();
  }

  std::shared_ptr<State> state_;
};

}  // namespace sphshell::statics
