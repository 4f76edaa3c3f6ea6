#pragma once
// SolverOptions, grouped by concern. Each group is a plain struct that the
// part it concerns receives on its own (the stepper the time options, the
// ledger the monitoring options, …); SolverOptions derives from all of them, so
// a user still writes `options.density = 2700.0` and `options.damping = …`.
// Units are SI. The method behind each option is in docs/method.md.

#include <sphshell/core/error.hpp>
#include <sphshell/io/vtu_format.hpp>

#include <cmath>
#include <iosfwd>
#include <string>

namespace sphshell {

// How the stress points form the transverse shear (docs/method.md §4,
// "Transverse shear tied to the cell edges").
enum class TransverseShear {
  // Tied to the tangential shear strains of the stress point's cell edges and
  // integrated at the cell's corners (an assumed strain, as MITC shell
  // elements do): free of thin-plate locking. Needs the model's cells; a model
  // made without cells (the general ShellModel constructor) uses
  // shape_functions.
  cell_edges,
  // From the approximation's gradients at the stress point (one point per
  // cell). It leaves a checkerboard deflection mode that only the particles'
  // shear term (particle_shear_weight, e.g. 0.01) controls, and that term
  // locks thin plates (clamped, L/d = 500: −8.6 % at 21 × 21 particles).
  shape_functions,
};

// The shell's physics and its discretization.
struct PhysicsOptions {
  double density = 7850.0;  // ρ, kg/m³
  // Geometrically nonlinear (Green strain, paper §3.2) or linear (§3.1) analysis.
  bool nonlinear = true;
  // Support radius of the approximation in units of the particle spacing.
  double support_radius_factor = 2.0;
  // Rotary inertia ρ d³/12 A is multiplied by this (≥ 1), as explicit FE shell
  // codes do to lift the shear–rotation frequency limit on thin shells.
  double rotary_inertia_scale = 1.0;
  double shear_correction = 5.0 / 6.0;  // κs of the elastic transverse shear
  TransverseShear transverse_shear = TransverseShear::cell_edges;
  // Adds to every quadrilateral cell the elastic bending energy of its
  // directors' hourglass (the ξη part of their bilinear interpolation), which
  // neither the stress points nor the particles see (shell/cell_hourglass.hpp;
  // docs/method.md, "The director hourglass"). Needs the edge-tied shear and a
  // model with cells.
  bool director_hourglass = false;
};

// Particle integration (docs/method.md, "Quadrature and the particle share"):
// the share of the membrane and bending work carried by the particles (the
// stress points carry the rest), in [0, 1); the particles' transverse-shear
// weight (a fraction of their area) and the softening d² / (d² + s Δ²) of its
// stiffness. Any share > 0 removes the stress points' spurious bending modes.
// The particles' shear term is off by default: the edge-tied shear
// (TransverseShear::cell_edges) needs no help, and the term locks thin plates.
// With TransverseShear::shape_functions (or a model without cells) set it to
// 0.01, the former default, to control the checkerboard deflection mode.
// Fracture runs whose crack path matters want a small share such as 0.02:
// only stress points become crack points (see the method document and the
// docs/validation.md).
struct ParticleIntegrationOptions {
  double particle_integration_share = 0.5;
  double particle_shear_weight = 0.0;
  double particle_shear_softening = 0.01;
};

// Time integration.
struct TimeOptions {
  // The time step is safety_factor × the stable bound (see stable_time_step()).
  double safety_factor = 0.8;
  // A user time step (s); 0 selects safety_factor × the bound. A step above the
  // bound is refused.
  double time_step = 0.0;
  // Mass-proportional damping coefficient c (1/s): M a = f − c M v. For
  // quasi-static solutions by dynamic relaxation; 0 for dynamics.
  double damping = 0.0;
  // run_until refuses, before its first step, an end time more than this many
  // steps ahead (a step far too small for the end time would run for ever);
  // raise it for longer runs.
  long long max_steps_per_run = 1'000'000'000;
};

// What the run reports while it goes.
struct MonitoringOptions {
  // Write a progress line every this many steps (0: quiet) to progress_stream
  // (nullptr: std::clog).
  long progress_interval = 0;
  std::ostream* progress_stream = nullptr;
  // A run stops with an error when |energy balance| exceeds this fraction of
  // the largest energy in play (checked every few steps after the first ones;
  // docs/method.md, "Energy accounting"). The examples stay below 0.05
  // (plate tearing 0.043, the detonation tube 0.038, the square plate 0.0013).
  double energy_tolerance = 0.1;
};

// Where the points of a ParaView frame sit (OutputOptions::frame_coordinates).
enum class FrameCoordinates {
  // The current positions: ParaView's default view shows the deformed shell.
  // The point array "displacement" is there to colour by; Warp By Vector
  // would add it a second time.
  deformed,
  // The reference positions: Warp By Vector with "displacement" (scale 1)
  // shows the deformed shell, any other scale exaggerates it.
  reference,
};

// Files.
struct OutputOptions {
  // ParaView output: every output_interval seconds of simulated time, and at
  // the end of every run_until, one .vtu of the particles, one of the stress
  // points and (with a crack policy) one of the crack segments, listed in
  // particles.pvd, stress_points.pvd and cracks.pvd inside output_directory
  // (created if missing). The shell is drawn as its cells (ShellModel::cells()):
  // the particle file carries point data, the stress-point file one cell per
  // stress point with its data; a removed stress point's cell is left out and
  // a cell a crack cuts is drawn as a vertex at its stress point, so cracks
  // show as gaps (solver/output.hpp has the details). A directory used before
  // loses its earlier frames (particles_*.vtu, stress_points_*.vtu, cracks_*.vtu, the three .pvd and
  // their .tmp files) when the first frame is written; other files stay.
  // The solver holds the directory while it lives (the lock file
  // .sphshell.lock: a second live solver there is an Error), and a probe file
  // or checkpoint_path that is a frame, a collection or the lock file is an
  // Error (solver/output.hpp).
  // output_interval > 0 needs an output_directory; with a directory and an
  // interval of 0, frames are written only by Solver::write_frame().
  std::string output_directory;
  double output_interval = 0.0;
  // How frames are stored (io/vtu_format.hpp). The defaults suit big runs:
  // zlib-compressed (when sphshell is built with zlib, else raw binary) and
  // single precision, a fraction of the size of raw doubles, read natively by
  // ParaView. float64 keeps every bit for post-processing; ascii is for
  // reading a frame in a text editor.
  io::VtuEncoding frame_encoding = io::vtu_zlib_available ? io::VtuEncoding::zlib : io::VtuEncoding::binary;
  io::VtuPrecision frame_precision = io::VtuPrecision::float32;
  FrameCoordinates frame_coordinates = FrameCoordinates::deformed;
  // Probes (add_particle_probe, add_stress_point_probe) write a CSV row every
  // probe_interval seconds (0: every step); each probe needs a file of its own.
  double probe_interval = 0.0;
  // Periodic checkpoints (Solver::save_checkpoint) into checkpoint_path, after
  // every checkpoint_every_steps-th step and/or when checkpoint_every_seconds
  // of wall-clock time have passed since the last one (0: not on that count).
  // Each replaces the previous one atomically. The wall clock only schedules
  // the writes; the run's numbers never depend on it.
  std::string checkpoint_path;
  long checkpoint_every_steps = 0;
  double checkpoint_every_seconds = 0.0;
};

struct SolverOptions : PhysicsOptions,
                       ParticleIntegrationOptions,
                       TimeOptions,
                       MonitoringOptions,
                       OutputOptions {
  PhysicsOptions& physics() { return *this; }
  const PhysicsOptions& physics() const { return *this; }
  ParticleIntegrationOptions& particle_integration() { return *this; }
  const ParticleIntegrationOptions& particle_integration() const { return *this; }
  TimeOptions& time() { return *this; }
  const TimeOptions& time() const { return *this; }
  MonitoringOptions& monitoring() { return *this; }
  const MonitoringOptions& monitoring() const { return *this; }
  OutputOptions& output() { return *this; }
  const OutputOptions& output() const { return *this; }
};

// Every option in its allowed range, or an Error naming it.
inline void validate(const SolverOptions& options) {
  detail::require_positive("density", options.density);
  detail::require_half_open_interval("safety_factor", options.safety_factor, 0.0, 1.0);
  detail::require_nonnegative("time_step", options.time_step);
  detail::require_nonnegative("damping", options.damping);
  detail::require_positive("support_radius_factor", options.support_radius_factor);
  if (!(options.rotary_inertia_scale >= 1.0) || !std::isfinite(options.rotary_inertia_scale))
    detail::invalid_parameter("rotary_inertia_scale", options.rotary_inertia_scale, "must be finite and >= 1");
  detail::require_half_open_interval("shear_correction", options.shear_correction, 0.0, 1.0);
  if (!(options.particle_integration_share >= 0.0 && options.particle_integration_share < 1.0))
    detail::invalid_parameter("particle_integration_share", options.particle_integration_share, "must lie in [0, 1)");
  detail::require_nonnegative("particle_shear_weight", options.particle_shear_weight);
  detail::require_nonnegative("particle_shear_softening", options.particle_shear_softening);
  detail::require_positive("energy_tolerance", options.energy_tolerance);
  if (options.progress_interval < 0)
    detail::invalid_parameter("progress_interval", options.progress_interval, "must be >= 0 steps (0: quiet)");
  if (options.max_steps_per_run < 1)
    detail::invalid_parameter("max_steps_per_run", options.max_steps_per_run, "must be >= 1");
  detail::require_nonnegative("output_interval", options.output_interval);
  if (options.output_interval > 0.0 && options.output_directory.empty())
    detail::invalid_parameter("output_interval", options.output_interval,
                              "needs an output_directory for the frames; set one, or 0 for no frames");
  detail::require_nonnegative("probe_interval", options.probe_interval);
  if (options.checkpoint_every_steps < 0)
    detail::invalid_parameter("checkpoint_every_steps", options.checkpoint_every_steps, "must be >= 0 (0: not by steps)");
  detail::require_nonnegative("checkpoint_every_seconds", options.checkpoint_every_seconds);
  if ((options.checkpoint_every_steps > 0 || options.checkpoint_every_seconds > 0.0) && options.checkpoint_path.empty())
    detail::invalid_parameter("checkpoint_path", "(empty)",
                              "periodic checkpoints (checkpoint_every_steps or checkpoint_every_seconds > 0) need a "
                              "file; set one, or set both to 0");
  const io::VtuEncoding encoding = options.frame_encoding;
  if (encoding != io::VtuEncoding::ascii && encoding != io::VtuEncoding::binary && encoding != io::VtuEncoding::zlib)
    detail::invalid_parameter("frame_encoding", static_cast<int>(encoding), "must be ascii, binary or zlib");
  if (encoding == io::VtuEncoding::zlib && !io::vtu_zlib_available)
    detail::invalid_parameter("frame_encoding", "zlib",
                              "needs sphshell built with zlib (SPHSHELL_HAVE_ZLIB and -lz, as the CMake target "
                              "and pkg-config file give when zlib was found); use binary or ascii");
  if (options.frame_precision != io::VtuPrecision::float32 && options.frame_precision != io::VtuPrecision::float64)
    detail::invalid_parameter("frame_precision", static_cast<int>(options.frame_precision),
                              "must be float32 or float64");
  if (options.frame_coordinates != FrameCoordinates::deformed &&
      options.frame_coordinates != FrameCoordinates::reference)
    detail::invalid_parameter("frame_coordinates", static_cast<int>(options.frame_coordinates),
                              "must be deformed or reference");
}

}  // namespace sphshell
