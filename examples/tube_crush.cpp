// Axial crush of a circular aluminium tube between two rigid walls: the tube
// stands on a fixed wall and a wall moving down at a prescribed speed
// flattens it into folds (progressive axisymmetric or diamond buckling). The
// tube is J2-plastic (linear hardening), its ends touch the walls through the
// rigid-body penalty contact (contact/penalty.hpp, Coulomb friction) and its
// folds touch each other through the shell's self contact
// (contact/shell_contact.hpp). The mean crush force is compared with the
// empirical fit of Guillow, Lu & Grzebieta (Int. J. Mech. Sci. 43, 2001,
// 2103–2123) for quasi-static crushing: F_av / M_p = 72.3 (D/t)^0.32,
// M_p = σ0 t² / 4 (docs/validation.md says how close it comes).
// `tube_crush --help` lists the options, their defaults and the files written.

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

constexpr double pi = 3.14159265358979323846;

struct Arguments {
  double diameter = 0.05;
  double thickness = 2e-3;
  double length = 0.06;
  double spacing = 3e-3;
  double speed = 10.0;
  double crush = 0.03;
  double yield_stress = 200e6;
  double hardening = 500e6;
  double friction = 0.2;
  double safety_factor = 0.8;
  double exclusion_spacings = 1.5;
  double patch_spacings = 1.0;
  double contact_stiffness = contact::default_penalty_stiffness_scale;
  bool no_self_contact = false;
  std::string output = "tube_crush";
  bool frames = false;
};

std::optional<Arguments> parse(int argc, char** argv) {
  Arguments a;
  example::CommandLine command_line(
      "tube_crush",
      "A circular aluminium tube (E 70 GPa, ν 0.3, ρ 2700 kg/m³, J2 plasticity with linear hardening) is "
      "crushed axially between a fixed rigid wall and a rigid wall moving down at the given speed (reached "
      "over the first 2 % of the crush). Walls: penalty contact with Coulomb friction; folds: the shell's "
      "self contact. Reports the peak and the mean crush force and Guillow, Lu & Grzebieta's (2001) "
      "F_av = 72.3 (D/t)^0.32 σ0 t²/4.");
  command_line.number("--diameter", a.diameter, "m", "tube mid-surface diameter D");
  command_line.number("--thickness", a.thickness, "m", "wall thickness t");
  command_line.number("--length", a.length, "m", "tube length");
  command_line.number("--spacing", a.spacing, "m", "target particle spacing (around and along the tube)");
  command_line.number("--speed", a.speed, "m/s", "moving wall's speed");
  command_line.number("--crush", a.crush, "m", "crush distance (the moving wall's travel)");
  command_line.number("--yield-stress", a.yield_stress, "Pa", "initial yield stress σ0");
  command_line.number("--hardening", a.hardening, "Pa", "plastic modulus E Et / (E − Et)");
  command_line.number("--friction", a.friction, "", "Coulomb friction coefficient at the walls");
  command_line.number("--safety-factor", a.safety_factor, "", "time step / stable bound, in (0, 1)");
  command_line.number("--exclusion-spacings", a.exclusion_spacings, "",
                      "self contact: material neighbours' reach in spacings (ShellContactOptions::exclusion_spacings)");
  command_line.number("--patch-spacings", a.patch_spacings, "",
                      "self contact: patch radius in spacings (ShellContactOptions::patch_spacings), in (1/√2, "
                      "--exclusion-spacings)");
  command_line.number("--contact-stiffness", a.contact_stiffness, "",
                      "penalty stiffness scale s of walls and self contact (k = s m / dt^2), in (0, 4)");
  command_line.flag("--no-self-contact", a.no_self_contact, "leave the shell's self contact off (folds pass through each other)");
  command_line.output_folder(a.output);
  command_line.flag("--frames", a.frames,
                    "also write ParaView frames every 2 % of the crush (particles.pvd lists the tube and, as "
                    "parts 1 and 2, the walls; stress_points.pvd)");
  command_line.writes("force.csv", "every 10th step: t, crush distance, the moving and the fixed wall's contact "
                                   "force, self contacts, energy absorbed");
  command_line.writes("moving_wall.csv", "the moving wall's probe (Solver::add_rigid_body_probe), every step");
  command_line.writes("force.svg", "chart of the crush force against the crush distance, with the mean and Guillow's fit");
  command_line.writes("*.pvd, *.vtu", "with --frames: ParaView frames of the tube and the walls");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  for (const auto& [name, value] :
       {std::pair{"--diameter", a.diameter}, {"--thickness", a.thickness}, {"--length", a.length},
        {"--spacing", a.spacing}, {"--speed", a.speed}, {"--crush", a.crush}, {"--yield-stress", a.yield_stress}})
    detail::require_positive(name, value);
  detail::require_nonnegative("--hardening", a.hardening);
  detail::require_nonnegative("--friction", a.friction);
  if (!(a.safety_factor > 0.0 && a.safety_factor < 1.0))
    detail::invalid_parameter("--safety-factor", a.safety_factor, "must lie in (0, 1)");
  if (!(a.thickness < 0.2 * a.diameter))
    detail::invalid_parameter("--thickness", a.thickness, "must be below a fifth of --diameter (a thin shell)");
  if (!(a.crush < 0.9 * a.length))
    detail::invalid_parameter("--crush", a.crush, "must be below 90 % of --length");
  if (!(a.spacing <= 0.25 * a.length))
    detail::invalid_parameter("--spacing", a.spacing, "must be at most a quarter of --length");
  return a;
}

