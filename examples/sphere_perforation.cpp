// A rigid sphere perforating a thin clamped plate: residual velocity against
// impact velocity over a list of speeds, with the Lambert–Jonas fit
// v_r = a (v_i^p − v_bl^p)^(1/p) (Lambert & Jonas, BRL Report 1852, 1976).
// The geometry is that of Qiang et al. (Proc. IMechE C, 2022,
// doi:10.1177/09544062221080139, as quoted in docs/validation.md): a 12.7 mm,
// 8.3 g sphere against a 0.71 mm plate clamped on a 100 mm circle. The plate
// is a Johnson–Cook steel with Johnson–Cook failure (4340 steel: Johnson &
// Cook 1983 Table 1 and 1985 Table 3), not the paper's 304 stainless steel,
// whose constants this project has no source for: the run shows the method,
// it does not reproduce the paper's ballistic limit.
// `sphere_perforation --help` lists the options, their defaults and the files written.

#include <sphshell/approx/all.hpp>
#include <sphshell/contact/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/svg_plot.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "example_arguments.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

using namespace sphshell;

namespace {

struct Arguments {
  int n = 51;
  std::vector<double> speeds{150.0, 200.0, 250.0, 300.0, 400.0};
  double end_time = 3e-4;
  std::string output = "sphere_perforation";
  bool frames = false;
};

std::vector<double> parse_speeds(const std::string& text) {
  std::vector<double> speeds;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    const double speed = example::parse_number("--speeds", item);
    detail::require_positive("--speeds", speed);
    speeds.push_back(speed);
  }
  if (speeds.empty()) detail::invalid_parameter("--speeds", text, "must list at least one speed");
  return speeds;
}

std::optional<Arguments> parse(int argc, char** argv) {
  Arguments a;
  example::CommandLine command_line(
      "sphere_perforation",
      "A rigid sphere (12.7 mm, 8.3 g, the geometry of Qiang et al. 2022) strikes the centre of a "
      "0.1 m square plate 0.71 mm thick whose particles on and outside the 100 mm circle are clamped; "
      "Johnson–Cook 4340 steel with Johnson–Cook failure (Johnson & Cook 1983, 1985) and "
      "crack::LineSegments. One run per speed; the residual velocity is the sphere's speed at the end "
      "when it has passed through the plate (0 when it stopped or rebounded). The Lambert–Jonas "
      "curve is fitted to all runs (at least 3, 2 of them perforating), its ballistic limit searched "
      "between the fastest run that did not perforate and the slowest that did.");
  command_line.integer("--n", a.n, "particles along each edge, at least 9");
  command_line.custom("--speeds", "V1,V2,...", "m/s", "150,200,250,300,400", "impact speeds, > 0",
                      [&a](const std::string& text) { a.speeds = parse_speeds(text); });
  command_line.number("--end-time", a.end_time, "s", "simulated time of each run");
  command_line.output_folder(a.output);
  command_line.flag("--frames", a.frames,
                    "also write ParaView frames every 10 µs, one folder per speed (frames_<speed>/particles.pvd "
                    "lists the plate and, as part 1, the sphere)");
  command_line.writes("residual.csv", "impact speed, residual speed, perforated (1/0), sphere's contact impulse");
  command_line.writes("sphere_<speed>.csv", "the sphere's probe in each run (Solver::add_rigid_body_probe)");
  command_line.writes("residual.svg", "residual against impact velocity with the Lambert–Jonas fit");
  command_line.writes("frames_<speed>/*.pvd, *.vtu", "with --frames: ParaView frames of plate, cracks and sphere");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  if (a.n < 9) detail::invalid_parameter("--n", a.n, "must be at least 9");
  detail::require_positive("--end-time", a.end_time);
  return a;
}

constexpr double side = 0.1, thickness = 0.71e-3, clamped_radius = 0.05;
constexpr double sphere_radius = 6.35e-3, sphere_mass = 8.3e-3;
// The sphere starts this fraction of the thickness above the plate's face.
constexpr double start_gap_per_thickness = 0.05;
// Perforated: the sphere's centre is this many radii below the plate and moving down.
constexpr double passed_radii = 1.0;

