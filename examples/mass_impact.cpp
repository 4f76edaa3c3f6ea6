// A rigid mass dropped on a clamped square mild-steel plate: a free,
// flat-ended rigid cylinder strikes the plate centre (contact/penalty.hpp)
// and the plate deforms plastically (Cowper–Symonds mild steel). The kind of
// test Jones (Thin-Walled Structures 50, 2012, 68–75) compares his
// rigid-plastic theory with; the sizes here are illustrative, not one of the
// tests (docs/validation.md says what is and is not compared).
// `mass_impact --help` lists the options, their defaults and the files written.

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
#include <optional>
#include <string>

using namespace sphshell;

namespace {

struct Arguments {
  int n = 41;
  double side = 0.2;
  double thickness = 2e-3;
  double mass = 2.0;
  double speed = 5.0;
  double striker_radius = 0.0125;
  double end_time = 6e-3;
  std::string output = "mass_impact";
  bool frames = false;
};

std::optional<Arguments> parse(int argc, char** argv) {
  Arguments a;
  example::CommandLine command_line(
      "mass_impact",
      "A free, flat-ended rigid cylinder of the given mass strikes the centre of a clamped square "
      "mild-steel plate (Cowper–Symonds: E 210 GPa, ν 0.3, σ0 235 MPa, Ep 1 GPa, D 40.4 /s, q 5; "
      "ρ 7850 kg/m³) at the given speed, with penalty contact (contact/penalty.hpp, default "
      "stiffness scale). Reports the peak contact force, the largest and the final central deflection "
      "and the striker's rebound speed.");
  command_line.integer("--n", a.n, "particles along each edge, at least 5");
  command_line.number("--side", a.side, "m", "plate side length");
  command_line.number("--thickness", a.thickness, "m", "plate thickness");
  command_line.number("--mass", a.mass, "kg", "striker mass");
  command_line.number("--speed", a.speed, "m/s", "impact speed");
  command_line.number("--striker-radius", a.striker_radius, "m", "radius of the striker's flat end");
  command_line.number("--end-time", a.end_time, "s", "simulated time");
  command_line.output_folder(a.output);
  command_line.flag("--frames", a.frames,
                    "also write ParaView frames every 0.1 ms (particles.pvd lists the plate and, as part 1, "
                    "the striker's surface; stress_points.pvd)");
  command_line.writes("history.csv", "every 5th step: t, striker position and velocity, contact force, "
                                     "central deflection");
  command_line.writes("striker.csv", "the striker's probe (Solver::add_rigid_body_probe), every step");
  command_line.writes("history.svg", "chart of the contact force and the central deflection against time");
  command_line.writes("*.pvd, *.vtu", "with --frames: ParaView frames of the plate and the striker");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  if (a.n < 5) detail::invalid_parameter("--n", a.n, "must be at least 5");
  for (const auto& [name, value] : {std::pair{"--side", a.side}, {"--thickness", a.thickness}, {"--mass", a.mass},
                                    {"--speed", a.speed}, {"--striker-radius", a.striker_radius},
                                    {"--end-time", a.end_time}})
    detail::require_positive(name, value);
  if (!(a.striker_radius < 0.25 * a.side))
    detail::invalid_parameter("--striker-radius", a.striker_radius, "must be below a quarter of --side");
  return a;
}

constexpr double density = 7850.0;
// Mild steel; D = 40.4 /s, q = 5 (Cowper & Symonds 1957, as quoted by Jones,
// Structural Impact, 2012).
const material::CowperSymonds::Parameters mild_steel{210e9, 0.3, 235e6, 1e9, 40.4, 5.0};
// The striker's length, for its drawing and rotational inertia (it is rigid:
// only its mass and inertia act).
constexpr double striker_length_per_radius = 4.0;
// Gap between the striker's face and the plate at the start.
constexpr double start_gap_per_thickness = 0.01;

int run(const Arguments& a) {
  using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::CowperSymonds>;
  using Striker = contact::RigidBody<contact::Cylinder, contact::Free>;
  SolverOptions options;
  options.density = density;
  options.output_directory = a.frames ? a.output : "";
  options.output_interval = a.frames ? 1e-4 : 0.0;
  options.progress_interval = 2000;
  PlateSolver solver(ShellModel::rectangular_plate(a.side, a.side, a.n, a.n, a.thickness), mild_steel, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("boundary"));
  const int centre = model.set("centre")[0];

  // A solid cylinder's principal inertia: m R²/2 about its axis, m (3R² + L²)/12 across.
  const double length = striker_length_per_radius * a.striker_radius;
  const double axial = 0.5 * a.mass * a.striker_radius * a.striker_radius;
  const double across = a.mass * (3.0 * a.striker_radius * a.striker_radius + length * length) / 12.0;
  contact::RigidKinematics start;
  start.position = Vector3(0.5 * a.side, 0.5 * a.side,
                           0.5 * a.thickness * (1.0 + 2.0 * start_gap_per_thickness) + 0.5 * length);
  start.velocity = Vector3(0.0, 0.0, -a.speed);
  const contact::RigidBodyId striker = solver.add_rigid_body(
      Striker(contact::Cylinder({Vector3::UnitZ(), a.striker_radius, length, contact::CylinderEnds::flat}),
              contact::Free({a.mass, Vector3(across, across, axial), Vector3::Zero()}), start));

  std::filesystem::create_directories(a.output);
  solver.add_rigid_body_probe(a.output + "/striker.csv", striker);
  const std::string csv = a.output + "/history.csv";
  io::CsvProbe history(csv, {"t [s]", "striker_z [m]", "striker_vz [m/s]", "contact_force [N]",
                             "central_deflection [m]"});
  std::cout << "mass impact: " << model.particle_count() << " particles, plate " << a.side << " m × " << a.side
            << " m × " << a.thickness << " m, striker " << a.mass << " kg at " << a.speed
            << " m/s (kinetic energy " << 0.5 * a.mass * a.speed * a.speed << " J), dt = " << solver.time_step()
            << " s" << std::endl;

  double peak_force = 0.0, peak_force_time = 0.0, peak_deflection = 0.0, peak_deflection_time = 0.0;
  // The central deflection integrated over time since the striker last touched
  // the plate: its mean is the permanent deflection with the elastic
  // vibration averaged out.
  double free_deflection_time = 0.0, free_time = 0.0;
  bool touched = false;
  io::PlotSeries force{"contact force on the striker", {}, {}};
  io::PlotSeries deflection{"central deflection", {}, {}};
  const auto wall_start = std::chrono::steady_clock::now();
  solver.run_until(a.end_time, [&](const PlateSolver& s) {
    const contact::RigidBodyState body = s.rigid_body(striker);
    const double f = body.contact_force.z();
    const double w = -s.displacement(centre).z();
    if (f > peak_force) {
      peak_force = f;
      peak_force_time = s.time();
    }
    if (body.contacts > 0) {
      touched = true;
      free_deflection_time = free_time = 0.0;
    } else if (touched) {
      free_deflection_time += s.time_step() * w;
      free_time += s.time_step();
    }
    if (w > peak_deflection) {
      peak_deflection = w;
      peak_deflection_time = s.time();
    }
    if (s.steps() % 5 != 0) return;
    history.write_row({s.time(), body.kinematics.position.z(), body.kinematics.velocity.z(), f, w});
    force.x.push_back(s.time() * 1e3);
    force.y.push_back(f * 1e-3);
    deflection.x.push_back(s.time() * 1e3);
    deflection.y.push_back(w * 1e3);
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const contact::RigidBodyState body = solver.rigid_body(striker);
  const EnergyReport energy = solver.energy();
  std::cout << "done: " << solver.steps() << " steps in " << seconds << " s\n"
            << "peak contact force " << peak_force << " N at t = " << peak_force_time * 1e3 << " ms\n"
            << "largest central deflection " << peak_deflection * 1e3 << " mm at t = " << peak_deflection_time * 1e3
            << " ms\n"
            << "central deflection at the end " << -solver.displacement(centre).z() * 1e3 << " mm\n";
  if (free_time > 0.0)
    std::cout << "mean central deflection over the " << free_time * 1e3
              << " ms since the striker left (permanent deflection, vibration averaged out) "
              << free_deflection_time / free_time * 1e3 << " mm\n";
  else
    std::cout << "the striker is still on the plate at the end: no permanent deflection yet\n";
  std::cout << "striker velocity at the end " << body.kinematics.velocity.z() << " m/s (contact impulse "
            << body.contact_impulse.z() << " N s)\n"
            << "energy at the end: plate kinetic " << energy.kinetic << " J, internal " << energy.internal
            << " J (plastic dissipation " << energy.plastic_dissipation << " J), striker kinetic "
            << energy.rigid_body_kinetic << " J, contact " << energy.contact_energy << " J, balance "
            << energy.balance() << " J\n";
  const std::string plot = a.output + "/history.svg";
  io::write_svg_plot(plot, {{"Contact force", "t [ms]", "F [kN]", {force}},
                            {"Central deflection", "t [ms]", "w [mm]", {deflection}}});
  std::cout << "history written to " << csv << ", plot to " << plot << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::optional<Arguments> arguments = parse(argc, argv);
    if (!arguments) return 0;
    return run(*arguments);
  } catch (const std::exception& error) {
    std::cerr << "mass_impact: " << error.what() << '\n';
    return 1;
  }
}