constexpr double density = 2700.0;
constexpr double youngs_modulus = 70e9;
constexpr double poisson_ratio = 0.3;
// The wall reaches its speed over this share of the crush: no shock at the start.
constexpr double ramp_share = 0.02;
// Guillow, Lu & Grzebieta (2001), eq. (5): F_av / M_p = 72.3 (D/t)^0.32.
constexpr double guillow_coefficient = 72.3;
constexpr double guillow_exponent = 0.32;
int run(const Arguments& a) {
  using TubeSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, material::J2Plasticity>;
  const double radius = 0.5 * a.diameter;
  const int around = std::max(12, static_cast<int>(std::lround(pi * a.diameter / a.spacing)));
  const int along = std::max(5, static_cast<int>(std::lround(a.length / a.spacing)) + 1);
  SolverOptions options;
  options.density = density;
  options.safety_factor = a.safety_factor;
  options.output_directory = a.frames ? a.output : "";
  const double ramp_time = ramp_share * a.crush / a.speed;
  const double end_time = a.crush / a.speed + 0.5 * ramp_time;  // the ramp loses half its time's travel
  options.output_interval = a.frames ? 0.02 * end_time : 0.0;
  options.progress_interval = 5000;
  TubeSolver solver(ShellModel::cylindrical_panel(radius, a.length, 2.0 * pi, around, along, a.thickness),
                    material::J2Plasticity::Parameters{youngs_modulus, poisson_ratio, a.yield_stress, a.hardening},
                    options);
  // The two halves of a fold lie about a fold length apart along the tube,
  // ≈ 0.99 √(R t) each (Alexander's estimate, about 7 mm here): the self
  // contact must spare fewer neighbours than that, or it lets the fold pass
  // through itself at a coarse spacing.
  // Patches of a whole spacing by default (--patch-spacings): the flanks of
  // a closing fold meet near each other's patch rims, where patches of
  // 0.75 Δ (Σ w down to 0.05 on a regular sheet) let the shares fade as at a
  // sheet's edge (docs/method.md eq. 12.2) and the flanks press deep into
  // each other; patches of Δ overlap to Σ w ≥ 1, so the shares sum to 1
  // wherever the sheet is.
  contact::ShellContactOptions self_contact;
  self_contact.patch_spacings = a.patch_spacings;
  self_contact.exclusion_spacings = a.exclusion_spacings;
  self_contact.stiffness_scale = a.contact_stiffness;
  if (!a.no_self_contact) solver.enable_shell_contact(self_contact);
  // The ends stand square on the walls: their rotations are held (a platen
  // keeps the end ring from tilting), their translations are left to the
  // contact. An end particle touches a wall edge-on, its director along the
  // wall: a free rotation would swing its contact point between its faces.
  const ShellModel& model = solver.model();
  for (const char* end : {"z_min", "z_max"})
    for (int axis = 0; axis < 3; ++axis)
      solver.fix_rotation(model.set(end), Vector3::Unit(axis));

  contact::PenaltyOptions wall_contact;
  wall_contact.friction_coefficient = a.friction;
  wall_contact.stiffness_scale = a.contact_stiffness;
  using FixedWall = contact::RigidBody<contact::Plane, contact::Fixed>;
  solver.add_rigid_body(FixedWall(contact::Plane(Vector3::UnitZ()), contact::Fixed{}), wall_contact);
  const double speed = a.speed;
  const auto wall_velocity = [speed, ramp_time](double t) {
    return Vector3(0.0, 0.0, -speed * std::min(1.0, t / ramp_time));
  };
  contact::RigidKinematics top;
  top.position = Vector3(0.0, 0.0, a.length);
  const contact::RigidBodyId moving = solver.add_rigid_body(
      contact::RigidBody(contact::Plane(-Vector3::UnitZ()), contact::prescribed(wall_velocity), top), wall_contact);
  const contact::RigidBodyId fixed = 0;

  std::filesystem::create_directories(a.output);
  solver.add_rigid_body_probe(a.output + "/moving_wall.csv", moving);
  const std::string csv = a.output + "/force.csv";
  io::CsvProbe history(csv, {"t [s]", "crush [m]", "moving_wall_force [N]", "fixed_wall_force [N]",
                             "self_contacts", "absorbed_energy [J]"});
  const double plastic_moment = a.yield_stress * a.thickness * a.thickness / 4.0;
  const double guillow_force =
      guillow_coefficient * std::pow(a.diameter / a.thickness, guillow_exponent) * plastic_moment;
  std::cout << "tube crush: " << model.particle_count() << " particles (" << around << " around × "
            << along << " along), D " << a.diameter << " m, t " << a.thickness << " m (D/t "
            << a.diameter / a.thickness << "), L " << a.length << " m, σ0 " << a.yield_stress << " Pa, wall at "
            << a.speed << " m/s, self contact " << (a.no_self_contact ? "off" : "on") << ", dt "
            << solver.time_step() << " s" << std::endl;

  double peak_force = 0.0, peak_crush = 0.0, absorbed = 0.0, last_crush = 0.0, last_force = 0.0;
  std::size_t most_self_contacts = 0;
  io::PlotSeries force_series{"moving wall", {}, {}};
  const auto wall_start = std::chrono::steady_clock::now();
  solver.run_until(end_time, [&](const TubeSolver& s) {
    const contact::RigidBodyState wall = s.rigid_body(moving);
    const double crush = a.length - wall.kinematics.position.z();
    // The tube pushes the moving wall up (+z): the crush force.
    const double force = wall.contact_force.z();
    absorbed += 0.5 * (force + last_force) * (crush - last_crush);
    last_crush = crush;
    last_force = force;
    if (force > peak_force) {
      peak_force = force;
      peak_crush = crush;
    }
    const std::size_t self_contacts = s.shell_contact_statistics().contacts;
    most_self_contacts = std::max(most_self_contacts, self_contacts);
    if (s.steps() % 10 != 0) return;
    history.write_row({s.time(), crush, force, -s.rigid_body(fixed).contact_force.z(),
                       static_cast<double>(self_contacts), absorbed});
    force_series.x.push_back(crush * 1e3);
    force_series.y.push_back(force * 1e-3);
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const double mean_force = last_crush > 0.0 ? absorbed / last_crush : 0.0;
  const EnergyReport energy = solver.energy();
  std::cout << "done: " << solver.steps() << " steps in " << seconds << " s\n"
            << "crush distance " << last_crush * 1e3 << " mm\n"
            << "peak crush force " << peak_force * 1e-3 << " kN at " << peak_crush * 1e3 << " mm\n"
            << "mean crush force (energy absorbed / crush distance) " << mean_force * 1e-3 << " kN ("
            << absorbed << " J absorbed)\n"
            << "Guillow, Lu & Grzebieta (2001) F_av = 72.3 (D/t)^0.32 σ0 t²/4 = " << guillow_force * 1e-3
            << " kN: ratio " << mean_force / guillow_force << '\n'
            << "most particles in self contact in a step " << most_self_contacts << '\n'
            << "energy at the end: tube kinetic " << energy.kinetic << " J, internal " << energy.internal
            << " J (plastic dissipation " << energy.plastic_dissipation << " J), contact " << energy.contact_energy
            << " J, friction " << energy.friction_dissipation << " J, balance " << energy.balance() << " J\n";
  io::PlotSeries mean_series{"mean crush force", {0.0, last_crush * 1e3}, {mean_force * 1e-3, mean_force * 1e-3}};
  io::PlotSeries guillow_series{"Guillow et al. (2001)", {0.0, last_crush * 1e3},
                                {guillow_force * 1e-3, guillow_force * 1e-3}};
  const std::string plot = a.output + "/force.svg";
  io::write_svg_plot(plot, {{"Crush force", "crush [mm]", "F [kN]", {force_series, mean_series, guillow_series}}});
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
    std::cerr << "tube_crush: " << error.what() << '\n';
    return 1;
  }
}