// 4340 steel: Johnson & Cook (1983), Table 1 (A, B, n, C, m, Tm, ρ, cp) and
// (1985), Table 3 (D1–D5); ε̇0 = 1/s, Tr = 293 K; E, ν of steel.
material::JohnsonCook::Parameters steel_4340() {
  material::JohnsonCook::Parameters p{};
  p.E = 200e9;
  p.nu = 0.29;
  p.A = 792e6;
  p.B = 510e6;
  p.n = 0.26;
  p.C = 0.014;
  p.reference_strain_rate = 1.0;
  p.m = 1.03;
  p.reference_temperature = 293.0;
  p.melting_temperature = 1793.0;
  p.initial_temperature = 293.0;
  p.taylor_quinney = 0.9;
  p.density = 7830.0;
  p.specific_heat = 477.0;
  p.D1 = -0.80;
  p.D2 = 2.10;
  p.D3 = -0.5;
  p.D4 = 0.002;
  p.D5 = 0.61;
  return p;
}

struct Shot {
  double impact = 0.0, residual = 0.0, impulse = 0.0;
  bool perforated = false;
};

Shot fire(const Arguments& a, double speed) {
  using PlateSolver =
      Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::JohnsonCook, crack::LineSegments>;
  using Ball = contact::RigidBody<contact::Sphere, contact::Free>;
  const material::JohnsonCook::Parameters steel = steel_4340();
  std::ostringstream tag;
  tag << speed;
  SolverOptions options;
  options.density = steel.density;
  options.nonlinear = true;
  options.output_directory = a.frames ? a.output + "/frames_" + tag.str() : "";
  options.output_interval = a.frames ? 1e-5 : 0.0;
  options.progress_interval = 0;
  ShellModel model = ShellModel::rectangular_plate(side, side, a.n, a.n, thickness);
  const Vector3 centre(0.5 * side, 0.5 * side, 0.0);
  model.define_set("clamped", [&](const Vector3& x) { return (x - centre).norm() >= clamped_radius - 1e-9; });
  PlateSolver solver(model, steel, options);
  solver.clamp(solver.model().set("clamped"));
  contact::RigidKinematics start;
  start.position = centre + Vector3(0.0, 0.0, sphere_radius + thickness * (0.5 + start_gap_per_thickness));
  start.velocity = Vector3(0.0, 0.0, -speed);
  const double inertia = 0.4 * sphere_mass * sphere_radius * sphere_radius;
  const contact::RigidBodyId ball = solver.add_rigid_body(
      Ball(contact::Sphere(sphere_radius), contact::Free({sphere_mass, Vector3::Constant(inertia), Vector3::Zero()}),
           start));
  solver.add_rigid_body_probe(a.output + "/sphere_" + tag.str() + ".csv", ball);
  const auto wall_start = std::chrono::steady_clock::now();
  solver.run_until(a.end_time);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const contact::RigidBodyState state = solver.rigid_body(ball);
  Shot shot;
  shot.impact = speed;
  shot.impulse = state.contact_impulse.z();
  shot.perforated = state.kinematics.position.z() < -passed_radii * sphere_radius && state.kinematics.velocity.z() < 0.0;
  shot.residual = shot.perforated ? -state.kinematics.velocity.z() : 0.0;
  std::cout << "v_i = " << speed << " m/s: " << (shot.perforated ? "perforated" : "not perforated")
            << ", v_r = " << shot.residual << " m/s, sphere at z = " << state.kinematics.position.z() * 1e3
            << " mm moving at " << state.kinematics.velocity.z() << " m/s, " << solver.damaged_stress_point_count()
            << " failed stress points, crack length " << solver.crack().total_length() * 1e3 << " mm ("
            << solver.steps() << " steps, dt " << solver.time_step() << " s, " << seconds << " s)" << std::endl;
  return shot;
}

// Lambert–Jonas v_r = a (v_i^p − v_bl^p)^(1/p), v_r = 0 below v_bl: for each
// p and v_bl on a grid, a follows by linear least squares; the triple of least
// squared error is kept.
struct LambertJonas {
  double a = 0.0, p = 0.0, ballistic_limit = 0.0, rms = std::numeric_limits<double>::infinity();
  double operator()(double v) const {
    return v <= ballistic_limit ? 0.0 : a * std::pow(std::pow(v, p) - std::pow(ballistic_limit, p), 1.0 / p);
  }
};

