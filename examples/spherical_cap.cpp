// The clamped spherical cap under an inward step pressure, the classic
// nonlinear shell dynamics benchmark the paper checks its SPH shell against
// (§3, Figs 6-7): apex displacement history, on the O-grid cap builder
// (spherical_cap_ogrid) by default, drawn beside the independent
// axisymmetric shell solution of tests/support/axisymmetric_shell.hpp (the
// reference the validation test test_validation_spherical_cap checks against).
// `spherical_cap --help` lists the options, their defaults and the files written.

#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/svg_plot.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/shell/spherical_cap_ogrid.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "example_arguments.hpp"
#include "support/spherical_cap_case.hpp"

#include <cmath>
#include <filesystem>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

using namespace sphshell;
namespace cap = sphshell::test_support::spherical_cap;

namespace {

// The paper's five Gauss points through the thickness.
using CapRule = thickness::Gauss<5>;

struct Arguments {
  bool plastic = false;
  bool linear = false;
  std::string grid = "ogrid";
  int m = 48;
  int n = 25;
  int reference_elements = 200;
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
      "nonlinear, through-thickness rule " + example::rule_name<CapRule>() +
          ". Prints the apex displacement u/d while running on standard error, then on standard output its "
          "first peak beside that of an independent axisymmetric shell solution, which the chart draws too.");
  command_line.flag("--plastic", arguments.plastic,
                    "the elastoplastic variant (σs0 = 165.5 MPa, tangent modulus Et = 1.448 GPa) instead of "
                    "the elastic cap");
  command_line.flag("--linear", arguments.linear, "linear analysis (small displacements, elastic)");
  command_line.choice("--grid", arguments.grid, {"ogrid", "square"},
                      "ogrid: a central block and rings of well-shaped cells (spherical_cap_ogrid); square: "
                      "a square grid mapped onto the cap (ShellModel::spherical_cap, distorted near the rim)");
  command_line.integer("--m", arguments.m, "O-grid: cells along the central block's side, even, at least 2 "
                                           "(4m cells round each ring)");
  command_line.integer("--n", arguments.n, "square grid: particles along each side, at least 3 (n × n particles)");
  command_line.integer("--reference-elements", arguments.reference_elements,
                       "meridian elements of the axisymmetric reference (0: no reference)");
  command_line.number("--end-time", arguments.end_time, "s", "simulated time");
  command_line.output_folder(arguments.output);
  command_line.flag("--frames", arguments.frames,
                    "also write ParaView frames every 50 µs of simulated time (particles.pvd, stress_points.pvd)");
  command_line.writes("apex.csv", "every step: t and the apex displacement along the inward normal, u/d");
  command_line.writes("reference.csv", "the axisymmetric reference's t and u/d (unless --reference-elements 0)");
  command_line.writes("apex.svg", "chart of u/d over t with the reference beside it (paper Fig. 7)");
  command_line.writes("*.pvd, *.vtu", "with --frames: ParaView frames of particles and stress points");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  if (arguments.n < 3) detail::invalid_parameter("--n", arguments.n, "must be at least 3");
  if (arguments.m < 2 || arguments.m % 2 != 0) detail::invalid_parameter("--m", arguments.m, "must be even and at least 2");
  if (arguments.reference_elements < 0)
    detail::invalid_parameter("--reference-elements", arguments.reference_elements, "must be >= 0");
  if (arguments.plastic && arguments.linear)
    throw Error("--plastic and --linear exclude each other (the linear analysis is elastic)");
  detail::require_positive("--end-time", arguments.end_time);
  return arguments;
}

ShellModel cap_model(const Arguments& arguments) {
  if (arguments.grid == "square")
    return ShellModel::spherical_cap(cap::radius, cap::half_angle, arguments.n, cap::thickness);
  return spherical_cap_ogrid(cap::radius, cap::half_angle, arguments.m, cap::thickness);
}

cap::Case analysis(const Arguments& arguments) {
  if (arguments.plastic) return cap::Case::elastoplastic;
  return arguments.linear ? cap::Case::linear : cap::Case::nonlinear_elastic;
}

