// The clamped spherical cap under an inward step pressure, the classic
// nonlinear shell dynamics benchmark the paper checks its SPH shell against
// (§3, Figs 6-7): apex displacement history.
// `spherical_cap --help` lists the options, their defaults and the files written.

#include <sphshell/sphshell.hpp>

#include "example_arguments.hpp"

#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

using namespace sphshell;

namespace {

struct Arguments {
  bool plastic = false;
  int n = 25;
  double end_time = 1e-3;
  std::string output = "spherical_cap";
  bool frames = false;
};

// Nothing when --help was asked for.
std::optional<Arguments> parse(int argc, char** argv) {
  Arguments arguments;
  example::CommandLine command_line(
      "spherical_cap",
      "The clamped spherical cap of the paper's Figs 6-7: R = 22.27 in = 0.5657 m, d = 0.41 in = 0.010414 m, "
      "half angle 26.67°, E = 72.4 GPa, ν = 0.3, ρ = 2618 kg/m³, inward step pressure 600 psi, geometrically "
      "nonlinear, 5 Gauss points. Prints the apex displacement u/d while running and its peak at the end.");
  command_line.flag("--plastic", arguments.plastic,
                    "the elastoplastic variant (σs0 = 165.5 MPa, tangent modulus Et = 1.448 GPa) instead of "
                    "the elastic cap");
  command_line.integer("--n", arguments.n, "particles along each side of the square grid mapped onto the cap, "
                                           "at least 3 (n × n particles)");
  command_line.number("--end-time", arguments.end_time, "s", "simulated time");
  command_line.output_folder(arguments.output);
  command_line.flag("--frames", arguments.frames,
                    "also write ParaView frames every 50 µs of simulated time (particles.pvd, stress_points.pvd)");
  command_line.writes("apex.csv", "every step: t and the apex displacement along the inward normal, u/d");
  command_line.writes("apex.svg", "chart of u/d over t (paper Fig. 7)");
  command_line.writes("*.pvd, *.vtu", "with --frames: ParaView frames of particles and stress points");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  if (arguments.n < 3) detail::invalid_parameter("--n", arguments.n, "must be at least 3");
  detail::require_positive("--end-time", arguments.end_time);
  return arguments;
}

template <class Material>
int run(const Arguments& arguments, const typename Material::Parameters& parameters) {
  const double radius = 0.5657, thickness = 0.010414, half_angle = 26.67 * M_PI / 180.0;
  const double pressure = 600.0 * 6894.757;
  SolverOptions options;
  options.density = 2618.0;
  options.nonlinear = true;
  options.output_directory = arguments.frames ? arguments.output : "";
  options.output_interval = arguments.frames ? 5e-5 : 0.0;
  Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>, Material> solver(
      ShellModel::spherical_cap(radius, half_angle, arguments.n, thickness), parameters, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("boundary"));
  const ParticleSet all = model.all_particles();
  solver.add_uniform_pressure(all, pressure);  // inward: normals point outward
  const int apex = model.set("apex")[0];
  const std::string csv = arguments.output + "/apex.csv";
  std::filesystem::create_directories(arguments.output);
  io::CsvProbe history(csv, {"t [s]", "u/d [-]"});
  double peak = 0.0, peak_time = 0.0;
  long next_report = 0;
  io::PlotSeries apex_curve{"apex (SPH shell)", {}, {}};
  std::cout << "spherical cap: " << model.particle_count() << " particles, " << model.stress_point_count()
            << " stress points, " << Material::name << ", dt = " << solver.time_step() << " s\n";
  solver.run_until(arguments.end_time, [&](const auto& s) {
    const double u = -s.displacement(apex).dot(model.particle_normal[apex]) / thickness;
    history.write_row({s.time(), u});
    apex_curve.x.push_back(s.time() * 1e3);
    apex_curve.y.push_back(u);
    if (u > peak) {
      peak = u;
      peak_time = s.time();
    }
    if (s.steps() >= next_report) {
      std::cout << "  t = " << s.time() * 1e3 << " ms  apex u/d = " << u << '\n';
      next_report += 100;
    }
  });
  const std::string plot = std::filesystem::path(csv).replace_extension(".svg").string();
  io::write_svg_plot(plot, {{"Apex displacement (paper Fig. 7)", "t [ms]", "u/d [-]", {apex_curve}}});
  std::cout << "peak apex u/d = " << peak << " at t = " << peak_time * 1e3 << " ms; history in " << csv
            << ", plot in " << plot << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::optional<Arguments> parsed = parse(argc, argv);
    if (!parsed) return 0;
    const Arguments& arguments = *parsed;
    const double E = 72.4e9, nu = 0.3;
    if (arguments.plastic) {
      const double Et = 1.448e9;
      return run<material::J2Plasticity>(arguments, {E, nu, 165.5e6, E * Et / (E - Et)});
    }
    return run<material::Elastic>(arguments, {E, nu});
  } catch (const std::exception& error) {
    std::cerr << "spherical_cap: " << error.what() << '\n';
    return 1;
  }
}