constexpr std::size_t minimum_fitted_runs = 3;
constexpr long minimum_fitted_perforations = 2;

LambertJonas fit_lambert_jonas(const std::vector<Shot>& shots) {
  double highest_stopped = 0.0, lowest_perforated = std::numeric_limits<double>::infinity();
  for (const Shot& s : shots) {
    if (s.perforated)
      lowest_perforated = std::min(lowest_perforated, s.impact);
    else
      highest_stopped = std::max(highest_stopped, s.impact);
  }
  LambertJonas best;
  // Three constants: at least three runs, two of them through the plate.
  const auto perforated = std::count_if(shots.begin(), shots.end(), [](const Shot& s) { return s.perforated; });
  if (shots.size() < minimum_fitted_runs || perforated < minimum_fitted_perforations) return best;
  constexpr int limit_steps = 400, exponent_steps = 200;
  constexpr double lowest_exponent = 1.0, highest_exponent = 5.0;
  for (int i = 0; i < limit_steps; ++i) {
    const double limit = highest_stopped + (lowest_perforated - highest_stopped) * i / limit_steps;
    for (int j = 0; j <= exponent_steps; ++j) {
      LambertJonas trial;
      trial.ballistic_limit = limit;
      trial.p = lowest_exponent + (highest_exponent - lowest_exponent) * j / exponent_steps;
      trial.a = 1.0;
      double gg = 0.0, gv = 0.0;
      for (const Shot& s : shots) {
        const double g = trial(s.impact);
        gg += g * g;
        gv += g * s.residual;
      }
      if (!(gg > 0.0)) continue;
      trial.a = gv / gg;
      double squared = 0.0;
      for (const Shot& s : shots) squared += std::pow(trial(s.impact) - s.residual, 2);
      trial.rms = std::sqrt(squared / shots.size());
      if (trial.rms < best.rms) best = trial;
    }
  }
  return best;
}

int run(const Arguments& a) {
  std::filesystem::create_directories(a.output);
  std::cout << "sphere perforation: " << a.n * a.n << " particles, sphere " << sphere_mass * 1e3 << " g, "
            << a.speeds.size() << " speeds" << std::endl;
  std::vector<Shot> shots;
  for (const double speed : a.speeds) shots.push_back(fire(a, speed));
  std::sort(shots.begin(), shots.end(), [](const Shot& x, const Shot& y) { return x.impact < y.impact; });
  const std::string csv = a.output + "/residual.csv";
  io::CsvProbe table(csv, {"v_i [m/s]", "v_r [m/s]", "perforated", "impulse [N s]"});
  io::PlotSeries measured{"runs", {}, {}, io::PlotStyle::points};
  for (const Shot& s : shots) {
    table.write_row({s.impact, s.residual, s.perforated ? 1.0 : 0.0, s.impulse});
    measured.x.push_back(s.impact);
    measured.y.push_back(s.residual);
  }
  std::vector<io::PlotSeries> series{measured};
  const LambertJonas fit = fit_lambert_jonas(shots);
  if (std::isfinite(fit.rms)) {
    io::PlotSeries curve{"Lambert–Jonas fit", {}, {}};
    const double top = shots.back().impact;
    constexpr int curve_points = 100;
    for (int k = 0; k <= curve_points; ++k) {
      const double v = top * k / curve_points;
      curve.x.push_back(v);
      curve.y.push_back(fit(v));
    }
    series.push_back(curve);
    std::cout << "Lambert–Jonas fit: v_bl = " << fit.ballistic_limit << " m/s, a = " << fit.a << ", p = " << fit.p
              << " (rms " << fit.rms << " m/s)\n";
  } else {
    std::cout << "Lambert–Jonas fit: none (it needs at least 3 runs, 2 of them perforating)\n";
  }
  const std::string plot = a.output + "/residual.svg";
  io::write_svg_plot(plot, {{"Residual velocity", "v_i [m/s]", "v_r [m/s]", series}});
  std::cout << "table written to " << csv << ", plot to " << plot << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::optional<Arguments> arguments = parse(argc, argv);
    if (!arguments) return 0;
    return run(*arguments);
  } catch (const std::exception& error) {
    std::cerr << "sphere_perforation: " << error.what() << '\n';
    return 1;
  }
}