template <class Material>
int run(const Arguments& arguments, const typename Material::Parameters& parameters) {
  SolverOptions options;
  options.density = cap::density;
  options.nonlinear = !arguments.linear;
  options.output_directory = arguments.frames ? arguments.output : "";
  options.output_interval = arguments.frames ? 5e-5 : 0.0;
  Solver<approx::MLS<kernel::CubicSpline>, CapRule, Material> solver(cap_model(arguments), parameters,
                                                                                  options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("boundary"));
  const ParticleSet all = model.all_particles();
  // Inward (normals point outward): along the current director, or the
  // reference normal in the linear analysis.
  solver.add_uniform_pressure(all, cap::pressure, time_function::Step{},
                              arguments.linear ? PressureDirection::fixed : PressureDirection::follower);
  const int apex = model.set("apex")[0];
  const std::string csv = arguments.output + "/apex.csv";
  std::filesystem::create_directories(arguments.output);
  io::CsvProbe history(csv, {"t [s]", "u/d [-]"});
  cap::History sph;
  long next_report = 0;
  io::PlotSeries apex_curve{"apex (SPH shell)", {}, {}};
  std::cout << "spherical cap (" << arguments.grid << " grid): " << model.particle_count() << " particles, "
            << model.stress_point_count() << " stress points, " << Material::name << ", "
            << cap::name(analysis(arguments)) << ", dt = " << solver.time_step() << " s (stable "
            << solver.stable_time_step() << " s)" << std::endl;  // before the progress lines on stderr
  solver.run_until(arguments.end_time, [&](const auto& s) {
    const double u = -s.displacement(apex).dot(model.particle_normal[apex]);
    history.write_row({s.time(), u / cap::thickness});
    sph.time.push_back(s.time());
    sph.apex.push_back(u);
    apex_curve.x.push_back(s.time() * 1e3);
    apex_curve.y.push_back(u / cap::thickness);
    if (s.steps() >= next_report) {
      std::clog << "  t = " << s.time() * 1e3 << " ms  apex u/d = " << u / cap::thickness << '\n';
      next_report += 100;
    }
  });
  std::vector<io::PlotSeries> curves{apex_curve};
  const cap::Peak peak = cap::first_peak(sph);
  if (peak.found)
    std::cout << "first apex peak u/d = " << peak.value / cap::thickness << " (" << peak.value * 1e3 << " mm) at t = "
              << peak.time * 1e3 << " ms\n";
  else
    std::cout << "no first apex peak within " << arguments.end_time * 1e3 << " ms\n";
  if (arguments.reference_elements > 0) {
    cap::History reference = cap::reference_history(analysis(arguments), arguments.reference_elements);
    io::CsvProbe reference_csv(arguments.output + "/reference.csv", {"t [s]", "u/d [-]"});
    io::PlotSeries reference_curve{"axisymmetric reference (" + std::to_string(arguments.reference_elements) +
                                       " meridian elements)",
                                   {}, {}, io::PlotStyle::dashed};
    for (std::size_t k = 0; k < reference.time.size() && reference.time[k] <= arguments.end_time; ++k) {
      reference_csv.write_row({reference.time[k], reference.apex[k] / cap::thickness});
      reference_curve.x.push_back(reference.time[k] * 1e3);
      reference_curve.y.push_back(reference.apex[k] / cap::thickness);
    }
    curves.push_back(reference_curve);
    const cap::Peak reference_peak = cap::first_peak(reference);
    std::cout << "reference first peak u/d = " << reference_peak.value / cap::thickness << " ("
              << reference_peak.value * 1e3 << " mm) at t = " << reference_peak.time * 1e3 << " ms";
    if (peak.found)
      std::cout << "; SPH - reference: " << 100.0 * (peak.value / reference_peak.value - 1.0) << " % in value, "
                << 100.0 * (peak.time / reference_peak.time - 1.0) << " % in time";
    std::cout << '\n';
  }
  const std::string plot = std::filesystem::path(csv).replace_extension(".svg").string();
  io::write_svg_plot(plot, {{"Apex displacement (paper Fig. 7)", "t [ms]", "u/d [-]", curves}});
  std::cout << "history in " << csv << ", plot in " << plot << '\n';
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::optional<Arguments> parsed = parse(argc, argv);
    if (!parsed) return 0;
    const Arguments& arguments = *parsed;
    if (arguments.plastic)
      return run<material::J2Plasticity>(arguments, {cap::youngs_modulus, cap::poisson_ratio, cap::yield_stress,
                                                     cap::plastic_modulus});
    return run<material::Elastic>(arguments, {cap::youngs_modulus, cap::poisson_ratio});
  } catch (const std::exception& error) {
    std::cerr << "spherical_cap: " << error.what() << '\n';
    return 1;
  }
}
